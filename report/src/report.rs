//! `runner report`: error against run time for every product, on every backend.
//!
//! Each quality knob is swept — samples of the BRDF table and of the prefilter, the
//! table's size, the prefilter's source-mip bias, the source level of the irradiance
//! convolution and of SH9, and whole quality levels for the final shaded colour — and
//! each result is timed and compared with a converged reference from
//! `splitsum_reference`, which shares no code with what it checks: an adaptive f64
//! quadrature for the table, exact sums over every source texel for the prefilter and the
//! irradiance, and the full reflectance integral (no split) for the shaded colour. The
//! shaded colour is also computed from exact ingredients (exact prefiltered radiance,
//! irradiance and table), which isolates the error of the split-sum approximation itself
//! (n = v = r, and the split) from the sampling and filtering error of the bake.
//!
//! Outputs: `report.html` (every figure and table), `report.md` (the same, for a
//! repository), `report.csv` (the typed rows, `splitsum::measured`), `error_vs_time.svg`
//! (small multiples, [`crate::plot`]) and the error on surfaces ([`crate::surface`]).

use crate::measurement::{Device, Knob, Measurement, Method, Metric, Part, Product, arr, rel};
use crate::surface::ErrorMap;
use rayon::prelude::*;
use splitsum::backend::Backend;
use splitsum::bake;
use splitsum::environment::Environment;
use splitsum::error::Result;
use splitsum::files;
use splitsum::settings::{Settings, Target, level_of_size};
use splitsum::texture::Cube;
use splitsum_reference as reference;
use splitsum_shaders::brdf::microfacet::Masking;
use splitsum_shaders::cubemap::{self, CubeLayout};
use splitsum_shaders::glam::{Vec2, Vec3};
use splitsum_shaders::irradiance::sh9_irradiance;
use splitsum_shaders::prefilter::RoughnessMapping;
use splitsum_shaders::shade::{self, Material, ShadeOptions};
use splitsum_shaders::{lut, sampling};
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

/// The sweeps of a report.
#[derive(Clone, Debug)]
pub struct Sweep {
    /// Face size of the source cube everything is filtered from (and the references sum).
    pub source_size: u32,
    /// Face size of mip 0 of the prefiltered cube.
    pub specular_size: u32,
    /// Mips of the prefiltered cube (roughness `m/(M−1)`).
    pub mips: u32,
    /// Width of the BRDF table whose texel centres are compared.
    pub lut_size: u32,
    /// Sample counts swept for the table and the prefilter.
    pub samples: Vec<u32>,
    /// Table sizes swept (bilinear lookups compared at scattered points).
    pub lut_sizes: Vec<u32>,
    /// Source-mip biases swept, at each of `bias_samples` sample counts.
    pub biases: Vec<f32>,
    /// Sample counts of the bias sweep.
    pub bias_samples: Vec<u32>,
    /// Face sizes of the roughness-⅓ level swept (cube size).
    pub cube_sizes: Vec<u32>,
    /// Source levels (face sizes) swept for the irradiance convolution.
    pub irradiance_sources: Vec<u32>,
    /// Face size of the irradiance cube.
    pub irradiance_size: u32,
    /// Source levels swept for SH9.
    pub sh_sources: Vec<u32>,
    /// Quality levels of the shaded colour.
    pub qualities: Vec<Settings>,
    /// Probe directions per comparison.
    pub directions: u32,
    /// Largest face size of the source cube of the end-to-end measure (`accuracy`): the
    /// environment's own resolution up to this.
    pub accuracy_source: u32,
    /// Shading points and prefiltered lookups of the end-to-end measure.
    pub accuracy_points: (u32, u32),
}

impl Sweep {
    /// The full report: a few minutes on lavapipe and 2 CPU cores. Its shaded colour also
    /// measures the default bake settings (`Settings::default()`).
    pub fn full() -> Self {
        let mut sweep = Self::with(
            128,
            64,
            32,
            vec![16, 64, 256, 1024, 4096],
            vec![8, 16, 32, 64, 128],
            vec![256, 1024],
            vec![8, 16, 32, 64],
            vec![4, 8, 16, 32, 64],
            vec![8, 16, 32, 64, 128],
            32,
        );
        sweep.qualities.push(Settings::default());
        sweep
    }

    /// A quick report for CI: the same sweeps, smaller and shorter.
    pub fn quick() -> Self {
        let mut sweep = Self::with(16, 8, 8, vec![4, 16, 64], vec![4, 8, 16], vec![16], vec![4, 8], vec![4, 8, 16], vec![4, 8, 16], 8);
        sweep.accuracy_source = 16;
        sweep.accuracy_points = (48, 48);
        sweep
    }

    /// The display methods the end-to-end measure compares, for an environment whose native
    /// face size is `native`: the seed method, today's defaults, and each shading option.
    pub fn methods(&self, native: u32) -> Vec<crate::accuracy::Method> {
        use crate::accuracy::{Method, seed_settings};
        use crate::measurement::Method as Kind;
        let src = native.min(self.accuracy_source).max(4);
        let default = Settings { size: src, source_size: Some(src), ..Settings::default() };
        let flags = ShadeOptions::DEFAULT.flags & !(ShadeOptions::IBL | ShadeOptions::DIRECT);
        let mut methods = Vec::new();
        // Each method's error against its bake time: the seed at three sample counts, the
        // defaults at three (mip 1's count; ×2 per mip after it).
        for n in [64, 256, 1024] {
            methods.push(Method { kind: Kind::Seed, settings: Settings { samples: n, ..seed_settings(src) }, flags: 0 });
        }
        for n in [16, 256] {
            methods.push(Method { kind: Kind::Defaults, settings: Settings { samples: n, ..default.clone() }, flags });
        }
        methods.extend(vec![
            Method { kind: Kind::Defaults, settings: default.clone(), flags },
            Method { kind: Kind::MirrorDirection, settings: default.clone(), flags: flags & !ShadeOptions::DOMINANT_DIRECTION },
            Method { kind: Kind::MultipleScattering, settings: default.clone(), flags: flags | ShadeOptions::MULTISCATTER },
            Method { kind: Kind::FilteredSampling, settings: default.clone(), flags: flags | ShadeOptions::FILTERED_SAMPLING },
            Method { kind: Kind::LinearMipBlend, settings: default.clone(), flags: flags & !ShadeOptions::LOG_MIP_BLEND },
            Method { kind: Kind::TableF0, settings: default.clone(), flags: flags | ShadeOptions::TABLE_F0 },
            Method { kind: Kind::NoHorizonLift, settings: default.clone(), flags: flags & !ShadeOptions::LIFT_ABOVE_HORIZON },
        ]);
        // The shading ladder: the defaults' bake read with 2, 4, 8 and 16 fetches.
        let base = ShadeOptions { flags, ..ShadeOptions::DEFAULT };
        for rung in 1..shade::LADDER_RUNGS {
            let flags = base.with_fetches(1 << rung).flags;
            methods.push(Method { kind: Kind::Ladder, settings: default.clone(), flags });
        }
        methods.push(Method { kind: Kind::SmithSchlickTable, settings: Settings { lut_masking: Some(Masking::SmithSchlick), ..default.clone() }, flags });
        // Each engine target's levels, read as its engine reads them (linear between mips).
        for (kind, target) in [(Kind::KhronosBevyLookup, Target::Khronos), (Kind::FilamentLookup, Target::Filament)] {
            let fixed = target.fixed();
            let settings = Settings { mapping: fixed.mapping, mips: fixed.mips.map(|m| m(src)), ..default.clone() };
            methods.push(Method { kind, settings, flags: flags & !(ShadeOptions::LOG_MIP_BLEND | ShadeOptions::LIFT_ABOVE_HORIZON) });
        }
        methods
    }

