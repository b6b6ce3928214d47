//! # splitsum-shaders
//!
//! The math of split-sum image-based lighting, written once. rust-gpu compiles this crate
//! to SPIR-V compute kernels (see [`kernels`]); the same functions compile natively, where
//! the CPU backend and the tests call them. Every texture read that must agree between
//! the two goes through code here (cube maps live in plain buffers and are filtered in
//! software by [`cubemap`]), never through a hardware sampler.
//!
//! Data flow: an equirect environment ([`equirect`]) is resampled to a cube and its mip
//! chain ([`cubemap`]); from it come the GGX-prefiltered specular cube ([`prefilter`]),
//! the diffuse irradiance ([`irradiance`]); the BRDF table ([`lut`]) needs no environment.
//! A renderer's cubes may be baked from a split source, whose brightest texels [`excess`]
//! adds back exactly at every read.
//! [`brdf`] holds the reflectance models, [`sampling`] the sample generators and [`math`]
//! the elementary functions both backends evaluate identically.
#![cfg_attr(not(test), warn(unused_crate_dependencies))]
#![no_std]

pub mod brdf;
pub mod bright;
pub mod calibrate;
pub mod choice;
pub mod cubemap;
pub mod display;
pub mod equirect;
pub mod excess;
pub mod half;
pub mod irradiance;
pub mod kernels;
pub mod lut;
pub mod math;
pub mod prefilter;
pub mod quadrature;
pub mod sampling;
pub mod scene;
pub mod shade;
pub mod surface;
pub mod tonemap;

pub use spirv_std::glam;
