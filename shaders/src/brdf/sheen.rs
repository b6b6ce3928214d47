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
use spirv_std::glam::{Vec2, Vec3, Vec4};

/// Sheen width `α = r²` of perceptual sheen roughness `r`, with `r` clamped to
/// [10⁻⁶, 1] as the engines clamp it (at `r = 0` the lobe would be a delta at grazing).
#[inline]
pub fn alpha(roughness: f32) -> f32 {
    let r = math::clamp(roughness, 1e-6, 1.0);
    r * r
}

/// The Charlie distribution `D(h)` at `n·h` for width `α` (Estevez & Kulla 2017, eq. 2).
/// `sin²θ` is clamped at 0 against rounding (`n·h` a hair above 1).
#[cfg_attr(target_arch = "spirv", inline(never))]
#[cfg_attr(not(target_arch = "spirv"), inline)]
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
#[cfg_attr(target_arch = "spirv", inline(never))]
#[cfg_attr(not(target_arch = "spirv"), inline)]
pub fn lambda_charlie(cos_theta: f32, alpha: f32) -> f32 {
    let c = math::saturate(math::abs(cos_theta));
    if c < 0.5 { math::exp2(l_fit(c, alpha) * core::f32::consts::LOG2_E) } else { math::exp2((2.0 * l_fit(0.5, alpha) - l_fit(1.0 - c, alpha)) * core::f32::consts::LOG2_E) }
}

/// The Charlie visibility `V = 1/((1 + Λ(v) + Λ(l))·4(n·l)(n·v))` (Estevez & Kulla 2017,
/// §3, with the height-correlated form `G = 1/(1 + Λ(v) + Λ(l))`), clamped to [0, 1] as the
/// glTF Sample Viewer's `V_Sheen` clamps it. Zero where either cosine is not positive.
#[cfg_attr(target_arch = "spirv", inline(never))]
#[cfg_attr(not(target_arch = "spirv"), inline)]
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

/// The sheen prefilter's lobe over light directions (glTF-IBL-Sampler's Charlie filter,
/// `filter.frag`, with `v = n` as for GGX): the mean of the radiance weighted by
/// `D(h)·(n·l)` over the hemisphere of `l`, `h` the half vector of `n` and `l`.
///
/// With `v = n`, `l = 2(n·h)h − n`, so `u = n·l = cos 2θ = 1 − 2 sin²θ` (θ the angle of `h`
/// from `n`) and `D(h) ∝ (sin²θ)^k = ((1 − u)/2)^k`, `k = 1/(2α)`. The lobe is a ring
/// about the horizon, not a cone about `n`: at small `α` it sits just above the horizon
/// (its `u` has mean `2/(k + 2) = 4α/(1 + 4α)`) and at `α → 0` it is the horizon itself.
///
/// **Sampling.** glTF-IBL-Sampler draws `h` from `D(h)(n·h)` ([`sample_charlie_tangent`]),
/// weighs each `l` by `n·l` and drops those below the horizon. In `t = sin²θ` that density is
/// `(k + 1)·t^k`, and `n·l > 0` is `t < ½`, which holds for a share `2^−(k+1)` of the
/// samples: 1/8 at `r = 0.5`, 1/90 at `r = 0.3`, one in 8000 at `r = 0.2`; below that its
/// filter averages a handful of samples or none. splitsum draws `l` from the whole weight
/// instead, so that every sample counts once: over `dω = du dφ` the weight is
/// `u (1 − u)^k`, a Beta(2, b) density in `u` with `b = k + 1`, whose survival function is
/// `S(u) = (1 − u)^b (1 + b u)`. With `1 − u = e^(−y/b)` (exact for any `b`, however large),
/// `S = e^(−y)(1 + c)`, `c = b·u = b(1 − e^(−y/b))`, and `S = ξ` is solved for `y` by
/// Newton's method on `f(y) = −y + ln(1 + c) − ln ξ`, `f′ = −1 + e^(−y/b)/(1 + c)` (`f` is
/// concave and decreasing, and the start `y₀ = −ln ξ + √(−2 ln ξ)` lies right of the root,
/// where Newton's steps fall monotonically onto it: `y₀ − ln(1 + y₀) ≥ −ln ξ` because
/// `eˢ ≥ 1 + s + s²/2`). The density per solid angle, for the source level a sample reads:
///
/// ```text
/// pdf(l) = u (1 − u)^k / (2π ∫₀¹ u (1 − u)^k du) = b(b + 1)/(2π) · u (1 − u)^(b−1)
///        = (b + 1) · c · e^(−y) · e^(y/b) / (2π)
/// ```
///
/// Returns `l` in the normal's tangent frame (`z = u > 0`) and, in `w`, its density.
/// **Exact sums** weigh each texel by `D(h)·(n·l)·Ω` with `D` scaled by its largest value
/// on the hemisphere, `(1 − n·l)^k` ([`charlie_light_weight`]): no underflow at `n·l = 0`
/// however small `α`.
#[cfg_attr(target_arch = "spirv", inline(never))]
#[cfg_attr(not(target_arch = "spirv"), inline)]
pub fn charlie_light_sample(xi: Vec2, alpha: f32) -> Vec4 {
    let b = 1.0 + 0.5 / alpha;
    // −ln ξ, ξ ∈ (0, 1).
    let target = -math::log2(xi.y) * core::f32::consts::LN_2;
    let mut y = target + math::sqrt(2.0 * target);
    let mut i = 0;
    while i < CHARLIE_NEWTON_STEPS {
        let (c, e) = charlie_c(y, b);
        let f = -y + math::ln_1p(c) + target;
        let fp = -1.0 + e / (1.0 + c);
        y = math::max(y - f / fp, 0.0);
        i += 1;
    }
    let (c, e) = charlie_c(y, b);
    let u = math::saturate(c / b);
    let pdf = (b + 1.0) * c * math::exp2(-y * core::f32::consts::LOG2_E) / (e * math::TAU);
    let sin_l = math::sqrt(math::max((1.0 - u) * (1.0 + u), 0.0));
    let (s, co) = math::sin_cos_turns(xi.x);
    Vec4::new(sin_l * co, sin_l * s, u, pdf)
}

