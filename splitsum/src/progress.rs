//! Progress on stderr. Every step of a bake shows a spinner with its elapsed time and its
//! estimate with how far it may be off (made by `crate::estimate`), and the CPU backend's long loops a bar under
//! it; all are drawn by one `indicatif::MultiProgress`. Where stderr is not a terminal
//! (CI logs, pipes), bars are hidden and each step prints one line as it starts instead.
//!
//! A library stays quiet in its caller's terminal: nothing is shown until [`show`] turns it
//! on (the command line does).

use indicatif::{MultiProgress, ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::sync::LazyLock;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

static MULTI: LazyLock<MultiProgress> = LazyLock::new(MultiProgress::new);
static ON: AtomicBool = AtomicBool::new(false);

/// Shows progress on stderr from now on (`false`: hides it again).
pub fn show(on: bool) {
    ON.store(on, Ordering::Relaxed);
}

/// Whether progress is shown (the command line turned it on).
pub fn shown() -> bool {
    ON.load(Ordering::Relaxed)
}

fn interactive() -> bool {
    std::io::stderr().is_terminal()
}

/// Says `message` (a note or a warning) on stderr where progress is shown, and through
/// `log::warn!` otherwise, so that an application's logger gets it.
pub fn note(message: &str) {
    if shown() {
        eprintln!("{message}");
    } else {
        log::warn!("{message}");
    }
}

/// A bar of `len` units named `what`.
pub fn bar(what: &str, len: u64) -> ProgressBar {
    if !shown() {
        return ProgressBar::hidden();
    }
    let bar = MULTI.add(ProgressBar::new(len));
    bar.set_style(
        ProgressStyle::with_template("{prefix:>14} [{bar:30}] {pos}/{len} {elapsed_precise} (eta {eta})").expect("valid template").progress_chars("=> "),
    );
    bar.set_prefix(what.to_string());
    bar
}

/// A step of a run, shown until dropped (nothing at all where progress is not shown: no
/// bar is made, so that a library in a browser, where indicatif's clock does not run,
/// never touches one).
pub struct Step(Option<ProgressBar>);

/// An estimate of a step's wall time (`crate::estimate` makes them).
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize)]
pub struct Estimate {
    /// Seconds.
    pub seconds: f64,
    /// How far it may be off, relative (0.3: ±30 %; infinite where nothing was measured).
    pub within: f64,
}

/// Steps estimated under this (seconds) show no estimate: under load such a step either
/// runs within one slice of the scheduler or waits for the next, and is off by up to 3×.
pub const SHOWN: f64 = 0.1;

/// Starts step `what`, estimated to take `estimate` (if known): shown with how far it may
/// be off where the estimate comes from this device's rates, alone where it does not.
pub fn step(what: &str, estimate: Option<Estimate>) -> Step {
    let est = match estimate {
        Some(e) if e.seconds >= SHOWN && e.within.is_finite() => format!(" (estimate {} ±{:.0} %)", seconds(e.seconds), 100.0 * e.within),
        Some(e) if e.seconds >= SHOWN => format!(" (estimate {}, at built-in rates)", seconds(e.seconds)),
        _ => String::new(),
    };
    if !shown() {
        return Step(None);
    }
    if !interactive() {
        eprintln!("{what}…{est}");
        return Step(None);
    }
    let bar = MULTI.add(ProgressBar::new_spinner());
    bar.set_style(ProgressStyle::with_template("{spinner} {prefix} {elapsed}{msg}").expect("valid template"));
    bar.set_prefix(what.to_string());
    bar.set_message(est);
    bar.enable_steady_tick(Duration::from_millis(120));
    Step(Some(bar))
}

impl Drop for Step {
    fn drop(&mut self) {
        if let Some(bar) = &self.0 {
            bar.finish_and_clear();
        }
    }
}

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
