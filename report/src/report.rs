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
//! Outputs, written by [`crate::pages`]: `report.html` (every figure and table), `report.md` (the same, for a
//! repository), `report.csv` (the typed rows, `splitsum::measured`), `error_vs_time.svg`
//! (small multiples, [`crate::plot`]) and the error on surfaces ([`crate::surface`]).

use crate::measurement::{Device, Knob, Measurement, Method, Metric, Part, Quantity, arr, rel};
use crate::write::write_outputs;
use crate::sweep::{Sets, Sweep};
use rayon::prelude::*;
use splitsum::Product;
use splitsum::backend::Backend;
use splitsum::bake;
use splitsum::environment::Environment;
use splitsum::error::Result;
use splitsum::files;
use splitsum::settings::{Job, Settings};
use splitsum::texture::Cube;
use splitsum_reference as reference;
use splitsum_shaders::brdf::microfacet::Masking;
use splitsum_shaders::cubemap::{self, CubeLayout};
use splitsum_shaders::glam::{Vec2, Vec3};
use splitsum_shaders::irradiance::sh9_irradiance;
use splitsum_shaders::prefilter::Lobe;
use splitsum_shaders::shade::{self, Material, ShadeOptions};
use splitsum_shaders::{lut, sampling};
use std::path::Path;
use std::time::Instant;

fn timed<T>(f: impl FnOnce() -> Result<T>) -> Result<(T, f64)> {
    let start = Instant::now();
    let v = f()?;
    Ok((v, start.elapsed().as_secs_f64() * 1e3))
}

/// Unit directions spread over the sphere (a Hammersley set through the equirect map).
fn directions(n: u32) -> Vec<Vec3> {
    (0..n).map(|i| splitsum_shaders::equirect::uv_to_dir(sampling::hammersley(i, n) * Vec2::new(1.0, 0.96) + Vec2::new(0.0, 0.02))).collect()
}

