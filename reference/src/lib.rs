//! # splitsum-reference
//!
//! Independent references for splitsum's tests and `runner report`, in f64. None of them
//! calls the code under test: they use other formulas (textbook forms, not the
//! numerically rearranged ones), other parametrisations (Driscoll's corner formula for
//! texel solid angles, the OpenGL face table inverted by hand), and deterministic
//! quadrature or exact sums instead of Hammersley sampling. The only thing shared with the
//! code under test is the data: texel values of a cube, read as `glam::Vec4`.

#![cfg_attr(not(test), warn(unused_crate_dependencies))]
pub mod quadrature;
pub mod sheen;

use crate::quadrature::adaptive;
use std::f64::consts::PI;

/// Smith–Schlick G with `k`, textbook form `G₁(x) = x/(x(1−k)+k)`.
fn g_schlick(n_dot_v: f64, n_dot_l: f64, k: f64) -> f64 {
    let g1 = |x: f64| x / (x * (1.0 - k) + k);
    g1(n_dot_v) * g1(n_dot_l)
}

/// The masking–shadowing term of a reference integral.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Smith {
    /// Separable Smith with Schlick's G₁, `k = α/2`.
    Schlick,
    /// Height-correlated Smith for GGX in its textbook form
    /// `G₂ = 1/(1 + Λ(v) + Λ(l))`, `Λ(θ) = (−1 + √(1 + α² tan²θ))/2` (Heitz 2014, eq. 99;
    /// Walter et al. 2007, eq. 34 for Λ).
    Correlated,
    /// Separable Smith for GGX, `G₂ = G₁(v)·G₁(l)` with `G₁ = 1/(1 + Λ)` (Heitz 2014,
    /// eq. 98): Mitsuba 3's `roughconductor` (`MicrofacetDistribution::G` in
    /// `include/mitsuba/render/microfacet.h`, "Smith's separable shadowing-masking
    /// approximation"), not the glTF BRDF's.
    Separable,
}

impl Smith {
    /// `G(v, l)` at `n·v`, `n·l` for GGX width `alpha`.
    pub fn g(self, n_dot_v: f64, n_dot_l: f64, alpha: f64) -> f64 {
        match self {
            Smith::Schlick => g_schlick(n_dot_v, n_dot_l, alpha / 2.0),
            Smith::Correlated | Smith::Separable => {
                let lambda = |c: f64| {
                    let tan2 = (1.0 - c * c) / (c * c);
                    (-1.0 + (1.0 + alpha * alpha * tan2).sqrt()) / 2.0
                };
                if self == Smith::Correlated {
                    1.0 / (1.0 + lambda(n_dot_v) + lambda(n_dot_l))
                } else {
                    1.0 / ((1.0 + lambda(n_dot_v)) * (1.0 + lambda(n_dot_l)))
                }
            }
        }
    }
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
    brdf_lut_with(n_dot_v, roughness, tol, Smith::Schlick)
}

/// [`brdf_lut`] with the masking–shadowing term `smith`.
pub fn brdf_lut_with(n_dot_v: f64, roughness: f64, tol: f64, smith: Smith) -> (f64, f64) {
    let a = brdf_lut_part(n_dot_v, roughness, tol, false, smith);
    let b = brdf_lut_part(n_dot_v, roughness, tol, true, smith);
    (a, b)
}

