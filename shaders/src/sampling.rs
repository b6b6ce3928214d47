//! Low-discrepancy points and GGX importance sampling.
//!
//! - Hammersley points (Hammersley & Handscomb 1964; Pharr, Jakob & Humphreys, *PBRT* 3e
//!   §7.4.1): `(i/N, Φ₂(i))` with Φ₂ the base-2 radical inverse (van der Corput).
//! - GGX half-vector sampling with density `D(h)·(n·h)` (Walter et al. 2007, "Microfacet
//!   Models for Refraction through Rough Surfaces", eq. 35–36; Karis 2013, "Real Shading
//!   in Unreal Engine 4", `ImportanceSampleGGX`).
//! - GGX visible-normal sampling, density `G₁(v)·max(0, v·h)·D(h)/(n·v)` (Heitz 2018,
//!   "Sampling the GGX Distribution of Visible Normals", JCGT 7(4), listing 1).
//! - An orthonormal frame around a unit normal that stays finite at both poles (Duff et
//!   al. 2017, "Building an Orthonormal Basis, Revisited", JCGT 6(1)).

use crate::math;
use spirv_std::glam::{Vec2, Vec3};

/// Φ₂(i): the bits of `i` mirrored about the binary point, as an f32 in [0, 1).
///
/// All 32 bits of `i` take part, so points stay distinct (as far as f32 can tell them
/// apart) for any count up to 2³² − 1: there is no wrap at 2¹⁶ or 2²⁴. The result is the
/// correctly rounded f32 of the exact 32-bit fraction, except that values that would
/// round up to 1.0 are held at the largest f32 below 1.
#[inline]
pub fn radical_inverse(i: u32) -> f32 {
    let v = i.reverse_bits() as f32 * 2.328_306_4e-10; // × 2⁻³²
    math::min(v, ONE_MINUS_EPSILON)
}

/// The largest f32 below 1.
pub const ONE_MINUS_EPSILON: f32 = 0.999_999_94;

/// The `i`-th of `n` Hammersley points in [0, 1)²: `(i/n, Φ₂(i))`.
///
/// `i/n` is the correctly rounded quotient whenever `i` and `n` are at most 2²⁴ (both are
/// then exact in f32); above that it is within 2 ULP, and it is held below 1 (for
/// `n = 2²⁴ + 1` the last `i/n` would otherwise round to 1.0).
#[inline]
pub fn hammersley(i: u32, n: u32) -> Vec2 {
    Vec2::new(math::min(i as f32 / n as f32, ONE_MINUS_EPSILON), radical_inverse(i))
}

/// Tangent and bitangent `(t, b)` such that `(t, b, n)` is a right-handed orthonormal
/// basis, for a unit `n`. Branchless except for the sign of `n.z`; finite for every unit
/// vector including `±z` (Duff et al. 2017, listing 3).
#[inline]
pub fn orthonormal_basis(n: Vec3) -> (Vec3, Vec3) {
    let sign = if n.z >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x), Vec3::new(b, sign + n.y * n.y * a, -n.y))
}

/// A GGX-distributed half vector in tangent space (`z` is the normal), for the unit-square
/// point `xi` and GGX width `alpha` (= roughness²).
///
/// With `u = xi.y`: `cos²θ = (1−u)/((1−u) + α²u)` and `sin²θ = α²u/((1−u) + α²u)`, both
/// computed directly, so neither loses precision to `1 − cos²θ` when `α` is tiny, and
/// `α = 0` gives exactly `(0, 0, 1)`. `φ = 2π·xi.x`.
#[inline]
pub fn sample_ggx_tangent(xi: Vec2, alpha: f32) -> Vec3 {
    let a2 = alpha * alpha;
    let one_minus_u = 1.0 - xi.y;
    let denom = one_minus_u + a2 * xi.y; // > 0 because xi.y < 1
    let cos_theta = math::sqrt(one_minus_u / denom);
    let sin_theta = math::sqrt(a2 * xi.y / denom);
    let (sin_phi, cos_phi) = math::sin_cos_turns(xi.x);
    Vec3::new(sin_theta * cos_phi, sin_theta * sin_phi, cos_theta)
}

