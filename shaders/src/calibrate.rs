//! The calibration kernel's work: what a device does per second on the three kinds of work
//! a bake is made of, for the cost model of `runner bench` (`splitsum::cost::Machine`).
//! Each mode reads the same buffers the same way the bake's steps do, with as little else
//! as possible, so that its rate is the device's limit for that kind of work:
//!
//! - [`Rate::Filtered`]: texel reads through the seamless trilinear cube lookup
//!   (`cubemap::sample_lod`, 8 reads each) at directions that move across a texel's
//!   neighbourhood, as the GGX samples of a prefilter do;
//! - [`Rate::Summed`]: texel reads of a level in order, every invocation reading the same
//!   texel at the same time, as the exact sums of the irradiance and the rough mips do;
//! - [`Rate::Arithmetic`]: multiply–adds in four independent chains of four lanes (32
//!   floating-point operations a step), no memory.

use crate::cubemap::{self, CubeLayout};
use crate::math;
use spirv_std::glam::{Vec3, Vec4};

/// The kind of work a calibration measures.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
#[repr(u32)]
pub enum Rate {
    /// Texel reads inside trilinear cube lookups.
    Filtered = 0,
    /// Texel reads of a summed level, in order.
    Summed = 1,
    /// Floating-point operations.
    Arithmetic = 2,
}

impl Rate {
    /// The mode of code `c` (an unknown code is `Arithmetic`).
    pub fn from_u32(c: u32) -> Self {
        match c {
            0 => Rate::Filtered,
            1 => Rate::Summed,
            _ => Rate::Arithmetic,
        }
    }

    /// Units of work one step of a [`texel`] loop does: texel reads, or floating-point
    /// operations.
    pub const fn per_step(self) -> u32 {
        match self {
            Rate::Filtered => 8,
            Rate::Summed => 1,
            Rate::Arithmetic => 32,
        }
    }
}

/// Texel `(face, x, y)` of a `size`² calibration output: `count` steps of work `rate` over
/// `src` (a cube of `layout`). The result is written so no compiler can drop the work.
pub fn texel(src: &[Vec4], layout: CubeLayout, rate: Rate, face: u32, x: u32, y: u32, size: u32, count: u32) -> Vec4 {
    let mut acc = Vec4::ZERO;
    let mut k = 0u32;
    match rate {
        Rate::Filtered => {
            let n = cubemap::texel_dir(face, x, y, size);
            let spread = 4.0 / size as f32;
            while k < count {
                let t = (k as f32 + 0.5) / count as f32;
                let d = n + Vec3::new(t - 0.5, 0.5 - t, t * t - 0.25) * spread;
                acc += cubemap::sample_lod(src, layout, d, t);
                k += 1;
            }
        }
        Rate::Summed => {
            // A range the size of a summed level with its geometry (2·6·16² texels, 48 KiB):
            // as cache-resident as the bake's sums are.
            let m = if layout.texel_count() < 3072 { layout.texel_count() } else { 3072 };
            let mut i = 0u32;
            while k < count {
                acc += src[i as usize];
                i += 1;
                if i == m {
                    i = 0;
                }
                k += 1;
            }
        }
        Rate::Arithmetic => {
            // Four independent chains of four lanes, so that the rate is the units'
            // throughput, not one chain's latency.
            let v = Vec4::new(x as f32, y as f32, face as f32, 1.0) * 1e-3;
            let (mut v0, mut v1, mut v2, mut v3) = (v, v + Vec4::ONE, v * 0.5, v + Vec4::splat(2.0));
            let a = Vec4::splat(0.999_9);
            let b = Vec4::splat(math::FRAC_1_PI * 1e-4);
            while k < count {
                v0 = v0 * a + b;
                v1 = v1 * a + b;
                v2 = v2 * a + b;
                v3 = v3 * a + b;
                k += 1;
            }
            acc = v0 + v1 + v2 + v3;
        }
    }
    acc
}