    /// The methods the measure over sets compares: the seed at its 1024 samples, the
    /// defaults, and each shading option.
    pub fn set_methods(&self, native: u32) -> Vec<crate::accuracy::Method> {
        let n = Settings::default().samples;
        self.methods(native)
            .into_iter()
            .filter(|m| match m.kind {
                Method::Seed => m.settings.samples == 1024,
                _ => m.settings.samples == n,
            })
            .collect()
    }

    #[allow(clippy::too_many_arguments)]
    fn with(
        source_size: u32,
        specular_size: u32,
        lut_size: u32,
        samples: Vec<u32>,
        lut_sizes: Vec<u32>,
        bias_samples: Vec<u32>,
        cube_sizes: Vec<u32>,
        irradiance_sources: Vec<u32>,
        sh_sources: Vec<u32>,
        directions: u32,
    ) -> Self {
        let mips = 4;
        let level = |n: u32, lut: u32, irr: u32| Settings {
                size: specular_size,
                source_size: Some(source_size),
                mips: Some(mips),
                samples: n,
                irradiance_size: (specular_size / 2).max(4),
                irradiance_source: Some(irr.min(source_size)),
                sh_source: Some(source_size),
                lut_size: lut,
                lut_samples: n,
                ..Settings::default()
        };
        let q = &samples;
        let qualities = vec![
            level(q[0], lut_sizes[0], irradiance_sources[0]),
            level(q[q.len() / 2], lut_sizes[lut_sizes.len() / 2], irradiance_sources[irradiance_sources.len() / 2]),
            level(q[q.len() - 1], *lut_sizes.last().expect("sizes"), *irradiance_sources.last().expect("sizes")),
        ];
        Self {
            source_size,
            specular_size,
            mips,
            lut_size,
            samples,
            lut_sizes,
            biases: vec![-1.0, -0.5, 0.0, 0.5, 1.0, 1.5, 2.0],
            bias_samples,
            cube_sizes,
            irradiance_sources,
            irradiance_size: (specular_size / 2).max(4),
            sh_sources,
            qualities,
            directions,
            accuracy_source: 256,
            accuracy_points: (512, 512),
        }
    }
}

fn timed<T>(f: impl FnOnce() -> Result<T>) -> Result<(T, f64)> {
    let start = Instant::now();
    let v = f()?;
    Ok((v, start.elapsed().as_secs_f64() * 1e3))
}

/// Unit directions spread over the sphere (a Hammersley set through the equirect map).
fn directions(n: u32) -> Vec<Vec3> {
    (0..n).map(|i| splitsum_shaders::equirect::uv_to_dir(sampling::hammersley(i, n) * Vec2::new(1.0, 0.96) + Vec2::new(0.0, 0.02))).collect()
}

/// The measure over the tuning and held-out sets ([`crate::sets`]), when a report asks.
#[derive(Clone, Debug)]
pub struct Sets {
    /// The folder of Blender's studio lights.
    pub dir: std::path::PathBuf,
    /// Only the environments present (and the generated ones), for a quick report.
    pub present_only: bool,
    /// Only this set (to iterate on the tuning set without looking at the held-out one).
    pub only: Option<splitsum::measured::Set>,
}

/// Runs the report's sweeps of `env` on `backends` (and the measure over `sets`, if
/// given, on the first backend), writes the files into `dir` with the shading ladder's
/// `costs` (`Product::ShadingCost` rows, timed by the renderer's owner) beside its errors,
/// and returns the measurements.
pub fn run(env: &Environment, name: &str, backends: &[Backend], sweep: &Sweep, sets: Option<&Sets>, costs: &[Measurement], dir: &Path) -> Result<Vec<Measurement>> {
    if let Some(s) = sets
        && !s.present_only
    {
        crate::sets::check(&s.dir)?;
    }
    files::create_folder(dir)?;
    files::check_writable(&dir.join("report.md"))?;
    let settings = Settings { source_size: Some(sweep.source_size), size: sweep.source_size, ..Settings::default() };
    let source = bake::host_source_cube(&Backend::Cpu, env, &settings)?;
    let texels = reference::texels(source.level(0), sweep.source_size);
    let refs = {
        let _step = splitsum::progress::step("report: references (f64)", None);
        References::compute(sweep, &texels)
    };
    let mut rows = Vec::new();
    rows.extend(refs.split_error_rows());
    for backend in backends {
        let b = Device::of(backend);
        let _step = splitsum::progress::step(&format!("report: every product on {}", backend.describe()), None);
        // Warm-up, outside the timings: first dispatches pay for driver set-up and caches.
        backend.brdf_lut(4, 4)?;
        backend.brdf_table(4, Masking::SmithSchlick)?;
        backend.prefilter(&source, CubeLayout::new(4, 1), &[0.5], 4, 0.0)?;
        backend.irradiance(&source, source.layout.levels - 1, 4)?;
        rows.extend(lut_rows(backend, &b, sweep, &refs)?);
        rows.extend(prefilter_rows(backend, &b, sweep, &refs, &source)?);
        rows.extend(irradiance_rows(backend, &b, sweep, &refs, &source)?);
        rows.extend(shaded_rows(backend, &b, sweep, &refs, env)?);
    }
    // The end-to-end measure: what a renderer shows.
    let native = env.native_face_size();
    let methods = sweep.methods(native);
    let src = methods[0].settings.source_size.unwrap_or(methods[0].settings.size);
    let acc_source = bake::host_source_cube(&Backend::Cpu, env, &Settings { source_size: Some(src), size: src, ..Settings::default() })?;
    let points = {
        let what =
            format!("report: end-to-end references (f64, {} shading points, {} lookups, {src}² source)", sweep.accuracy_points.0, sweep.accuracy_points.1);
        let _step = splitsum::progress::step(&what, None);
        crate::accuracy::Points::new(&acc_source, sweep.accuracy_points.0, sweep.accuracy_points.1)
    };
    for backend in backends {
        let _step = splitsum::progress::step(&format!("report: end to end on {}", backend.describe()), None);
        rows.extend(crate::accuracy::measure(backend, env, &methods, &points)?);
    }
    // The budget-to-error curve: the settings chosen for each time budget, measured the same way.
    let base = methods.iter().find(|m| m.kind == Method::Defaults && m.settings.samples == Settings::default().samples).unwrap_or(&methods[0]);
    for backend in backends {
        let _step = splitsum::progress::step(&format!("report: time budgets on {}", backend.describe()), None);
        rows.extend(crate::accuracy::budget_rows(backend, env, base, &points)?);
    }
    if let Some(sets) = sets {
        let keep = |m: &crate::sets::Member| {
            sets.only.is_none_or(|s| s == m.set)
                && match m.source {
                    crate::sets::Source::File(f) => !sets.present_only || sets.dir.join(f).exists(),
                    _ => true,
                }
        };
        rows.extend(crate::sets::run(&backends[0], &sets.dir, sweep.accuracy_source, sweep.accuracy_points, |n| sweep.set_methods(n), keep)?);
    }
    // The error on surfaces: the defaults' sphere grid against the exact integral, on this
    // environment and on a clear sky with a sun 10⁴ times brighter than its zenith.
    let defaults = &methods.iter().find(|m| m.kind == Method::Defaults && m.settings.samples == Settings::default().samples).unwrap_or(&methods[0]).settings;
    let sky = crate::skies::sunny(4 * src.max(64), 1e4, 35.0);
    let mut maps = Vec::new();
    // The truth sums the source cube the end-to-end measure used (`acc_source`), or the
    // sky's at the same size.
    let sky_source = bake::host_source_cube(&Backend::Cpu, &sky, &Settings { source_size: Some(src), size: src, ..Settings::default() })?;
    for (what, e, cube) in [(name.to_string(), env, &acc_source), ("a clear sky with a sun of 10^4 (generated)".to_string(), &sky, &sky_source)] {
        let _step = splitsum::progress::step(&format!("report: error on surfaces of {what} (f64 sphere grid)"), None);
        let baked = bake::bake_for_display(&backends[0], e, &Settings { size: src, source_size: Some(src), ..defaults.clone() })?;
        let exact = reference::Environment::new(cube.level(0), cube.layout.size);
        maps.push((what, crate::surface::error_map(&baked, &exact)));
    }
    rows.extend_from_slice(costs);
    let _step = splitsum::progress::step("report: writing report.html, report.md, report.csv and the figures", None);
    write_outputs(dir, name, backends, sweep, &rows, &maps)?;
    Ok(rows)
}

