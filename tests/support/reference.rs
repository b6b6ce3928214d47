//! Independent f64 references. None of them calls the code under test: they use other
//! formulas (textbook forms, not the numerically rearranged ones), other
//! parametrisations and deterministic quadrature instead of Hammersley sampling.

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
