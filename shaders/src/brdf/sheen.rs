//! The sheen lobe: the "Charlie" microfibre distribution of Estevez & Kulla 2017
//! ("Production Friendly Microfacet Sheen BRDF", SIGGRAPH 2017 course, §2–3), as
//! `KHR_materials_sheen` (glTF 2.0 extension, "Implementation Notes") and Filament's cloth
//! model use it, with the two visibility terms the engines read:
//!
//! - [`v_charlie`], the paper's fitted masking (its §3, Table 1): what the glTF Sample
//!   Viewer's punctual lights read (`V_Sheen`), and the one the extension recommends;
//! - [`v_neubelt`], Neubelt & Pettineo 2013 ("Crafting a Next-Gen Material Pipeline for
//!   The Order: 1886", §3.2) (`1/(4(n·l + n·v − (n·l)(n·v)))`, after Ashikhmin & Premože
//!   2007): Filament's `visibilityCloth`, and the one glTF-IBL-Sampler integrates into the
//!   Charlie table the Sample Viewer reads for image-based sheen.
//!
//! Both engines take the sheen roughness `r` as perceptual and `α = r²`, clamping `r` to at
//! least 10⁻⁶ (the Sample Viewer's `D_Charlie` and `V_Sheen`, glTF-IBL-Sampler's
//! `D_Charlie`); the extension's text writes `alphaG = sheenRoughness`, the engines square
//! it, and splitsum follows the engines.
//!
//! The distribution, with `θ` the angle between `h` and `n`:
//!
//! ```text
//! D(h) = (2 + 1/α) · sin(θ)^(1/α) / (2π)
//! ```
//!
//! normalised so that `∫ D(h)(n·h) dω = 2π ∫₀¹ (2 + 1/α)/(2π) · s^(1/α) · s ds = 1` with
//! `s = sin θ` (`cos θ dω = 2π s ds` over the hemisphere), so that `(n·h)·D` is a density
//! of half vectors. Its cumulative distribution in `s` is `s^(2 + 1/α)`, which
//! [`sample_charlie_tangent`] inverts: `s = ξ^(α/(2α + 1))` (glTF-IBL-Sampler's
//! `getSampleVector` for Charlie).

use crate::math;
use spirv_std::glam::{Vec2, Vec3};

/// Sheen width `α = r²` of perceptual sheen roughness `r`, with `r` clamped to
/// [10⁻⁶, 1] as the engines clamp it (at `r = 0` the lobe would be a delta at grazing).
#[inline]
pub fn alpha(roughness: f32) -> f32 {
    let r = math::clamp(roughness, 1e-6, 1.0);
    r * r
}

/// The Charlie distribution `D(h)` at `n·h` for width `α` (Estevez & Kulla 2017, eq. 2).
/// `sin²θ` is clamped at 0 against rounding (`n·h` a hair above 1).
#[inline]
pub fn d_charlie(n_dot_h: f32, alpha: f32) -> f32 {
    let inv = 1.0 / alpha;
    let sin2 = math::max(1.0 - n_dot_h * n_dot_h, 0.0);
    (2.0 + inv) * math::pow(sin2, 0.5 * inv) * (0.5 * math::FRAC_1_PI)
}

/// The fitted exponent `L(x)` of the Charlie masking (Estevez & Kulla 2017, §3, Table 1):
/// `a/(1 + b·x^c) + d·x + e`, its five coefficients blended between the paper's two fits
/// by `(1 − α)²`.
#[inline]
fn l_fit(x: f32, alpha: f32) -> f32 {
    let t = (1.0 - alpha) * (1.0 - alpha);
    let mix = |lo: f32, hi: f32| lo + (hi - lo) * t;
    let a = mix(21.5473, 25.3245);
    let b = mix(3.82987, 3.32435);
    let c = mix(0.19823, 0.16801);
    let d = mix(-1.97760, -1.27393);
    let e = mix(-4.32054, -4.85967);
    a / (1.0 + b * math::pow(x, c)) + d * x + e
}

/// The Charlie masking `Λ(θ)` at `cos θ` for width `α`: `exp(L(cos θ))` below `cos θ = ½`,
/// `exp(2L(½) − L(1 − cos θ))` above (Estevez & Kulla 2017, §3: the fit is made on the
/// grazing half and mirrored, which keeps `Λ` smooth at ½).
#[inline]
pub fn lambda_charlie(cos_theta: f32, alpha: f32) -> f32 {
    let c = math::saturate(math::abs(cos_theta));
    if c < 0.5 { math::exp2(l_fit(c, alpha) * core::f32::consts::LOG2_E) } else { math::exp2((2.0 * l_fit(0.5, alpha) - l_fit(1.0 - c, alpha)) * core::f32::consts::LOG2_E) }
}

/// The Charlie visibility `V = 1/((1 + Λ(v) + Λ(l))·4(n·l)(n·v))` (Estevez & Kulla 2017,
/// §3, with the height-correlated form `G = 1/(1 + Λ(v) + Λ(l))`), clamped to [0, 1] as the
/// glTF Sample Viewer's `V_Sheen` clamps it. Zero where either cosine is not positive.
#[inline]
pub fn v_charlie(n_dot_l: f32, n_dot_v: f32, alpha: f32) -> f32 {
    if !(n_dot_l > 0.0 && n_dot_v > 0.0) {
        return 0.0;
    }
    let g = 1.0 / (1.0 + lambda_charlie(n_dot_v, alpha) + lambda_charlie(n_dot_l, alpha));
    math::saturate(g / (4.0 * n_dot_l * n_dot_v))
}

/// The Neubelt–Pettineo visibility `1/(4(n·l + n·v − (n·l)(n·v)))` (Neubelt & Pettineo
/// 2013, §3.2; Filament's `visibilityCloth`), clamped to [0, 1] as glTF-IBL-Sampler's
/// `V_Neubelt` clamps it. Zero where either cosine is not positive.
#[inline]
pub fn v_neubelt(n_dot_l: f32, n_dot_v: f32) -> f32 {
    if !(n_dot_l > 0.0 && n_dot_v > 0.0) {
        return 0.0;
    }
    math::saturate(1.0 / (4.0 * (n_dot_l + n_dot_v - n_dot_l * n_dot_v)))
}

/// A half vector in the tangent frame of the normal (`z` along it), distributed by the
/// density `D(h)(n·h)` for the point `xi` ∈ [0, 1)²: `sin θ = ξ_y^(α/(2α + 1))` (the inverse
/// of the cumulative distribution `s^(2 + 1/α)`, see the module header), `φ = 2π ξ_x`.
#[inline]
pub fn sample_charlie_tangent(xi: Vec2, alpha: f32) -> Vec3 {
    let sin_t = math::pow(xi.y, alpha / (2.0 * alpha + 1.0));
    let cos_t = math::sqrt(math::max(1.0 - sin_t * sin_t, 0.0));
    let (s, c) = math::sin_cos_turns(xi.x);
    Vec3::new(sin_t * c, sin_t * s, cos_t)
}
