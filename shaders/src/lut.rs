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

use crate::brdf::{alpha_from_roughness, fresnel, microfacet};
use crate::math::{self, CompensatedSum};
use crate::sampling;
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
