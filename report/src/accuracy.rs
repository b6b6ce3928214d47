//! What a renderer shows: the shaded colour of the display's image-based light, end to
//! end, at any roughness and view, against the full reflectance integral; and the
//! prefiltered radiance a renderer reads at any roughness, between mips and around the sun.
//!
//! **Truth.** The environment is the source cube at the bake's resolution, taken as a
//! piecewise-constant function (each texel a patch of sphere). The references of
//! `splitsum_reference::Environment` integrate over it in f64, splitting a texel into
//! sub-patches wherever the GGX lobe is narrower than the texel. The shaded colour's
//! truth is the single-scattering GGX microfacet BRDF with the exact (height-correlated)
//! Smith masking, plus the `(1 − F)`-weighted Lambert diffuse of glTF, integrated with no
//! split.
//!
//! **Points.** Roughness is drawn continuously over `[0.02, 1]` (below 0.02 the lobe is
//! narrower than the references' finest sub-patch), `n·v` over `(0, 1]`, normals spread
//! over the sphere (a Hammersley set), plus normals facing the brightest texel (the sun)
//! and normals whose mirror direction is the sun; metals and dielectrics alternate.
//!
//! **Decomposition** of each method's error against the truth:
//! - (a) *bake*: the display with the baked products against the same display formula fed
//!   exact ingredients (exact prefiltered radiance along the direction the method reads,
//!   exact irradiance, exact table): sampling, resolution and mip interpolation;
//! - (b) *split sum*: that exact-ingredient display against the full integral with the
//!   method's own masking term: `n = v = r`, the split, the read direction;
//! - (c) *model*: the full integral with the method's masking term against the truth
//!   (Smith–Schlick against exact Smith).

use crate::measurement::{Knob, Measurement, Method as Kind, Metric, Part, Quantity, arr, rel, rel64};
use rayon::prelude::*;
use splitsum::Product;
use splitsum::backend::Backend;
use splitsum::bake;
use splitsum::reading;
use splitsum::environment::Environment;
use splitsum::error::Result;
use splitsum::settings::{Settings, TableMethod};
use splitsum::texture::Cube;
use splitsum_reference as reference;
use splitsum_shaders::brdf::microfacet::Masking;
use splitsum_shaders::glam::{Vec2, Vec3};
use splitsum_shaders::prefilter::RoughnessMapping;
use splitsum_shaders::shade::{self, IblSample, Material, ShadeOptions};
use splitsum_shaders::{equirect, sampling};
use std::time::Instant;

/// Roughness bands of the report (lower bounds; the last ends at 1).
pub const ROUGHNESS_BANDS: [f32; 7] = [0.02, 0.05, 0.1, 0.2, 0.35, 0.5, 0.75];
/// `n·v` bands (upper bounds; the first starts at 0).
pub const VIEW_BANDS: [f32; 4] = [0.1, 0.3, 0.6, 1.0];

/// The roughness band `[lo, hi)` holding `r` (the last band ends at 1, inclusive).
fn roughness_band(r: f32) -> (f32, f32) {
    let i = ROUGHNESS_BANDS.iter().rposition(|&lo| r >= lo).unwrap_or(0);
    (ROUGHNESS_BANDS[i], ROUGHNESS_BANDS.get(i + 1).copied().unwrap_or(1.0))
}

/// The `n·v` band `(lo, hi]` holding `nv`.
fn view_band(nv: f32) -> (f32, f32) {
    let i = VIEW_BANDS.iter().position(|&hi| nv <= hi).unwrap_or(VIEW_BANDS.len() - 1);
    (if i == 0 { 0.0 } else { VIEW_BANDS[i - 1] }, VIEW_BANDS[i])
}

/// A display method: bake settings and shading flags.
#[derive(Clone, Debug)]
pub struct Method {
    /// Which method (its colour on the plots; methods that differ only in the sample
    /// count share one, told apart by `settings.samples`).
    pub kind: Kind,
    /// How it bakes.
    pub settings: Settings,
    /// `ShadeOptions::flags` of its image-based light (`IBL` and options).
    pub flags: u32,
}

impl Method {
    fn options(&self) -> ShadeOptions {
        ShadeOptions { flags: self.flags | ShadeOptions::IBL, ..ShadeOptions::DEFAULT }
    }

    /// Whether it reads a split source as splitsum's renderer does (`reading::for_display`);
    /// the seed and the engine targets' reads stand for other renderers, which read the
    /// whole cubes of their files.
    fn reads_split(&self) -> bool {
        !matches!(self.kind, Kind::Seed | Kind::KhronosBevyLookup | Kind::FilamentLookup)
    }

