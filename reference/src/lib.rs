//! # splitsum-reference
//!
//! Independent references for splitsum's tests and `runner report`, in f64. None of them
//! calls the code under test: they use other formulas (textbook forms, not the
//! numerically rearranged ones), other parametrisations (Driscoll's corner formula for
//! texel solid angles, the OpenGL face table inverted by hand), and deterministic
//! quadrature or exact sums instead of Hammersley sampling. The only thing shared with the
//! code under test is the data: texel values of a cube, read as `glam::Vec4`.

pub mod quadrature;

use crate::quadrature::adaptive;
use std::f64::consts::PI;

/// Smith–Schlick G with `k`, textbook form `G₁(x) = x/(x(1−k)+k)`.
fn g_schlick(n_dot_v: f64, n_dot_l: f64, k: f64) -> f64 {
    let g1 = |x: f64| x / (x * (1.0 - k) + k);
    g1(n_dot_v) * g1(n_dot_l)
}

/// Split-sum `(A, B)` at `(n·v, roughness)` by nested adaptive Gauss–Kronrod quadrature over
/// the half vector, in the substitution `tan θ_h = α tan x`, where GGX's peak flattens:
/// `D(h)(n·h) dω_h = (1/π) sin x cos x dx dφ`. With `dω_l = 4(v·h) dω_h`,
///
/// `A = ∫ D G (v·h) / ((n·h)(n·v)) (1 − F_c) dω_h`, `B` likewise with `F_c`.
///
/// φ runs over `[0, φ_max(x)]`, the part of the azimuth where `n·l > 0` (solved in closed
/// form), doubled by the symmetry about the plane of `n` and `v`; `tol` is the absolute
/// tolerance of each integral.
pub fn brdf_lut(n_dot_v: f64, roughness: f64, tol: f64) -> (f64, f64) {
    let a = brdf_lut_part(n_dot_v, roughness, tol, false);
    let b = brdf_lut_part(n_dot_v, roughness, tol, true);
    (a, b)
}

fn brdf_lut_part(n_dot_v: f64, roughness: f64, tol: f64, bias: bool) -> f64 {
    let alpha = roughness * roughness;
    let k = alpha / 2.0;
    let sin_v = (1.0 - n_dot_v * n_dot_v).sqrt();
    let v = [sin_v, 0.0, n_dot_v];
    let outer = |x: f64| -> f64 {
        let theta_h = (alpha * x.tan()).atan();
        let (st, ct) = theta_h.sin_cos();
        let measure = x.sin() * x.cos() / PI;
        // n·l = 2(v·h)(n·h) − n·v > 0  ⇔  cos φ > c*, with v·h = sin θ_v sin θ_h cos φ + cos θ_v cos θ_h.
        let c_star = (n_dot_v / (2.0 * ct) - n_dot_v * ct) / (sin_v * st);
        let phi_max = if c_star.is_nan() || c_star <= -1.0 {
            PI
        } else if c_star >= 1.0 {
            return 0.0;
        } else {
            c_star.acos()
        };
        let inner = |phi: f64| -> f64 {
            let h = [st * phi.cos(), st * phi.sin(), ct];
            let v_dot_h = v[0] * h[0] + v[1] * h[1] + v[2] * h[2];
            let n_dot_l = 2.0 * v_dot_h * h[2] - v[2];
            if n_dot_l <= 0.0 || v_dot_h <= 0.0 {
                return 0.0;
            }
            let g = g_schlick(n_dot_v, n_dot_l, k);
            let vis = g * v_dot_h / (ct * n_dot_v);
            let fc = (1.0 - v_dot_h).powi(5);
            vis * if bias { fc } else { 1.0 - fc }
        };
        2.0 * measure * adaptive(&inner, 0.0, phi_max, tol)
    };
    adaptive(&outer, 0.0, PI / 2.0, tol)
}

/// Unit direction of texel `(x, y)` of `face` (size `s`), in f64, from the face table of
/// OpenGL 4.6 §8.13 (major axis, s_c, t_c) inverted by hand.
pub fn texel_dir(face: u32, x: u32, y: u32, s: u32) -> [f64; 3] {
    let a = 2.0 * (x as f64 + 0.5) / s as f64 - 1.0;
    let b = 2.0 * (y as f64 + 0.5) / s as f64 - 1.0;
    let d = match face {
        0 => [1.0, -b, -a],
        1 => [-1.0, -b, a],
        2 => [a, 1.0, b],
        3 => [a, -1.0, -b],
        4 => [a, -b, 1.0],
        _ => [-a, -b, -1.0],
    };
    normalize(d)
}

/// `d / |d|`.
pub fn normalize(d: [f64; 3]) -> [f64; 3] {
    let l = dot(d, d).sqrt();
    [d[0] / l, d[1] / l, d[2] / l]
}