fn brdf_lut_part(n_dot_v: f64, roughness: f64, tol: f64, bias: bool, smith: Smith) -> f64 {
    let alpha = roughness * roughness;
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
            let g = smith.g(n_dot_v, n_dot_l, alpha);
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
    face_dir(face, 2.0 * (x as f64 + 0.5) / s as f64 - 1.0, 2.0 * (y as f64 + 0.5) / s as f64 - 1.0)
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
    let n = normalize(n); // see Environment::prefilter
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

/// The glTF 2.0 metallic–roughness BRDF times `n·l` (glTF 2.0 specification, Appendix
/// B.3.5, with B.3.4's `fresnel_mix` and `conductor_fresnel`), per channel:
///
/// `mix(fresnel_mix(ior 1.5, base/π, spec), conductor_fresnel(base, spec), metallic)`
/// `= (1 − metallic)(1 − F_d)·base/π + F·spec`, `spec = D G / (4 (n·l)(n·v))`,
/// with Schlick's `F_d = 0.04 + 0.96(1 − v·h)⁵` (the dielectric, `((1 − 1.5)/(1 + 1.5))²`)
/// and `F = F₀ + (1 − F₀)(1 − v·h)⁵`, `F₀ = mix(0.04, base, metallic)` (the two layers'
/// Fresnel terms mixed: Schlick is linear in `F₀`). `d` is GGX's `D(h)` and `g` the masking
/// term's `G(l, v)`.
#[allow(clippy::too_many_arguments)]
pub fn gltf_brdf_cos(base: [f64; 3], metallic: f64, d: f64, g: f64, n_dot_l: f64, n_dot_v: f64, v_dot_h: f64) -> [f64; 3] {
    let fc = (1.0 - v_dot_h.clamp(0.0, 1.0)).powi(5);
    let f_dielectric = 0.04 + 0.96 * fc;
    std::array::from_fn(|c| {
        let f0 = 0.04 + (base[c] - 0.04) * metallic;
        let f = f0 + (1.0 - f0) * fc;
        ((1.0 - metallic) * (1.0 - f_dielectric) * base[c] / PI + d * g * f / (4.0 * n_dot_l * n_dot_v)) * n_dot_l
    })
}

/// The cosine-weighted mean of Schlick's weight over the hemisphere of light directions,
/// `(1/π) ∫ (1 − v·h)⁵ (n·l) dl` with `h` the half vector of `v` and `l`, by nested adaptive
/// quadrature over `l` in polar coordinates about `n` (`θ` in `[0, π/2]`, `φ` in `[0, π]`
/// doubled by symmetry), `v·h = √((1 + v·l)/2)`. Under a constant sky the glTF diffuse layer
/// reflects `(1 − 0.04)(1 − this)` of its albedo.
pub fn schlick_weight_hemispherical_mean(n_dot_v: f64, tol: f64) -> f64 {
    let sin_v = (1.0 - n_dot_v * n_dot_v).max(0.0).sqrt();
    let outer = |theta: f64| {
        let (st, ct) = theta.sin_cos();
        let inner = |phi: f64| {
            let v_dot_l = sin_v * st * phi.cos() + n_dot_v * ct;
            let v_dot_h = ((1.0 + v_dot_l) / 2.0).max(0.0).sqrt();
            (1.0 - v_dot_h).powi(5)
        };
        2.0 * adaptive(&inner, 0.0, PI, tol) * ct * st
    };
    adaptive(&outer, 0.0, PI / 2.0, tol) / PI
}

/// Reflected radiance towards `v` of a glTF metallic–roughness surface with normal `n`,
/// lit by every texel of an environment (`texels` from [`texels`]), by the full
/// reflectance integral with no split: `L_o = Σ f(l, v) L(l) max(0, n·l) Ω` with `f` the
/// glTF BRDF ([`gltf_brdf_cos`]), GGX `D` (α = r²) in its textbook form and Smith–Schlick
/// `G` with `k = α/2` (the remapping the split sum's sampled table uses).
pub fn shade_full(texels: &[([f64; 3], f64, [f64; 3])], n: [f64; 3], v: [f64; 3], base: [f64; 3], metallic: f64, roughness: f64) -> [f64; 3] {
    let (n, v) = (normalize(n), normalize(v)); // see Environment::prefilter
    let a2 = (roughness * roughness).powi(2);
    let k = roughness * roughness / 2.0;
    let nv = dot(n, v);
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
        let f = gltf_brdf_cos(base, metallic, d, g1(nv) * g1(nl), nl, nv, vh);
        for c in 0..3 {
            out[c] += f[c] * radiance[c] * omega;
        }
    }
    out
}

/// Rec. 709 luminance.
pub fn luminance(c: [f64; 3]) -> f64 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

/// One texel of a cube level as the sub-sampled references see it.
#[derive(Clone, Copy, Debug)]
pub struct Texel {
    /// Face (OpenGL order).
    pub face: u32,
    /// Column.
    pub x: u32,
    /// Row.
    pub y: u32,
    /// Unit direction through its centre.
    pub dir: [f64; 3],
    /// Its solid angle.
    pub omega: f64,
    /// Its radiance.
    pub rgb: [f64; 3],
}

