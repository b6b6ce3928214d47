//! A split source's excess added back at read time: the GGX-prefiltered radiance of the
//! excess list (`crate::bright`'s split of a source level), summed exactly per lookup.
//!
//! **Why.** Near a sun of 10⁴–10⁶, a blend of two prefiltered mips cannot follow GGX's
//! tails (`∝ α²/θ⁴`), and the one read is 40–50 % off at r 0.05–0.1 (the guide's decision
//! records). The prefilter is linear in the radiance: with the source split into a residual
//! (no texel brighter than the threshold) and an excess list, the prefiltered radiance is
//! the residual's, read from its own mips, plus each excess texel's exact term.
//!
//! **The term.** For a lookup along `d` (`n = v = d`, as the prefilter has it) at GGX
//! width `α`, an excess texel of radiance `E` over a patch `P` of the sphere adds
//! `E·∫_P D(h)(d·l)⁺ dl / N(α)`, with `N(α) = ∫ D(h)(d·l)⁺ dl` over the sphere
//! ([`ggx_lobe_integral`]). In slope space (`t = tan θ_h`, the gnomonic plane of `h`,
//! where `dh = cos³θ_h d²t` and `dl = 4(v·h) dh`), GGX is exactly the planar density
//! `C_α(t) = α²/(π(α² + |t|²)²)` and the weight is `D(h)(d·l) dl = 4(d·l)·C_α(t) d²t`.
//! A texel of solid angle `Ω`, at half-angle `θ_l/2 = atan t₀` from `d`, is a disc of
//! angular radius `ρ = √(Ω/π)`; the map from `l` to `t` scales every direction at `l` by
//! `(1 + t₀²)/2` (radially `dt = (1 + t²)dθ_h`, `dθ_h = dθ_l/2`; across, by
//! `1/(2cos²θ_h)`), so the texel is a disc of radius `ρₜ = ρ(1 + t₀²)/2` about `t₀`.
//! `C_α` is the stereographic image of the uniform sphere, which maps discs to caps, so its
//! mass over that disc has a closed form:
//!
//! ```text
//! M = ½·(1 − (A − ρₜ²)/S),  A = α² + t₀²,  S = √((A − ρₜ²)² + 4ρₜ²α²)
//!   = 2ρₜ²α² / (S·(S + A − ρₜ²))          (where A ≥ ρₜ², free of cancellation)
//! ```
//!
//! and the term is `E·4(d·l)·M/N(α)`, `d·l` at the texel's centre ([`texel_weight`]). A
//! texel far wider than the lobe (`α → 0`, the mirror) gives `M = 1` inside its disc and 0
//! outside; one far narrower gives `M → πρₜ²·C_α(t₀)`, the point weight
//! `D(h)(d·l)Ω/N`. Every quantity comes from `d·l` and `|d × l|`
//! (`t₀ = |d × l|/(1 + d·l)`): at r ≤ 0.05 (`α² ≤ 6·10⁻⁶`), `n·h` is 1 to within f32's
//! epsilon across the lobe and `D` taken from it reads hundreds of percent off.
//!
//! **Irradiance.** The irradiance cube is baked from the residual too, and the excess's
//! irradiance is summed per point ([`irradiance`]): a sun just below a normal's horizon
//! then gives it nothing, where a bilinear read of a 32² cube smears the kink of
//! `max(0, n·l)` over a texel of 3°.
//!
//! **Shading.** A lookup stands for the lobe of `n = v = r`; a surface seen at a grazing
//! view has a stretched lobe cut by its horizon. So the shading lights each excess texel
//! by the glTF BRDF's specular term itself ([`reflected_weight`]: `F·D·V·(n·l)`, `D` over
//! the texel's disc in slope space about `n`, nothing from below the horizon), and reads
//! only the residual through the split sum (`crate::shade::excess_lobe_radiance`).

use crate::bright::ENTRY;
use crate::brdf::{alpha_from_roughness, microfacet};
use crate::math::{self, CompensatedSum4};
use crate::sampling;
use spirv_std::glam::{Vec2, Vec3, Vec4};

