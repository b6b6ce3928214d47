//! The shading ladder: 1 to 16 fetches over the prefiltered mips by filtered importance
//! sampling of the true GGX lobe ([`lobe_radiance`]), blended with the split sum's one
//! fetch as `n·v` rises, for the views where one fetch cannot follow the lobe.

use super::*;
use crate::brdf::{alpha_from_roughness, microfacet};
use crate::{math, sampling};
use spirv_std::glam::{Vec2, Vec3, Vec4};

/// Rungs of the shading ladder: 1, 2, 4, 8 and 16 fetches.
pub const LADDER_RUNGS: u32 = 5;
/// Most prefiltered fetches per pixel of the ladder.
pub const MAX_FETCHES: u32 = 1 << (LADDER_RUNGS - 1);

/// The radiance the specular lobe of material `m` averages, for normal `n` and view `v`:
/// one fetch of the prefiltered cube along the read direction (the split sum), or with
/// [`ShadeOptions::fetches`] `K > 1` the shading ladder's estimate over `K` fetches. Every
/// fetch reads the cube alone ([`cube_read`]): where the source was split, the residual,
/// whose excess [`super::excess_lobe_radiance`] adds once, exactly.
///
/// **Why.** The split sum reads radiance prefiltered with the lobe of `n = v = r`: at
/// grazing views the true lobe is stretched, leans towards the normal and is cut by the
/// horizon, which one fetch along one direction cannot follow (at `n·v = 0.1` that is most
/// of the error against the full integral). The ladder spends `K` fetches to follow it.
///
/// **Estimator** (filtered importance sampling, Colbert & Křivánek 2007, GPU Gems 3
/// ch. 20, over the prefiltered mips instead of the source's box-filtered ones):
/// 1. `K` half vectors from GGX's visible normals ([`sampling::sample_vndf_tangent`]) on a
///    Vogel spiral: radius from `(i + ½)/K`, angle `¼ + i·`[`GOLDEN`] turns (the first in
///    the plane of incidence); `l = reflect(v, h)`. (Hammersley's angles put the outermost of
///    four samples in that plane towards the normal, where a sun 16° off read 4.5× the rest:
///    28 % mean error at K = 4 on the tuning set, against 12 % on the spiral.) The
///    density of `l` is `p(l) = G₁(v) D(h) / (4 n·v)`, so the weight of a sample for
///    `∫ f_s L (n·l) dl` is `f_s (n·l) / p(l) = F(v·h) G₂(v,l) / G₁(v)`. Samples below the
///    horizon (`n·l ≤ 0`) weigh nothing: light from under the surface is kept out.
///    The spiral is drawn in towards the disk's centre by [`spiral_radius2`], so that
///    the samples' spread and their footprints' spread add up to the lobe's.
/// 2. Each sample stands for a solid angle `Ω = 1 / (K p(l))`. It reads the prefiltered
///    cube at the roughness whose own lobe covers that much sky: the prefilter's lobe
///    (`n = v`) has peak density `D(0)/4 = 1/(4πα²)`, so it covers `4πα_f²` and
///    `α_f² = Ω/(4π) = (n·v) q² / (K G₁(v) α²)` with `q = (n·h)²(α² − 1) + 1`
///    (`D = α²/(π q²)`); never rougher than the material itself. Read along `l` lifted
///    as the one fetch's direction is ([`above_horizon`], at the footprint's roughness),
///    so that the footprint's core stays above the surface: without it, the lower half of
///    a white metal sphere (normals facing down, a bright sky under their horizon) reads
///    more light than is there, and the worst of `scripts/mitsuba.sh`'s spheres at 16
///    fetches was 12.0 % off the exact integral, against 9.6 % with it (sunrise, r 0.5).
///    The one fetch's measured [`HORIZON_LIFT`] serves: a lift of the whole median cone
///    (1 instead of 0.75) was better on the spheres (8.2 %) and worse at grazing views
///    (held out, 16 fetches at `n·v ≤ 0.1`: 8.1 against 8.0 %; tuning set, the mean over
///    rungs 2–16: 2.98 against 2.93 %).
/// 3. The samples set only the *shape* of the average: `Σ wᵢ Lᵢ / Σ wᵢ` with
///    `wᵢ = F(v·hᵢ) V(n·v, n·lᵢ) (n·lᵢ)` (`V = G₂/(4 n·l n·v)`; the constant `4 n·v / G₁(v)`
///    cancels). The energy still comes from the table (`F·A + B` in [`ibl`]), which is
///    exact, so a constant sky is reproduced exactly at any `K` and the ladder only buys
///    down the split, never adds noise to the albedo.
/// 4. Near normal incidence the split sum's lobe is the true one and the one fetch, exact
///    for it, beats `K` filtered samples; the estimate is blended into the one fetch as
///    `n·v` rises, the later the more fetches it has ([`ladder_weight`]).
#[inline]
pub fn lobe_radiance(shape: EnvironmentShape, specular: &[Vec4], opts: ShadeOptions, m: &Material, n: Vec3, v: Vec3) -> Vec3 {
    let roughness = m.roughness;
    let ladder = opts.fetches() > 1 && opts.specular == SpecularModel::CookTorrance as u32;
    // The ladder reads without filtered sampling, its one fetch included.
    let read = if ladder { opts.flags & !ShadeOptions::FILTERED_SAMPLING } else { opts.flags };
    let alpha = alpha_from_roughness(math::saturate(roughness));
    let a2 = alpha * alpha;
    let (t, b) = sampling::orthonormal_basis(n);
    // The view, held above the horizon as the table holds it (n·v ≥ MIN_N_DOT_V).
    let vt = sampling::normalize_or(Vec3::new(v.dot(t), v.dot(b), math::max(n.dot(v), MIN_N_DOT_V)), Vec3::Z);
    let view = t * vt.x + b * vt.y + n * vt.z;
    let nv = vt.z;
    let s = ladder_weight(nv, opts.fetches());
    let fetches = if ladder && s > 0.0 { opts.fetches() } else { 0 };
    let g1 = 2.0 * nv / (nv + math::sqrt(nv * nv * (1.0 - a2) + a2));
    let f0 = m.f0();
    let mut one = Vec3::ZERO;
    let mut sum = Vec3::ZERO;
    let mut weights = Vec3::ZERO;
    // Fetch 0 is the split sum's one fetch; fetches 1 to K follow the lobe. One loop around
    // one lookup: each lookup written out is one the GPU compiler emits again.
    let mut k = 0;
    while k <= fetches {
        let (dir, r, w, read_it) = if k == 0 {
            (read_direction(read, n, v, roughness), roughness, Vec3::ONE, true)
        } else {
            let i = k - 1;
            let turn = 0.25 + i as f32 * GOLDEN;
            let xi = Vec2::new(spiral_radius2(i, fetches), turn - math::floor(turn));
            let ht = sampling::sample_vndf_tangent(xi, alpha, vt);
            let h = t * ht.x + b * ht.y + n * ht.z;
            let l = sampling::reflect(view, h);
            let nl = n.dot(l);
            if nl > 0.0 {
                let w = fresnel(opts.fresnel, f0, math::saturate(view.dot(h))) * (microfacet::vis_smith_correlated(nv, nl, alpha) * nl);
                let q = ht.z * ht.z * (a2 - 1.0) + 1.0;
                let covered = nv * q * q / (fetches as f32 * g1 * math::max(a2, 1e-12));
                let rf = math::min(math::sqrt(math::sqrt(covered)), roughness);
                (above_horizon(n, l, rf), rf, w, true)
            } else {
                // Below the horizon: weighs nothing, and is not read.
                (l, roughness, Vec3::ZERO, false)
            }
        };
        if read_it {
            let value = cube_read(shape, specular, read, dir, r).truncate();
            if k == 0 {
                one = value;
            } else {
                sum += w * value;
                weights += w;
            }
        }
        k += 1;
    }
    if fetches == 0 || !(weights.x > 0.0 && weights.y > 0.0 && weights.z > 0.0) {
        return one;
    }
    one + (sum / weights - one) * s
}

