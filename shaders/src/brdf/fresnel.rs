//! Fresnel reflectance approximations.
//!
//! - Schlick 1994, "An Inexpensive BRDF Model for Physically-based Rendering", eq. 15:
//!   `F = F₀ + (1 − F₀)(1 − cos θ)⁵`.
//! - The roughness-aware variant for the ambient term (Lagarde, "Adopting a physically
//!   based shading model", 2011; LearnOpenGL "Diffuse irradiance"):
//!   `F = F₀ + (max(1 − r, F₀) − F₀)(1 − n·v)⁵`.
//! - UE4's spherical-Gaussian fit to Schlick (Karis 2013, "Specular F"):
//!   `F = F₀ + (1 − F₀)·2^((−5.55473 cos θ − 6.98316) cos θ)`.

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