/// Runs the report's sweeps of `env` on `backends` (and the measure over `sets`, if
/// given, on the first backend), writes the files into `dir` with the shading ladder's
/// `costs` (`Quantity::ShadingCost` rows, timed by the renderer's owner) beside its errors,
/// and returns the measurements.
pub fn run(
    env: &Environment,
    name: &str,
    backends: &[Backend],
    sweep: &Sweep,
    sets: Option<&Sets>,
    costs: &[Measurement],
    dir: &Path,
) -> Result<Vec<Measurement>> {
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
    let job = sweep.level_job()?;
    let refs = {
        let _step = splitsum::progress::step("report: references (f64)", None);
        References::compute(sweep, &job, &texels)
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
        rows.extend(prefilter_rows(backend, &b, sweep, &job, &refs, &source)?);
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
        let baked = splitsum::reading::bake_for_display(&backends[0], e, &Settings { size: src, source_size: Some(src), ..defaults.clone() })?;
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
    fn compute(sweep: &Sweep, job: &Job, texels: &[([f64; 3], f64, [f64; 3])]) -> Self {
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
        let roughness = job.roughness_per_mip();
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
                        let material = Material {
                            base_color: Vec3::new(0.9, 0.6, 0.3),
                            metallic,
                            roughness: r,
                            occlusion: 1.0,
                            emissive: Vec3::ZERO,
                            sheen_color: Vec3::ZERO,
                            sheen_roughness: 0.0,
                        };
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
                let row = Measurement::of(Quantity::ShadedColour, Method::ExactIngredients, &errors, Metric::RelativeLuminance);
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
        rows.push(Measurement {
            knob: Knob::Samples,
            samples: Some(n),
            size,
            time_ms: Some(ms),
            ..b.row(Quantity::BrdfTable, Method::Seed, &errors, Metric::RelativeAlbedo)
        });
    }
    // The deterministic quadrature (the default table), on the same texels.
    let (table, ms) = timed(|| backend.brdf_table(sweep.lut_size, Masking::SmithSchlick))?;
    let errors = albedo_errors(table.texels.iter().copied(), refs.lut.iter().copied());
    rows.push(Measurement { size, time_ms: Some(ms), ..b.row(Quantity::BrdfTable, Method::Defaults, &errors, Metric::RelativeAlbedo) });
    let n = *sweep.samples.last().expect("samples");
    for &size in &sweep.lut_sizes {
        let (table, ms) = timed(|| backend.brdf_lut(size, n))?;
        let errors = albedo_errors(refs.lut_points.iter().map(|(p, _)| lut::sample(&table.texels, size, p.x, p.y)), refs.lut_points.iter().map(|(_, r)| *r));
        rows.push(Measurement {
            knob: Knob::Size,
            samples: Some(n),
            size: Some(size),
            time_ms: Some(ms),
            ..b.row(Quantity::BrdfTableLookup, Method::Seed, &errors, Metric::RelativeAlbedo)
        });
    }
    Ok(rows)
}

/// The prefiltered cube at the levels of [`Sweep::levels`] (the defaults at the report's
/// size): each sampled mip's sample sweep (its default count among them) and bias sweep,
/// mip 1's face-size sweep, and the default bake of the whole cube (`Knob::Quality`: each
/// mip as the defaults make it, sampled with their growth or summed exactly, one timed
/// dispatch whose time every mip's row carries).
fn prefilter_rows(backend: &Backend, b: &Device, sweep: &Sweep, job: &Job, refs: &References, source: &Cube) -> Result<Vec<Measurement>> {
    let mut rows = Vec::new();
    let roughness = job.roughness_per_mip();
    // Level `level` of `cube` against the reference of mip `m`'s roughness.
    let errors_of = |cube: &Cube, level: u32, m: usize| -> Vec<f64> {
        refs.prefilter_dirs.iter().zip(&refs.prefilter[m]).map(|(&d, r)| rel(cubemap::sample_bilinear(&cube.texels, cube.layout, level, d).truncate(), *r)).collect()
    };
    let mut level = |n: u32, bias: f32, m: usize, size: u32, knob: Knob| -> Result<()> {
        let layout = CubeLayout::new(size, 1);
        let (cube, ms) = timed(|| backend.prefilter(source, layout, &[roughness[m]], n, bias))?;
        let row = b.row(Quantity::Prefilter, Method::Defaults, &errors_of(&cube, 0, m), Metric::RelativeLuminance);
        let r = Some(roughness[m]);
        rows.push(Measurement { knob, samples: Some(n), bias: Some(bias), size: Some(size), roughness_lo: r, roughness_hi: r, time_ms: Some(ms), ..row });
        Ok(())
    };
    // The mirror (roughness 0) is a copy: nothing to sweep.
    let sampled: Vec<usize> = (0..roughness.len()).filter(|&m| roughness[m] > 0.0).collect();
    for &m in &sampled {
        let size = (job.size >> m).max(1);
        let mut counts = sweep.samples.clone();
        counts.push(job.samples_per_mip[m]);
        counts.sort_unstable();
        counts.dedup();
        for n in counts {
            level(n, job.lod_bias, m, size, Knob::Samples)?;
        }
        for &n in &sweep.bias_samples {
            for &bias in &sweep.biases {
                level(n, bias, m, size, Knob::Bias)?;
            }
        }
    }
    let n = sweep.bias_samples[sweep.bias_samples.len() - 1];
    if let Some(&first) = sampled.first() {
        for &size in &sweep.cube_sizes {
            level(n, job.lod_bias, first, size, Knob::Size)?;
        }
    }
    let all: Vec<u32> = (0..job.mips).collect();
    let (cube, ms) =
        timed(|| backend.prefilter_levels(Lobe::Ggx, source, job.specular_layout(), roughness, &all, &job.samples_per_mip, true, job.lod_bias))?;
    for m in sampled {
        let row = b.row(Quantity::Prefilter, Method::Defaults, &errors_of(&cube, m as u32, m), Metric::RelativeLuminance);
        let r = Some(roughness[m]);
        let (samples, size) = (Some(job.samples_per_mip[m]), Some((job.size >> m).max(1)));
        rows.push(Measurement { knob: Knob::Quality, samples, bias: Some(job.lod_bias), size, roughness_lo: r, roughness_hi: r, time_ms: Some(ms), ..row });
    }
    Ok(rows)
}

fn irradiance_rows(backend: &Backend, b: &Device, sweep: &Sweep, refs: &References, source: &Cube) -> Result<Vec<Measurement>> {
    let mut rows = Vec::new();
    for &s in &sweep.irradiance_sources {
        let level = source.layout.level_of_size(s);
        let (cube, ms) = timed(|| backend.irradiance(source, level, sweep.irradiance_size))?;
        let errors: Vec<f64> = refs
            .irradiance_dirs
            .iter()
            .zip(&refs.irradiance)
            .map(|(&d, r)| rel(cubemap::sample_bilinear(&cube.texels, cube.layout, 0, d).truncate(), *r))
            .collect();
        let row = b.row(Quantity::Irradiance, Method::Defaults, &errors, Metric::RelativeLuminance);
        rows.push(Measurement { knob: Knob::SourceSize, source_size: Some(s), size: Some(sweep.irradiance_size), time_ms: Some(ms), ..row });
    }
    for &s in &sweep.sh_sources {
        let level = source.layout.level_of_size(s);
        let (sh, ms) = timed(|| backend.sh9(source, level))?;
        let coeffs = sh.as_vec4();
        let errors: Vec<f64> = refs.irradiance_dirs.iter().zip(&refs.irradiance).map(|(&d, r)| rel(sh9_irradiance(&coeffs, d), *r)).collect();
        let row = b.row(Quantity::Irradiance, Method::Sh9, &errors, Metric::RelativeLuminance);
        rows.push(Measurement { knob: Knob::SourceSize, source_size: Some(s), time_ms: Some(ms), ..row });
    }
    Ok(rows)
}

fn shaded_rows(backend: &Backend, b: &Device, sweep: &Sweep, refs: &References, env: &Environment) -> Result<Vec<Measurement>> {
    let mut rows = Vec::new();
    for settings in &sweep.qualities {
        let (baked, ms) = timed(|| splitsum::reading::bake_for_display(backend, env, settings))?;
        let (spec, irr, table, shape) = (baked.specular_buffer(), baked.cube(Product::Irradiance), baked.table(Product::BrdfTable), baked.shape());
        for &(lo, hi) in &VIEWS {
            let errors: Vec<f64> = refs
                .shading
                .iter()
                .filter(|p| in_view(p, (lo, hi)))
                .map(|p| {
                    let s = shade::ibl_sample(shape, &spec, &irr.texels, &table.texels, ShadeOptions::DEFAULT, &p.material, p.n, p.v);
                    rel(shade::ibl(ShadeOptions::DEFAULT, &p.material, p.n, p.v, s), p.full)
                })
                .collect();
            let row = b.row(Quantity::ShadedColour, Method::Defaults, &errors, Metric::RelativeLuminance);
            let (samples, size) = (Some(settings.samples), Some(settings.size));
            rows.push(Measurement { knob: Knob::Quality, samples, size, nv_lo: Some(lo), nv_hi: Some(hi), time_ms: Some(ms), ..row });
        }
    }
    Ok(rows)
}
