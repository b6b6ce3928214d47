//! The 2D BRDF integration table of the split-sum approximation (Karis 2013, "Real
//! Shading in Unreal Engine 4", eq. 8 and `IntegrateBRDF`).
//!
//! The specular integral `∫ f_s(l, v) (n·l) dl` with Schlick's Fresnel splits into a scale
//! and a bias to `F₀`:
//!
//! `∫ f_s (n·l) dl = F₀·A + B`,
//! `A = ∫ (f_s/F) (1 − F_c) (n·l) dl`, `B = ∫ (f_s/F) F_c (n·l) dl`, `F_c = (1 − v·h)⁵`.
//!
//! Sampling `h` with density `D(h)(n·h)` and `l = reflect(v, h)` (pdf of `l` is
//! `D (n·h) / (4 v·h)`), each sample contributes
//! `G_vis = G(v, l)·(v·h) / ((n·h)(n·v))` times `1 − F_c` or `F_c`, with Smith–Schlick
//! `G` and `k = α/2` (the IBL remapping). `G₁(n·v)/(n·v)` is folded into
//! `1/((n·v)(1−k)+k)` so nothing divides by a vanishing `n·v`.
//!
//! Table layout: column `x` holds `n·v = (x+½)/S`, row `y` holds roughness `(y+½)/S`.
//!
//! Two ways to evaluate it:
//! - [`integrate_brdf`]: Monte Carlo over Hammersley points (Karis's `IntegrateBRDF`, the
//!   seed method; error about `N^(-1)` to `N^(-½)`: 6·10⁻³ at 1024 points).
//! - [`integrate_brdf_quadrature`]: a deterministic product Gauss–Legendre quadrature over
//!   the half vector, split where the integrand has kinks, accurate to about 10⁻⁶ with
//!   some 550 evaluations per texel on average (the derivation is on the function).

use crate::brdf::microfacet::Masking;
use crate::brdf::sheen::{self, SheenVisibility};
use crate::brdf::{alpha_from_roughness, fresnel, microfacet};
use crate::math::{self, CompensatedSum};
use crate::{quadrature, sampling};
use spirv_std::glam::{Vec2, Vec3, Vec4};

/// Smallest `n·v` the table is evaluated at. At `n·v = 0` the view direction lies in the
/// surface plane: its mirror direction grazes the surface (`n·l = 0`) and the reflected
/// energy is the 0·∞ limit of a vanishing solid angle. Clamping to 10⁻⁴ (Filament's
/// `MIN_N_DOT_V`) keeps every term finite and changes no texel centre of a table up to
/// 4096 wide (whose first column is at `n·v ≥ 1.2·10⁻⁴`).
pub const MIN_N_DOT_V: f32 = 1e-4;

/// Split-sum `(scale, bias)` for `n·v` and perceptual `roughness`, from `samples`
/// Hammersley points. `scale + bias ≤ 1`: the sum is the directional albedo of the
/// specular lobe with `F₀ = 1`. Runs as [`accumulate`] over chunks of `math::CHUNK`
/// samples, then [`resolve`] — the same arithmetic the GPU runs one chunk per dispatch.
pub fn integrate_brdf(n_dot_v: f32, roughness: f32, samples: u32) -> Vec2 {
    let n = samples.max(1);
    let mut state = Vec4::ZERO;
    let mut start = 0u32;
    while start < n {
        let count = if n - start < math::CHUNK { n - start } else { math::CHUNK };
        state = accumulate(n_dot_v, roughness, n, start, count, state);
        start += count;
    }
    resolve(state, n)
}