/// The converged references every measurement is compared with.
struct References {
    lut: Vec<Vec2>,
    lut_points: Vec<(Vec2, Vec2)>,
    prefilter_dirs: Vec<Vec3>,
    prefilter: Vec<Vec<[f64; 3]>>,
    irradiance_dirs: Vec<Vec3>,
    irradiance: Vec<[f64; 3]>,
    shading: Vec<ShadingPoint>,
}

/// The view-angle classes `(lo, hi]` the shaded colour of the quality levels is reported
/// in: near normal and grazing, where the split sum's `n = v = r` assumption is known to
/// fail. The points sit at `n·v` 0.95, 0.6 and 0.25.
const VIEWS: [(f32, f32); 2] = [(0.59, 1.0), (0.0, 0.3)];

fn in_view(p: &ShadingPoint, (lo, hi): (f32, f32)) -> bool {
    let nv = p.n.dot(p.v);
    nv > lo && nv <= hi + 1e-3
}

struct ShadingPoint {
    material: Material,
    n: Vec3,
    v: Vec3,
    full: [f64; 3],
    exact_split: Vec3,
}

impl References {
    fn compute(sweep: &Sweep, texels: &[([f64; 3], f64, [f64; 3])]) -> Self {
        let t = sweep.lut_size;
        let lut: Vec<Vec2> = (0..t * t)
            .into_par_iter()
            .map(|i| {
                let c = lut::texel_coords(i % t, i / t, t);
                let (a, b) = reference::brdf_lut(c.x as f64, c.y as f64, 1e-7);
                Vec2::new(a as f32, b as f32)
            })
            .collect();
        let lut_points: Vec<(Vec2, Vec2)> = (0..64u32)
            .into_par_iter()
            .map(|i| {
                let p = sampling::hammersley(i, 64) * 0.96 + Vec2::splat(0.02);
                let (a, b) = reference::brdf_lut(p.x as f64, p.y as f64, 1e-7);
                (p, Vec2::new(a as f32, b as f32))
            })
            .collect();
        let prefilter_dirs = directions(sweep.directions);
        let roughness: Vec<f32> = (0..sweep.mips).map(|m| RoughnessMapping::Linear.roughness(m, sweep.mips)).collect();
        let prefilter = roughness.iter().map(|&r| prefilter_dirs.par_iter().map(|&n| reference::prefilter(texels, arr(n), r as f64)).collect()).collect();
        let irradiance_dirs = directions(2 * sweep.directions);
        let irradiance = irradiance_dirs.par_iter().map(|&n| reference::irradiance(texels, arr(n))).collect();
        // Shading points: rough enough that a sum over the source's texels resolves the
        // lobe (r ≥ 0.3 on a 64² source), metals and dielectrics, several view angles.
        let mut shading = Vec::new();
        let normals = directions(6);
        for (k, &n) in normals.iter().enumerate() {
            for &r in &[0.3f32, 0.5, 0.7, 1.0] {
                for &metallic in &[0.0f32, 1.0] {
                    for &nv in &[0.95f32, 0.6, 0.25] {
                        let (t, b) = sampling::orthonormal_basis(n);
                        let side = if k % 2 == 0 { t } else { b };
                        let v = (n * nv + side * (1.0 - nv * nv).sqrt()).normalize();
                        let material = Material { base_color: Vec3::new(0.9, 0.6, 0.3), metallic, roughness: r, occlusion: 1.0, emissive: Vec3::ZERO, sheen_color: Vec3::ZERO, sheen_roughness: 0.0 };
                        shading.push(ShadingPoint { material, n, v, full: [0.0; 3], exact_split: Vec3::ZERO });
                    }
                }
            }
        }
        shading.par_iter_mut().for_each(|p| {
            let m = &p.material;
            p.full = reference::shade_full(texels, arr(p.n), arr(p.v), arr(m.base_color), m.metallic as f64, m.roughness as f64);
            let refl = sampling::reflect(p.v, p.n);
            let pre = reference::prefilter(texels, arr(refl), m.roughness as f64);
            let irr = reference::irradiance(texels, arr(p.n));
            let (a, b) = reference::brdf_lut(p.n.dot(p.v) as f64, m.roughness as f64, 1e-7);
            let f = |c: [f64; 3]| Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32);
            let s = shade::IblSample { prefiltered: f(pre), irradiance: f(irr), brdf: Vec2::new(a as f32, b as f32) };
            p.exact_split = shade::ibl(ShadeOptions::DEFAULT, m, p.n, p.v, s);
        });
        Self { lut, lut_points, prefilter_dirs, prefilter, irradiance_dirs, irradiance, shading }
    }

    fn split_error_rows(&self) -> Vec<Measurement> {
        VIEWS
            .iter()
            .map(|&(lo, hi)| {
                let errors: Vec<f64> = self.shading.iter().filter(|p| in_view(p, (lo, hi))).map(|p| rel(p.exact_split, p.full)).collect();
                let row = Measurement::of(Product::ShadedColour, Method::ExactIngredients, &errors, Metric::RelativeLuminance);
                Measurement { part: Part::SplitSum, nv_lo: Some(lo), nv_hi: Some(hi), ..row }
            })
            .collect()
    }
}

