//! GGX-prefiltered specular radiance, one roughness per mip (Karis 2013, "Real Shading in
//! Unreal Engine 4", eq. 7 and `PrefilterEnvMap`; LearnOpenGL "Specular IBL").
//!
//! The first sum of the split-sum approximation, with `n = v = r` (the lobe is assumed
//! isotropic about the reflection direction):
//!
//! `L̃(r) = Σ L(lₖ)(n·lₖ) / Σ (n·lₖ)`, `hₖ ~ D(h)(n·h)`, `lₖ = reflect(v, hₖ)`.
//!
//! **Source-mip selection against fireflies** (Colbert & Křivánek 2007, GPU Gems 3 ch. 20,
//! "filtered importance sampling"; Filament `cmgen`): each sample reads the source cube at
//! `lod = ½·log₂(Ωₛ/Ωₚ) + bias`, where `Ωₛ = 1/(N·pdf(l))` is the solid angle the sample
//! stands for and `Ωₚ = 4π/(6s²)` the mean solid angle of a source texel. With `n = v`,
//! `pdf(l) = D(h)(n·h)/(4 v·h) = D(h)/4`. A sun one texel wide is then seen through a
//! filter as wide as the sample spacing instead of being hit or missed.
//!
//! **Roughness 0** is a mirror: the result is the source itself (copied exactly where the
//! output level has the source's resolution).
//!
//! **Exact sums for rough mips.** A rough lobe spans many texels of a coarse source level,
//! so the same mean can be summed exactly over every texel of that level,
//! `L̃ = Σⱼ Lⱼ D(hⱼ)(n·lⱼ)Ωⱼ / Σⱼ D(hⱼ)(n·lⱼ)Ωⱼ`, `hⱼ = (n + lⱼ)/|n + lⱼ|`, with no sampling
//! noise. [`exact_source_size`] picks the level (eight texels per `α`), and [`prefers_exact`]
//! takes the exact sum where its `6t²` terms cost less than the samples (a sample costs
//! about eight texel terms: a trilinear lookup and the GGX terms).
//!
//! **The sheen cube** ([`Lobe::Charlie`]) is the same mean with the Charlie distribution
//! in place of GGX (glTF-IBL-Sampler's `-distribution Charlie`): its samples and weights
//! are `brdf::sheen`'s ([`charlie_sample`]). It has no mirror: at sheen roughness 0 the lobe
//! is the horizon ring, which its samples trace. Its other sampled levels read a split
//! source: the brightest texels summed exactly, the rest sampled (`crate::bright`).

use crate::brdf::{alpha_from_roughness, microfacet, sheen};
use crate::cubemap::{self, CubeLayout};
use crate::math::{self, MeanPartial};
use crate::sampling;
use spirv_std::glam::{Vec2, Vec3, Vec4};

/// How the mips of the prefiltered cube map to roughness.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
#[repr(u32)]
pub enum RoughnessMapping {
    /// `r = m / (M − 1)` (UE4, LearnOpenGL).
    Linear = 0,
    /// `r = (m / (M − 1))²`: more mips at low roughness, where the lobe changes fastest.
    Quadratic = 1,
    /// Mip 0 the mirror; mip 1 at `α₁ = 2^(−M)`, then `α` in geometric progression up to
    /// `α = 1` (r = 1) at the last mip: `α_m = α₁^((M−1−m)/(M−2))`. With `M = log₂ s₀ − 2`
    /// (mips down to 8²; the default), `α₁ = 4/s₀`: mip 1 holds its lobe at two of its
    /// texels, and the lobe grows faster than the texels shrink from there on, so every
    /// mip resolves its lobe (Filament's and Bevy's log-roughness mappings aim for the
    /// same). Between the mirror and mip 1, `α` is interpolated linearly; above, `log α`.
    Geometric = 2,
    /// `r = 1 − √(1 − m/(M − 1))`, the inverse of Filament's `lod = (M − 1)·r·(2 − r)`
    /// (cmgen `lodToPerceptualRoughness`; Filament `perceptualRoughnessToLod` in
    /// `shaders/src/light_indirect.fs`), a quadratic fit of `log₂ r` for a 256² cube with 5
    /// mips.
    Filament = 3,
}

