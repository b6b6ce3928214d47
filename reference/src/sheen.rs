//! The Charlie sheen lobe in f64, written from Estevez & Kulla 2017 ("Production Friendly
//! Microfacet Sheen BRDF") and the `KHR_materials_sheen` text, sharing nothing with
//! `splitsum_shaders::brdf::sheen`: angles instead of cosines (`sin θ` from `θ`), `exp`
//! and `powf` instead of the shaders' polynomials, and the directional albedo integrated
//! over the light direction in spherical coordinates by adaptive Gauss–Kronrod quadrature
//! (the shaders' side samples half vectors).

use crate::quadrature::adaptive;
use std::f64::consts::PI;

/// `α = r²` with `r` clamped to [10⁻⁶, 1], as the engines do.
pub fn alpha(roughness: f64) -> f64 {
    roughness.clamp(1e-6, 1.0).powi(2)
}

/// `D` at the angle `theta_h` between `h` and `n`: `(2 + 1/α)·sin(θ)^(1/α)/(2π)`.
pub fn d_charlie_angle(theta_h: f64, alpha: f64) -> f64 {
    (2.0 + 1.0 / alpha) * theta_h.sin().abs().powf(1.0 / alpha) / (2.0 * PI)
}

/// `D` at `n·h` (through the angle).
pub fn d_charlie(n_dot_h: f64, alpha: f64) -> f64 {
    d_charlie_angle(n_dot_h.clamp(-1.0, 1.0).acos(), alpha)
}

/// Estevez & Kulla's Table 1 fits, blended by `(1 − α)²`, and `Λ` from them.
pub fn lambda_charlie(cos_theta: f64, alpha: f64) -> f64 {
    let t = (1.0 - alpha).powi(2);
    let fit = |x: f64| {
        let p = [(21.5473, 25.3245), (3.82987, 3.32435), (0.19823, 0.16801), (-1.97760, -1.27393), (-4.32054, -4.85967)];
        let [a, b, c, d, e] = p.map(|(lo, hi)| lo * (1.0 - t) + hi * t);
        a / (1.0 + b * x.powf(c)) + d * x + e
    };
    let x = cos_theta.abs().min(1.0);
    if x < 0.5 { fit(x).exp() } else { (2.0 * fit(0.5) - fit(1.0 - x)).exp() }
}

/// The Charlie visibility, clamped to [0, 1] as the Sample Viewer's `V_Sheen`.
pub fn v_charlie(n_dot_l: f64, n_dot_v: f64, alpha: f64) -> f64 {
    if n_dot_l <= 0.0 || n_dot_v <= 0.0 {
        return 0.0;
    }
    (1.0 / ((1.0 + lambda_charlie(n_dot_v, alpha) + lambda_charlie(n_dot_l, alpha)) * 4.0 * n_dot_l * n_dot_v)).clamp(0.0, 1.0)
}

/// The Neubelt–Pettineo visibility, clamped to [0, 1] as glTF-IBL-Sampler's `V_Neubelt`.
pub fn v_neubelt(n_dot_l: f64, n_dot_v: f64) -> f64 {
    if n_dot_l <= 0.0 || n_dot_v <= 0.0 {
        return 0.0;
    }
    (0.25 / (n_dot_l + n_dot_v - n_dot_l * n_dot_v)).clamp(0.0, 1.0)
}

/// Which visibility term a sheen integral uses.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Visibility {
    /// Estevez & Kulla's fitted masking.
    Charlie,
    /// Neubelt & Pettineo's.
    Neubelt,
}

/// The directional albedo `E(n·v) = ∫ D(h)·V·(n·l) dω_l` of the sheen BRDF (no Fresnel,
/// colour 1) for the view at `n_dot_v` and perceptual sheen roughness `roughness`: over
/// the light's polar angle and azimuth (mirror-symmetric about the plane of `n` and `v`,
/// so over half the azimuth, doubled), to absolute tolerance `tol` per integral.
pub fn albedo(n_dot_v: f64, roughness: f64, visibility: Visibility, tol: f64) -> f64 {
    let a = alpha(roughness);
    let v = [(1.0 - n_dot_v * n_dot_v).max(0.0).sqrt(), 0.0, n_dot_v];
    let outer = |theta_l: f64| {
        let (sl, cl) = theta_l.sin_cos();
        let inner = |phi: f64| {
            let l = [sl * phi.cos(), sl * phi.sin(), cl];
            let h = [l[0] + v[0], l[1] + v[1], l[2] + v[2]];
            let len = (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]).sqrt();
            if len == 0.0 {
                return 0.0;
            }
            let theta_h = (h[2] / len).clamp(-1.0, 1.0).acos();
            let vis = match visibility {
                Visibility::Charlie => v_charlie(cl, n_dot_v, a),
                Visibility::Neubelt => v_neubelt(cl, n_dot_v),
            };
            d_charlie_angle(theta_h, a) * vis * cl
        };
        2.0 * adaptive(&inner, 0.0, PI, tol) * sl
    };
    adaptive(&outer, 0.0, PI / 2.0, tol)
}

