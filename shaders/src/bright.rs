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
//! **Traced coarse.** The residual's mean is a continuous function of `n`, smooth at the
//! scale of the lobe's band, which is at least four texels of the split level wide. So a
//! level finer than the split level is traced at the split level's size and read
//! bilinearly at its own, and only the excess is summed at every output texel
//! ([`traced_texel`]): mip 1 of a 256² cube (128²) takes a quarter of its samples, and the
//! sunny sky of `tests/sheen.rs` kept its 0.46 % mean there.
//!
//! **The density, tabulated.** Every texel of a split level adds every entry, and the
//! density's power, `(1 − n·l)^(1/(2α))`, was most of that cost (on the CPU, at mip 1, more
//! than the residual's samples). The density depends on `u = n·l` alone, one function per
//! level, so a level reads it from a table of its values at `u = i/N`, `N` =
//! [`DENSITY_STEPS`] ([`density_table_entry`], made once per level from
//! `sheen::charlie_light_pdf` itself), interpolated linearly ([`excess_density`]). The
//! table follows the entries in a traced level's buffer ([`traced_texel`]) and precedes
//! them in the list of a level summed at its own texels ([`accumulate`], [`list_start`]).
//! It is off by at most `h²/8·max|pdf''|` (`h = 1/N`), about `1.05·10⁻⁸·k²` of the
//! density's peak for `k = 1/(2α)` above 2, so it is read only where `k ≤ 32` (sheen
//! roughness 0.125 and up: at most 1.1·10⁻⁵ of the peak; 1.6·10⁻⁶ at 0.2, the default
//! mip 1) and `u ≤ 63/64`; nearer the normal, where `(1 − u)^k` has an unbounded second
//! derivative for `k < 2` (and the density is small), and at sharper levels, the density
//! is computed. `shaders/tests/sheen.rs` checks the bound against the f64 density. Below
//! the horizon the density is exactly 0.
//!
//! **The ring** (sheen roughness 0, `α → 0`): the mean of the radiance round the great
//! circle `n·l = 0`, always traced coarse. Of the excess, each texel is a disc of its
//! solid angle, `ρ = √(Ω/π)`, which the circle at `u = n·l` crosses along a chord
//! `2√(ρ² − u²)`: the texel adds `E·2√(ρ² − u²)/(2π)`, centred on the excess's centroid
//! within the texel. On the sunny sky of `tests/sheen.rs` that is 0.48 % off (1.9 % with
//! each disc at its texel's centre; 2.9 % for 64 samples of the ring at full size), at a
//! sixteenth of the samples.

use crate::brdf::sheen;
use crate::math::{CompensatedSum4, MeanPartial};
use crate::prefilter::Lobe;
use crate::sampling;
use spirv_std::glam::{Vec3, Vec4};

/// `Vec4`s per entry of the excess list: a direction and the texel's solid angle `(l, Ω)`
/// (the host puts `l` at the centroid of the excess within the texel), then its excess
/// radiance.
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

/// Intervals of the density table over `u = n·l ∈ [0, 1]` (see the module header).
pub const DENSITY_STEPS: u32 = 8192;

/// Entries of the density table: its intervals up to `u` = 63/64 ([`excess_density`]).
pub const DENSITY_ENTRIES: u32 = DENSITY_STEPS / 64 * 63;

/// Whether a level of width `alpha` reads its density from a table (see the module
/// header): `k = 1/(2α) ≤ 32`, where the interpolation is within 1.1·10⁻⁵ of its peak.
#[inline]
pub fn tabulates(alpha: f32) -> bool {
    alpha >= 1.0 / 64.0
}

/// Entry `i` of the density table for width `alpha`: the density
/// (`sheen::charlie_light_pdf`) at both ends of interval `i`, `(pdf(i/N), pdf((i + 1)/N),
/// 0, 0)` with `N` = [`DENSITY_STEPS`], so that a lookup reads one entry.
#[inline]
pub fn density_table_entry(i: u32, alpha: f32) -> Vec4 {
    let h = 1.0 / DENSITY_STEPS as f32;
    Vec4::new(sheen::charlie_light_pdf(i as f32 * h, alpha), sheen::charlie_light_pdf((i + 1) as f32 * h, alpha), 0.0, 0.0)
}

/// The density table of a level of width `alpha`: its [`DENSITY_ENTRIES`] entries in
/// order where it [`tabulates`], else none.
#[cfg(not(target_arch = "spirv"))]
pub fn density_table(alpha: f32) -> impl Iterator<Item = Vec4> {
    let n = if tabulates(alpha) { DENSITY_ENTRIES } else { 0 };
    (0..n).map(move |i| density_table_entry(i, alpha))
}