impl RoughnessMapping {
    /// Roughness of mip `mip` out of `mips`.
    #[inline]
    pub fn roughness(self, mip: u32, mips: u32) -> f32 {
        if mips <= 1 {
            return 0.0;
        }
        let t = mip as f32 / (mips - 1) as f32;
        match self {
            Self::Linear => t,
            Self::Quadratic => t * t,
            Self::Filament => 1.0 - math::sqrt(math::max(1.0 - t, 0.0)),
            Self::Geometric => {
                if mip == 0 {
                    0.0
                } else if mips <= 2 {
                    1.0
                } else {
                    // r = √α = 2^(−M(M−1−m) / (2(M−2)))
                    let m = mips as f32;
                    math::exp2(-m * (m - 1.0 - mip as f32) / (2.0 * (m - 2.0)))
                }
            }
        }
    }

    /// The fractional mip holding roughness `roughness`, for trilinear lookup.
    #[inline]
    pub fn lod(self, roughness: f32, mips: u32) -> f32 {
        let r = math::saturate(roughness);
        if mips <= 1 {
            return 0.0;
        }
        let top = mips as f32 - 1.0;
        match self {
            Self::Linear => r * top,
            Self::Quadratic => math::sqrt(r) * top,
            Self::Filament => r * (2.0 - r) * top,
            Self::Geometric => {
                let alpha = r * r;
                let m = mips as f32;
                let alpha1 = math::exp2(-m); // α of mip 1
                if alpha <= alpha1 { alpha / alpha1 } else { 1.0 + (m - 2.0) * (math::log2(alpha) + m) / m }
            }
        }
    }
}

/// The distribution a prefiltered cube is filtered with.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
#[repr(u32)]
pub enum Lobe {
    /// GGX (Trowbridge–Reitz): the specular cube.
    Ggx = 0,
    /// Charlie (Estevez & Kulla 2017; `brdf::sheen`): the sheen cube.
    Charlie = 1,
}

impl Lobe {
    /// The lobe's width for perceptual `roughness`: GGX's `α`, or the sheen's
    /// (`sheen::alpha`, `r` clamped to at least 10⁻⁶).
    #[inline]
    pub fn alpha(self, roughness: f32) -> f32 {
        match self {
            Lobe::Ggx => alpha_from_roughness(math::saturate(roughness)),
            Lobe::Charlie => sheen::alpha(roughness),
        }
    }

    /// Sample `i` of `samples` for `roughness` ([`ggx_sample`] or [`charlie_sample`]).
    #[inline]
    pub fn sample(self, i: u32, samples: u32, alpha: f32, src_size: u32, lod_bias: f32) -> Vec4 {
        match self {
            Lobe::Ggx => ggx_sample(i, samples, alpha, src_size, lod_bias),
            Lobe::Charlie => charlie_sample(i, samples, alpha, src_size, lod_bias),
        }
    }

    /// Whether a level of `roughness` is the source itself (GGX at roughness 0).
    #[inline]
    pub fn is_mirror(self, roughness: f32) -> bool {
        self == Lobe::Ggx && roughness <= 0.0
    }
}

/// Source level for a sample of density `pdf` out of `samples`, on a source cube of face
/// size `src_size`: `½·log₂(Ωₛ/Ωₚ) + bias`, not clamped. An infinite `pdf` (a mirror-like
/// lobe) gives `−∞`, a zero `pdf` gives `+∞`; callers clamp to the stored levels.
#[inline]
pub fn source_lod(pdf: f32, samples: u32, src_size: u32, bias: f32) -> f32 {
    let s = src_size as f32;
    // Ωₛ/Ωₚ = (1/(N·pdf)) / (4π/(6s²)) = 6s² / (4π·N·pdf)
    let ratio = 6.0 * s * s / (4.0 * math::PI * samples as f32 * pdf);
    0.5 * math::log2(ratio) + bias
}