/// `N(α) = ∫ D(h)(n·l)⁺ dl` over the sphere for `n = v`: the GGX prefilter's normaliser.
///
/// With `u = (n·h)²`, `n·l = 2u − 1`, `dl = 4(n·h) dh` and `dh = d(n·h) dφ`, it is
/// `4α² ∫_{½}^{1} (2u − 1)/(1 + ku)² du` with `k = α² − 1`, whose antiderivative is
/// `(2/k²)·ln(1 + ku) + (2/k + 1)/(k(1 + ku))`:
///
/// ```text
/// N(α) = 8α²/k² · ln(2α²/(1 + α²)) − 4/k        (4 at α = 0, 1 at α = 1)
/// ```
///
/// Near `α = 1` the two terms cancel (`k → 0`); there, with `x = 1 − α²`, the series from
/// `ln(1 − x) − ln(1 − x/2) = −Σ aₙxⁿ`, `aₙ = (1 − 2⁻ⁿ)/n`, is `N = Σ cₘxᵐ` with
/// `cₘ = 8(aₘ₊₁ − aₘ₊₂)`: `1 + 2x/3 + 11x²/24 + 13x³/40 + 19x⁴/80 + 5x⁵/28 + …`, taken to
/// `x⁹` below `x = 0.3` (the rest under 5·10⁻⁷); above, the closed form's terms cancel to
/// within a factor 10 (`tests/prefilter.rs`: within 10⁻⁵ of a quadrature everywhere).
#[inline]
pub fn ggx_lobe_integral(alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    if !(a2 > 0.0) {
        return 4.0;
    }
    let x = 1.0 - math::min(a2, 1.0);
    if x < 0.3 {
        let tail = 0.178_571_43 + x * (0.137_834_82 + x * (0.108_940_97 + x * (0.087_934_03 + x * 0.072_301_14)));
        1.0 + x * (2.0 / 3.0 + x * (11.0 / 24.0 + x * (13.0 / 40.0 + x * (19.0 / 80.0 + x * tail))))
    } else {
        // ln y = log₂ y · ln 2
        8.0 * a2 / (x * x) * (math::log2(2.0 * a2 / (1.0 + a2)) * core::f32::consts::LN_2) + 4.0 / x
    }
}

/// The mass of GGX's slope density `C_α` (`a2 = α²`) over a disc of squared radius
/// `rho2` whose centre lies at squared slope `t2` from the peak (the module header's `M`):
/// 1 inside and 0 outside as `α → 0`, `πρ²·C_α(t)` for a small disc.
#[inline]
pub fn disc_mass(a2: f32, t2: f32, rho2: f32) -> f32 {
    let gap = a2 + t2 - rho2;
    let s = math::sqrt(gap * gap + 4.0 * rho2 * a2);
    if gap >= 0.0 {
        let den = s * (s + gap);
        if den > 0.0 { 2.0 * rho2 * a2 / den } else { 0.0 }
    } else {
        0.5 * (1.0 - gap / s)
    }
}

/// The weight of one excess entry `g = (l, Ω)` (unit `l`) in the prefiltered radiance
/// along unit `d` at GGX width `alpha`, `4(d·l)·M/N` (the module header), given
/// `inv_n = 1/N(α)`. Zero for an entry behind the lobe (`d·l ≤ 0`) or of no area (an
/// unused entry).
#[inline]
pub fn texel_weight(d: Vec3, alpha: f32, inv_n: f32, g: Vec4) -> f32 {
    let l = g.truncate();
    let c = d.dot(l);
    if !(c > 0.0 && g.w > 0.0) {
        return 0.0;
    }
    let one_c = 1.0 + c;
    let t2 = d.cross(l).length_squared() / (one_c * one_c);
    let stretch = 0.5 * (1.0 + t2);
    let rho2 = g.w * (1.0 / math::PI) * stretch * stretch;
    4.0 * c * disc_mass(alpha * alpha, t2, rho2) * inv_n
}