    /// Its bake, as its renderer reads it.
    fn bake(&self, backend: &Backend, env: &Environment) -> Result<reading::BakedEnvironment> {
        if self.reads_split() {
            return reading::bake_for_display(backend, env, &self.settings);
        }
        let job = self.settings.resolve(splitsum::InputShape::of(env), splitsum::Products::DISPLAY)?;
        Ok(bake::bake_job(backend, env, &job)?.into_display(job.mapping))
    }
}

/// One shading point and its references.
struct ShadingPoint {
    material: Material,
    n: Vec3,
    v: Vec3,
    /// Full integral, exact Smith: the truth.
    truth: [f64; 3],
    /// Full integral with Smith–Schlick (`k = α/2`).
    full_schlick: [f64; 3],
    /// Exact `E/π` along `n`.
    irradiance: [f64; 3],
    /// The same two of the residual of the source split for reading
    /// (`reading::split_for_reading`): what a split read's cubes stand for.
    residual: ([f64; 3], [[f64; 3]; 4]),
    /// Exact prefiltered radiance along each direction the one fetch may read along
    /// (`shade::read_direction`), indexed by [`read_index`].
    prefiltered: [[f64; 3]; 4],
    /// Exact tables `(A, B)`: Smith–Schlick, exact Smith.
    table: [Vec2; 2],
}

/// The read-direction flags of [`ShadingPoint::prefiltered`]'s entries.
const READ_FLAGS: [u32; 4] =
    [0, ShadeOptions::DOMINANT_DIRECTION, ShadeOptions::LIFT_ABOVE_HORIZON, ShadeOptions::DOMINANT_DIRECTION | ShadeOptions::LIFT_ABOVE_HORIZON];

/// The entry of [`ShadingPoint::prefiltered`] that shading with `flags` reads along: the
/// one whose read-direction flags are those of `flags`.
fn read_index(flags: u32) -> usize {
    let read = flags & (ShadeOptions::DOMINANT_DIRECTION | ShadeOptions::LIFT_ABOVE_HORIZON);
    READ_FLAGS.iter().position(|&f| f == read).expect("READ_FLAGS lists every combination of the read-direction flags")
}

/// One lookup of the prefiltered radiance.
struct LookupPoint {
    dir: Vec3,
    roughness: f32,
    near_sun: bool,
    exact: [f64; 3],
}

/// The points and their references, computed once for every method.
pub struct Points {
    shading: Vec<ShadingPoint>,
    lookups: Vec<LookupPoint>,
}

fn vec(c: [f64; 3]) -> Vec3 {
    Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32)
}

/// A unit direction spread over the sphere (point `i` of `n` of a Hammersley set through
/// the equirect map, area-uniform in `cos θ`).
fn sphere_dir(i: u32, n: u32) -> Vec3 {
    let p = sampling::hammersley(i, n);
    // v = acos(1 − 2y)/π makes the set uniform in area.
    let z = 1.0 - 2.0 * p.y;
    let v = (z.clamp(-1.0, 1.0)).acos() / std::f32::consts::PI;
    equirect::uv_to_dir(Vec2::new(p.x, v))
}

/// Base-3 radical inverse: a third low-discrepancy dimension.
fn radical3(mut i: u32) -> f32 {
    let (mut f, mut r) = (1.0f64, 0.0f64);
    while i > 0 {
        f /= 3.0;
        r += f * (i % 3) as f64;
        i /= 3;
    }
    r as f32
}

/// The golden-ratio sequence `frac(i·φ)`: a low-discrepancy dimension uncorrelated with
/// the parity of `i` (which picks metal or dielectric, sun or not).
fn golden(i: u32) -> f32 {
    ((i as f64 * 0.618_033_988_749_895 + 0.5).fract()) as f32
}

/// A unit vector perpendicular to `n`, turned by `turn` (in turns) about it.
fn tangent(n: Vec3, turn: f32) -> Vec3 {
    let (t, b) = sampling::orthonormal_basis(n);
    let (s, c) = (turn * std::f32::consts::TAU).sin_cos();
    t * c + b * s
}