/// The table's error at each texel: the relative error of the directional albedo
/// `F₀·A + B` it gives, the larger of a dielectric's (`F₀ = 0.04`) and a white metal's.
fn albedo_errors(got: impl Iterator<Item = Vec2>, want: impl Iterator<Item = Vec2>) -> Vec<f64> {
    got.zip(want)
        .map(|(g, r)| {
            [0.04f64, 1.0]
                .iter()
                .map(|&f0| {
                    let (eg, er) = (f0 * g.x as f64 + g.y as f64, f0 * r.x as f64 + r.y as f64);
                    (eg - er).abs() / er.max(1e-6)
                })
                .fold(0.0, f64::max)
        })
        .collect()
}

fn lut_rows(backend: &Backend, b: &Device, sweep: &Sweep, refs: &References) -> Result<Vec<Measurement>> {
    let mut rows = Vec::new();
    let size = Some(sweep.lut_size);
    for &n in &sweep.samples {
        let (table, ms) = timed(|| backend.brdf_lut(sweep.lut_size, n))?;
        let errors = albedo_errors(table.texels.iter().copied(), refs.lut.iter().copied());
        rows.push(Measurement { knob: Knob::Samples, samples: Some(n), size, time_ms: Some(ms), ..b.row(Product::BrdfTable, Method::Seed, &errors, Metric::RelativeAlbedo) });
    }
    // The deterministic quadrature (the default table), on the same texels.
    let (table, ms) = timed(|| backend.brdf_table(sweep.lut_size, Masking::SmithSchlick))?;
    let errors = albedo_errors(table.texels.iter().copied(), refs.lut.iter().copied());
    rows.push(Measurement { size, time_ms: Some(ms), ..b.row(Product::BrdfTable, Method::Defaults, &errors, Metric::RelativeAlbedo) });
    let n = *sweep.samples.last().expect("samples");
    for &size in &sweep.lut_sizes {
        let (table, ms) = timed(|| backend.brdf_lut(size, n))?;
        let errors = albedo_errors(refs.lut_points.iter().map(|(p, _)| lut::sample(&table.texels, size, p.x, p.y)), refs.lut_points.iter().map(|(_, r)| *r));
        rows.push(Measurement {
            knob: Knob::Size,
            samples: Some(n),
            size: Some(size),
            time_ms: Some(ms),
            ..b.row(Product::BrdfTableLookup, Method::Seed, &errors, Metric::RelativeAlbedo)
        });
    }
    Ok(rows)
}

fn prefilter_rows(backend: &Backend, b: &Device, sweep: &Sweep, refs: &References, source: &Cube) -> Result<Vec<Measurement>> {
    let mut rows = Vec::new();
    let roughness: Vec<f32> = (0..sweep.mips).map(|m| RoughnessMapping::Linear.roughness(m, sweep.mips)).collect();
    let mut level = |n: u32, bias: f32, m: usize, size: u32, knob: Knob| -> Result<()> {
        let layout = CubeLayout::new(size, 1);
        let (cube, ms) = timed(|| backend.prefilter(source, layout, &[roughness[m]], n, bias))?;
        let errors: Vec<f64> = refs
            .prefilter_dirs
            .iter()
            .zip(&refs.prefilter[m])
            .map(|(&d, r)| rel(cubemap::sample_bilinear(&cube.texels, layout, 0, d).truncate(), *r))
            .collect();
        let row = b.row(Product::Prefilter, Method::Defaults, &errors, Metric::RelativeLuminance);
        let r = Some(roughness[m]);
        rows.push(Measurement { knob, samples: Some(n), bias: Some(bias), size: Some(size), roughness_lo: r, roughness_hi: r, time_ms: Some(ms), ..row });
        Ok(())
    };
    let default_bias = Settings::default().lod_bias;
    for (m, _) in roughness.iter().enumerate().skip(1) {
        let size = (sweep.specular_size >> m).max(1);
        for &n in &sweep.samples {
            level(n, default_bias, m, size, Knob::Samples)?;
        }
        for &n in &sweep.bias_samples {
            for &bias in &sweep.biases {
                level(n, bias, m, size, Knob::Bias)?;
            }
        }
    }
    let n = sweep.bias_samples[sweep.bias_samples.len() - 1];
    for &size in &sweep.cube_sizes {
        level(n, default_bias, 1, size, Knob::Size)?;
    }
    Ok(rows)
}

fn irradiance_rows(backend: &Backend, b: &Device, sweep: &Sweep, refs: &References, source: &Cube) -> Result<Vec<Measurement>> {
    let mut rows = Vec::new();
    for &s in &sweep.irradiance_sources {
        let level = level_of_size(source.layout, s);
        let (cube, ms) = timed(|| backend.irradiance(source, level, sweep.irradiance_size))?;
        let errors: Vec<f64> = refs
            .irradiance_dirs
            .iter()
            .zip(&refs.irradiance)
            .map(|(&d, r)| rel(cubemap::sample_bilinear(&cube.texels, cube.layout, 0, d).truncate(), *r))
            .collect();
        let row = b.row(Product::Irradiance, Method::Defaults, &errors, Metric::RelativeLuminance);
        rows.push(Measurement { knob: Knob::SourceSize, source_size: Some(s), size: Some(sweep.irradiance_size), time_ms: Some(ms), ..row });
    }
    for &s in &sweep.sh_sources {
        let level = level_of_size(source.layout, s);
        let (sh, ms) = timed(|| backend.sh9(source, level))?;
        let coeffs = sh.as_vec4();
        let errors: Vec<f64> = refs.irradiance_dirs.iter().zip(&refs.irradiance).map(|(&d, r)| rel(sh9_irradiance(&coeffs, d), *r)).collect();
        let row = b.row(Product::Irradiance, Method::Sh9, &errors, Metric::RelativeLuminance);
        rows.push(Measurement { knob: Knob::SourceSize, source_size: Some(s), time_ms: Some(ms), ..row });
    }
    Ok(rows)
}

fn shaded_rows(backend: &Backend, b: &Device, sweep: &Sweep, refs: &References, env: &Environment) -> Result<Vec<Measurement>> {
    let mut rows = Vec::new();
    for settings in &sweep.qualities {
        let (baked, ms) = timed(|| bake::bake_for_display(backend, env, settings))?;
        let (spec, irr, table, shape) = (&baked.specular, &baked.irradiance, &baked.lut, baked.shape());
        for &(lo, hi) in &VIEWS {
            let errors: Vec<f64> = refs
                .shading
                .iter()
                .filter(|p| in_view(p, (lo, hi)))
                .map(|p| {
                    let s = shade::ibl_sample(shape, &spec.texels, &irr.texels, &table.texels, ShadeOptions::DEFAULT, &p.material, p.n, p.v);
                    rel(shade::ibl(ShadeOptions::DEFAULT, &p.material, p.n, p.v, s), p.full)
                })
                .collect();
            let row = b.row(Product::ShadedColour, Method::Defaults, &errors, Metric::RelativeLuminance);
            let (samples, size) = (Some(settings.samples), Some(settings.size));
            rows.push(Measurement { knob: Knob::Quality, samples, size, nv_lo: Some(lo), nv_hi: Some(hi), time_ms: Some(ms), ..row });
        }
    }
    Ok(rows)
}