/// GGX-prefiltered radiance in direction `n` for perceptual `roughness`, from `samples` GGX
/// samples over the source cube `src`, source levels chosen with `lod_bias`: [`accumulate`]
/// over chunks of `math::CHUNK` samples, then the weighted mean.
pub fn prefilter_dir(src: &[Vec4], layout: CubeLayout, n: Vec3, roughness: f32, samples: u32, lod_bias: f32) -> Vec4 {
    let alpha = alpha_from_roughness(math::saturate(roughness));
    if alpha == 0.0 {
        return cubemap::sample_bilinear(src, layout, 0, sampling::normalize_or(n, Vec3::Z));
    }
    sampled_dir(Lobe::Ggx, src, layout, n, roughness, samples, lod_bias)
}

/// The sampled mean of `lobe` in direction `n`: [`accumulate`] over chunks of
/// `math::CHUNK` samples, then the weighted mean.
pub fn sampled_dir(lobe: Lobe, src: &[Vec4], layout: CubeLayout, n: Vec3, roughness: f32, samples: u32, lod_bias: f32) -> Vec4 {
    let count = samples.max(1);
    // An explicit loop, not `MeanPartial::chunked`: the display's fragment shader calls
    // this (filtered sampling), and a closure holding the storage-buffer slice becomes a
    // struct of a runtime array, which naga rejects ("Expected data type").
    let mut p = MeanPartial::default();
    let mut start = 0u32;
    while start < count {
        let c = if count - start < math::CHUNK { count - start } else { math::CHUNK };
        p = accumulate(lobe, src, layout, n, roughness, count, start, c, lod_bias, p);
        start += c;
    }
    p.resolve()
}

/// GGX sample `i` of `samples` for `alpha` (α = r²) in the tangent frame of the normal
/// (`z` along it): the light direction `l = 2(n·h)h − n` of the half vector `h` (`xyz`,
/// `z = n·l`), and in `w` the source level the sample reads,
/// from its density `D(h)·(n·h) / (4·(v·h)) = D(h)/4` at `v = n` ([`source_lod`]; Karis
/// 2013, with the filtered importance sampling of Křivánek & Colbert 2008). It depends on
/// no texel: the GPU computes it per sample, the CPU backend once per level
/// ([`lobe_samples`]) and reads it back ([`accumulate_samples`]), the same values.
#[cfg_attr(target_arch = "spirv", inline(never))]
#[cfg_attr(not(target_arch = "spirv"), inline)]
pub fn ggx_sample(i: u32, samples: u32, alpha: f32, src_size: u32, lod_bias: f32) -> Vec4 {
    let ht = sampling::sample_ggx_tangent(sampling::hammersley(i, samples), alpha);
    let pdf = 0.25 * microfacet::d_ggx(ht.z, alpha);
    let lt = ht * (2.0 * ht.z) - Vec3::Z;
    lt.extend(source_lod(pdf, samples, src_size, lod_bias))
}

/// Charlie sample `i` of `samples` for the sheen width `alpha`, as [`ggx_sample`]: the light
/// direction in the normal's tangent frame, drawn from the whole weight `D(h)·(n·l)`
/// (`sheen::charlie_light_sample`: every sample above the horizon, all of equal weight),
/// and its source level. The point is `(radical inverse of i, (i + ½)/N)`: the second
/// coordinate (stratified, never 0 or 1) for `n·l`, the first for the azimuth.
#[cfg_attr(target_arch = "spirv", inline(never))]
#[cfg_attr(not(target_arch = "spirv"), inline)]
pub fn charlie_sample(i: u32, samples: u32, alpha: f32, src_size: u32, lod_bias: f32) -> Vec4 {
    let xi = Vec2::new(sampling::radical_inverse(i), (i as f32 + 0.5) / samples as f32);
    let s = sheen::charlie_light_sample(xi, alpha);
    s.truncate().extend(source_lod(s.w, samples, src_size, lod_bias))
}

