//! # runner
//!
//! The `runner` command line: a thin client of `splitsum` (the bake), `splitsum-display`
//! (scenes, plans, rendering, the viewer) and `splitsum-report` (accuracy against run
//! time), one module per subcommand under [`cli`]. It maps the library's errors to the
//! flags a user wrote.

#![cfg_attr(not(test), warn(unused_crate_dependencies))]
pub mod bars;
pub mod cli;

// The crates the subcommands call, under short names.
use splitsum::{Backend, BackendKind, Error, bake, cache, cost, environment, files, ktx2, output, progress, settings};
use splitsum_display::{model, plan, prepare, render, scene, view};
use splitsum_report::report;

/// Logs warnings and errors to stderr (`RUST_LOG` chooses otherwise): wgpu's and the
/// library's notes when no progress bar shows them.
pub fn log_warnings() {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
}