/// The squared disk radius of the ladder's sample `i` of `k`: the Vogel spiral's
/// `(i + ½)/k`, drawn in by `1 − 1/k`.
///
/// **Why** (the law of total variance): what the ladder averages is the mixture of its
/// `k` footprints, and a mixture's spread is the spread of its centres plus the mean
/// spread of each part. Each footprint already covers `1/k` of the lobe (step 2 of
/// [`lobe_radiance`]), so the centres may spread over only `1 − 1/k` of it, or the
/// average is wider than the lobe (`k = 2`: one and a half times its spread). On the
/// sample disk, where the lobe is uniform, the spread is the mean `r²` (½ for the disk,
/// and for the spiral's `(i + ½)/k`), so each `r²` is scaled by `1 − 1/k`. One fetch
/// (`k = 1`) collapses onto the centre with a footprint of the whole lobe, at normal
/// incidence the split sum's own read (the mirror direction at the material's roughness); as
/// `k` grows the scale goes to 1 and the ladder to filtered importance sampling of the
/// lobe. Scaling the radius instead, as widths add for Cauchy lobes (`(1 − 1/√k)²` on
/// `r²`), was worse at every rung on the tuning set (2 fetches 5.3 % against 4.1 %).
#[inline]
pub fn spiral_radius2(i: u32, k: u32) -> f32 {
    let k = k as f32;
    (i as f32 + 0.5) / k * (1.0 - 1.0 / k)
}

