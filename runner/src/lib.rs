//! # runner
//!
//! The host side of splitsum: backends (wgpu GPU and native CPU) that run the
//! `splitsum_shaders` functions, the files that go in and out, and the orchestration of
//! bakes. It holds no BRDF or sampling math: that lives once, in `splitsum_shaders`.

pub mod accuracy;
pub mod backend;
pub mod bake;
pub mod cache;
pub mod cli;
pub mod cpu;
pub mod environment;
pub mod error;
pub mod files;
pub mod gpu;
pub mod ktx2;
pub mod measurement;
pub mod model;
pub mod plan;
pub mod plot;
pub mod preview;
pub mod progress;
pub mod raster;
pub mod render;
pub mod report;
pub mod scene;
pub mod texture;
pub mod view;

pub use backend::{Backend, BackendKind};
pub use error::{Error, Result};