/// The sheen-prefiltered radiance (glTF-IBL-Sampler's Charlie filter, `v = n`) that the
/// sheen cube converges to, by an exact sum over `texels` (as [`crate::texels`] lists them):
/// `L̃(n) = Σ L D(h) (n·l) Ω / Σ D(h) (n·l) Ω` over `n·l > 0`, `h = (n + l)/|n + l|`.
/// `D` is taken through the angle of `h` and divided by its value at 45° (the largest over
/// `n·l ≥ 0`) in the log domain, `exp((ln sin²θ − ln ½)/(2α))`, so that no weight
/// underflows before the ratio; a texel is split into sub-patches where the ring the lobe
/// makes about the horizon (`4α/(1 + 4α)` wide in `n·l`) is narrower than eight of them.
pub fn prefilter(env: &crate::Environment, n: [f64; 3], roughness: f64) -> [f64; 3] {
    let a = alpha(roughness);
    let w = |l: [f64; 3]| {
        let nl = crate::dot(n, l);
        if nl <= 0.0 {
            return [0.0; 3];
        }
        let h = crate::normalize([n[0] + l[0], n[1] + l[1], n[2] + l[2]]);
        let theta = crate::dot(n, h).clamp(-1.0, 1.0).acos();
        let d = ((theta.sin().powi(2).ln() - 0.5f64.ln()) / (2.0 * a)).exp();
        [d * nl; 3]
    };
    let width = 4.0 * a / (1.0 + 4.0 * a);
    let (acc, wsum) = env.integrate(w, |_| width);
    if wsum[0] > 0.0 { acc.map(|v| v / wsum[0]) } else { [0.0; 3] }
}

/// The same sheen-prefiltered radiance as [`prefilter`], of a sky given as a function of
/// direction, by a product quadrature written in the lobe's own coordinates instead of over
/// texels: with `u = n·l` and `φ` the azimuth about `n`, the weight `D(h)(n·l)dω` is
/// `∝ u(1 − u)^k du dφ`, `k = 1/(2α)` (`n·h = √((1 + u)/2)`, `sin²θ = (1 − u)/2`). `u` by
/// Gauss–Legendre, 8 points on each of `panels` equal pieces of `[0, min(1, 60/k)]` (the
/// weight beyond is below `e⁻⁶⁰`), `φ` by the midpoint rule at `azimuths` points; where
/// `α < 10⁻⁵` (the lobe within `10⁻⁴` of the horizon) the mean over the horizon circle.
pub fn prefilter_of(sky: &dyn Fn([f64; 3]) -> [f64; 3], n: [f64; 3], roughness: f64, panels: usize, azimuths: usize) -> [f64; 3] {
    let n = crate::normalize(n);
    // A tangent frame: any unit vector off n, made orthogonal.
    let a = if n[0].abs() < 0.9 { [1.0, 0.0, 0.0] } else { [0.0, 1.0, 0.0] };
    let d = crate::dot(a, n);
    let t = crate::normalize([a[0] - d * n[0], a[1] - d * n[1], a[2] - d * n[2]]);
    let b = [n[1] * t[2] - n[2] * t[1], n[2] * t[0] - n[0] * t[2], n[0] * t[1] - n[1] * t[0]];
    let ring = |u: f64| {
        let s = (1.0 - u * u).max(0.0).sqrt();
        let mut acc = [0.0; 3];
        for j in 0..azimuths {
            let phi = std::f64::consts::TAU * (j as f64 + 0.5) / azimuths as f64;
            let (sp, cp) = phi.sin_cos();
            let l = [0, 1, 2].map(|c| s * (cp * t[c] + sp * b[c]) + u * n[c]);
            let v = sky(l);
            (0..3).for_each(|c| acc[c] += v[c]);
        }
        acc.map(|v| v / azimuths as f64)
    };
    let al = alpha(roughness);
    if al < 1e-5 {
        return ring(0.0);
    }
    let k = 0.5 / al;
    let top = (60.0 / k).min(1.0);
    let h = top / panels as f64;
    let rule = crate::quadrature::gauss_legendre(8, 0.0, h);
    let (mut acc, mut wsum) = ([0.0; 3], 0.0);
    for p in 0..panels {
        for &(x, w) in &rule {
            let u = p as f64 * h + x;
            // u(1 − u)^k in the log domain: no underflow for large k.
            let wu = w * (u.ln() + k * (-u).ln_1p()).exp();
            let r = ring(u);
            (0..3).for_each(|c| acc[c] += wu * r[c]);
            wsum += wu;
        }
    }
    acc.map(|v| v / wsum)
}
