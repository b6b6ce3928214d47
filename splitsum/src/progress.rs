//! Progress, as the caller shows it (Filament's `libs/ibl` passes progress in the same way):
//! a bake reports each step as it starts, with its estimate and how far it may be off
//! (made by `crate::estimate`), each long CPU loop as it advances, and its notes, as
//! [`Event`]s to the reporter the caller installs ([`report_to`]). The command line's
//! `indicatif` bars are one such reporter (`runner`'s `progress`).
//!
//! A library stays quiet in its caller's terminal: with no reporter installed nothing is
//! shown, nothing is measured for the estimates, and notes go to the `log` crate.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, RwLock};

/// What a run reports as it goes.
#[derive(Clone, Debug, PartialEq)]
pub enum Event<'a> {
    /// Step `what` starts, expected to take `estimate` (if known).
    Started {
        /// The step, in words.
        what: &'a str,
        /// Its estimated wall time.
        estimate: Option<Estimate>,
    },
    /// Step `what` ended (finished, failed or abandoned).
    Ended {
        /// The step, in words.
        what: &'a str,
    },
    /// A long loop named `what` has done `done` of its `len` units.
    Advanced {
        /// The loop, in words.
        what: &'a str,
        /// Units done.
        done: u64,
        /// Units in all.
        len: u64,
    },
    /// A note or a warning, in words.
    Note(&'a str),
}

/// A reporter: called with every [`Event`], from any thread.
pub type Reporter = dyn Fn(&Event<'_>) + Send + Sync;

static REPORTER: RwLock<Option<Arc<Reporter>>> = RwLock::new(None);

/// Sends events to `reporter` from now on (`None`: to nobody again).
pub fn report_to(reporter: Option<Arc<Reporter>>) {
    *REPORTER.write().unwrap_or_else(|e| e.into_inner()) = reporter;
}

fn reporter() -> Option<Arc<Reporter>> {
    REPORTER.read().unwrap_or_else(|e| e.into_inner()).clone()
}

internal! {
    /// Whether a reporter is installed (the command line installs one).
    pub fn shown() -> bool {
        reporter().is_some()
    }
}

internal! {
    /// Says `message` (a note or a warning) to the reporter, and through `log::warn!` where
    /// there is none, so that an application's logger gets it.
    pub fn note(message: &str) {
        match reporter() {
            Some(r) => r(&Event::Note(message)),
            None => log::warn!("{message}"),
        }
    }
}

internal! {
    /// A long loop of `len` units named `what`: [`Bar::inc`] reports each advance.
    pub struct Bar {
        what: String,
        len: u64,
        done: AtomicU64,
        reporter: Option<Arc<Reporter>>,
    }
}

internal! {
    /// A loop of `len` units named `what`.
    pub fn bar(what: &str, len: u64) -> Bar {
        Bar { what: what.to_string(), len, done: AtomicU64::new(0), reporter: reporter() }
    }
}

impl Bar {
    /// A loop that reports nothing (work whose time is itself measured).
    pub fn hidden() -> Bar {
        Bar { what: String::new(), len: 0, done: AtomicU64::new(0), reporter: None }
    }

    /// `n` more units done.
    pub fn inc(&self, n: u64) {
        if let Some(r) = &self.reporter {
            let done = self.done.fetch_add(n, Ordering::Relaxed) + n;
            r(&Event::Advanced { what: &self.what, done, len: self.len });
        }
    }
}

internal! {
    /// A step of a run, reported until dropped (nothing at all where no reporter is
    /// installed).
    pub struct Step {
        what: String,
        reporter: Option<Arc<Reporter>>,
    }
}

/// An estimate of a step's wall time (`crate::estimate` makes them).
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize)]
pub struct Estimate {
    /// Seconds.
    pub seconds: f64,
    /// How far it may be off, relative (0.3: ±30 %; infinite where nothing was measured).
    pub within: f64,
}

internal! {
    /// Steps estimated under this (seconds) show no estimate: under load such a step either
    /// runs within one slice of the scheduler or waits for the next, and is off by up to 3×.
    pub const SHOWN: f64 = 0.1;
}

impl Estimate {
    /// The estimate as a reporter shows it beside its step: with how far it may be off
    /// where it comes from this device's rates, alone where it does not, and nothing under
    /// 0.1 s (`SHOWN`).
    pub fn describe(&self) -> Option<String> {
        match self.seconds {
            s if s < SHOWN => None,
            s if self.within.is_finite() => Some(format!("estimate {} ±{:.0} %", seconds(s), 100.0 * self.within)),
            s => Some(format!("estimate {}, at built-in rates", seconds(s))),
        }
    }
}

internal! {
    /// Starts step `what`, estimated to take `estimate` (if known).
    pub fn step(what: &str, estimate: Option<Estimate>) -> Step {
        let reporter = reporter();
        if let Some(r) = &reporter {
            r(&Event::Started { what, estimate });
        }
        Step { what: what.to_string(), reporter }
    }
}

impl Drop for Step {
    fn drop(&mut self) {
        if let Some(r) = &self.reporter {
            r(&Event::Ended { what: &self.what });
        }
    }
}

internal! {
    /// `s` seconds in words: `0.04 s`, `2.4 s`, `12 s`, `3.2 min`, `5.1 h`, `12 days`.
    pub fn seconds(s: f64) -> String {
        if s < 1.0 {
            format!("{s:.2} s")
        } else if s < 10.0 {
            format!("{s:.1} s")
        } else if s < 120.0 {
            format!("{s:.0} s")
        } else if s < 7200.0 {
            format!("{:.1} min", s / 60.0)
        } else if s < 172_800.0 {
            format!("{:.1} h", s / 3600.0)
        } else {
            format!("{:.0} days", s / 86400.0)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Mutex;

    /// The events a step, a loop and a note send to the installed reporter, in order, and
    /// nothing once it is removed. (One test: the reporter is the process's.)
    #[test]
    fn a_reporter_gets_every_event_and_nothing_after_it_is_removed() {
        let seen: Arc<Mutex<Vec<String>>> = Arc::default();
        let log = seen.clone();
        report_to(Some(Arc::new(move |e: &Event<'_>| log.lock().unwrap().push(format!("{e:?}")))));
        assert!(shown());
        {
            let _step = step("specular", Some(Estimate { seconds: 2.0, within: 0.3 }));
            let b = bar("rows", 2);
            b.inc(1);
            b.inc(1);
            Bar::hidden().inc(5);
            note("a note");
        }
        report_to(None);
        let _quiet = step("unseen", None);
        assert!(!shown());
        let seen = seen.lock().unwrap().clone();
        assert_eq!(
            seen,
            [
                "Started { what: \"specular\", estimate: Some(Estimate { seconds: 2.0, within: 0.3 }) }",
                "Advanced { what: \"rows\", done: 1, len: 2 }",
                "Advanced { what: \"rows\", done: 2, len: 2 }",
                "Note(\"a note\")",
                "Ended { what: \"specular\" }",
            ]
        );
        assert_eq!(Estimate { seconds: 2.0, within: 0.3 }.describe().as_deref(), Some("estimate 2.0 s ±30 %"));
        assert_eq!(Estimate { seconds: 2.0, within: f64::INFINITY }.describe().as_deref(), Some("estimate 2.0 s, at built-in rates"));
        assert_eq!(Estimate { seconds: 0.05, within: 0.3 }.describe(), None);
    }
}
