//! The Cook–Torrance microfacet terms (Cook & Torrance 1982) in the form used by UE4
//! (Karis 2013, "Real Shading in Unreal Engine 4", "Specular BRDF"):
//!
//! `f_s = D·G·F / (4 (n·l)(n·v))`, with
//! - GGX / Trowbridge–Reitz `D(h) = α² / (π ((n·h)²(α²−1) + 1)²)` (Walter et al. 2007, eq. 33),
//! - Smith's separable masking with Schlick's G₁: `G₁(x) = x / (x(1−k) + k)`,
//!   `k = (r+1)²/8` for analytic lights ("hotness" remapping) and `k = α/2 = r²/2` for
//!   image-based lighting (Karis 2013, "Specular G").

use crate::math;
use spirv_std::glam::Vec3;

/// The GGX normal distribution `D(n·h)` for width `alpha`.
///
/// Evaluated as `(α / ((1 − (n·h)²) + (n·h·α)²))² / π` with `1 − (n·h)² = (1−n·h)(1+n·h)`
/// (Filament, "Physically Based Rendering in Filament", §4.4.1): the same value, but with
/// no catastrophic cancellation near the peak and no underflow of `α⁴` for tiny `α`.
#[cfg_attr(target_arch = "spirv", inline(never))]
#[cfg_attr(not(target_arch = "spirv"), inline)]
pub fn d_ggx(n_dot_h: f32, alpha: f32) -> f32 {
    let nh = math::saturate(n_dot_h);
    let one_minus_nh2 = (1.0 - nh) * (1.0 + nh);
    let a = nh * alpha;
    let k = alpha / (one_minus_nh2 + a * a);
    k * k * math::FRAC_1_PI
}

/// The GGX distribution for unit normal `n` and half vector `h`, with `1 − (n·h)²` taken
/// as `|n × h|²`: for widths below about 10⁻³ the peak is narrower than the f32 spacing of
/// `n·h` near 1, and only the cross product resolves it (Filament §4.4.1, "D_GGX with
/// NxH").
#[inline]
pub fn d_ggx_vec(n: Vec3, h: Vec3, alpha: f32) -> f32 {
    let nh = math::saturate(n.dot(h));
    let c = n.cross(h);
    let a = nh * alpha;
    let k = alpha / (c.dot(c) + a * a);
    k * k * math::FRAC_1_PI
}

/// Schlick's `k` for analytic (direct) lights: `(r+1)²/8`.
#[inline]
pub fn k_direct(roughness: f32) -> f32 {
    let r1 = roughness + 1.0;
    r1 * r1 * 0.125
}

/// Schlick's `k` for image-based lighting: `α/2 = r²/2`.
#[inline]
pub fn k_ibl(roughness: f32) -> f32 {
    roughness * roughness * 0.5
}

/// Schlick's single-direction masking `G₁(x) = x / (x(1−k) + k)`.
#[inline]
pub fn g1_schlick(n_dot_x: f32, k: f32) -> f32 {
    let x = math::saturate(n_dot_x);
    let denom = x * (1.0 - k) + k;
    if denom > 0.0 { x / denom } else { 1.0 }
}

/// Smith's separable masking–shadowing `G = G₁(n·v)·G₁(n·l)` with Schlick's `G₁`.
#[inline]
pub fn g_smith_schlick(n_dot_v: f32, n_dot_l: f32, k: f32) -> f32 {
    g1_schlick(n_dot_v, k) * g1_schlick(n_dot_l, k)
}

/// The visibility term `G / (4 (n·l)(n·v)) = 1 / (4 (n·v(1−k)+k)(n·l(1−k)+k))`,
/// algebraically equal but finite at grazing angles whenever `k > 0`.
#[inline]
pub fn vis_smith_schlick(n_dot_v: f32, n_dot_l: f32, k: f32) -> f32 {
    let v = math::saturate(n_dot_v) * (1.0 - k) + k;
    let l = math::saturate(n_dot_l) * (1.0 - k) + k;
    let denom = 4.0 * v * l;
    if denom > 0.0 { 1.0 / denom } else { 0.0 }
}

/// The masking–shadowing term a BRDF table or a light is evaluated with.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
#[repr(u32)]
pub enum Masking {
    /// Separable Smith with Schlick's `G₁` (`k = α/2` for image-based light, `(r+1)²/8`
    /// for direct light): UE4's choice (Karis 2013).
    SmithSchlick = 0,
    /// The exact height-correlated Smith term of GGX (Heitz 2014, "Understanding the
    /// Masking-Shadowing Function in Microfacet-Based BRDFs", JCGT 3(2), eq. 99).
    SmithCorrelated = 1,
}


/// The height-correlated Smith visibility of GGX, `V = G₂ / (4 (n·l)(n·v))`, with
/// `G₂ = 1 / (1 + Λ(v) + Λ(l))` and `Λ(x) = (√(1 + α² tan²θₓ) − 1)/2` (Heitz 2014, eq. 99),
/// rewritten without tangents as
/// `V = ½ / ((n·l)√((n·v)²(1−α²) + α²) + (n·v)√((n·l)²(1−α²) + α²))`
/// (Filament, "Physically Based Rendering in Filament", §4.4.2): finite at grazing angles
/// whenever `α > 0`.
#[cfg_attr(target_arch = "spirv", inline(never))]
#[cfg_attr(not(target_arch = "spirv"), inline)]
pub fn vis_smith_correlated(n_dot_v: f32, n_dot_l: f32, alpha: f32) -> f32 {
    let nv = math::saturate(n_dot_v);
    let nl = math::saturate(n_dot_l);
    let a2 = alpha * alpha;
    let gv = nl * math::sqrt(nv * nv * (1.0 - a2) + a2);
    let gl = nv * math::sqrt(nl * nl * (1.0 - a2) + a2);
    let denom = gv + gl;
    if denom > 0.0 { 0.5 / denom } else { 0.0 }
}