/// Newton steps of [`charlie_light_sample`]: from its start, three reach the root to f32
/// precision for every `ξ` ≥ 2⁻²⁴ and `α` from 10⁻¹² to 1 (`shaders/tests/sheen.rs`).
const CHARLIE_NEWTON_STEPS: u32 = 3;

/// `(c, e) = (b(1 − e^(−y/b)), e^(−y/b))` for [`charlie_light_sample`]: by its series where
/// `y/b` is small (where `1 − e^(−z)` would lose every digit), relative error below 10⁻¹⁰.
#[inline]
fn charlie_c(y: f32, b: f32) -> (f32, f32) {
    let z = y / b;
    let e = math::exp2(-z * core::f32::consts::LOG2_E);
    let c = if z < 1e-3 { y * (1.0 - z * (0.5 - z * (1.0 / 6.0))) } else { b * (1.0 - e) };
    (c, e)
}

/// `D(h)` of the light direction at `n·l` (with `v = n`), divided by its largest value over
/// `n·l ≥ 0`: `(1 − n·l)^(1/(2α))`, the exact sums' weight before `n·l·Ω`.
#[cfg_attr(target_arch = "spirv", inline(never))]
#[cfg_attr(not(target_arch = "spirv"), inline)]
pub fn charlie_light_weight(n_dot_l: f32, alpha: f32) -> f32 {
    math::pow(math::saturate(1.0 - n_dot_l), 0.5 / alpha)
}

/// The sheen prefilter's normalised density over light directions at `n·l` (with `v = n`):
/// `b(b + 1)/(2π) · u(1 − u)^(b−1)`, `u = n·l`, `b = 1 + 1/(2α)` (the density of
/// [`charlie_light_sample`], see there), zero below the horizon. Its integral over the
/// hemisphere is 1, so `Σⱼ Lⱼ·pdf(lⱼ)·Ωⱼ` over texels is the lobe's mean of their radiance.
#[cfg_attr(target_arch = "spirv", inline(never))]
#[cfg_attr(not(target_arch = "spirv"), inline)]
pub fn charlie_light_pdf(n_dot_l: f32, alpha: f32) -> f32 {
    if n_dot_l <= 0.0 {
        return 0.0;
    }
    let b = 1.0 + 0.5 / alpha;
    b * (b + 1.0) / math::TAU * math::saturate(n_dot_l) * charlie_light_weight(n_dot_l, alpha)
}

/// The width, in `n·l` (about radians of elevation near the horizon), of the sheen
/// prefilter's ring: its mean `n·l`, `4α/(1 + 4α)`.
#[inline]
pub fn charlie_ring_width(alpha: f32) -> f32 {
    4.0 * alpha / (1.0 + 4.0 * alpha)
}

/// Which visibility term a sheen integral uses (see the module header for which engine
/// reads which).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
#[repr(u32)]
pub enum SheenVisibility {
    /// Estevez & Kulla's fitted masking ([`v_charlie`]): the glTF Sample Viewer's sheen
    /// albedo-scaling table (`lut_sheen_E`).
    Charlie = 0,
    /// Neubelt & Pettineo's ([`v_neubelt`]): glTF-IBL-Sampler's Charlie table (the blue
    /// channel of its table, which the Sample Viewer reads for image-based sheen).
    Neubelt = 1,
}

