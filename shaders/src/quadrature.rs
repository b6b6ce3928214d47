//! A fixed Gauss–Legendre rule, for integrals whose integrand is smooth once the domain is
//! split at its kinks (see `lut::integrate_brdf_quadrature`).
//!
//! The 10-point rule is exact for polynomials of degree 19 (Abramowitz & Stegun 1964,
//! table 25.4; nodes are the roots of P₁₀, weights `2/((1−x²)P₁₀′(x)²)`), here mapped to
//! [0, 1]. The values were computed in f64 by Newton's iteration on P₁₀ and rounded to f32.

/// Points of the rule [`gauss_legendre_10`].
pub const GAUSS_LEGENDRE_POINTS: u32 = 10;

/// Node `i` (of [`GAUSS_LEGENDRE_POINTS`]) of the Gauss–Legendre rule on [0, 1] and its
/// weight; the weights sum to 1. A `match`, not an array, so that a shader indexes no
/// array with a run-time value.
#[inline]
pub fn gauss_legendre_10(i: u32) -> (f32, f32) {
    match i {
        0 => (0.013_046_736, 0.033_335_672),
        1 => (0.067_468_32, 0.074_725_674),
        2 => (0.160_295_22, 0.109_543_18),
        3 => (0.283_302_3, 0.134_633_36),
        4 => (0.425_562_83, 0.147_762_11),
        5 => (0.574_437_2, 0.147_762_11),
        6 => (0.716_697_7, 0.134_633_36),
        7 => (0.839_704_8, 0.109_543_18),
        8 => (0.932_531_7, 0.074_725_674),
        _ => (0.986_953_26, 0.033_335_672),
    }
}
