//! Diffuse reflectance models. Each returns the BRDF value `f_d` (not multiplied by `n·l`).
//!
//! - Lambert: `f = ρ/π`.
//! - Oren–Nayar, the qualitative model (Oren & Nayar 1994, "Generalization of Lambert's
//!   Reflectance Model", eq. 30): `f = ρ/π (A + B·max(0, cos(φᵢ−φᵣ))·sin α·tan β)` with
//!   `A = 1 − σ²/(2(σ²+0.33))`, `B = 0.45σ²/(σ²+0.09)`, `α = max(θᵢ, θᵣ)`, `β = min(θᵢ, θᵣ)`.
//!   Written with vectors: `cos(φᵢ−φᵣ) sin α tan β = (l·v − (n·l)(n·v)) / max(n·l, n·v)`,
//!   so there is no trigonometry and no division by `sin θ`. σ (radians) is the roughness.
//! - Fresnel-weighted diffuse (Ashikhmin & Shirley 2000, "An Anisotropic Phong BRDF
//!   Model", eq. 5; Shirley et al. 1997): `f = 28ρ/(23π) (1 − R_s)(1 − (1 − n·l/2)⁵)(1 − (1 − n·v/2)⁵)`,
//!   which leaves to the diffuse layer only the energy the specular layer (normal
//!   reflectance `R_s`) does not take.

use crate::math;
use spirv_std::glam::Vec3;

/// Lambert's BRDF `ρ/π`.
#[inline]
pub fn lambert(albedo: Vec3) -> Vec3 {
    albedo * math::FRAC_1_PI
}

/// Oren–Nayar's BRDF for surface roughness `sigma` (standard deviation of facet slopes,
/// radians). At `sigma = 0` it is exactly Lambert.
#[inline]
pub fn oren_nayar(albedo: Vec3, sigma: f32, n_dot_l: f32, n_dot_v: f32, l_dot_v: f32) -> Vec3 {
    let s2 = sigma * sigma;
    let a = 1.0 - 0.5 * s2 / (s2 + 0.33);
    let b = 0.45 * s2 / (s2 + 0.09);
    let nl = math::saturate(n_dot_l);
    let nv = math::saturate(n_dot_v);
    let s = l_dot_v - nl * nv;
    let t = math::max(nl, nv);
    let term = if s > 0.0 && t > 0.0 { s / t } else { 0.0 };
    albedo * (math::FRAC_1_PI * (a + b * term))
}

/// The Fresnel-weighted diffuse BRDF of Ashikhmin & Shirley, for specular normal
/// reflectance `rs` per channel.
#[inline]
pub fn fresnel_weighted(albedo: Vec3, rs: Vec3, n_dot_l: f32, n_dot_v: f32) -> Vec3 {
    let wl = 1.0 - math::pow5(1.0 - 0.5 * math::saturate(n_dot_l));
    let wv = 1.0 - math::pow5(1.0 - 0.5 * math::saturate(n_dot_v));
    albedo * (Vec3::ONE - rs) * (28.0 / (23.0 * math::PI) * wl * wv)
}
