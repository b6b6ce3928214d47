//! # splitsum
//!
//! Physically based image-based lighting for wgpu applications, on stable Rust. From an HDR
//! environment, splitsum bakes what a PBR renderer reads for the split-sum approximation
//! (Karis 2013, "Real Shading in Unreal Engine 4", §"Image-based lighting"): a cube
//! prefiltered with the GGX lobe at one roughness per mip, the irradiance `E/π` for the
//! diffuse term, and the BRDF table `(A, B)` that turns `F₀` into the specular reflectance —
//! on the caller's own `wgpu::Device` (Vulkan, Metal, DX12, GL: any backend wgpu offers),
//! or natively on the CPU with the same functions.
//!
//! ## A complete application
//!
//! A device of its own, a bake on it, the three textures bound as a renderer binds them,
//! and the files written (`examples/bake.rs`; `tests/library.rs` runs it on Vulkan, on GL
//! and with [`Compute::Cpu`]):
//!
#![cfg_attr(not(test), warn(unused_crate_dependencies))]
#![doc = concat!("```no_run\n", include_str!("../examples/bake.rs"), "\n```")]
//!
//! ## What is where
//!
//! - [`Baker`] bakes into textures on your device ([`Ibl`]: the specular cube with one
//!   roughness per mip, the irradiance cube, the table); [`Ibl::layout_entries`] and
//!   [`Ibl::views`] bind them, [`Ibl::lod`] says which mip a roughness reads, [`Ibl::read`]
//!   brings them back.
//! - [`Settings`] is every knob, with one set of defaults; a field left `None` is derived
//!   ([`Settings::resolve`], the one validation, gives the [`Job`] the bake runs). Errors
//!   name the field ([`Error::Setting`], [`Field`]).
//! - [`environment`] reads `.hdr`, `.exr` and six-face folders, with bounded memory;
//!   [`output::write`] writes the files of a [`Target`] (splitsum's folder, or what the glTF
//!   Sample Viewer, Bevy or Filament load) as a folder replaced whole;
//!   [`low_level::bake`] bakes into host memory on a [`low_level::Backend`] for tools that
//!   need no device of their own.
//! - Every formula lives in `splitsum-shaders` (no_std), compiled by rust-gpu to the SPIR-V
//!   module committed in `splitsum-spirv` and natively for the CPU.
//!
//! The library prints nothing (notes go to the `log` crate). In a debug build of your
//! application compile splitsum optimised (`[profile.dev.package."*"] opt-level = 2`): the
//! CPU backend is several times slower unoptimised.
//!
//! The feature `internals` makes public the modules the `runner` command line, its display
//! and its report are built from (backends' kernels, cache, cost model, progress, file
//! plumbing): they are not part of the stable API. `embedded-environment` embeds the CC0
//! courtyard HDRI the command line shows when given none.

#![warn(missing_docs)]
// On docs.rs (nightly rustdoc, `--cfg docsrs`): each item gated by a feature says which.
#![cfg_attr(docsrs, feature(doc_cfg))]

/// Declares modules public with the `internals` feature and private without it.
macro_rules! internal_modules {
    ($($(#[$meta:meta])* $name:ident;)*) => {
        $(
            $(#[$meta])*
            #[cfg(feature = "internals")]
            pub mod $name;
            $(#[$meta])*
            #[cfg(not(feature = "internals"))]
            #[allow(dead_code, unused_imports)]
            mod $name;
        )*
    };
}

/// Declares one item public with the `internals` feature and visible to the crate alone
/// without it: what the command line, its display and its report need from a public module
/// beyond the stable API.
macro_rules! internal {
    ($(#[$meta:meta])* pub $($item:tt)*) => {
        $(#[$meta])*
        #[cfg(feature = "internals")]
        pub $($item)*
        $(#[$meta])*
        #[cfg(not(feature = "internals"))]
        #[allow(dead_code)]
        pub(crate) $($item)*
    };
}

pub mod environment;
pub mod output;
pub mod progress;
pub mod texture;

internal_modules! {
    adjustment;
    backend;
    bake;
    cache;
    cost;
    error;
    estimate;
    field;
    files;
    host;
    ktx1;
    ktx2;
    measured;
    placement;
    preview;
    product;
    reading;
    settings;
    table;
    textures;
}

pub use error::{Error, Result};
pub use product::{Product, Products};
pub use settings::{Field, Job, Settings, TableMethod, Target};
pub use splitsum_shaders::brdf::microfacet::Masking;
pub use splitsum_shaders::equirect::Facing;
pub use splitsum_shaders::prefilter::RoughnessMapping;
pub use textures::{Baker, Compute, Ibl, IblViews, SheenTextures, Source};

pub mod low_level {
    //! Baking into host memory on a [`Backend`] of splitsum's own, for tools that need no
    //! device of theirs: [`bake()`] and [`bake_batch`] (one device for many environments,
    //! the next read and the last written while one bakes), and what they return.
    pub use crate::adjustment::Adjustment;
    pub use crate::backend::{Backend, BackendKind, Gpu};
    pub use crate::bake::{Baked, Batched, Made, Timing, bake, bake_batch};
}

// The workbench of the command line, its display and its report (`internals`): the names
// they read from the crate root.
#[cfg(feature = "internals")]
pub use crate::{
    backend::{Backend, BackendKind, Gpu},
    bake::{Baked, Batched, Timing, bake, bake_batch, bake_job},
    environment::{Environment, InputReport, InputShape},
    ktx2::Written,
    output::{About, Manifest},
    product::Item,
    texture::Format,
};
#[cfg(feature = "internals")]
pub use splitsum_shaders::{choice::Choice, cubemap::CubeLayout, glam};