impl Points {
    /// `shading` shading points and `lookups` lookups over `source` (its level 0).
    pub fn new(source: &Cube, shading: u32, lookups: u32) -> Self {
        let s = source.layout.size;
        let env = reference::Environment::new(source.level(0), s);
        let rest = reference::Environment::new(&reading::split_for_reading(source).0, s);
        let sun = vec(env.brightest()).normalize();
        let base = Vec3::new(0.9, 0.6, 0.3);
        let mut pts = Vec::new();
        for i in 0..shading {
            let nv = (1.0 - radical3(i + 1)).max(1e-3);
            let r = 0.02 + 0.98 * golden(i);
            let turn = sampling::hammersley(i, shading).x;
            // Every fourth point faces the sun; every fourth (offset by two) mirrors it.
            let (n, v) = match i % 4 {
                1 => (sun, (sun * nv + tangent(sun, turn) * (1.0 - nv * nv).sqrt()).normalize()),
                3 => {
                    // n halfway between the sun and a view at n·v from it: reflect(v, n) = sun.
                    let t = tangent(sun, turn);
                    let theta = nv.acos(); // angle between n and v (and n and sun)
                    let n = (sun * theta.cos() + t * theta.sin()).normalize();
                    (n, sampling::reflect(sun, n))
                }
                _ => {
                    let n = sphere_dir(i, shading);
                    (n, (n * nv + tangent(n, turn) * (1.0 - nv * nv).sqrt()).normalize())
                }
            };
            let material = Material {
                base_color: base,
                metallic: (i % 2) as f32,
                roughness: r,
                occlusion: 1.0,
                emissive: Vec3::ZERO,
                sheen_color: Vec3::ZERO,
                sheen_roughness: 0.0,
            };
            pts.push((material, n, v));
        }
        let shading: Vec<ShadingPoint> = pts
            .into_par_iter()
            .map(|(m, n, v)| {
                let (na, va, b) = (arr(n), arr(v), arr(m.base_color));
                let r = m.roughness as f64;
                let nv = n.dot(v).max(shade::MIN_N_DOT_V) as f64;
                let table = |smith| {
                    let (a, b) = reference::brdf_lut_with(nv, r, 1e-7, smith);
                    Vec2::new(a as f32, b as f32)
                };
                // The exact prefiltered radiance of `env` along the four read directions, each
                // summed once (most coincide away from grazing views).
                let prefiltered = |env: &reference::Environment| {
                    let dirs: [Vec3; 4] = std::array::from_fn(|k| shade::read_direction(READ_FLAGS[k], n, v, m.roughness));
                    let mut sums: [[f64; 3]; 4] = [[0.0; 3]; 4];
                    for k in 0..4 {
                        sums[k] = match (0..k).find(|&j| dirs[j] == dirs[k]) {
                            Some(j) => sums[j],
                            None => env.prefilter(arr(dirs[k]), r),
                        };
                    }
                    sums
                };
                let irradiance = |env: &reference::Environment| env.integrate(|l| [reference::dot(na, l).max(0.0) / std::f64::consts::PI; 3], |_| f64::INFINITY).0;
                ShadingPoint {
                    material: m,
                    n,
                    v,
                    truth: env.shade(na, va, b, m.metallic as f64, r, reference::Smith::Correlated),
                    full_schlick: env.shade(na, va, b, m.metallic as f64, r, reference::Smith::Schlick),
                    irradiance: irradiance(&env),
                    prefiltered: prefiltered(&env),
                    residual: (irradiance(&rest), prefiltered(&rest)),
                    table: [table(reference::Smith::Schlick), table(reference::Smith::Correlated)],
                }
            })
            .collect();
        // Lookups: half within a few lobe widths of the sun, half anywhere.
        let look: Vec<(Vec3, f32, bool)> = (0..lookups)
            .map(|i| {
                let r = 0.02 + 0.98 * golden(i / 2);
                let near = i % 2 == 0;
                let dir = if near {
                    // Up to three lobe widths (α = r², at least two source texels) from the sun.
                    let width = (r * r).max(2.0 * std::f32::consts::FRAC_PI_2 / s as f32);
                    let angle = 3.0 * width * radical3(i + 1);
                    (sun * angle.cos() + tangent(sun, sampling::hammersley(i, lookups).x) * angle.sin()).normalize()
                } else {
                    sphere_dir(i, lookups)
                };
                (dir, r, near)
            })
            .collect();
        let lookups = look
            .into_par_iter()
            .map(|(dir, roughness, near_sun)| LookupPoint { dir, roughness, near_sun, exact: env.prefilter(arr(dir), roughness as f64) })
            .collect();
        Self { shading, lookups }
    }
}

/// The settings splitsum's bake used before this measure existed (the seed method): six
/// mips with roughness `m/5`, 1024 GGX samples per texel at source bias 0.5, the sampled
/// 1024-point table; mip 0 at the source's size.
pub fn seed_settings(source_size: u32) -> Settings {
    Settings {
        size: source_size,
        source_size: Some(source_size),
        mips: Some(6.min(splitsum_shaders::cubemap::CubeLayout::full_chain(source_size))),
        mapping: Some(RoughnessMapping::Linear),
        samples: 1024,
        sample_growth: 1,
        exact_sums: false,
        lod_bias: 0.5,
        lut_method: TableMethod::Sampled,
        lut_masking: Some(Masking::SmithSchlick),
        lut_samples: 1024,
        ..Settings::default()
    }
}