/// A cube level as a piecewise-constant radiance function: every texel is a patch of the
/// sphere with one value. [`Environment::integrate`] sums a weight over it, splitting a
/// texel into `k×k` sub-patches (exact solid angles, by Driscoll's corner formula) where
/// the weight varies on a scale smaller than the texel, so that lobes narrower than a
/// texel are integrated, not point-sampled.
pub struct Environment {
    /// Face size.
    pub size: u32,
    /// Every texel.
    pub texels: Vec<Texel>,
}

/// The direction through face coordinates `(a, b)` ∈ [−1, 1]² of `face` (OpenGL 4.6
/// §8.13, major axis, s_c, t_c, inverted by hand).
pub fn face_dir(face: u32, a: f64, b: f64) -> [f64; 3] {
    normalize(match face {
        0 => [1.0, -b, -a],
        1 => [-1.0, -b, a],
        2 => [a, 1.0, b],
        3 => [a, -1.0, -b],
        4 => [a, -b, 1.0],
        _ => [-a, -b, -1.0],
    })
}

/// Solid angle of the face rectangle `[a0, a1] × [b0, b1]` (Driscoll 2012).
fn rect_solid_angle(a0: f64, a1: f64, b0: f64, b1: f64) -> f64 {
    let f = |u: f64, v: f64| (u * v).atan2((u * u + v * v + 1.0).sqrt());
    f(a0, b0) - f(a0, b1) - f(a1, b0) + f(a1, b1)
}

impl Environment {
    /// The level `level` (`s`×`s` faces, RGBA) of a cube.
    pub fn new(level: &[splitsum_shaders::glam::Vec4], s: u32) -> Self {
        let mut texels = Vec::with_capacity(level.len());
        for face in 0..6 {
            for y in 0..s {
                for x in 0..s {
                    let t = level[((face * s + y) * s + x) as usize];
                    let rgb = [t.x as f64, t.y as f64, t.z as f64];
                    texels.push(Texel { face, x, y, dir: texel_dir(face, x, y, s), omega: texel_solid_angle(x, y, s), rgb });
                }
            }
        }
        Self { size: s, texels }
    }

    /// The brightest texel's direction (by luminance).
    pub fn brightest(&self) -> [f64; 3] {
        self.texels.iter().max_by(|a, b| luminance(a.rgb).total_cmp(&luminance(b.rgb))).map_or([0.0, 0.0, 1.0], |t| t.dir)
    }

    /// `Σ L(l) w(l) dω` over the sphere and `Σ w(l) dω`, per channel, for a weight `w`
    /// (one per channel) whose angular scale of variation at `l` is `scale(l)` radians: a
    /// texel of angular size `√Ω` is split into `k = ⌈8√Ω/scale⌉` (at most 1024)
    /// sub-patches per side, eight to a scale, each summed by the midpoint rule.
    ///
    /// Eight, not two: GGX's `D` falls from its peak to a quarter within one `α`, and the
    /// midpoint rule at two points per `α` misses the peak's integral by tens of percent. On
    /// a constant sky (where the integral is the table's `A + B`, an independent 2-D
    /// quadrature) two per scale was 18 % low at `n·v = 0.25`, `r = 0.05` and 60 % low at
    /// `n·v = 0.1` on a 256² cube; eight is within 0.2 % for `r ≥ 0.02`, `n·v ≥ 0.1`
    /// (`reference_shading_matches_the_table_on_a_constant_sky`).
    pub fn integrate(&self, w: impl Fn([f64; 3]) -> [f64; 3], scale: impl Fn([f64; 3]) -> f64) -> ([f64; 3], [f64; 3]) {
        let mut acc = [0.0; 3];
        let mut wsum = [0.0; 3];
        let s = self.size as f64;
        for t in &self.texels {
            let k = ((8.0 * t.omega.sqrt() / scale(t.dir).max(1e-12)).ceil() as u32).clamp(1, 1024);
            let mut tw = [0.0; 3];
            if k == 1 {
                tw = w(t.dir).map(|x| x * t.omega);
            } else {
                let d = 2.0 / s;
                let (a0, b0) = (t.x as f64 * d - 1.0, t.y as f64 * d - 1.0);
                let h = d / k as f64;
                for j in 0..k {
                    for i in 0..k {
                        let (a, b) = (a0 + i as f64 * h, b0 + j as f64 * h);
                        let dir = face_dir(t.face, a + 0.5 * h, b + 0.5 * h);
                        let om = rect_solid_angle(a, a + h, b, b + h).abs();
                        let wd = w(dir);
                        for c in 0..3 {
                            tw[c] += wd[c] * om;
                        }
                    }
                }
            }
            for c in 0..3 {
                acc[c] += tw[c] * t.rgb[c];
                wsum[c] += tw[c];
            }
        }
        (acc, wsum)
    }