/// The sheen prefilter's density (`sheen::charlie_light_pdf`) at `u = n·l` for width
/// `alpha`, read from the level's table at index `table` of `buf` where the level
/// [`tabulates`] and `u ≤ 63/64`, interpolated linearly; computed elsewhere.
#[inline]
pub fn excess_density(buf: &[Vec4], table: u32, u: f32, alpha: f32) -> f32 {
    if tabulates(alpha) && u <= 63.0 / 64.0 {
        let t = crate::math::saturate(u) * DENSITY_STEPS as f32;
        let i = crate::math::min(crate::math::floor(t), (DENSITY_ENTRIES - 1) as f32);
        let e = buf[(table + i as u32) as usize];
        e.x + (e.y - e.x) * (t - i)
    } else {
        sheen::charlie_light_pdf(u, alpha)
    }
}

/// Where a level of width `alpha` finds entry 0 of the excess list in the buffer
/// [`accumulate`] reads: after its density table ([`density_table`]) where it
/// [`tabulates`], else at the start.
#[inline]
pub fn list_start(alpha: f32) -> u32 {
    if tabulates(alpha) { DENSITY_ENTRIES } else { 0 }
}

/// Adds entries `start .. start + count` of the excess list ([`ENTRY`] `Vec4`s each, from
/// [`list_start`] in `list`, after the level's density table if it has one) to the sums `p`
/// of the sheen mean in direction `n` for width `alpha`, once the residual's terms are in:
/// `Eⱼ·pdf(n·lⱼ)·Ωⱼ·W` to the sum (the density by [`excess_density`]), `W` the residual's
/// weight sum (1 to rounding for samples; the lobe's integral over the level for an exact
/// sum), nothing to the weight, so that the mean is `R̃ + Σⱼ Eⱼ·pdf(n·lⱼ)·Ωⱼ` (see the
/// module header).
pub fn accumulate(list: &[Vec4], n: Vec3, alpha: f32, start: u32, count: u32, p: MeanPartial) -> MeanPartial {
    let n = sampling::normalize_or(n, Vec3::Z);
    let total = p.weight.x;
    let base = list_start(alpha);
    let mut acc = CompensatedSum4::resume(p.sum, p.carry);
    let mut j = start;
    let end = start + count;
    while j < end {
        let g = list[(base + ENTRY * j) as usize];
        let u = n.dot(g.truncate());
        let w = if u > 0.0 { excess_density(list, 0, u, alpha) * g.w * total } else { 0.0 };
        if w > 0.0 {
            acc.add(list[(base + ENTRY * j + 1) as usize] * w);
        }
        j += 1;
    }
    let (sum, carry) = acc.parts();
    MeanPartial { sum, carry, weight: p.weight }
}

/// Texel direction `n` of a level traced coarser than its size (see the module header):
/// the residual's mean, a `size`² one-level cube at the start of `buf`, read bilinearly
/// along `n`, plus the `count` excess entries that follow it from index `list`: on the ring
/// (`ring`, sheen roughness 0) the chord the circle cuts through each entry's disc,
/// elsewhere its density term `Eⱼ·pdf(n·lⱼ)·Ωⱼ` for width `alpha` (the term [`accumulate`]
/// adds), the density read from the level's table where it has one ([`excess_density`]),
/// which follows the entries.
pub fn traced_texel(buf: &[Vec4], size: u32, list: u32, count: u32, n: Vec3, alpha: f32, ring: bool) -> Vec4 {
    let n = sampling::normalize_or(n, Vec3::Z);
    let table = list + ENTRY * count;
    let mut acc = CompensatedSum4::new();
    acc.add(crate::cubemap::sample_bilinear(buf, crate::cubemap::CubeLayout::new(size, 1), 0, n));
    let mut j = 0;
    while j < count {
        let g = buf[(list + ENTRY * j) as usize];
        let u = n.dot(g.truncate());
        let w = if ring {
            let rho2 = g.w * (1.0 / crate::math::PI);
            if u * u < rho2 { crate::math::sqrt(rho2 - u * u) * (1.0 / crate::math::PI) } else { 0.0 }
        } else if u > 0.0 {
            excess_density(buf, table, u, alpha) * g.w
        } else {
            0.0
        };
        if w > 0.0 {
            acc.add(buf[(list + ENTRY * j + 1) as usize] * w);
        }
        j += 1;
    }
    crate::math::finite4(acc.total())
}

/// Texels a side of a tile of the ring's output (the traced kernel's workgroup), each tile
/// listing the excess entries whose chords reach it ([`ring_tile_reached`]).
pub const RING_TILE: u32 = 8;

/// Tiles a side of a face of a `size`-wide ring output.
#[inline]
pub fn ring_tiles(size: u32) -> u32 {
    size.div_ceil(RING_TILE)
}

/// The tile that texel `(x, y)` of `face` of a `size`-wide ring output lies in, counted
/// face by face, row by row.
#[inline]
pub fn ring_tile(face: u32, x: u32, y: u32, size: u32) -> u32 {
    let t = ring_tiles(size);
    (face * t + y / RING_TILE) * t + x / RING_TILE
}

