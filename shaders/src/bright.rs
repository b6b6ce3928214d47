//! The brightest texels of a source level summed exactly, the rest sampled: the sheen
//! cube's filter under a sun of 10⁴–10⁶.
//!
//! A sampled filter reads each sample through a footprint on a source mip (filtered
//! importance sampling, [`crate::prefilter`]). A mip spreads a sun's flux over a texel far
//! wider than the sun, and the footprint is a disc while the sheen lobe is a thin ring
//! about the horizon: samples whose footprint only grazes that texel read the sun where
//! the lobe's weight is nearly zero. On a sky of 1 with a sun of 5·10⁴ (`tests/sheen.rs`),
//! 64–512 samples a texel put the sampled sheen mips 34–204 % off their integral, and
//! capping each sample's level at the one of the lobe's peak density still left 25–148 %.
//!
//! **The split.** The mean is linear in the radiance, so it can be taken in two parts.
//! With `T` the luminance of the `(K + 1)`-th brightest texel of a source level (`K` is
//! the host's `splitsum::backend::split::TEXELS`), each texel `L` brighter than `T` is split
//! into a residual `L·T/lum(L)` and an excess `E = L − L·T/lum(L)`; every other texel is
//! its own residual:
//!
//! ```text
//! L̃(n) = R̃(n) + Σⱼ Eⱼ · pdf(n·lⱼ) · Ωⱼ
//! ```
//!
//! `R̃` is the sampled mean over the residual and its own mips, none of whose texels is
//! brighter than `T`; the sum runs over at most `K` texels `lⱼ` of solid angle `Ωⱼ` with
//! the lobe's normalised density (`sheen::charlie_light_pdf`), so the sun is summed
//! exactly at the level's resolution. The Charlie samples carry weight `1/N` each and all
//! lie above the horizon, so `R̃`'s weights sum to 1 and the excess adds to the sum alone
//! ([`accumulate`]).
//!
//! **Where.** A level splits where its lobe has a width (roughness above 0) that the
//! source resolves ([`splits`]); a sampled level samples the residual, an exact one sums
//! the residual's level of its size. The host picks the split level and `K`
//! (`splitsum::backend::split`).
//!
//! **The ring** (sheen roughness 0, `α → 0`): the mean of the radiance round the great
//! circle `n·l = 0`. Of the residual, a continuous function of `n` (the circle's share of
//! any bounded region moves continuously with it), it is traced at the split level's size
//! and read bilinearly at the output's ([`ring_texel`]); of the excess, each texel is a disc
//! of its solid angle, `ρ = √(Ω/π)`, which the circle at `u = n·l` crosses along a chord
//! `2√(ρ² − u²)`: the texel adds `E·2√(ρ² − u²)/(2π)`. On the sunny sky of
//! `tests/sheen.rs` that is 1.9 % off against 2.9 % for 64 samples of the ring at full
//! size, at a sixteenth of the samples.

use crate::brdf::sheen;
use crate::math::{CompensatedSum4, MeanPartial};
use crate::prefilter::Lobe;
use crate::sampling;
use spirv_std::glam::{Vec3, Vec4};

/// `Vec4`s per entry of the excess list: the texel's direction and solid angle
/// `(l, Ω)`, then its excess radiance.
pub const ENTRY: u32 = 2;

/// Whether a level of `lobe` for `roughness` is split on a source of faces `src_size`: a
/// Charlie level of roughness above 0 whose ring the source resolves (its width at least
/// eight texels of level 0, the rule of [`crate::prefilter::exact_source_size`]), sampled or
/// summed exactly.
#[inline]
pub fn splits(lobe: Lobe, roughness: f32, src_size: u32) -> bool {
    lobe == Lobe::Charlie && roughness > 0.0 && crate::math::PI / (2.0 * src_size as f32) <= 0.125 * sheen::charlie_ring_width(lobe.alpha(roughness))
}

/// A texel `c` of the split level against the threshold `threshold` (a luminance):
/// `(residual, excess)`, the excess zero unless `c` is brighter.
#[inline]
pub fn split_texel(c: Vec4, threshold: f32) -> (Vec4, Vec4) {
    let lum = crate::tonemap::luminance(c.truncate());
    if lum > threshold && lum.is_finite() {
        let keep = (c.truncate() * (crate::math::max(threshold, 0.0) / lum)).extend(c.w);
        (keep, (c.truncate() - keep.truncate()).extend(0.0))
    } else {
        (c, Vec4::ZERO)
    }
}

/// Adds entries `start .. start + count` of the excess list `list` ([`ENTRY`] `Vec4`s each)
/// to the sums `p` of the sheen mean in direction `n` for width `alpha`, once the
/// residual's terms are in: `Eⱼ·pdf(n·lⱼ)·Ωⱼ·W` to the sum, `W` the residual's weight sum
/// (1 to rounding for samples; the lobe's integral over the level for an exact sum),
/// nothing to the weight, so that the mean is `R̃ + Σⱼ Eⱼ·pdf(n·lⱼ)·Ωⱼ` (see the module
/// header).
pub fn accumulate(list: &[Vec4], n: Vec3, alpha: f32, start: u32, count: u32, p: MeanPartial) -> MeanPartial {
    let n = sampling::normalize_or(n, Vec3::Z);
    let total = p.weight.x;
    let mut acc = CompensatedSum4::resume(p.sum, p.carry);
    let mut j = start;
    let end = start + count;
    while j < end {
        let g = list[(ENTRY * j) as usize];
        let w = sheen::charlie_light_pdf(n.dot(g.truncate()), alpha) * g.w * total;
        if w > 0.0 {
            acc.add(list[(ENTRY * j + 1) as usize] * w);
        }
        j += 1;
    }
    let (sum, carry) = acc.parts();
    MeanPartial { sum, carry, weight: p.weight }
}

/// Texel direction `n` of the sheen ring (sheen roughness 0) from a split source (see the
/// module header): the residual's ring, a `ring_size`² one-level cube at the start of
/// `buf`, read bilinearly along `n`, plus the chords of the `count` excess entries that
/// follow it from index `list`.
pub fn ring_texel(buf: &[Vec4], ring_size: u32, list: u32, count: u32, n: Vec3) -> Vec4 {
    let n = sampling::normalize_or(n, Vec3::Z);
    let mut acc = CompensatedSum4::new();
    acc.add(crate::cubemap::sample_bilinear(buf, crate::cubemap::CubeLayout::new(ring_size, 1), 0, n));
    let mut j = 0;
    while j < count {
        let g = buf[(list + ENTRY * j) as usize];
        let u = n.dot(g.truncate());
        let rho2 = g.w * (1.0 / crate::math::PI);
        if u * u < rho2 {
            acc.add(buf[(list + ENTRY * j + 1) as usize] * (crate::math::sqrt(rho2 - u * u) * (1.0 / crate::math::PI)));
        }
        j += 1;
    }
    crate::math::finite4(acc.total())
}