impl SheenVisibility {
    /// The term at `n·l`, `n·v` for width `α`.
    #[inline]
    pub fn eval(self, n_dot_l: f32, n_dot_v: f32, alpha: f32) -> f32 {
        match self {
            SheenVisibility::Charlie => v_charlie(n_dot_l, n_dot_v, alpha),
            SheenVisibility::Neubelt => v_neubelt(n_dot_l, n_dot_v),
        }
    }
}

/// The smallest `n·v` the albedo is integrated at (a view exactly in the surface has no
/// arc left to integrate; 10⁻⁴ is below the first texel centre of any table up to 4096²).
pub const MIN_N_DOT_V: f32 = 1e-4;

/// Equal pieces in θ of the sheen albedo's full-circle part.
const FULL_PIECES: u32 = 8;
/// Midpoint azimuths over `[0, π]` there (the integrand is smooth and periodic in φ).
const FULL_AZIMUTHS: u32 = 32;
/// Pieces of the arc part, geometric in `θ₂ − θ`.
const ARC_PIECES: u32 = 16;
/// Equal pieces of the arc's azimuth `[0, φₘ]`.
const AZIMUTH_PIECES: u32 = 4;

/// `D(h)·V·(n·l)·4(v·h)·sin θ` at the half vector `(sin θ, cos θ) = (st, ct)`, azimuth
/// cosine `cos_phi` from the plane of `n` and `v`: the sheen albedo's integrand per
/// `dθ dφ`, zero where `n·l ≤ 0`.
#[inline]
#[allow(clippy::too_many_arguments)]
fn albedo_term(vis: SheenVisibility, nv: f32, sv: f32, st: f32, ct: f32, cos_phi: f32, alpha: f32) -> f32 {
    let vh = sv * st * cos_phi + nv * ct;
    let nl = 2.0 * vh * ct - nv;
    if nl > 0.0 && vh > 0.0 { d_charlie(ct, alpha) * vis.eval(nl, nv, alpha) * nl * 4.0 * vh * st } else { 0.0 }
}

/// The 10×10-point Gauss–Legendre sum over `θ ∈ [θa, θb]` (through
/// `θ = θa + (θb − θa)(1 − cos πx)/2` where `ends`) and `φ ∈ [0, φₘ(θ)]`, doubled for the
/// other half of the azimuth.
#[allow(clippy::too_many_arguments)]
fn arc_piece(vis: SheenVisibility, nv: f32, sv: f32, alpha: f32, ta: f32, tb: f32, ends: bool) -> f32 {
    let mut total = 0.0;
    let mut i = 0;
    while i < crate::quadrature::GAUSS_LEGENDRE_POINTS {
        let (x, w) = crate::quadrature::gauss_legendre_10(i);
        let (t, dt) = if ends {
            let (s, c) = math::sin_cos_turns(0.5 * x);
            (0.5 * (1.0 - c), 0.5 * math::PI * s)
        } else {
            (x, 1.0)
        };
        let (st, ct) = math::sin_cos(ta + (tb - ta) * t);
        // cos φₘ = cos θᵥ(1 − 2cos²θ)/(2 cos θ sin θ sin θᵥ) (`lut::arc_piece`'s boundary).
        let c_star = math::clamp(nv * (1.0 - 2.0 * ct * ct) / (2.0 * ct * st * sv), -1.0, 1.0);
        let phi_max = math::atan2(math::sqrt((1.0 - c_star) * (1.0 + c_star)), c_star);
        let mut arc = 0.0;
        let mut p = 0;
        while p < AZIMUTH_PIECES {
            let mut j = 0;
            while j < crate::quadrature::GAUSS_LEGENDRE_POINTS {
                let (y, wy) = crate::quadrature::gauss_legendre_10(j);
                let (_, cos_phi) = math::sin_cos((p as f32 + y) * (1.0 / AZIMUTH_PIECES as f32) * phi_max);
                arc += albedo_term(vis, nv, sv, st, ct, cos_phi, alpha) * wy * (1.0 / AZIMUTH_PIECES as f32);
                j += 1;
            }
            p += 1;
        }
        total += arc * phi_max * 2.0 * (tb - ta) * dt * w;
        i += 1;
    }
    total
}

/// Evaluations of the integrand per [`albedo`]: the full-circle part's and the arc's.
pub const ALBEDO_EVALUATIONS: u32 = FULL_PIECES * crate::quadrature::GAUSS_LEGENDRE_POINTS * FULL_AZIMUTHS
    + (ARC_PIECES + 1) * crate::quadrature::GAUSS_LEGENDRE_POINTS * AZIMUTH_PIECES * crate::quadrature::GAUSS_LEGENDRE_POINTS;

