//! Normalised Phong and Blinn–Phong specular lobes, kept for comparison with GGX.
//!
//! - Phong (Phong 1975), energy-normalised (Lewis 1994, "Making Shaders More Physically
//!   Plausible"): `f = (n+2)/(2π) · max(0, r·l)ⁿ`, `r` the mirror of `v`.
//! - Blinn–Phong (Blinn 1977), normalised for the half vector: `f = (n+8)/(8π) · (n·h)ⁿ`.
//! - Exponent from GGX width: `n_BP = 2/α² − 2` (Walter et al. 2007, §5.2; Karis,
//!   "Specular BRDF Reference", 2013), and `n_Phong = n_BP / 4` (the Phong lobe about `r`
//!   is about four times narrower in exponent than the Blinn lobe about `n`).

use crate::math;

/// Blinn–Phong exponent equivalent to GGX width `alpha` (clamped to ≥ 10⁻⁴ so that the
/// exponent stays finite; see [`crate::shade::MIN_DIRECT_ROUGHNESS`]).
#[inline]
pub fn blinn_exponent(alpha: f32) -> f32 {
    let a = math::max(alpha, 1e-4);
    math::max(2.0 / (a * a) - 2.0, 0.0)
}

/// The normalised Blinn–Phong lobe for exponent `n`.
#[inline]
pub fn blinn_phong(n_dot_h: f32, n: f32) -> f32 {
    (n + 8.0) * (0.125 * math::FRAC_1_PI) * math::pow(math::saturate(n_dot_h), n)
}

/// The normalised Phong lobe for exponent `n`.
#[inline]
pub fn phong(r_dot_l: f32, n: f32) -> f32 {
    (n + 2.0) * (0.5 * math::FRAC_1_PI) * math::pow(math::saturate(r_dot_l), n)
}