/// [`Lobe::sample`] for every sample of a level of `roughness` with `samples` samples.
#[cfg(not(target_arch = "spirv"))]
pub fn lobe_samples(lobe: Lobe, samples: u32, roughness: f32, src_size: u32, lod_bias: f32) -> impl Iterator<Item = Vec4> {
    let total = samples.max(1);
    let alpha = lobe.alpha(roughness);
    (0..total).map(move |i| lobe.sample(i, total, alpha, src_size, lod_bias))
}

/// Adds sample `g` ([`ggx_sample`], [`charlie_sample`]) around the unit normal `n` with
/// tangent frame `(t, b)` to the sums: its light direction `l` weighted by `n·l/N` where
/// `cosine` (GGX's samples follow `D(h)` alone; `n·l` is the tangent frame's `z`), else by
/// `1/N` (Charlie's follow the whole weight), read trilinearly at the sample's source level.
#[inline]
#[allow(clippy::too_many_arguments)]
fn add_sample(src: &[Vec4], layout: CubeLayout, n: Vec3, t: Vec3, b: Vec3, g: Vec4, cosine: bool, inv_count: f32, acc: &mut math::CompensatedSum4, wsum: &mut math::CompensatedSum) {
    let l = t * g.x + b * g.y + n * g.z;
    let n_dot_l = g.z;
    if n_dot_l > 0.0 {
        let w = if cosine { n_dot_l * inv_count } else { inv_count };
        acc.add(cubemap::sample_lod(src, layout, l, g.w) * w);
        wsum.add(w);
    }
}

/// Adds samples `start .. start + count` of `total` around `n` to `p`, sample `i` being
/// `sample(i)` ([`Lobe::sample`]'s form): the sums both [`accumulate`] and
/// [`accumulate_samples`] run.
#[inline]
#[allow(clippy::too_many_arguments)]
fn accumulate_with(src: &[Vec4], layout: CubeLayout, n: Vec3, cosine: bool, total: u32, start: u32, count: u32, p: MeanPartial, sample: impl Fn(u32) -> Vec4) -> MeanPartial {
    // A zero or non-finite direction is read as +z rather than turned into NaN.
    let n = sampling::normalize_or(n, Vec3::Z);
    // Weights n·l/N sum to at most 1: no overflow, whatever the radiance.
    let inv_count = 1.0 / total.max(1) as f32;
    let mut acc = math::CompensatedSum4::resume(p.sum, p.carry);
    let mut wsum = math::CompensatedSum::resume(p.weight.x, p.weight.y);
    let (t, b) = sampling::orthonormal_basis(n);
    let mut i = start;
    let end = start + count;
    while i < end {
        add_sample(src, layout, n, t, b, sample(i), cosine, inv_count, &mut acc, &mut wsum);
        i += 1;
    }
    let (sum, carry) = acc.parts();
    let (w, wc) = wsum.parts();
    MeanPartial { sum, carry, weight: Vec4::new(w, wc, 0.0, 0.0) }
}

/// Adds samples `start .. start + count` (of `samples` in all) of `lobe` around `n` to `p`.
#[allow(clippy::too_many_arguments)]
pub fn accumulate(
    lobe: Lobe,
    src: &[Vec4],
    layout: CubeLayout,
    n: Vec3,
    roughness: f32,
    samples: u32,
    start: u32,
    count: u32,
    lod_bias: f32,
    p: MeanPartial,
) -> MeanPartial {
    let alpha = lobe.alpha(roughness);
    let total = samples.max(1);
    let size = layout.size;
    accumulate_with(src, layout, n, lobe == Lobe::Ggx, total, start, count, p, |i| lobe.sample(i, total, alpha, size, lod_bias))
}

