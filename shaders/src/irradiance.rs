//! Diffuse irradiance: the cosine convolution of the environment, as a small cube map and
//! as nine spherical-harmonic coefficients.
//!
//! **Convention**: stored values are irradiance divided by π, `E(n)/π = (1/π)∫ L(l) max(0, n·l) dl`,
//! the cosine-weighted mean radiance. A Lambert surface of albedo ρ under it reflects
//! `ρ·E/π`, and a constant environment `L` gives exactly `L`.
//!
//! **Convolution** (the brute-force sum of LearnOpenGL "Diffuse irradiance", without its
//! sampling noise): `E/π = Σⱼ Lⱼ wⱼ / Σⱼ wⱼ`, `wⱼ = max(0, n·ωⱼ) Ωⱼ`, over every texel `j` of
//! one level of the source cube (`Ωⱼ` its exact solid angle). The normalisation by `Σ wⱼ`
//! (≈ π) makes a constant environment exact.
//!
//! **Spherical harmonics** (Ramamoorthi & Hanrahan 2001, "An Efficient Representation
//! for Irradiance Environment Maps", eq. 7–8; real basis of Sloan 2008, "Stupid Spherical
//! Harmonics Tricks", appendix A2): radiance coefficients `L_lm = Σⱼ Lⱼ Y_lm(ωⱼ) Ωⱼ`, and
//! `E(n)/π = Σ (Âₗ/π) L_lm Y_lm(n)` with `Âₗ/π = 1, 2/3, 1/4` for `l = 0, 1, 2`.

use crate::cubemap::{self, CubeLayout};
use crate::math::{self, MeanPartial};
use spirv_std::glam::{Vec3, Vec4};

/// Number of SH coefficients up to band 2.
pub const SH9: usize = 9;

/// The polynomials of the nine real SH basis functions at unit direction `d`, ordered
/// `(0,0), (1,−1), (1,0), (1,1), (2,−2), (2,−1), (2,0), (2,1), (2,2)`:
/// `1, y, z, x, xy, yz, 3z² − 1, xz, x² − y²`.
#[inline]
pub fn sh9_polynomials(d: Vec3) -> [f32; SH9] {
    let (x, y, z) = (d.x, d.y, d.z);
    [1.0, y, z, x, x * y, y * z, 3.0 * z * z - 1.0, x * z, x * x - y * y]
}

/// The normalising constants `Kₖ` of the basis: `Y_k = Kₖ·Pₖ` ([`sh9_polynomials`]):
/// `½√(1/π)`, `½√(3/π)`, `½√(15/π)`, `¼√(5/π)`, `¼√(15/π)`.
pub const SH9_K: [f32; SH9] = [0.282_094_8, 0.488_602_5, 0.488_602_5, 0.488_602_5, 1.092_548_4, 1.092_548_4, 0.315_391_57, 1.092_548_4, 0.546_274_2];

/// The nine real SH basis functions `Y_lm` at unit direction `d` (order as
/// [`sh9_polynomials`]).
#[inline]
pub fn sh9_basis(d: Vec3) -> [f32; SH9] {
    let p = sh9_polynomials(d);
    let mut y = [0.0; SH9];
    let mut k = 0;
    while k < SH9 {
        y[k] = SH9_K[k] * p[k];
        k += 1;
    }
    y
}

/// Cosine-lobe convolution factors `Âₗ/π` per coefficient.
pub const SH9_COSINE: [f32; SH9] = [1.0, 2.0 / 3.0, 2.0 / 3.0, 2.0 / 3.0, 0.25, 0.25, 0.25, 0.25, 0.25];

/// `E(n)/π` from radiance coefficients `coeffs` (RGB in `xyz`).
#[inline]
pub fn sh9_irradiance(coeffs: &[Vec4; SH9], n: Vec3) -> Vec3 {
    let y = sh9_basis(n);
    let mut e = Vec3::ZERO;
    let mut k = 0;
    while k < SH9 {
        e += coeffs[k].truncate() * (SH9_COSINE[k] * y[k]);
        k += 1;
    }
    e
}

/// `E(n)/π` as coefficients of [`sh9_polynomials`] of the unit normal, from radiance
/// coefficients `coeffs`: `cₖ = (Âₗ/π)·Kₖ·L_k` ([`SH9_K`]). This is the form Filament's shader
/// evaluates (`Irradiance_SphericalHarmonics` in `shaders/src/light_indirect.fs`, with
/// cmgen's `--sh-shader` pre-scaling, `CubemapSH::preprocessSHForShader`): its
/// `E/π = max(0, Σ cₖ Pₖ(n))`.
#[inline]
pub fn sh9_polynomial(coeffs: &[Vec4; SH9]) -> [Vec3; SH9] {
    let mut out = [Vec3::ZERO; SH9];
    let mut k = 0;
    while k < SH9 {
        out[k] = coeffs[k].truncate() * (SH9_COSINE[k] * SH9_K[k]);
        k += 1;
    }
    out
}

/// `E(n)/π` at normal `n` by the exact cosine-weighted sum over every texel of `level` of
/// the source cube: [`accumulate`] over chunks of `math::CHUNK` texels, then the mean. The
/// level's geometry is at `src[geometry..]` or computed per term (see
/// `cubemap::weighted_level_sum`).
pub fn convolve_dir(src: &[Vec4], layout: CubeLayout, level: u32, geometry: u32, n: Vec3) -> Vec4 {
    let s = layout.level_size(level);
    MeanPartial::chunked(cubemap::FACES * s * s, |start, c, p| accumulate(src, layout, level, geometry, n, start, c, p))
}

/// Adds texels `start .. start + count` of `level` (numbered face by face, row by row) to
/// the cosine-weighted mean for normal `n`.
#[allow(clippy::too_many_arguments)]
pub fn accumulate(src: &[Vec4], layout: CubeLayout, level: u32, geometry: u32, n: Vec3, start: u32, count: u32, p: MeanPartial) -> MeanPartial {
    // A zero or non-finite normal is read as +z: never an empty hemisphere, never NaN.
    let n = crate::sampling::normalize_or(n, Vec3::Z);
    // Scaled by 1/(4π) so the weights sum to about 1/4: no overflow.
    cubemap::weighted_level_sum(src, layout, level, geometry, start, count, p, |d, omega| math::max(n.dot(d), 0.0) * omega * (0.25 * math::FRAC_1_PI))
}

/// The contribution of row `y` of `face` of `level` to the SH projection: nine RGB
/// coefficient partial sums, then the row's total solid angle in `[SH9].x` (the host adds
/// the rows in f64 and rescales so that the solid angles sum to exactly 4π).
pub fn sh9_row(src: &[Vec4], layout: CubeLayout, level: u32, face: u32, y: u32) -> [Vec4; SH9 + 1] {
    let s = layout.level_size(level);
    let mut out = [Vec4::ZERO; SH9 + 1];
    let mut x = 0;
    while x < s {
        let d = cubemap::texel_dir(face, x, y, s);
        let w = cubemap::texel_solid_angle(x, y, s);
        let l = src[layout.index(level, face, x, y) as usize] * w;
        let basis = sh9_basis(d);
        let mut k = 0;
        while k < SH9 {
            out[k] += l * basis[k];
            k += 1;
        }
        out[SH9].x += w;
        x += 1;
    }
    out
}