/// Whether excess entry `g` (`(l, Ω)`, [`ENTRY`]'s first `Vec4`) adds a chord anywhere
/// in tile `(face, tx, ty)` of a `size`-wide ring output: whether some direction of the
/// tile lies within `ρ = √(Ω/π)` of the plane `n·l = 0`. The tile's directions lie in the
/// cone about its centre `c` whose half-angle `β` reaches its farthest corner (a spherical
/// quadrilateral is convex, so a corner is the farthest point); the disc's chord band is
/// `γ = asin ρ` wide each side of the circle. So the band reaches the tile where the
/// centre lies within `β + γ` of the circle: `|c·l| ≤ sin(β + γ) = sin β cos γ + cos β sin γ`
/// (always, once `β + γ ≥ π/2`). Conservative, and a texel out of reach adds no chord, so
/// the tile's list gives each texel the same sum as the whole list.
pub fn ring_tile_reached(face: u32, tx: u32, ty: u32, size: u32, g: Vec4) -> bool {
    ring_cone_reached(ring_tile_cone(face, tx, ty, size), g)
}

/// The cone of [`ring_tile_reached`] for tile `(face, tx, ty)` of a `size`-wide ring
/// output: its centre `c` and `cos β`, β the angle to its farthest corner. The same for
/// every entry, so a table of the tiles makes it once per tile.
pub fn ring_tile_cone(face: u32, tx: u32, ty: u32, size: u32) -> Vec4 {
    let s = size as f32;
    let (x0, y0) = ((tx * RING_TILE) as f32, (ty * RING_TILE) as f32);
    let (x1, y1) = (crate::math::min(x0 + RING_TILE as f32, s), crate::math::min(y0 + RING_TILE as f32, s));
    let c = crate::cubemap::face_uv_to_dir(face, spirv_std::glam::Vec2::new(0.5 * (x0 + x1) / s, 0.5 * (y0 + y1) / s));
    let mut cos_beta = 1.0f32;
    let mut k = 0;
    while k < 4 {
        let corner = spirv_std::glam::Vec2::new(if k & 1 == 0 { x0 } else { x1 }, if k < 2 { y0 } else { y1 }) / s;
        cos_beta = crate::math::min(cos_beta, c.dot(crate::cubemap::face_uv_to_dir(face, corner)));
        k += 1;
    }
    c.extend(crate::math::clamp(cos_beta, -1.0, 1.0))
}

/// Whether excess entry `g` adds a chord anywhere in the tile of cone `cone`
/// ([`ring_tile_cone`]): [`ring_tile_reached`]'s test.
pub fn ring_cone_reached(cone: Vec4, g: Vec4) -> bool {
    match ring_reach(cone.w, g.w) {
        Some(reach) => crate::math::abs(cone.truncate().dot(g.truncate())) <= reach,
        None => true,
    }
}

/// How far `|c·l|` may be for an entry of solid angle `omega` to reach a tile whose cone
/// has `cos β` ([`ring_tile_reached`]): `sin(β + γ)`, with a margin of 10⁻³ for rounding (a
/// tile kept too many is only slower); `None` where every entry reaches it (`β + γ ≥ π/2`).
#[inline]
fn ring_reach(cos_beta: f32, omega: f32) -> Option<f32> {
    let sin_beta = crate::math::sqrt(1.0 - cos_beta * cos_beta);
    let sin_gamma = crate::math::min(crate::math::sqrt(crate::math::max(omega, 0.0) * (1.0 / crate::math::PI)), 1.0);
    let cos_gamma = crate::math::sqrt(1.0 - sin_gamma * sin_gamma);
    if cos_beta * cos_gamma - sin_beta * sin_gamma <= 0.0 {
        return None;
    }
    Some(sin_beta * cos_gamma + cos_beta * sin_gamma + 1e-3)
}

/// The expected number of `entries` excess entries of solid angle `omega` whose chords
/// reach tile `(face, tx, ty)` of a `size`-wide ring output, their directions taken as
/// uniform on the sphere: then `c·l` is uniform on [−1, 1], so each reaches it with
/// chance `min(sin(β + γ), 1)` ([`ring_tile_reached`]'s reach). For the cost model,
/// which cannot know the sky's entries before the bake (the tables hold 0.93–1.09 of this
/// on the eight vendored skies at 256², studio.exr at 512², sunset.exr at 128² and
/// city.exr at 64² and 1024²).
pub fn ring_tile_expected(face: u32, tx: u32, ty: u32, size: u32, entries: u32, omega: f32) -> f32 {
    let chance = ring_reach(ring_tile_cone(face, tx, ty, size).w, omega).map_or(1.0, |r| crate::math::min(r, 1.0));
    entries as f32 * chance
}