/// Adds samples `start .. start + count` (of `samples` in all) of the table's integrand at
/// `(n·v, roughness)` to `state`, the compensated partial sums `(A, carry, B, carry)`.
pub fn accumulate(n_dot_v: f32, roughness: f32, samples: u32, start: u32, count: u32, state: Vec4) -> Vec4 {
    let nv = math::clamp(n_dot_v, MIN_N_DOT_V, 1.0);
    let r = math::saturate(roughness);
    let alpha = alpha_from_roughness(r);
    let k = microfacet::k_ibl(r);
    // View vector in tangent space, normal = +z.
    let v = Vec3::new(math::sqrt((1.0 - nv) * (1.0 + nv)), 0.0, nv);
    let n = samples.max(1);
    let mut a = CompensatedSum::resume(state.x, state.y);
    let mut b = CompensatedSum::resume(state.z, state.w);
    let mut i = start;
    let end = start + count;
    while i < end {
        let h = sampling::sample_ggx_tangent(sampling::hammersley(i, n), alpha);
        let v_dot_h = v.dot(h);
        let l = h * (2.0 * v_dot_h) - v;
        let n_dot_l = l.z;
        let n_dot_h = h.z;
        if n_dot_l > 0.0 && v_dot_h > 0.0 {
            // G·(v·h)/((n·h)(n·v)) with G₁(n·v)/(n·v) = 1/((n·v)(1−k)+k).
            let g_vis = microfacet::g1_schlick(n_dot_l, k) * v_dot_h / (n_dot_h * (nv * (1.0 - k) + k));
            let fc = fresnel::schlick_weight(v_dot_h);
            a.add((1.0 - fc) * g_vis);
            b.add(fc * g_vis);
        }
        i += 1;
    }
    let (sa, ca) = a.parts();
    let (sb, cb) = b.parts();
    Vec4::new(sa, ca, sb, cb)
}

/// The table value from the partial sums of all `samples`.
pub fn resolve(state: Vec4, samples: u32) -> Vec2 {
    let inv = 1.0 / samples.max(1) as f32;
    let (a, b) = (state.x * inv, state.z * inv);
    // The integral is a directional albedo, at most 1 (exactly 1 for a mirror). Rounding of
    // the sums — GPU compilers may drop the summation's compensation — can push the
    // estimate a few 10⁻⁶ past that bound; project it back so a renderer never gains
    // energy from the table.
    let s = a + b;
    if s > 1.0 { Vec2::new(a / s, b / s) } else { Vec2::new(a, b) }
}

/// The coordinates `(n·v, roughness)` of texel `(x, y)` in an `size`×`size` table.
#[inline]
pub fn texel_coords(x: u32, y: u32, size: u32) -> Vec2 {
    let s = size as f32;
    Vec2::new((x as f32 + 0.5) / s, (y as f32 + 0.5) / s)
}

/// The value of texel `(x, y)` of an `size`×`size` table integrated with `samples` points.
#[inline]
pub fn texel(x: u32, y: u32, size: u32, samples: u32) -> Vec2 {
    let c = texel_coords(x, y, size);
    integrate_brdf(c.x, c.y, samples)
}

/// Bilinear lookup in a `size`×`size` table stored row-major, clamped to the texel
/// centres, as a renderer samples it with a clamp-to-edge sampler.
pub fn sample(table: &[Vec2], size: u32, n_dot_v: f32, roughness: f32) -> Vec2 {
    let s = size as f32;
    let fx = math::clamp(n_dot_v * s - 0.5, 0.0, s - 1.0);
    let fy = math::clamp(roughness * s - 0.5, 0.0, s - 1.0);
    let x0 = math::floor(fx);
    let y0 = math::floor(fy);
    let tx = fx - x0;
    let ty = fy - y0;
    let x0 = x0 as u32;
    let y0 = y0 as u32;
    let x1 = if x0 + 1 < size { x0 + 1 } else { x0 };
    let y1 = if y0 + 1 < size { y0 + 1 } else { y0 };
    let row0 = (y0 * size) as usize;
    let row1 = (y1 * size) as usize;
    let a = table[row0 + x0 as usize] * (1.0 - tx) + table[row0 + x1 as usize] * tx;
    let b = table[row1 + x0 as usize] * (1.0 - tx) + table[row1 + x1 as usize] * tx;
    a * (1.0 - ty) + b * ty
}

/// Mean integrand evaluations per texel of [`integrate_brdf_quadrature`] over a 256²
/// table (more at grazing `n·v`, fewer near normal incidence): for cost estimates.
pub const QUADRATURE_MEAN_EVALUATIONS: u32 = 550;

/// Azimuth points of the full-circle part of [`integrate_brdf_quadrature`] (the midpoint
/// rule, which is spectrally accurate for a smooth periodic integrand).
const FULL_CIRCLE_AZIMUTHS: u32 = 8;
/// Equal pieces in θ of the full-circle part.
const FULL_CIRCLE_PIECES: u32 = 3;
/// Most pieces of each half of the cut part (one per factor 4 of its scale range).
const MAX_CUT_PIECES: u32 = 16;

