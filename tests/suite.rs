//! splitsum's integration tests, one module per subject, in one binary. `bash scripts/dev.sh
//! test` runs them all, then the GPU subjects again on wgpu's GL backend
//! (`cargo test --test suite -- prefilter:: lut:: …`).

mod architecture;
mod book;
mod choices;
mod cli;
mod commands;
mod equirect;
mod excess;
mod files;
mod fuzz;
mod irradiance;
mod library;
mod lut;
mod model;
mod plan;
mod portability;
mod prefilter;
mod public_api;
mod render;
mod report;
mod sample_viewer;
mod shading;
mod sheen;
mod stability;
mod targets;
mod web;