/// [`accumulate`] with the samples read from `table` (all of them, [`lobe_samples`]) instead
/// of made per texel: the same values.
#[cfg(not(target_arch = "spirv"))]
#[allow(clippy::too_many_arguments)]
pub fn accumulate_samples(lobe: Lobe, src: &[Vec4], layout: CubeLayout, n: Vec3, table: &[Vec4], start: u32, count: u32, p: MeanPartial) -> MeanPartial {
    accumulate_with(src, layout, n, lobe == Lobe::Ggx, table.len() as u32, start, count, p, |i| table[i as usize])
}

/// Source texels sample `g` ([`Lobe::sample`]) reads in [`accumulate`] on a cube of
/// `levels` levels: none below the horizon (`add_sample` skips it), else the trilinear
/// lookup's at the sample's level ([`cubemap::lookup_texels`]). For the cost model, which
/// counts a level's reads sample by sample.
#[inline]
pub fn sample_texels(g: Vec4, levels: u32) -> u32 {
    if g.z > 0.0 { cubemap::lookup_texels(g.w, levels) } else { 0 }
}

/// [`prefilter_dir`] from a table of its samples ([`lobe_samples`] of a non-zero roughness):
/// the same values, without making the samples again for every texel.
#[cfg(not(target_arch = "spirv"))]
pub fn prefilter_dir_samples(lobe: Lobe, src: &[Vec4], layout: CubeLayout, n: Vec3, table: &[Vec4]) -> Vec4 {
    MeanPartial::chunked(table.len().max(1) as u32, |start, c, p| accumulate_samples(lobe, src, layout, n, table, start, c, p))
}

/// At roughness 0 (a mirror) a `dst_size`-wide level is the source level of that size, bit
/// for bit: its index, or [`SAMPLED`] if the source has no level of that size. (An index,
/// not an `Option<Vec4>`: rust-gpu cannot lower the latter's niche constant.)
pub fn mirror_level(layout: CubeLayout, dst_size: u32) -> u32 {
    let mut level = 0;
    while level < layout.levels {
        if layout.level_size(level) == dst_size {
            return level;
        }
        level += 1;
    }
    SAMPLED
}

/// Texel `(x, y)` of `face` of a `dst_size`-wide output level of `lobe` for `roughness`:
/// [`mirror_texel`] for a GGX mirror, the exact sum over source level `exact_level`
/// ([`exact_dir`]) unless that is [`SAMPLED`], else the sampled mean at the texel centre.
#[allow(clippy::too_many_arguments)]
pub fn prefilter_texel(
    lobe: Lobe,
    src: &[Vec4],
    layout: CubeLayout,
    face: u32,
    x: u32,
    y: u32,
    dst_size: u32,
    roughness: f32,
    samples: u32,
    lod_bias: f32,
    exact_level: u32,
) -> Vec4 {
    if lobe.is_mirror(roughness) {
        return mirror_texel(src, layout, face, x, y, dst_size);
    }
    let n = cubemap::texel_dir(face, x, y, dst_size);
    if exact_level != SAMPLED {
        return exact_dir(lobe, src, layout, exact_level, cubemap::INLINE_GEOMETRY, n, roughness);
    }
    sampled_dir(lobe, src, layout, n, roughness, samples, lod_bias)
}

/// Texel `(x, y)` of `face` of a `dst_size`-wide level of a GGX mirror (roughness 0): the
/// source texel itself, bit for bit, where the source has a level of that size
/// ([`mirror_level`]), else the source read bilinearly along the texel's direction.
pub fn mirror_texel(src: &[Vec4], layout: CubeLayout, face: u32, x: u32, y: u32, dst_size: u32) -> Vec4 {
    let level = mirror_level(layout, dst_size);
    if level != SAMPLED {
        return src[layout.index(level, face, x, y) as usize];
    }
    cubemap::sample_bilinear(src, layout, 0, cubemap::texel_dir(face, x, y, dst_size))
}

/// `PrefilterParams::exact_level` of a level that is sampled, not summed exactly.
pub const SAMPLED: u32 = u32::MAX;