/// The panel of the error-against-time figure a row belongs to, if any: every sample or
/// size sweep and every end-to-end method (the bias and cube-size sweeps, and the bands,
/// are in the tables only).
pub fn panel(r: &Measurement) -> Option<String> {
    if r.time_ms.is_none() || r.part != Part::Total || r.backend.is_empty() || r.set.is_some() {
        return None;
    }
    match (r.product, r.knob) {
        (Product::Prefilter, Knob::Samples) => Some(format!("prefiltered cube, r = {:.2}", r.roughness_lo?)),
        (Product::Prefilter, _) => None,
        (Product::ShadedColour, Knob::Quality) => Some(format!("shaded colour, quality levels, n·v in ({}, {}]", r.nv_lo?, r.nv_hi?)),
        (Product::ShadedColour | Product::PrefilteredLookup, _) => Some(format!("{}, end to end", r.product.title())),
        (p, _) => Some(p.title().to_string()),
    }
}

/// For each panel and backend, the measurement with the smallest mean error × time.
pub fn best_per_ms(rows: &[Measurement]) -> Vec<(String, &Measurement)> {
    let mut best: Vec<(String, &Measurement)> = Vec::new();
    for r in rows {
        let Some(p) = panel(r) else { continue };
        let score = |m: &Measurement| m.mean_error * m.time_ms.unwrap_or(f64::INFINITY);
        match best.iter_mut().find(|(q, b)| *q == p && b.backend == r.backend) {
            Some(slot) if score(r) < score(slot.1) => slot.1 = r,
            Some(_) => {}
            None => best.push((p, r)),
        }
    }
    best
}

/// The small multiples of every panel: one series per method and backend.
pub fn panels(rows: &[Measurement]) -> Vec<crate::plot::Panel> {
    let mut panels: Vec<crate::plot::Panel> = Vec::new();
    for r in rows {
        let Some(title) = panel(r) else { continue };
        let k = match panels.iter().position(|p| p.title == title) {
            Some(k) => k,
            None => {
                panels.push(crate::plot::Panel { title, x_label: "bake time (ms)".into(), series: vec![] });
                panels.len() - 1
            }
        };
        let series = &mut panels[k].series;
        let point = (r.time_ms.unwrap_or(f64::NAN), r.mean_error);
        match series.iter_mut().find(|s| s.method == r.method && s.backend == r.backend) {
            Some(s) => s.points.push(point),
            None => series.push(crate::plot::Series { method: r.method, backend: r.backend.clone(), points: vec![point] }),
        }
    }
    panels
}

/// A row's band, in words: roughness, `n·v`, near the sun.
fn band(r: &Measurement) -> String {
    let mut parts = Vec::new();
    if let (Some(lo), Some(hi)) = (r.roughness_lo, r.roughness_hi) {
        parts.push(if lo == hi { format!("r = {lo:.2}") } else { format!("r in [{lo}, {hi})") });
    }
    if let (Some(lo), Some(hi)) = (r.nv_lo, r.nv_hi) {
        parts.push(format!("n·v in ({lo}, {hi}]"));
    }
    match r.near_sun {
        Some(true) => parts.push("near the sun".into()),
        Some(false) => parts.push("away from the sun".into()),
        None => {}
    }
    if parts.is_empty() { "all".into() } else { parts.join(", ") }
}

fn part_name(p: Part) -> &'static str {
    match p {
        Part::Total => "total",
        Part::Bake => "(a) bake",
        Part::SplitSum => "(b) split sum",
        Part::Model => "(c) model",
    }
}