/// The ladder's weight against the one fetch at view `n_dot_v` with `k` fetches: 1 below
/// `n·v = 1 − `[`LADDER_CROSSOVER`]`/√k`, falling linearly to 0 over the next
/// [`LADDER_BLEND`] (0 for one fetch).
///
/// **Why.** The two estimates err for different reasons. The one fetch reads the lobe of
/// `n = v`, exact at normal incidence, and its error grows as the view falls from the
/// normal (the lobe stretches, leans and is cut). The ladder follows the true lobe, and
/// its error is that of a `k`-point quadrature, which falls as `k` grows, roughly as
/// `1/√k`, whatever the view. So the view at which the ladder starts to lose to the one
/// fetch rises with `k`: with an error of the one fetch growing as `1 − n·v`, where the
/// two meet is `1 − n·v ∝ 1/√k`. One constant sets it, and one the ramp's width.
///
/// **Measured** (`runner report --sets`, tuning set, then held out): with a fixed
/// crossover at `n·v` 0.4 (blend 0.3), two fetches lost to one at `n·v` 0.1–0.3 on the
/// tuning set (5.9 against 5.1 %), and sixteen stayed at 2.1 % at `n·v ≥ 0.6`, as one
/// fetch. With the fetches lifted, every constant from 1.4 to 1.6 with a ramp of 0.3 or
/// 0.5 put every rung at or below the rung beneath it, in every band, on both sets; 1.4
/// and 0.5 had the tuning set's mean over rungs 2–16 within 0.01 point of the best (2.93
/// against 3.17 %), confirmed held out (3.66 against 3.79 %).
#[inline]
pub fn ladder_weight(n_dot_v: f32, k: u32) -> f32 {
    if k <= 1 {
        return 0.0;
    }
    let full_below = 1.0 - LADDER_CROSSOVER / math::sqrt(k as f32);
    math::saturate((full_below + LADDER_BLEND - n_dot_v) / LADDER_BLEND)
}

/// `c` of the view `n·v = 1 − c/√k` below which the ladder's `k` fetches are used alone
/// ([`ladder_weight`]).
pub const LADDER_CROSSOVER: f32 = 1.4;
/// Width in `n·v` of the ladder's blend into the one fetch.
pub const LADDER_BLEND: f32 = 0.5;
