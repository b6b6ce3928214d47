//! Fresnel reflectance approximations.
//!
//! - Schlick 1994, "An Inexpensive BRDF Model for Physically-based Rendering", eq. 15:
//!   `F = F₀ + (1 − F₀)(1 − cos θ)⁵`.
//! - The roughness-aware variant for the ambient term (Lagarde, "Adopting a physically
//!   based shading model", 2011; LearnOpenGL "Diffuse irradiance"):
//!   `F = F₀ + (max(1 − r, F₀) − F₀)(1 − n·v)⁵`.
//! - UE4's spherical-Gaussian fit to Schlick (Karis 2013, "Specular F"):
//!   `F = F₀ + (1 − F₀)·2^((−5.55473 cos θ − 6.98316) cos θ)`.
//! - The cosine-weighted mean of Schlick's weight over the light directions
//!   ([`schlick_weight_hemispherical_mean`]): what the diffuse layer of glTF's
//!   `fresnel_mix` loses to the specular under a constant sky.

use crate::math;
use spirv_std::glam::Vec3;

/// Schlick's weight `(1 − cos θ)⁵`.
#[inline]
pub fn schlick_weight(cos_theta: f32) -> f32 {
    math::pow5(1.0 - math::saturate(cos_theta))
}

/// Schlick's Fresnel for a scalar `f0`.
#[inline]
pub fn schlick(f0: f32, cos_theta: f32) -> f32 {
    f0 + (1.0 - f0) * schlick_weight(cos_theta)
}

/// Schlick's Fresnel per colour channel.
#[inline]
pub fn schlick3(f0: Vec3, cos_theta: f32) -> Vec3 {
    f0 + (Vec3::ONE - f0) * schlick_weight(cos_theta)
}

/// The spherical-Gaussian weight `2^((−5.55473 c − 6.98316) c)` replacing `(1 − c)⁵`.
#[inline]
pub fn spherical_gaussian_weight(cos_theta: f32) -> f32 {
    let c = math::saturate(cos_theta);
    math::exp2((-5.554_73 * c - 6.983_16) * c)
}

/// UE4's spherical-Gaussian Fresnel per colour channel.
#[inline]
pub fn spherical_gaussian3(f0: Vec3, cos_theta: f32) -> Vec3 {
    f0 + (Vec3::ONE - f0) * spherical_gaussian_weight(cos_theta)
}

/// Schlick's Fresnel with roughness, for the split-sum ambient term: rough surfaces do not
/// reach full reflectance at grazing angles.
#[inline]
pub fn schlick_roughness3(f0: Vec3, n_dot_v: f32, roughness: f32) -> Vec3 {
    let g = Vec3::splat(1.0 - roughness).max(f0);
    f0 + (g - f0) * schlick_weight(n_dot_v)
}

/// The cosine-weighted mean of Schlick's weight over every light direction `l` of the
/// hemisphere, with `h` the half vector of `v` and `l`:
/// `C(n·v) = (1/π) ∫ (1 − v·h)⁵ (n·l) dl`.
///
/// **Why.** glTF 2.0's dielectric is `fresnel_mix(base = ρ/π, layer = specular)` (glTF 2.0
/// specification, Appendix B.3.4): the diffuse layer is weighted by `1 − F(v·h)` with
/// `F₀ = 0.04`. Under a constant sky `L` it reflects
/// `L·ρ·(1/π)∫ (1 − F(v·h))(n·l) dl = L·ρ·(1 − F₀)(1 − C(n·v))`, whatever the roughness
/// (`h` is the half vector of `v` and `l`, not a microfacet normal). So `(1 − F₀)(1 − C)`
/// is the exact image-based diffuse weight of that BRDF.
///
/// **Derivation.** In a frame about `v`, a light direction at angle `γ` from `v` has
/// `v·h = cos(γ/2)`, and with `μ = n·v`, `a = μ cos γ`, `b = √(1 − μ²) sin γ`, its
/// azimuth integral of `max(0, n·l)` is the clipped cosine `I = 2πa` (`a ≥ b`), `0`
/// (`a ≤ −b`), else `2(aφ₀ + b sin φ₀)` with `φ₀ = acos(−a/b)`. That leaves the 1-D integral
/// `C(μ) = (1/π) ∫₀^π (1 − cos(γ/2))⁵ I(μ, γ) sin γ dγ`.
///
/// **Estimator.** That integral by the midpoint rule (30 000 points) at 80 Chebyshev
/// nodes of `[0, 1]`, fitted by least squares with a quintic in `μ`: within 4·10⁻⁶ of it
/// everywhere on `[0, 1]`, where `C` runs from 0.02816 at grazing views to 8.2·10⁻⁵ at
/// normal incidence (`shading::ambient_weights_are_the_gltf_integrals` checks it against
/// the reference's 2-D quadrature over `l`).
#[inline]
pub fn schlick_weight_hemispherical_mean(n_dot_v: f32) -> f32 {
    let x = math::saturate(n_dot_v);
    0.028_159_536 + x * (-0.079_712_956 + x * (0.085_544_156 + x * (-0.041_392_05 + x * (0.006_574_336_7 + x * 0.000_910_778_6))))
}
