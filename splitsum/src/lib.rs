//! # splitsum
//!
//! Physically based image-based lighting for wgpu applications, on stable Rust. From an HDR
//! environment, splitsum bakes what a PBR renderer reads for the split-sum approximation
//! (Karis 2013, "Real Shading in Unreal Engine 4", §"Image-based lighting"): a cube
//! prefiltered with the GGX lobe at one roughness per mip, the irradiance `E/π` for the
//! diffuse term, and the BRDF table `(A, B)` that turns `F₀` into the specular reflectance.
//!
//! ```no_run
//! # fn demo(device: &wgpu::Device, queue: &wgpu::Queue) -> splitsum::Result<()> {
//! use splitsum::{Baker, Compute, Settings, Source, environment};
//! let (env, _report) = environment::load(std::path::Path::new("sky.exr"), false)?;
//! let baker = Baker::new(device, queue, Compute::Gpu)?;
//! let ibl = baker.bake(Source::Environment(&env), &Settings::default())?;
//! // Bind ibl.specular (cube, one roughness per mip), ibl.irradiance and ibl.brdf.
//! # Ok(()) }
//! ```
//!
//! The math lives once, in `splitsum-shaders` (no_std): rust-gpu compiles it to the SPIR-V
//! module committed in `splitsum-spirv`, and the same functions compile natively for the
//! CPU backend. Both backends implement [`backend::Kernels`]; [`bake`](mod@bake) is the one bake
//! sequence over them; [`textures`] puts the products into the caller's textures.
//!
//! Modules, in the order data flows: [`environment`] (reading HDR files), [`settings`]
//! (what to bake; one set of defaults, one validation), [`backend`] (CPU and GPU),
//! [`bake`](mod@bake), [`textures`] (the wgpu API), [`output`] and [`ktx2`] (files), [`cache`]
//! (baked products by content), [`cost`] (estimates before a bake runs).

#![warn(missing_docs)]

pub mod adjustment;
pub mod backend;
pub mod bake;
pub mod cache;
pub mod cost;
pub mod environment;
pub mod error;
pub mod field;
pub mod files;
pub mod host;
pub mod ktx1;
pub mod ktx2;
pub mod output;
pub mod preview;
pub mod progress;
pub mod settings;
pub mod texture;
pub mod textures;

pub use backend::{Backend, BackendKind};
pub use bake::{Baked, BakedEnvironment, bake};
pub use environment::Environment;
pub use error::{Error, Result};
pub use settings::{Products, Settings, Target};
pub use textures::{Baker, Compute, Ibl, Source};