/// One of the report's tables: its title, header and cells.
type Table = (String, [&'static str; 8], Vec<[String; 8]>);

/// The report's tables: one per product, rows in measurement order.
fn tables(rows: &[Measurement]) -> Vec<Table> {
    let mut products: Vec<Product> = rows.iter().filter(|r| r.set.is_none() && r.product != Product::ShadingCost).map(|r| r.product).collect();
    products.sort();
    products.dedup();
    let header = ["method", "backend", "setting", "band", "part", "time (ms)", "mean error", "max error"];
    products
        .into_iter()
        .map(|p| {
            let cells = rows
                .iter()
                .filter(|r| r.product == p && r.set.is_none())
                .map(|r| {
                    [
                        r.method.title().to_string(),
                        if r.backend.is_empty() { "-".into() } else { r.backend.clone() },
                        r.setting(),
                        band(r),
                        part_name(r.part).into(),
                        r.time_ms.map_or("-".into(), |t| format!("{t:.1}")),
                        format!("{:.2e}", r.mean_error),
                        format!("{:.2e}", r.max_error),
                    ]
                })
                .collect();
            (p.title().to_string(), header, cells)
        })
        .collect()
}

/// What the measure over sets is, in the report.
const SETS_NOTE: &str = "The end-to-end measure (shaded colour against the full reflectance integral, exact Smith, no split) over environments of every kind. Design choices may look at the tuning set only; the held-out set confirms them. Mean relative luminance error over each set's environments (the largest point in brackets).";

/// `mean (max)` over the environments of a set: the mean of their means, the largest of
/// their maxima; `-` where no row matches.
fn over_environments<'a>(rows: impl Iterator<Item = &'a Measurement>) -> String {
    let (mut sum, mut n, mut max) = (0.0, 0usize, 0.0f64);
    for r in rows {
        sum += r.mean_error;
        n += 1;
        max = max.max(r.max_error);
    }
    if n == 0 { "-".into() } else { format!("{:.1} % ({:.0} %)", 100.0 * sum / n as f64, 100.0 * max) }
}

/// The measure over sets: per set, each method's shaded colour over every point and per
/// `n·v` band, the bake's share and the prefiltered lookup (mean over the set's
/// environments, max in brackets); then each environment's figures for the defaults.
fn set_tables(rows: &[Measurement]) -> Vec<Table> {
    use crate::measurement::Set;
    let set_rows: Vec<&Measurement> = rows.iter().filter(|r| r.set.is_some()).collect();
    if set_rows.is_empty() {
        return vec![];
    }
    let no_band = |r: &Measurement| r.roughness_lo.is_none() && r.nv_lo.is_none() && r.near_sun.is_none();
    // A method is its kind, its sample count and its fetches (the ladder's rungs apart).
    type Key = (Method, u32, u32);
    let key = |r: &Measurement| -> Key { (r.method, r.samples.unwrap_or(0), r.fetches.unwrap_or(1)) };
    let mut methods: Vec<Key> = set_rows.iter().map(|r| key(r)).collect();
    methods.sort();
    methods.dedup();
    let mut tables = Vec::new();
    for set in [Set::Tuning, Set::HeldOut] {
        let mut envs: Vec<&str> = set_rows.iter().filter(|r| r.set == Some(set)).map(|r| r.environment.as_str()).collect();
        envs.dedup();
        let of = |m: Key| set_rows.iter().copied().filter(move |r| r.set == Some(set) && key(r) == m);
        let cells = methods
            .iter()
            .map(|&m| {
                let shaded = |part: Part| over_environments(of(m).filter(|r| r.product == Product::ShadedColour && r.part == part && no_band(r)));
                let view = |hi: f32| over_environments(of(m).filter(|r| r.product == Product::ShadedColour && r.part == Part::Total && r.nv_hi == Some(hi)));
                [
                    match m.2 {
                        1 => format!("{}, {} samples", m.0.title(), m.1),
                        k => format!("{}, {k} fetches", m.0.title()),
                    },
                    shaded(Part::Total),
                    view(0.1),
                    view(0.3),
                    view(0.6),
                    view(1.0),
                    shaded(Part::Bake),
                    over_environments(of(m).filter(|r| r.product == Product::PrefilteredLookup && no_band(r))),
                ]
            })
            .collect();
        let header = ["method", "shaded colour", "n·v ≤ 0.1", "0.1–0.3", "0.3–0.6", "0.6–1", "(a) bake's share", "prefiltered lookup"];
        tables.push((format!("{}: {}", set.title(), envs.join(", ")), header, cells));
    }
    let defaults: Key = (Method::Defaults, Settings::default().samples, 1);
    let mut envs: Vec<(&str, Set)> = set_rows.iter().map(|r| (r.environment.as_str(), r.set.expect("set rows"))).collect();
    envs.dedup();
    let cells = envs
        .iter()
        .map(|&(env, set)| {
            let of = |m: Key| set_rows.iter().copied().filter(move |r| r.environment == env && key(r) == m);
            let shaded = |m, part: Part| over_environments(of(m).filter(|r| r.product == Product::ShadedColour && r.part == part && no_band(r)));
            let view = |hi: f32| over_environments(of(defaults).filter(|r| r.product == Product::ShadedColour && r.part == Part::Total && r.nv_hi == Some(hi)));
            [
                env.to_string(),
                set.title().to_string(),
                shaded(defaults, Part::Total),
                view(0.3),
                view(0.1),
                shaded(defaults, Part::Bake),
                shaded(defaults, Part::SplitSum),
                shaded((Method::Seed, 1024, 1), Part::Total),
            ]
        })
        .collect();
    let header = ["environment", "set", "defaults", "n·v 0.1–0.3", "n·v ≤ 0.1", "(a) bake", "(b) split sum", "seed, 1024 samples"];
    tables.push(("each environment (shaded colour, defaults unless named)".to_string(), header, cells));
    tables
}

/// What the shading ladder is, in the report.
const BUDGET_NOTE: &str = "For each time budget per bake, the settings splitsum::estimate::for_budget chooses on this backend (by this backend's estimator, as runner bake --budget chooses: its rates measured now, the built-in error model): the sample count at mip 1 and the irradiance source. Each is baked, timed (the bake as run here, not the estimate) and measured end to end like the methods below: shaded colour against the full reflectance integral over this environment's points.";

const LADDER_NOTE: &str = "The shading ladder: the split sum's one prefiltered fetch, then 2 to 16 fetches of filtered importance sampling of the true GGX lobe over the prefiltered mips (shade::lobe_radiance), used below n·v 0.7. Shaded colour against the full reflectance integral (mean relative luminance error, the largest point in brackets), against what a shaded pixel costs: ns per pixel of a sphere in the default view, direct lights included (a frame with the spheres less one without, best of three).";

/// The method of the ladder's rung with `fetches`: the defaults' one fetch, the ladder above.
pub fn rung_method(fetches: u32) -> Method {
    if fetches == 1 { Method::Defaults } else { Method::Ladder }
}

/// The rungs of the ladder present in `rows`, in order.
fn rungs(rows: &[Measurement]) -> Vec<u32> {
    let mut k: Vec<u32> =
        rows.iter().filter(|r| r.product == Product::ShadingCost).filter_map(|r| r.fetches.filter(|&k| r.method == rung_method(k))).collect();
    k.sort();
    k.dedup();
    k
}

/// The cost per shaded pixel of `method` with `fetches` on the backend `engine`.
fn cost_of(rows: &[Measurement], method: Method, fetches: u32, engine: &str) -> Option<f64> {
    rows.iter().find(|r| r.product == Product::ShadingCost && r.method == method && r.fetches == Some(fetches) && r.backend == engine).and_then(|r| r.ns_per_pixel)
}

/// The shaded colour's rows of `method` with `fetches` at the default sample count, part
/// total.
fn method_rows(rows: &[Measurement], method: Method, fetches: u32) -> impl Iterator<Item = &Measurement> {
    let samples = Settings::default().samples;
    rows.iter().filter(move |r| {
        r.product == Product::ShadedColour
            && r.part == Part::Total
            && r.method == method
            && r.fetches == Some(fetches)
            && r.samples == Some(samples)
            && r.knob != Knob::Quality
            && r.roughness_lo.is_none()
            && r.near_sun.is_none()
    })
}

/// The shaded colour's rows of the rung with `fetches`, part total.
fn rung_rows(rows: &[Measurement], fetches: u32) -> impl Iterator<Item = &Measurement> {
    method_rows(rows, rung_method(fetches), fetches)
}

/// The ladder's table: per rung, its cost on each backend and its error on the report's
/// environment and over each set, all points and per `n·v` band.
fn ladder_table(rows: &[Measurement]) -> Option<Table> {
    let rungs = rungs(rows);
    if rungs.is_empty() {
        return None;
    }
    let first = rows.iter().find(|r| r.product == Product::ShadedColour && r.set.is_none() && !r.backend.is_empty()).map(|r| r.backend.clone());
    // The rungs, then the quality mode below mip 1 (`--filtered`, one fetch but sixteen
    // samples where it applies) for its cost beside theirs.
    let mut lines: Vec<(String, Method, u32)> = rungs.iter().map(|&k| (format!("{k}"), rung_method(k), k)).collect();
    if cost_of(rows, Method::FilteredSampling, 1, "gpu").or(cost_of(rows, Method::FilteredSampling, 1, "cpu")).is_some() {
        lines.push(("1, --filtered".into(), Method::FilteredSampling, 1));
    }
    let cells = lines
        .into_iter()
        .map(|(label, method, k)| {
            let cost = |engine: &str| cost_of(rows, method, k, engine).map_or("-".into(), |ns| format!("{ns:.0}"));
            let own = |band: Option<f32>| over_environments(method_rows(rows, method, k).filter(|r| r.set.is_none() && Some(&r.backend) == first.as_ref() && r.nv_hi == band));
            let set = |s: crate::measurement::Set, band: Option<f32>| over_environments(method_rows(rows, method, k).filter(|r| r.set == Some(s) && r.nv_hi == band));
            [
                label,
                cost("gpu"),
                cost("cpu"),
                own(None),
                own(Some(0.1)),
                set(crate::measurement::Set::Tuning, None),
                set(crate::measurement::Set::HeldOut, None),
                set(crate::measurement::Set::HeldOut, Some(0.1)),
            ]
        })
        .collect();
    let header = ["fetches", "ns/pixel, GPU", "ns/pixel, CPU", "this environment", "its n·v ≤ 0.1", "tuning set", "held-out set", "held-out n·v ≤ 0.1"];
    Some(("shading ladder: shaded colour against cost".to_string(), header, cells))
}

/// The ladder's figure: error against ns per pixel, a panel per backend's cost, a curve
/// per environment or set (its points the rungs, 1 to 16 fetches).
pub fn ladder_panels(rows: &[Measurement]) -> Vec<crate::plot::LadderPanel> {
    use crate::measurement::Set;
    let rungs = rungs(rows);
    let mut panels = Vec::new();
    for engine in ["gpu", "cpu"] {
        let ns = |k: u32| cost_of(rows, rung_method(k), k, engine);
        if rungs.iter().all(|&k| ns(k).is_none()) {
            continue;
        }
        let mut curves = Vec::new();
        for (label, set, band) in [
            ("this environment", None, None),
            ("this environment, n·v ≤ 0.1", None, Some(0.1)),
            ("tuning set", Some(Set::Tuning), None),
            ("held-out set", Some(Set::HeldOut), None),
            ("held-out set, n·v ≤ 0.1", Some(Set::HeldOut), Some(0.1)),
        ] {
            let points: Vec<(f64, f64, u32)> = rungs
                .iter()
                .filter_map(|&k| {
                    let errs: Vec<f64> = rung_rows(rows, k).filter(|r| r.set == set && r.nv_hi == band && (set.is_some() || r.backend == engine)).map(|r| r.mean_error).collect();
                    (!errs.is_empty()).then(|| Some((ns(k)?, errs.iter().sum::<f64>() / errs.len() as f64, k)))?
                })
                .collect();
            if !points.is_empty() {
                curves.push(crate::plot::LadderCurve { label: label.to_string(), points });
            }
        }
        panels.push(crate::plot::LadderPanel {
            title: format!("shading ladder, cost on the {}", if engine == "gpu" { "GPU" } else { "CPU" }),
            x_label: "ns per shaded pixel".into(),
            curves,
        });
    }
    panels
}

/// The budget curve's rows: the shaded colour's total over all points of the report's
/// environment (or its `n·v ≤ 0.1` band), per backend and budget.
fn budget_rows(rows: &[Measurement], band: Option<f32>) -> impl Iterator<Item = &Measurement> {
    rows.iter().filter(move |r| {
        r.method == Method::TimeBudget
            && r.product == Product::ShadedColour
            && r.part == Part::Total
            && r.set.is_none()
            && r.roughness_lo.is_none()
            && r.near_sun.is_none()
            && r.nv_hi == band
    })
}

/// The budget curve's table: per backend and budget, the settings chosen, their estimated
/// and measured bake time, and their error end to end.
fn budget_table(rows: &[Measurement]) -> Option<Table> {
    let cells: Vec<[String; 8]> = budget_rows(rows, None)
        .map(|r| {
            let grazing = budget_rows(rows, Some(0.1)).find(|g| g.backend == r.backend && g.budget_s == r.budget_s).map_or("-".into(), |g| format!("{:.1} %", 100.0 * g.mean_error));
            [
                r.backend.clone(),
                format!("{}", r.budget_s.unwrap_or(f64::NAN)),
                r.samples.map_or("-".into(), |n| n.to_string()),
                r.source_size.map_or("-".into(), |s| format!("{s}²")),
                r.estimate_s.map_or("-".into(), |e| format!("{e:.3}")),
                r.time_ms.map_or("-".into(), |t| format!("{:.3}", t * 1e-3)),
                format!("{:.1} %", 100.0 * r.mean_error),
                grazing,
            ]
        })
        .collect();
    (!cells.is_empty()).then(|| {
        let header = ["backend", "budget (s)", "samples at mip 1", "irradiance from", "estimate (s)", "bake (s)", "error, this environment", "its n·v ≤ 0.1"];
        ("time budget: the settings chosen and their error".to_string(), header, cells)
    })
}

/// The budget curve's figure: the error end to end against the budget, a panel per backend.
pub fn budget_panels(rows: &[Measurement]) -> Vec<crate::plot::LadderPanel> {
    let mut panels = Vec::new();
    for engine in ["gpu", "cpu"] {
        let curve = |band: Option<f32>| -> Vec<(f64, f64, u32)> {
            budget_rows(rows, band).filter(|r| r.backend == engine).filter_map(|r| Some((r.budget_s?, r.mean_error, r.samples?))).collect()
        };
        let curves: Vec<crate::plot::LadderCurve> = [("this environment", None), ("its n·v ≤ 0.1", Some(0.1))]
            .into_iter()
            .map(|(label, band)| crate::plot::LadderCurve { label: label.to_string(), points: curve(band) })
            .filter(|c| !c.points.is_empty())
            .collect();
        if !curves.is_empty() {
            panels.push(crate::plot::LadderPanel {
                title: format!("time budget on the {}", if engine == "gpu" { "GPU" } else { "CPU" }),
                x_label: "budget per bake (s)".into(),
                curves,
            });
        }
    }
    panels
}

fn html_escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}