/// The directional albedo `E(n·v) = ∫ D(h)·V·(n·l) dω_l` of the sheen lobe (colour 1, no
/// Fresnel) at perceptual sheen roughness `roughness`, by deterministic quadrature: the
/// sheen tables' integrand.
///
/// **Derivation.** Over half vectors, `dω_l = 4(v·h) dω_h` and `dω_h = sin θ dθ dφ`, so
/// `E = ∫∫ D(θ)·V·(n·l)·4(v·h)·sin θ dθ dφ` where `n·l = 2(v·h)(n·h) − n·v > 0`. That
/// region is the GGX table's (`lut::integrate_brdf_quadrature`): the whole azimuth for
/// `θ < θ₁ = π/4 − θᵥ/2`, the arc `φ < φₘ(θ)` for `θ₁ ≤ θ ≤ θ₂ = π/4 + θᵥ/2`, nothing
/// beyond. `D` grows towards `θ = π/2` as `sin(θ)^(1/α)`, so at grazing views the mass sits
/// at the arc's closing end `θ₂`, where `φₘ` has a square-root end.
///
/// **Estimator.** `θ ∈ [0, θ₁]`: `FULL_PIECES` equal pieces, the 10-point
/// Gauss–Legendre rule in θ, the midpoint rule with `FULL_AZIMUTHS` points in
/// `φ ∈ [0, π]`. `θ ∈ [θ₁, θ₂]`: `ARC_PIECES` pieces in geometric progression of
/// `θ₂ − θ` down to `min(θ₂ − θ₁, n·v)/256`, then the last piece to `θ₂`, the end pieces
/// through `θ = θa + (θb − θa)(1 − cos πx)/2` to smooth the square-root ends; the 10-point
/// rule in θ and on `AZIMUTH_PIECES` equal pieces of `φ ∈ [0, φₘ]` (the visibilities'
/// clamp at 1 puts a kink inside the arc at grazing views, which one 10-point rule missed by
/// 1.3·10⁻³). About 9 400 evaluations. `shaders/tests/sheen.rs` holds it within 10⁻⁴ of
/// the f64 reference at 90 points (measured 7.3·10⁻⁵ at worst, n·v 0.002); every texel of
/// a table is not checked yet.
pub fn albedo(n_dot_v: f32, roughness: f32, vis: SheenVisibility) -> f32 {
    let nv = math::clamp(n_dot_v, MIN_N_DOT_V, 1.0);
    let alpha = alpha(roughness);
    let sv = math::sqrt((1.0 - nv) * (1.0 + nv));
    let theta_v = math::atan2(sv, nv);
    let quarter = 0.25 * math::PI;
    let (theta1, theta2) = (quarter - 0.5 * theta_v, quarter + 0.5 * theta_v);
    let mut total = 0.0;
    // θ ∈ [0, θ₁]: the whole circle.
    let mut piece = 0;
    while piece < FULL_PIECES {
        let ta = theta1 * piece as f32 / FULL_PIECES as f32;
        let tb = theta1 * (piece + 1) as f32 / FULL_PIECES as f32;
        let mut i = 0;
        while i < crate::quadrature::GAUSS_LEGENDRE_POINTS {
            let (x, w) = crate::quadrature::gauss_legendre_10(i);
            let (st, ct) = math::sin_cos(ta + (tb - ta) * x);
            let mut ring = 0.0;
            let mut j = 0;
            while j < FULL_AZIMUTHS {
                let (_, cos_phi) = math::sin_cos_turns((j as f32 + 0.5) / (2 * FULL_AZIMUTHS) as f32);
                ring += albedo_term(vis, nv, sv, st, ct, cos_phi, alpha);
                j += 1;
            }
            total += ring * (2.0 * math::PI / FULL_AZIMUTHS as f32) * (tb - ta) * w;
            i += 1;
        }
        piece += 1;
    }
    // θ ∈ [θ₁, θ₂]: the arc. Empty at n·v = 1.
    if theta2 > theta1 {
        let d_max = theta2 - theta1;
        let d_min = math::min(d_max, nv) * (1.0 / 256.0);
        let step = math::log2(d_max / d_min) / ARC_PIECES as f32;
        let mut k = 0;
        while k <= ARC_PIECES {
            let ta = theta2 - d_max * math::exp2(-step * k as f32);
            let tb = if k == ARC_PIECES { theta2 } else { theta2 - d_max * math::exp2(-step * (k + 1) as f32) };
            total += arc_piece(vis, nv, sv, alpha, ta, tb, k == 0 || k == ARC_PIECES);
            k += 1;
        }
    }
    total
}