/// `a·b`.
pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Solid angle of texel `(x, y)` of an `s`×`s` face by the corner formula
/// `Ω = A(x₀,y₀) − A(x₀,y₁) − A(x₁,y₀) + A(x₁,y₁)`, `A(x, y) = atan2(xy, √(x²+y²+1))`
/// (Driscoll 2012, "Cubemap Texel Solid Angle") — another formula than the code's.
pub fn texel_solid_angle(x: u32, y: u32, s: u32) -> f64 {
    let c = |i: u32| 2.0 * i as f64 / s as f64 - 1.0;
    let a = |u: f64, v: f64| (u * v).atan2((u * u + v * v + 1.0).sqrt());
    let (x0, x1, y0, y1) = (c(x), c(x + 1), c(y), c(y + 1));
    a(x0, y0) - a(x0, y1) - a(x1, y0) + a(x1, y1)
}

/// Every texel of one level (`s`×`s` faces, RGBA) with its direction and solid angle.
pub fn texels(level: &[splitsum_shaders::glam::Vec4], s: u32) -> Vec<([f64; 3], f64, [f64; 3])> {
    let mut out = Vec::with_capacity(level.len());
    for face in 0..6 {
        for y in 0..s {
            for x in 0..s {
                let t = level[((face * s + y) * s + x) as usize];
                out.push((texel_dir(face, x, y, s), texel_solid_angle(x, y, s), [t.x as f64, t.y as f64, t.z as f64]));
            }
        }
    }
    out
}

/// The GGX-prefiltered radiance that the split sum's first term converges to, by an exact
/// sum over every source texel: with `n = v = r`, `pdf(l) ∝ D(h)` and weight `n·l`,
/// `L̃(n) = Σ L D(h) max(0, n·l) Ω / Σ D(h) max(0, n·l) Ω`, `h = (n + l)/|n + l|`.
/// GGX `D` in its textbook form `α² / (π ((n·h)²(α² − 1) + 1)²)`.
pub fn prefilter(texels: &[([f64; 3], f64, [f64; 3])], n: [f64; 3], roughness: f64) -> [f64; 3] {
    let a2 = (roughness * roughness).powi(2);
    let mut acc = [0.0; 3];
    let mut wsum = 0.0;
    for (l, omega, c) in texels {
        let nl = dot(n, *l);
        if nl <= 0.0 {
            continue;
        }
        let h = normalize([n[0] + l[0], n[1] + l[1], n[2] + l[2]]);
        let nh = dot(n, h);
        let d = a2 / (PI * (nh * nh * (a2 - 1.0) + 1.0).powi(2));
        let w = d * nl * omega;
        for k in 0..3 {
            acc[k] += w * c[k];
        }
        wsum += w;
    }
    acc.map(|v| v / wsum)
}

/// Irradiance over π, `(1/π) Σ L max(0, n·l) Ω`, by an exact sum over every texel.
pub fn irradiance(texels: &[([f64; 3], f64, [f64; 3])], n: [f64; 3]) -> [f64; 3] {
    let mut acc = [0.0; 3];
    for (l, omega, c) in texels {
        let nl = dot(n, *l);
        if nl > 0.0 {
            for k in 0..3 {
                acc[k] += c[k] * nl * omega;
            }
        }
    }
    acc.map(|v| v / PI)
}

/// Reflected radiance towards `v` of a glTF metallic–roughness surface with normal `n`,
/// lit by every texel of an environment (`texels` from [`texels`]), by the full
/// reflectance integral with no split:
///
/// `L_o = Σ f(l, v) L(l) max(0, n·l) Ω`, with
/// `f = (1 − F(v·h))(1 − metallic)·base/π + D(h) G(l, v) F(v·h) / (4 (n·l)(n·v))`,
/// GGX `D` (α = r²) in its textbook form, Smith–Schlick `G` with `k = α/2` (the remapping
/// the split sum's table uses), Schlick `F` with `F₀ = mix(0.04, base, metallic)`.
pub fn shade_full(texels: &[([f64; 3], f64, [f64; 3])], n: [f64; 3], v: [f64; 3], base: [f64; 3], metallic: f64, roughness: f64) -> [f64; 3] {
    let a2 = (roughness * roughness).powi(2);
    let k = roughness * roughness / 2.0;
    let nv = dot(n, v);
    let f0: [f64; 3] = std::array::from_fn(|c| 0.04 + (base[c] - 0.04) * metallic);
    let g1 = |x: f64| x / (x * (1.0 - k) + k);
    let mut out = [0.0; 3];
    for (l, omega, radiance) in texels {
        let nl = dot(n, *l);
        if nl <= 0.0 {
            continue;
        }
        let h = normalize([l[0] + v[0], l[1] + v[1], l[2] + v[2]]);
        let nh = dot(n, h);
        let vh = dot(v, h).max(0.0);
        let d = a2 / (PI * (nh * nh * (a2 - 1.0) + 1.0).powi(2));
        let g = g1(nv) * g1(nl);
        let fc = (1.0 - vh).powi(5);
        for c in 0..3 {
            let f = f0[c] + (1.0 - f0[c]) * fc;
            let brdf = (1.0 - f) * (1.0 - metallic) * base[c] / PI + d * g * f / (4.0 * nl * nv);
            out[c] += brdf * radiance[c] * nl * omega;
        }
    }
    out
}

/// Rec. 709 luminance.
pub fn luminance(c: [f64; 3]) -> f64 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}