/// `G·(v·h)/((n·h)(n·v))`: what one half vector of density `D(h)(n·h)` contributes to the
/// table (before the Fresnel split), for `masking`, with `k = α/2` for Smith–Schlick.
#[inline]
fn half_vector_weight(masking: Masking, nv: f32, nl: f32, vh: f32, nh: f32, alpha: f32) -> f32 {
    if masking == Masking::SmithCorrelated {
        // G₂ = 4(n·v)(n·l)V, so G₂(v·h)/((n·h)(n·v)) = 4(n·l)(v·h)V/(n·h): no 1/(n·v).
        4.0 * nl * vh * microfacet::vis_smith_correlated(nv, nl, alpha) / nh
    } else {
        let k = 0.5 * alpha;
        microfacet::g1_schlick(nl, k) * vh / (nh * (nv * (1.0 - k) + k))
    }
}

/// `(A, B)` contributions of the half vector at polar angle `(sin θ, cos θ) = (st, ct)` and
/// azimuth cosine `cos_phi` (from the plane of `n` and `v`), or zero where `n·l ≤ 0`.
#[inline]
fn half_vector_terms(masking: Masking, nv: f32, sv: f32, st: f32, ct: f32, cos_phi: f32, alpha: f32) -> Vec2 {
    let vh = sv * st * cos_phi + nv * ct;
    let nl = 2.0 * vh * ct - nv;
    if nl > 0.0 && vh > 0.0 {
        let w = half_vector_weight(masking, nv, nl, vh, ct, alpha);
        let fc = fresnel::schlick_weight(vh);
        Vec2::new((1.0 - fc) * w, fc * w)
    } else {
        Vec2::ZERO
    }
}

/// `1 − u(θ)` for the GGX cumulative `u(θ) = tan²θ/(α² + tan²θ)` of the half vector's
/// polar angle: `α²cos²θ/(α²cos²θ + sin²θ)`, with no cancellation near `u = 1`.
#[inline]
fn ggx_cdf_complement(theta: f32, a2: f32) -> f32 {
    let (s, c) = math::sin_cos(theta);
    let ac = a2 * c * c;
    ac / (ac + s * s)
}

/// Pieces for a span of `octaves` factors of two: one per two octaves, at least one.
#[inline]
fn cut_pieces(octaves: f32) -> u32 {
    math::clamp(math::floor(0.5 * octaves) + 1.0, 1.0, MAX_CUT_PIECES as f32) as u32
}

/// The 10×10-point Gauss–Legendre sum over `θ ∈ [θa, θb]` (in θ; through
/// `θ = θa + (θb − θa)(1 − cos πx)/2` where `ends`) and `φ ∈ [0, φₘ(θ)]` of the half-vector
/// terms, weighted by `du/π`.
#[allow(clippy::too_many_arguments)]
fn arc_piece(masking: Masking, nv: f32, sv: f32, a2: f32, alpha: f32, ta: f32, tb: f32, ends: bool) -> Vec2 {
    let mut total = Vec2::ZERO;
    let mut i = 0;
    while i < quadrature::GAUSS_LEGENDRE_POINTS {
        let (x, w) = quadrature::gauss_legendre_10(i);
        let (t, dt) = if ends {
            let (s, c) = math::sin_cos_turns(0.5 * x); // sin πx, cos πx
            (0.5 * (1.0 - c), 0.5 * math::PI * s)
        } else {
            (x, 1.0)
        };
        let theta = ta + (tb - ta) * t;
        let (st, ct) = math::sin_cos(theta);
        let q = a2 * ct * ct + st * st;
        let du = 2.0 * a2 * st * ct / (q * q) * (tb - ta) * dt * w;
        // cos φₘ = cos θᵥ(1 − 2cos²θ)/(2 cos θ sin θ sin θᵥ), clamped to [−1, 1].
        let c_star = math::clamp(nv * (1.0 - 2.0 * ct * ct) / (2.0 * ct * st * sv), -1.0, 1.0);
        let phi_max = math::atan2(math::sqrt((1.0 - c_star) * (1.0 + c_star)), c_star);
        let mut arc = Vec2::ZERO;
        let mut j = 0;
        while j < quadrature::GAUSS_LEGENDRE_POINTS {
            let (y, wy) = quadrature::gauss_legendre_10(j);
            let (_, cos_phi) = math::sin_cos(y * phi_max);
            arc += half_vector_terms(masking, nv, sv, st, ct, cos_phi, alpha) * wy;
            j += 1;
        }
        total += arc * (du * phi_max * math::FRAC_1_PI);
        i += 1;
    }
    total
}