/// One shading point's errors: roughness, `n·v`, then against the truth, and the
/// bake's, the split sum's and the model's shares.
struct PointErrors {
    roughness: f32,
    n_dot_v: f32,
    parts: [(Part, f64); 4],
}

/// Bakes each method on `backend`, times it and measures it at `points`.
pub fn measure(backend: &Backend, env: &Environment, methods: &[Method], points: &Points) -> Result<Vec<Measurement>> {
    let device = crate::measurement::Device::of(backend);
    let mut rows = Vec::new();
    // Methods that differ only in their shading share one bake (and its time).
    let mut last: Option<(Settings, reading::BakedEnvironment, f64)> = None;
    // Warm-up, outside the timings: the first bake on a backend pays for its pipelines and
    // threads (measured: 0.61 s against 0.02 s for the same quick bake), which would be
    // charged to the first method. A small bake of each method's kernels does it.
    if let Some(first) = methods.first() {
        reading::bake_for_display(backend, env, &Settings { size: 8, source_size: Some(8), mips: None, irradiance_source: None, sh_source: None, ..first.settings.clone() })?;
    }
    for method in methods {
        if last.as_ref().is_none_or(|(s, b, _)| *s != method.settings || b.excess.is_empty() == method.reads_split()) {
            let start = Instant::now();
            let baked = method.bake(backend, env)?;
            last = Some((method.settings.clone(), baked, start.elapsed().as_secs_f64() * 1e3));
        }
        let (_, baked, ms) = last.as_ref().expect("baked above");
        let ms = *ms;
        let (spec, irr, table, shape) = (baked.specular_buffer(), baked.cube(Product::Irradiance), baked.table(Product::BrdfTable), baked.shape());
        let opts = method.options();
        let read = read_index(opts.flags);
        let correlated = usize::from(method.settings.lut_masking.unwrap_or(method.settings.lut_method.default_masking()) == Masking::SmithCorrelated);
        let per_point: Vec<PointErrors> = points
            .shading
            .iter()
            .map(|p| {
                let m = &p.material;
                let s = shade::ibl_sample(shape, &spec, &irr.texels, &table.texels, opts, m, p.n, p.v);
                let shown = shade::ibl(opts, m, p.n, p.v, s);
                // The same read from exact ingredients: where the bake was split, the exact
                // residual's and this bake's excess list, read as the shading reads it.
                let exact = if baked.excess.is_empty() {
                    IblSample { prefiltered: vec(p.prefiltered[read]), irradiance: vec(p.irradiance), brdf: p.table[correlated] }
                } else {
                    let brdf = p.table[correlated];
                    IblSample {
                        prefiltered: vec(p.residual.1[read]) + shade::excess_lobe_radiance(shape, &spec, opts, m, p.n, p.v, brdf),
                        irradiance: vec(p.residual.0) + shade::excess_irradiance(shape, &spec, p.n),
                        brdf,
                    }
                };
                let split = shade::ibl(opts, m, p.n, p.v, exact);
                let full = if correlated == 1 { p.truth } else { p.full_schlick };
                PointErrors {
                    roughness: m.roughness,
                    n_dot_v: p.n.dot(p.v),
                    parts: [
                        (Part::Total, rel(shown, p.truth)),
                        (Part::Bake, rel(shown, arr(split))),
                        (Part::SplitSum, rel(split, full)),
                        (Part::Model, rel64(full, p.truth)),
                    ],
                }
            })
            .collect();
        let ladder = method.kind == Kind::Ladder;
        let row = |product: Quantity, errors: &[f64]| Measurement {
            samples: Some(method.settings.samples),
            fetches: Some(opts.fetches()),
            knob: if ladder { Knob::Fetches } else { Knob::Samples },
            ..device.row(product, method.kind, errors, Metric::RelativeLuminance)
        };
        // Over every point: the total (with the bake's time) and each part. The ladder's
        // error has no split-sum share to split off (it reads no split sum): total only.
        let parts = if ladder { 1 } else { 4 };
        for k in 0..parts {
            let all: Vec<f64> = per_point.iter().map(|p| p.parts[k].1).collect();
            // The ladder costs shading time, not bake time (`Quantity::ShadingCost`).
            let time_ms = (k == 0 && !ladder).then_some(ms);
            rows.push(Measurement { part: per_point[0].parts[k].0, time_ms, ..row(Quantity::ShadedColour, &all) });
        }
        // By roughness band, then by view band, each split into its parts.
        let mut roughness: Vec<(f32, f32)> = per_point.iter().map(|p| roughness_band(p.roughness)).collect();
        let mut views: Vec<(f32, f32)> = per_point.iter().map(|p| view_band(p.n_dot_v)).collect();
        for v in [&mut roughness, &mut views] {
            v.sort_by(|a, b| a.0.total_cmp(&b.0));
            v.dedup();
        }
        for k in 0..parts {
            let part = per_point[0].parts[k].0;
            for &(lo, hi) in &roughness {
                let e: Vec<f64> = per_point.iter().filter(|p| roughness_band(p.roughness) == (lo, hi)).map(|p| p.parts[k].1).collect();
                rows.push(Measurement { part, roughness_lo: Some(lo), roughness_hi: Some(hi), ..row(Quantity::ShadedColour, &e) });
            }
            for &(lo, hi) in &views {
                let e: Vec<f64> = per_point.iter().filter(|p| view_band(p.n_dot_v) == (lo, hi)).map(|p| p.parts[k].1).collect();
                rows.push(Measurement { part, nv_lo: Some(lo), nv_hi: Some(hi), ..row(Quantity::ShadedColour, &e) });
            }
        }
        if ladder {
            continue; // its lookups are the defaults': the same bake, read the same way
        }
        // The prefiltered radiance a renderer reads at any roughness.
        let lookups: Vec<(f32, bool, f64)> = points
            .lookups
            .iter()
            .map(|q| {
                let got = shade::prefiltered(shape, &spec, opts.flags, q.dir, q.roughness).truncate();
                (q.roughness, q.near_sun, rel(got, q.exact))
            })
            .collect();
        let all: Vec<f64> = lookups.iter().map(|l| l.2).collect();
        rows.push(Measurement { time_ms: Some(ms), ..row(Quantity::PrefilteredLookup, &all) });
        for &lo in &ROUGHNESS_BANDS {
            let band = roughness_band(lo);
            for near in [true, false] {
                let e: Vec<f64> = lookups.iter().filter(|l| l.1 == near && roughness_band(l.0) == band).map(|l| l.2).collect();
                if !e.is_empty() {
                    rows.push(Measurement {
                        roughness_lo: Some(band.0),
                        roughness_hi: Some(band.1),
                        near_sun: Some(near),
                        ..row(Quantity::PrefilteredLookup, &e)
                    });
                }
            }
        }
    }
    Ok(rows)
}

