//! # runner
//!
//! The `runner` command line: a thin client of `splitsum` (the bake), `splitsum-display`
//! (scenes, plans, rendering, the viewer) and `splitsum-report` (accuracy against run
//! time), one module per subcommand under [`cli`]. It maps the library's errors to the
//! flags a user wrote.

pub mod cli;

// The crates the subcommands call, under short names.
use splitsum::{Backend, BackendKind, Error, bake, cache, cost, environment, files, ktx2, output, progress, settings};
use splitsum_display::{model, plan, prepare, raster, render, scene, view};
use splitsum_report::report;