/// Split-sum `(scale, bias)` at `n·v` and perceptual `roughness` by deterministic
/// quadrature, for the masking model `masking`.
///
/// **Derivation.** With half vectors distributed as `D(h)(n·h)` and `l = reflect(v, h)`,
/// `A = E[(1 − F_c) g]`, `B = E[F_c g]` with `g = G(v·h)/((n·h)(n·v))` (see the module
/// header). Parametrise `h` by the GGX cumulative in its polar angle,
/// `u = tan²θ/(α² + tan²θ)` (uniform in `[0, 1)` under the distribution, the same map
/// Karis's sampler inverts), and its azimuth `φ` from the plane of `n` and `v`. Then
/// `E[·] = ∫₀¹ du (1/π)∫₀^π dφ`, using the symmetry `φ → −φ`.
///
/// Where `n·l = 2(v·h)(n·h) − n·v > 0`: with `v·h = sin θᵥ sin θ cos φ + cos θᵥ cos θ`
/// this is `cos φ > c*(θ) = cos θᵥ (1 − 2cos²θ) / (2 cos θ sin θ sin θᵥ) = −cot θᵥ cot 2θ`,
/// so the whole circle counts for `θ < θ₁ = π/4 − θᵥ/2`, an arc `φ < φₘ(θ) = acos c*(θ)`
/// for `θ₁ ≤ θ ≤ θ₂ = π/4 + θᵥ/2`, and nothing beyond. The integrand is smooth inside
/// each part; the kinks are at the part boundaries, where `φₘ` has square-root ends.
///
/// **Estimator.**
/// - `θ ∈ [0, θ₁]`: `FULL_CIRCLE_PIECES` equal pieces in θ, each with the 10-point
///   Gauss–Legendre rule in `u` (which flattens the GGX peak; `1 − u` is carried in closed
///   form, so tiny `α` loses nothing), times the midpoint rule with
///   `FULL_CIRCLE_AZIMUTHS` points in `φ ∈ [0, π]`.
/// - `θ ∈ [θ₁, θ₂]`: split at `θₘ = (θ₁ + θ₂)/2`; below it, pieces in geometric
///   progression of θ (the arc opens on the scale of θ₁ itself, which is tiny at grazing
///   `n·v`); above it, pieces in geometric progression of `θ₂ − θ` down to `½n·v` (near
///   the horizon the exact Smith term changes on the scale of `n·v`); one piece per factor
///   4, each with the 10-point rule in θ (`du = 2α² sin θ cos θ / (α² cos²θ + sin²θ)² dθ`, which cancels the
///   `1/cos θ` of `g` near 90°), the end pieces through `θ = θₐ + (θ_b − θₐ)(1 − cos πx)/2`
///   to smooth the square-root ends; and the 10-point rule in `φ ∈ [0, φₘ]`.
///
/// Against an adaptive f64 Gauss–Kronrod reference (`splitsum-reference`), the error is
/// below 10⁻⁵ at every texel centre of a 256² table (`tests/lut.rs`).
pub fn integrate_brdf_quadrature(n_dot_v: f32, roughness: f32, masking: Masking) -> Vec2 {
    let nv = math::clamp(n_dot_v, MIN_N_DOT_V, 1.0);
    let alpha = alpha_from_roughness(math::saturate(roughness));
    let a2 = alpha * alpha;
    if !(a2 > 1e-30) {
        // A mirror (α² below f32's normal range): h = n, l = reflect(v), G = 1, v·h = n·v.
        let fc = fresnel::schlick_weight(nv);
        return Vec2::new(1.0 - fc, fc);
    }
    let sv = math::sqrt((1.0 - nv) * (1.0 + nv));
    let theta_v = math::atan2(sv, nv);
    let quarter = 0.25 * math::PI;
    let theta1 = quarter - 0.5 * theta_v;
    let theta2 = quarter + 0.5 * theta_v;
    let mut total = Vec2::ZERO;

    // θ ∈ [0, θ₁]: the whole azimuth circle.
    let mut piece = 0;
    while piece < FULL_CIRCLE_PIECES {
        let oa = ggx_cdf_complement(theta1 * piece as f32 / FULL_CIRCLE_PIECES as f32, a2);
        let ob = ggx_cdf_complement(theta1 * (piece + 1) as f32 / FULL_CIRCLE_PIECES as f32, a2);
        let mut i = 0;
        while i < quadrature::GAUSS_LEGENDRE_POINTS {
            let (x, w) = quadrature::gauss_legendre_10(i);
            let om = oa - (oa - ob) * x; // 1 − u
            let den = om + a2 * (1.0 - om);
            let ct = math::sqrt(om / den);
            let st = math::sqrt(a2 * (1.0 - om) / den);
            let mut ring = Vec2::ZERO;
            let mut j = 0;
            while j < FULL_CIRCLE_AZIMUTHS {
                let (_, cos_phi) = math::sin_cos_turns((j as f32 + 0.5) / (2 * FULL_CIRCLE_AZIMUTHS) as f32);
                ring += half_vector_terms(masking, nv, sv, st, ct, cos_phi, alpha);
                j += 1;
            }
            total += ring * (w * (oa - ob) / FULL_CIRCLE_AZIMUTHS as f32);
            i += 1;
        }
        piece += 1;
    }

    // θ ∈ [θ₁, θ₂]: the arc φ < φₘ(θ). Empty at n·v = 1 (θ₁ = θ₂).
    if theta2 > theta1 {
        let mid = 0.5 * (theta1 + theta2);
        // [θ₁, θₘ]: pieces geometric in θ (the arc opens on the scale of θ₁).
        let low = cut_pieces(math::log2(mid / theta1));
        // [θₘ, θ₂]: pieces geometric in θ₂ − θ, down to ½n·v (where n·l ≈ n·v near the
        // horizon; the exact Smith term changes on that scale there).
        let d_max = theta2 - mid;
        let d_min = math::min(0.5 * nv, d_max);
        let high = cut_pieces(math::log2(d_max / d_min));
        let pieces = low + high;
        let mut piece = 0;
        while piece < pieces {
            let (ta, tb) = if piece < low {
                let step = math::log2(mid / theta1) / low as f32;
                let tb = if piece + 1 == low { mid } else { theta1 * math::exp2(step * (piece + 1) as f32) };
                (theta1 * math::exp2(step * piece as f32), tb)
            } else {
                let k = piece - low;
                let step = math::log2(d_max / d_min) / high as f32;
                let ta = theta2 - d_max * math::exp2(-step * k as f32);
                let tb = if k + 1 == high { theta2 } else { theta2 - d_max * math::exp2(-step * (k + 1) as f32) };
                (ta, tb)
            };
            let ends = piece == 0 || piece + 1 == pieces;
            total += arc_piece(masking, nv, sv, a2, alpha, ta, tb, ends);
            piece += 1;
        }
    }
    // A directional albedo: at most 1 (see `resolve`).
    let s = total.x + total.y;
    if s > 1.0 { total * (1.0 / s) } else { total }
}

/// Texel `(x, y)` of a `size`×`size` table by [`integrate_brdf_quadrature`].
#[inline]
pub fn texel_quadrature(x: u32, y: u32, size: u32, masking: Masking) -> Vec2 {
    let c = texel_coords(x, y, size);
    integrate_brdf_quadrature(c.x, c.y, masking)
}

/// Texel `(x, y)` of the sheen tables (x = n·v, y = sheen roughness, at texel centres as
/// [`texel_coords`]): the Charlie table with Neubelt's visibility (`x`; the blue channel
/// of glTF-IBL-Sampler's table, which the glTF Sample Viewer reads as `u_CharlieLUT`) and
/// the sheen albedo with the fitted Charlie visibility (`y`; the Sample Viewer's
/// `lut_sheen_E`, `u_SheenELUT`, for `albedoSheenScaling`): `brdf::sheen::albedo` each.
pub fn sheen_texel(x: u32, y: u32, size: u32) -> Vec2 {
    let c = texel_coords(x, y, size);
    Vec2::new(sheen::albedo(c.x, c.y, SheenVisibility::Neubelt), sheen::albedo(c.x, c.y, SheenVisibility::Charlie))
}