    /// GGX-prefiltered radiance with `n = v = r` (see [`prefilter`]), sub-sampled where the
    /// lobe is narrower than a texel.
    ///
    /// `n` is normalised here, in f64: a direction normalised in f32 is off unit length by
    /// up to 6·10⁻⁸, which moves `(n·h)²(α² − 1) + 1` by as much as `α²` itself at r 0.02
    /// (`α² = 1.6·10⁻⁷`) and puts the peak of `D` beside where it is: half a texel from a
    /// texel 10⁴ times its sky, 9.7 % off (`reference_directions_need_not_be_unit_length`).
    pub fn prefilter(&self, n: [f64; 3], roughness: f64) -> [f64; 3] {
        let n = normalize(n);
        let alpha = roughness * roughness;
        let a2 = alpha * alpha;
        let half = |l: [f64; 3]| normalize([n[0] + l[0], n[1] + l[1], n[2] + l[2]]);
        let w = |l: [f64; 3]| {
            let nl = dot(n, l);
            if nl <= 0.0 {
                return 0.0;
            }
            let nh = dot(n, half(l));
            a2 / (PI * (nh * nh * (a2 - 1.0) + 1.0).powi(2)) * nl
        };
        let scale = |l: [f64; 3]| 2.0 * alpha.max(dot(n, half(l)).clamp(-1.0, 1.0).acos());
        let (acc, wsum) = self.integrate(|l| [w(l); 3], scale);
        if wsum[0] > 0.0 { acc.map(|v| v / wsum[0]) } else { [0.0; 3] }
    }

    /// Reflected radiance towards `v` of a glTF metallic–roughness surface by the full
    /// reflectance integral of the glTF BRDF ([`gltf_brdf_cos`]) with no split, as
    /// [`shade_full`] but with the masking term `smith` (the glTF specification's is
    /// [`Smith::Correlated`]) and sub-sampled where the specular lobe is narrower than a
    /// texel.
    #[allow(clippy::too_many_arguments)]
    pub fn shade(&self, n: [f64; 3], v: [f64; 3], base: [f64; 3], metallic: f64, roughness: f64, smith: Smith) -> [f64; 3] {
        // Normalised in f64, as in `prefilter`.
        let (n, v) = (normalize(n), normalize(v));
        let alpha = roughness * roughness;
        let a2 = alpha * alpha;
        let nv = dot(n, v);
        let half = |l: [f64; 3]| normalize([l[0] + v[0], l[1] + v[1], l[2] + v[2]]);
        // The lobe in `l` is `2α` wide in the plane of `v` and `h`, and `2α(v·h)` across it
        // (reflection about `h` scales the perpendicular turn by `v·h`): at grazing views it
        // is a thin sliver, and the scale must follow its thin side.
        let scale = |l: [f64; 3]| {
            let h = half(l);
            2.0 * dot(v, h).max(0.01) * alpha.max(dot(n, h).clamp(-1.0, 1.0).acos())
        };
        let w = |l: [f64; 3]| {
            let nl = dot(n, l);
            if nl <= 0.0 || nv <= 0.0 {
                return [0.0; 3];
            }
            let h = half(l);
            let nh = dot(n, h);
            let vh = dot(v, h).max(0.0);
            let d = a2 / (PI * (nh * nh * (a2 - 1.0) + 1.0).powi(2));
            gltf_brdf_cos(base, metallic, d, smith.g(nv, nl, alpha), nl, nv, vh)
        };
        self.integrate(w, scale).0
    }
}
