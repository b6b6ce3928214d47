//! The command line's progress: the library's events (`splitsum::progress::Event`) drawn on
//! stderr by one `indicatif::MultiProgress`, a spinner per step with its elapsed time and
//! its estimate, and a bar per long CPU loop under it. Where stderr is not a terminal (CI
//! logs, pipes) each step prints one line as it starts instead, and loops print nothing.

use indicatif::{MultiProgress, ProgressBar, ProgressStyle};
use splitsum::progress::Event;
use std::collections::HashMap;
use std::io::IsTerminal;
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// Draws the library's progress on stderr from now on.
pub fn install() {
    let terminal = Terminal { multi: MultiProgress::new(), interactive: std::io::stderr().is_terminal(), steps: Mutex::default(), loops: Mutex::default() };
    splitsum::progress::report_to(Some(Arc::new(move |e: &Event<'_>| terminal.on(e))));
}

struct Terminal {
    multi: MultiProgress,
    interactive: bool,
    /// The steps running, innermost last.
    steps: Mutex<Vec<(String, ProgressBar)>>,
    /// The loops running, by name.
    loops: Mutex<HashMap<String, ProgressBar>>,
}

impl Terminal {
    fn on(&self, e: &Event<'_>) {
        match *e {
            Event::Started { what, estimate } => {
                let est = estimate.and_then(|e| e.describe()).map(|d| format!(" ({d})")).unwrap_or_default();
                if !self.interactive {
                    eprintln!("{what}…{est}");
                    return;
                }
                let bar = self.multi.add(ProgressBar::new_spinner());
                bar.set_style(ProgressStyle::with_template("{spinner} {prefix} {elapsed}{msg}").expect("valid template"));
                bar.set_prefix(what.to_string());
                bar.set_message(est);
                bar.enable_steady_tick(Duration::from_millis(120));
                self.steps.lock().unwrap_or_else(|e| e.into_inner()).push((what.to_string(), bar));
            }
            Event::Ended { what } => {
                let mut steps = self.steps.lock().unwrap_or_else(|e| e.into_inner());
                if let Some(i) = steps.iter().rposition(|(w, _)| w == what) {
                    steps.remove(i).1.finish_and_clear();
                }
            }
            Event::Advanced { what, done, len } => {
                if !self.interactive {
                    return;
                }
                let mut loops = self.loops.lock().unwrap_or_else(|e| e.into_inner());
                // Called for every row of a loop: the name is copied only when its bar is made.
                if !loops.contains_key(what) {
                    let bar = self.multi.add(ProgressBar::new(len));
                    bar.set_style(
                        ProgressStyle::with_template("{prefix:>14} [{bar:30}] {pos}/{len} {elapsed_precise} (eta {eta})")
                            .expect("valid template")
                            .progress_chars("=> "),
                    );
                    bar.set_prefix(what.to_string());
                    loops.insert(what.to_string(), bar);
                }
                let bar = &loops[what];
                bar.set_length(len);
                bar.set_position(done);
                if done >= len
                    && let Some(bar) = loops.remove(what)
                {
                    bar.finish_and_clear();
                }
            }
            Event::Note(message) => eprintln!("{message}"),
        }
    }
}