/// A GGX-distributed half vector around the unit normal `n`, in world space.
#[inline]
pub fn sample_ggx(xi: Vec2, alpha: f32, n: Vec3) -> Vec3 {
    let h = sample_ggx_tangent(xi, alpha);
    let (t, b) = orthonormal_basis(n);
    t * h.x + b * h.y + n * h.z
}

/// A GGX half vector drawn from the normals visible from `v` (tangent space, `z` the
/// normal, `v.z > 0`), for the unit-square point `xi` and GGX width `alpha`: Heitz 2018,
/// listing 1, isotropic. The view is stretched to the hemisphere configuration
/// (`v_h = normalize(α v.x, α v.y, v.z)`), a point of the unit disk is drawn (radius
/// `√xi.x`, angle `2π·xi.y`), warped onto the visible half of the projected hemisphere
/// (`t₂ ← (1 − s)√(1 − t₁²) + s t₂`, `s = (1 + v_h.z)/2`), lifted onto it, and unstretched.
/// Density `G₁(v) max(0, v·h) D(h) / v.z`; each sample's reflection `l` has density
/// `G₁(v) D(h) / (4 v.z)`. `α = 0` gives `(0, 0, 1)`; a point on the disk's rim cannot
/// give a zero vector (the normalisation falls back to the normal).
#[cfg_attr(target_arch = "spirv", inline(never))]
#[cfg_attr(not(target_arch = "spirv"), inline)]
pub fn sample_vndf_tangent(xi: Vec2, alpha: f32, v: Vec3) -> Vec3 {
    let vh = normalize_or(Vec3::new(alpha * v.x, alpha * v.y, v.z), Vec3::Z);
    let len2 = vh.x * vh.x + vh.y * vh.y;
    let t1 = if len2 > 1e-20 { Vec3::new(-vh.y, vh.x, 0.0) * (1.0 / math::sqrt(len2)) } else { Vec3::X };
    let t2 = vh.cross(t1);
    let radius = math::sqrt(xi.x);
    let (sin_phi, cos_phi) = math::sin_cos_turns(xi.y);
    let p1 = radius * cos_phi;
    let s = 0.5 * (1.0 + vh.z);
    let p2 = (1.0 - s) * math::sqrt(math::max(1.0 - p1 * p1, 0.0)) + s * (radius * sin_phi);
    let nh = t1 * p1 + t2 * p2 + vh * math::sqrt(math::max(1.0 - p1 * p1 - p2 * p2, 0.0));
    normalize_or(Vec3::new(alpha * nh.x, alpha * nh.y, math::max(nh.z, 0.0)), Vec3::Z)
}

/// A cosine-distributed direction in tangent space (`z` up), density `cos θ / π`
/// (Malley's method: a uniform disk point lifted to the hemisphere).
#[inline]
pub fn sample_cosine_tangent(xi: Vec2) -> Vec3 {
    let r = math::sqrt(xi.y);
    let (s, c) = math::sin_cos_turns(xi.x);
    Vec3::new(r * c, r * s, math::sqrt(1.0 - xi.y))
}

/// Mirror reflection of `v` about the unit `h`: `2(v·h)h − v`.
#[inline]
pub fn reflect(v: Vec3, h: Vec3) -> Vec3 {
    h * (2.0 * v.dot(h)) - v
}

/// `v / |v|`, or `fallback` when `v` is zero, subnormal-small or not finite, so that a
/// degenerate vector never turns into NaN.
#[inline]
pub fn normalize_or(v: Vec3, fallback: Vec3) -> Vec3 {
    let len2 = v.dot(v);
    if len2 > 1e-30 && len2 <= math::LARGEST { v * (1.0 / math::sqrt(len2)) } else { fallback }
}
