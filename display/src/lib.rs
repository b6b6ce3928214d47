//! # splitsum-display
//!
//! Shows what splitsum bakes. A scene file ([`scene`]) names an environment, materials,
//! objects, lights and a camera; [`plan`] decides what of the bake the scene needs (and
//! leaves the rest out); [`prepare`] bakes that plan or takes it from the cache. The same
//! shading (`splitsum_shaders::shade`) is drawn by wgpu ([`render`], in a window by
//! `view`, natively) and by a CPU rasteriser ([`raster`]) that checks it; [`model`] reads glTF.
//!
//! Depends on `splitsum` (the bake) and nothing above it.

#![cfg_attr(not(test), warn(unused_crate_dependencies))]
#![warn(missing_docs)]

pub mod model;
pub mod plan;
pub mod prepare;
pub mod raster;
pub mod render;
pub mod scene;
/// The window (winit): native systems only; a web page draws with [`render`] on its canvas.
#[cfg(not(target_arch = "wasm32"))]
pub mod view;