/// Face size of the source level an exact sum of `lobe` for `roughness` runs over: the
/// smallest power of two whose texel (`π/(2t)` radians) is at most an eighth of the lobe's
/// width, at most `src_size`. GGX's width is `α` (at `α/4` a texel-wide sun moved to its
/// coarse texel's centre still shifted `r = 1` by 10 % on city.exr); Charlie's is its
/// ring's ([`sheen::charlie_ring_width`]).
#[inline]
pub fn exact_source_size(lobe: Lobe, roughness: f32, src_size: u32) -> u32 {
    let alpha = lobe.alpha(roughness);
    let width = match lobe {
        Lobe::Ggx => alpha,
        Lobe::Charlie => sheen::charlie_ring_width(alpha),
    };
    let mut t = 1u32;
    while t < src_size && math::PI / (2.0 * t as f32) > 0.125 * width {
        t *= 2;
    }
    t
}

/// Whether a level of `lobe` for `roughness` with `samples` samples per texel is cheaper
/// summed exactly over [`exact_source_size`] (`6t²` terms) than sampled (about 8 terms a
/// sample).
#[inline]
pub fn prefers_exact(lobe: Lobe, roughness: f32, samples: u32, src_size: u32) -> bool {
    let t = exact_source_size(lobe, roughness, src_size);
    roughness > 0.0 && 6 * t * t <= 8 * samples
}

/// The source level (of `layout`) that a level of `lobe` for `roughness` with `samples`
/// samples per texel is summed over exactly, or [`SAMPLED`] where sampling is cheaper
/// ([`prefers_exact`]).
#[inline]
pub fn exact_level(lobe: Lobe, roughness: f32, samples: u32, layout: CubeLayout) -> u32 {
    if !prefers_exact(lobe, roughness, samples, layout.size) {
        return SAMPLED;
    }
    layout.level_of_size(exact_source_size(lobe, roughness, layout.size))
}

/// Adds texels `start .. start + count` of source level `level` to the exact mean weighted
/// by `lobe` for direction `n` and `roughness` (see the module header), the texels'
/// geometry read from `src[geometry..]` or computed per term (`cubemap::weighted_level_sum`:
/// the same values either way).
#[allow(clippy::too_many_arguments)]
pub fn exact_accumulate(lobe: Lobe, src: &[Vec4], layout: CubeLayout, level: u32, geometry: u32, n: Vec3, roughness: f32, start: u32, count: u32, p: MeanPartial) -> MeanPartial {
    let n = sampling::normalize_or(n, Vec3::Z);
    let alpha = lobe.alpha(roughness);
    // GGX: D ≤ 1/(πα²) and Ω ≤ 4π/6: scaled by α² so no weight exceeds about 1. Charlie:
    // D scaled by its largest value over the hemisphere (`sheen::charlie_light_weight`).
    let scale = alpha * alpha;
    let charlie = lobe == Lobe::Charlie;
    cubemap::weighted_level_sum(src, layout, level, geometry, start, count, p, |l, omega| {
        let n_dot_l = n.dot(l);
        if n_dot_l > 0.0 {
            let d = if charlie {
                sheen::charlie_light_weight(n_dot_l, alpha)
            } else {
                let h = sampling::normalize_or(n + l, n);
                microfacet::d_ggx_vec(n, h, alpha) * scale
            };
            d * n_dot_l * omega
        } else {
            0.0
        }
    })
}

/// The exact `lobe`-weighted mean over every texel of `level` (see [`exact_accumulate`],
/// which reads the geometry as `geometry` says),
/// chunked as the GPU runs it.
pub fn exact_dir(lobe: Lobe, src: &[Vec4], layout: CubeLayout, level: u32, geometry: u32, n: Vec3, roughness: f32) -> Vec4 {
    let s = layout.level_size(level);
    MeanPartial::chunked(cubemap::FACES * s * s, |start, c, p| exact_accumulate(lobe, src, layout, level, geometry, n, roughness, start, c, p))
}