/// The time budgets per bake (seconds) of the report's budget-to-error curve.
pub const BUDGETS: [f64; 6] = [0.1, 0.2, 0.3, 0.5, 1.0, 2.0];

/// The budget-to-error curve on `backend`: for each budget, the settings
/// `splitsum::estimate::for_budget` chooses from `base` (by this backend's estimator, as
/// `runner bake --budget` chooses: `splitsum::estimate::for_backend`), baked, timed and measured at `points` with `base`'s
/// shading, as [`measure`] does; the rows carry the budget and the estimate. Budgets that
/// choose the same settings share one bake.
pub fn budget_rows(backend: &Backend, env: &Environment, base: &Method, points: &Points) -> Result<Vec<Measurement>> {
    let estimator = splitsum::estimate::for_backend(backend)?;
    let shape = splitsum::InputShape::of(env);
    let calibration = splitsum::cost::Calibration::default();
    let mut rows = Vec::new();
    let mut done: Vec<(Settings, Vec<Measurement>)> = Vec::new();
    for budget in BUDGETS {
        let (settings, _, estimate) = splitsum::estimate::for_budget(&base.settings, shape, splitsum::Products::DISPLAY, budget, &estimator, &calibration)?;
        let measured = match done.iter().find(|(s, _)| *s == settings) {
            Some((_, r)) => r.clone(),
            None => {
                let method = Method { kind: Kind::TimeBudget, settings: settings.clone(), flags: base.flags };
                let r = measure(backend, env, &[method], points)?;
                done.push((settings.clone(), r.clone()));
                r
            }
        };
        let irradiance_source = settings.resolve(shape, splitsum::Products::DISPLAY)?.irradiance_source;
        rows.extend(measured.into_iter().map(|r| Measurement {
            knob: Knob::Budget,
            budget_s: Some(budget),
            estimate_s: Some(estimate),
            source_size: Some(irradiance_source),
            ..r
        }));
    }
    Ok(rows)
}