fn write_outputs(dir: &Path, name: &str, backends: &[Backend], sweep: &Sweep, rows: &[Measurement], maps: &[(String, ErrorMap)]) -> Result<()> {
    files::write_atomic(&dir.join("report.csv"), |w| splitsum::measured::write_csv(w, rows).map_err(std::io::Error::other))?;
    let svg = |w: &mut dyn std::io::Write, drawn: std::result::Result<String, Box<dyn std::error::Error>>| -> std::io::Result<()> {
        w.write_all(drawn.map_err(|e| std::io::Error::other(e.to_string()))?.as_bytes())
    };
    files::write_atomic(&dir.join("error_vs_time.svg"), |w| svg(w, crate::plot::small_multiples(&panels(rows), 3)))?;
    // surface{k}_splitsum.png, surface{k}_exact.png, surface{k}_error.png for each map.
    let picture = |k: usize, kind: &str| format!("surface{k}_{kind}.png");
    for (k, (_, map)) in maps.iter().enumerate() {
        for (kind, rgb) in [("splitsum", &map.splitsum), ("exact", &map.exact), ("error", &map.error)] {
            files::write_png(&dir.join(picture(k, kind)), map.width, map.height, rgb)?;
        }
    }
    let ladder = ladder_table(rows);
    if ladder.is_some() {
        files::write_atomic(&dir.join("ladder.svg"), |w| svg(w, crate::plot::ladder(&ladder_panels(rows))))?;
    }
    let budget = budget_table(rows);
    if budget.is_some() {
        files::write_atomic(&dir.join("budget.svg"), |w| svg(w, crate::plot::ladder(&budget_panels(rows))))?;
    }
    files::write_atomic(&dir.join("surface_scale.svg"), |w| {
        svg(w, crate::plot::colour_scale("relative luminance error", crate::surface::false_colour, &crate::surface::scale_ticks()))
    })?;

    let devices = backends.iter().map(|b| b.describe()).collect::<Vec<_>>().join("; ");
    let setup = format!(
        "Environment: {name}; source cube {0}x{0}; prefiltered cube {1}x{1}, {2} mips (roughness m/(M-1)). Backends: {devices}.",
        sweep.source_size, sweep.specular_size, sweep.mips
    );
    let references = "References (f64, independent of the code under test): adaptive Gauss-Kronrod quadrature for the BRDF table; exact sums over every texel of the source for the prefilter and the irradiance; the full reflectance integral (exact Smith, no split) for the shaded colour. Errors are relative: of the luminance, and for the table of the directional albedo F0*A + B (the larger of F0 = 0.04 and 1). Times are wall-clock, uploads and readbacks included.";
    let grid = format!(
        "Sphere grid (metal above, dielectric below; roughness {} across), orthographic view, shaded by splitsum from the default bake on {} against the exact integral (exact Smith, no split), with their relative luminance error.",
        crate::surface::ROUGHNESS.iter().map(|r| format!("{r}")).collect::<Vec<_>>().join(", "),
        backends[0].describe()
    );
    let caption = |what: &str, map: &ErrorMap| format!("{what}: mean relative error {:.2} %, max {:.0} %.", 100.0 * map.mean, 100.0 * map.max);
    let tables = tables(rows);
    let set_tables = set_tables(rows);
    let best = best_per_ms(rows);

    // Markdown.
    let mut md = String::new();
    let _ = writeln!(md, "# splitsum: error against run time\n\n{setup}\n\n{references}\n");
    let _ = writeln!(md, "![error against run time](error_vs_time.svg)\n\n{grid}\n\n| environment | splitsum | exact | error |\n|---|---|---|---|");
    for (k, (what, map)) in maps.iter().enumerate() {
        let _ = writeln!(md, "| {} | ![]({}) | ![]({}) | ![]({}) |", caption(what, map), picture(k, "splitsum"), picture(k, "exact"), picture(k, "error"));
    }
    let _ = writeln!(md, "\n![scale](surface_scale.svg)");
    let figures = [(&ladder, LADDER_NOTE, "ladder", "the shading ladder", "error against ns per shaded pixel, one point per rung"), (&budget, BUDGET_NOTE, "budget", "the budget curve", "error against the time budget, one point per budget")];
    for (table, note, id, alt, _) in figures {
        if let Some((title, header, cells)) = table {
            let _ = writeln!(md, "\n## {title}\n\n{note}\n\n![{alt}]({id}.svg)\n\n| {} |\n|{}", header.join(" | "), "---|".repeat(header.len()));
            for c in cells {
                let _ = writeln!(md, "| {} |", c.join(" | "));
            }
        }
    }
    if !set_tables.is_empty() {
        let _ = writeln!(md, "\n## Tuning and held-out sets\n\n{SETS_NOTE}");
    }
    for (title, header, cells) in set_tables.iter().chain(&tables) {
        let _ = writeln!(md, "\n## {title}\n\n| {} |\n|{}", header.join(" | "), "---|".repeat(header.len()));
        for c in cells {
            let _ = writeln!(md, "| {} |", c.join(" | "));
        }
    }
    let _ = writeln!(md, "\n## Best error per millisecond (smallest mean error x time)\n\n| panel | backend | setting | time (ms) | mean error |\n|---|---|---|---:|---:|");
    for (p, r) in &best {
        let _ = writeln!(md, "| {p} | {} | {} | {:.1} | {:.2e} |", r.backend, r.setting(), r.time_ms.unwrap_or(f64::NAN), r.mean_error);
    }
    files::write_atomic(&dir.join("report.md"), |w| std::io::Write::write_all(w, md.as_bytes()))?;

    // HTML: the same, every figure inline beside its caption.
    let mut html = String::new();
    let _ = writeln!(
        html,
        "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>splitsum: error against run time, {}</title>\n<style>body{{font-family:sans-serif;max-width:1120px;margin:2em auto;color:#222}} table{{border-collapse:collapse;font-size:13px;margin:0.5em 0 1.5em}} td,th{{border:1px solid #ccc;padding:2px 6px;text-align:right}} td:nth-child(-n+5),th:nth-child(-n+5){{text-align:left}} figure{{margin:1em 0}} .maps img{{image-rendering:pixelated;border:1px solid #ddd;margin-right:8px}}</style></head><body>",
        html_escape(name)
    );
    let _ = writeln!(html, "<h1>splitsum: error against run time</h1>\n<p>{}</p>\n<p>{}</p>", html_escape(&setup), html_escape(references));
    let _ = writeln!(html, "<figure id=\"error-vs-time\"><img src=\"error_vs_time.svg\" alt=\"error against run time, one panel per product\"><figcaption>Mean relative error against bake time, one panel per product: one colour per method, the GPU solid and the CPU dashed; ringed points are each panel's Pareto front.</figcaption></figure>");
    let _ = writeln!(html, "<h2>The error on surfaces</h2>\n<p>{}</p>", html_escape(&grid));
    for (k, (what, map)) in maps.iter().enumerate() {
        let _ = writeln!(
            html,
            "<figure class=\"maps\"><img src=\"{}\" alt=\"splitsum\"><img src=\"{}\" alt=\"exact\"><img src=\"{}\" alt=\"error\"><figcaption>Left to right: splitsum, the exact integral, their relative error. {}</figcaption></figure>",
            picture(k, "splitsum"),
            picture(k, "exact"),
            picture(k, "error"),
            html_escape(&caption(what, map))
        );
    }
    let _ = writeln!(html, "<img src=\"surface_scale.svg\" alt=\"error scale\">");
    for (table, note, id, _, alt) in figures {
        if let Some((title, header, cells)) = table {
            let _ = writeln!(
                html,
                "<h2 id=\"{id}\">{}</h2>\n<p>{}</p>\n<figure><img src=\"{id}.svg\" alt=\"{alt}\"></figure>\n<table><tr>{}</tr>",
                html_escape(title),
                html_escape(note),
                header.iter().map(|h| format!("<th>{}</th>", html_escape(h))).collect::<String>()
            );
            for c in cells {
                let _ = writeln!(html, "<tr>{}</tr>", c.iter().map(|v| format!("<td>{}</td>", html_escape(v))).collect::<String>());
            }
            let _ = writeln!(html, "</table>");
        }
    }
    if !set_tables.is_empty() {
        let _ = writeln!(html, "<h2>Tuning and held-out sets</h2>\n<p>{}</p>", html_escape(SETS_NOTE));
    }
    for (title, header, cells) in set_tables.iter().chain(&tables) {
        let _ = writeln!(html, "<h2>{}</h2>\n<table><tr>{}</tr>", html_escape(title), header.iter().map(|h| format!("<th>{}</th>", html_escape(h))).collect::<String>());
        for c in cells {
            let _ = writeln!(html, "<tr>{}</tr>", c.iter().map(|v| format!("<td>{}</td>", html_escape(v))).collect::<String>());
        }
        let _ = writeln!(html, "</table>");
    }
    let _ = writeln!(html, "<h2>Best error per millisecond</h2>\n<table><tr><th>panel</th><th>backend</th><th>setting</th><th>time (ms)</th><th>mean error</th></tr>");
    for (p, r) in &best {
        let _ = writeln!(html, "<tr><td>{}</td><td>{}</td><td>{}</td><td>{:.1}</td><td>{:.2e}</td></tr>", html_escape(p), r.backend, html_escape(&r.setting()), r.time_ms.unwrap_or(f64::NAN), r.mean_error);
    }
    let _ = writeln!(html, "</table></body></html>");
    files::write_atomic(&dir.join("report.html"), |w| std::io::Write::write_all(w, html.as_bytes()))?;
    Ok(())
}