/// What one excess entry `g = (l, Ω)` (unit `l`) reflects towards `v` from a GGX surface of
/// unit normal `n` and width `alpha`, but for its radiance and the Fresnel factor:
/// `(v·h, w)` with `w = V(n·v, n·l)·(n·l)·∫_texel D(h) dl`, so that the entry adds
/// `E·F(v·h)·w` (the glTF BRDF's specular term, `F·D·V`, over the texel).
///
/// In slope space about `n`, `∫ D(h) dl = 4(v·h)/(n·h)·∫ C_α d²t` (`dl = 4(v·h) dh`,
/// `D(h)(n·h) dh = C_α(t) d²t`), and the texel covers an area `Ω/(4(v·h)(n·h)³)` there
/// (`dh = dl/(4 v·h)`, `d²t = dh/(n·h)³`), taken as a disc of that area ([`disc_mass`];
/// at `v = n`, [`texel_weight`]'s disc). The texel is an ellipse there, not a disc: `l`
/// turns twice as fast as `h` in the plane of incidence but `2(v·h)` times across it, so
/// at a grazing view it is `1/(v·h)` times longer across. The disc is exact where the lobe
/// is wider than the texel and away from the highlight (the point weight `Ω·D`), and
/// within the texel's own width of a sharp highlight at a grazing view it is not:
/// `tests/prefilter.rs` measures both. Zero for an entry below the surface's horizon
/// (`n·l ≤ 0`). `n_dot_v` is the view's cosine as the shading holds it (at least
/// `MIN_N_DOT_V`).
#[inline]
pub fn reflected_weight(n: Vec3, v: Vec3, n_dot_v: f32, alpha: f32, g: Vec4) -> Vec2 {
    let l = g.truncate();
    let nl = n.dot(l);
    let sum = v + l;
    let len2 = sum.length_squared();
    if !(nl > 0.0 && g.w > 0.0 && len2 > 0.0) {
        return Vec2::ZERO;
    }
    let h = sum * (1.0 / math::sqrt(len2));
    let nh = n.dot(h);
    let vh = v.dot(h);
    if !(nh > 0.0 && vh > 0.0) {
        return Vec2::ZERO;
    }
    let t2 = n.cross(h).length_squared() / (nh * nh);
    let rho2 = g.w * (1.0 / math::PI) / (4.0 * vh * nh * nh * nh);
    let integral = 4.0 * vh / nh * disc_mass(alpha * alpha, t2, rho2);
    Vec2::new(vh, microfacet::vis_smith_correlated(n_dot_v, nl, alpha) * nl * integral)
}

/// The prefiltered radiance of the `count` excess entries that start at index `base` of
/// `buf` ([`ENTRY`] `Vec4`s each: `(l, Ω)`, then the excess radiance) along `d` for
/// perceptual `roughness`: `Σⱼ Eⱼ·`[`texel_weight`], to add to the residual's read. An
/// entry below the horizon of `n` (`n·l < 0`) adds nothing: the surface cannot see it
/// (`n` = 0 clips nothing).
pub fn prefiltered_excess(buf: &[Vec4], base: u32, count: u32, d: Vec3, roughness: f32, n: Vec3) -> Vec4 {
    let d = sampling::normalize_or(d, Vec3::Z);
    let alpha = alpha_from_roughness(math::saturate(roughness));
    let inv_n = 1.0 / ggx_lobe_integral(alpha);
    let mut acc = CompensatedSum4::new();
    let mut j = 0;
    while j < count {
        let g = buf[(base + ENTRY * j) as usize];
        let w = if n.dot(g.truncate()) < 0.0 { 0.0 } else { texel_weight(d, alpha, inv_n, g) };
        if w > 0.0 {
            acc.add(buf[(base + ENTRY * j + 1) as usize] * w);
        }
        j += 1;
    }
    math::finite4(acc.total())
}

/// The irradiance over π, `E/π`, that the `count` excess entries from index `base` of
/// `buf` give a surface of unit normal `n`: `Σⱼ Eⱼ·Ωⱼ·(n·lⱼ)⁺/π`, each texel at its
/// centre (the cosine varies little across a texel; its kink at the horizon, which no
/// irradiance texel grid follows, is exact here).
pub fn irradiance(buf: &[Vec4], base: u32, count: u32, n: Vec3) -> Vec3 {
    let mut acc = CompensatedSum4::new();
    let mut j = 0;
    while j < count {
        let g = buf[(base + ENTRY * j) as usize];
        let w = n.dot(g.truncate()) * g.w;
        if w > 0.0 {
            acc.add(buf[(base + ENTRY * j + 1) as usize] * (w * (1.0 / math::PI)));
        }
        j += 1;
    }
    math::finite4(acc.total()).truncate()
}
