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
//! Outputs: `report.md` (tables), `report.csv`, `error_vs_time.png` (log–log, one curve
//! per product and backend).

use crate::measurement::{ABS, Measurement, REL, arr, rel};
use crate::plot::{self, Series};
use rayon::prelude::*;
use splitsum::backend::Backend;
use splitsum::bake;
use splitsum::environment::Environment;
use splitsum::error::Result;
use splitsum::files;
use splitsum::settings::{Settings, level_of_size};
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
    /// Quality levels of the shaded colour: (label, settings).
    pub qualities: Vec<(String, Settings)>,
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
        sweep.qualities.push(("defaults (bake's)".to_string(), Settings::default()));
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
        let src = native.min(self.accuracy_source).max(4);
        let default = Settings { size: src, source_size: Some(src), ..Settings::default() };
        let flags = ShadeOptions::DEFAULT.flags & !(ShadeOptions::IBL | ShadeOptions::DIRECT);
        let mut methods = Vec::new();
        // Each method's error against its bake time: the seed at three sample counts, the
        // defaults at three (mip 1's count; ×2 per mip after it).
        for n in [64, 256, 1024] {
            let label = if n == 1024 { "seed (6 linear mips, 1024 samples, sampled table)".to_string() } else { format!("seed, {n} samples") };
            methods.push(Method { label, family: "seed method", settings: Settings { samples: n, ..seed_settings(src) }, flags: 0 });
        }
        for n in [16, 256] {
            methods.push(Method { label: format!("defaults, {n} samples"), family: "defaults", settings: Settings { samples: n, ..default.clone() }, flags });
        }
        methods.extend(vec![
            Method { label: "defaults".into(), family: "defaults", settings: default.clone(), flags },
            Method {
                label: "defaults, mirror direction".into(),
                family: "options",
                settings: default.clone(),
                flags: flags & !ShadeOptions::DOMINANT_DIRECTION,
            },
            Method { label: "defaults + multiple scattering".into(), family: "options", settings: default.clone(), flags: flags | ShadeOptions::MULTISCATTER },
            Method {
                label: "defaults + filtered sampling".into(),
                family: "options",
                settings: default.clone(),
                flags: flags | ShadeOptions::FILTERED_SAMPLING,
            },
            Method {
                label: "defaults, Smith-Schlick table".into(),
                family: "options",
                settings: Settings { lut_masking: Some(Masking::SmithSchlick), ..default },
                flags,
            },
        ]);
        methods
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
        let level = |label: &str, n: u32, lut: u32, irr: u32| {
            let s = Settings {
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
            (label.to_string(), s)
        };
        let q = &samples;
        let qualities = vec![
            level(&format!("q1 ({} samples)", q[0]), q[0], lut_sizes[0], irradiance_sources[0]),
            level(
                &format!("q2 ({} samples)", q[q.len() / 2]),
                q[q.len() / 2],
                lut_sizes[lut_sizes.len() / 2],
                irradiance_sources[irradiance_sources.len() / 2],
            ),
            level(&format!("q3 ({} samples)", q[q.len() - 1]), q[q.len() - 1], *lut_sizes.last().expect("sizes"), *irradiance_sources.last().expect("sizes")),
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

/// Runs the report's sweeps of `env` on `backends`, writes the three files into `dir`, and
/// returns the measurements.
pub fn run(env: &Environment, name: &str, backends: &[Backend], sweep: &Sweep, dir: &Path) -> Result<Vec<Measurement>> {
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
        let b = backend.describe();
        let _step = splitsum::progress::step(&format!("report: every product on {b}"), None);
        // Warm-up, outside the timings: first dispatches pay for driver set-up and caches.
        backend.brdf_lut(4, 4)?;
        backend.brdf_table(4, splitsum_shaders::brdf::microfacet::Masking::SmithSchlick)?;
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
    let _step = splitsum::progress::step("report: writing report.md, report.csv, error_vs_time.png", None);
    write_outputs(dir, name, backends, sweep, &rows)?;
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

/// The view-angle classes the shaded colour is reported in: near normal and grazing, where
/// the split sum's `n = v = r` assumption is known to fail.
const VIEWS: [(&str, f32, f32); 2] = [("(n.v >= 0.6)", 0.59, 1.01), ("(n.v = 0.25)", 0.0, 0.3)];

fn in_view(p: &ShadingPoint, lo: f32, hi: f32) -> bool {
    let nv = p.n.dot(p.v);
    nv >= lo && nv < hi
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
                        let material = Material { base_color: Vec3::new(0.9, 0.6, 0.3), metallic, roughness: r, occlusion: 1.0, emissive: Vec3::ZERO };
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
            .map(|&(label, lo, hi)| {
                let errors: Vec<f64> = self.shading.iter().filter(|p| in_view(p, lo, hi)).map(|p| rel(p.exact_split, p.full)).collect();
                Measurement::of(format!("shaded colour {label}: split-sum approximation"), "exact ingredients", "n = v = r, split", f64::NAN, &errors, REL)
            })
            .collect()
    }
}

fn lut_rows(backend: &Backend, b: &str, sweep: &Sweep, refs: &References) -> Result<Vec<Measurement>> {
    let mut rows = Vec::new();
    for &n in &sweep.samples {
        let (table, ms) = timed(|| backend.brdf_lut(sweep.lut_size, n))?;
        let errors: Vec<f64> = table.texels.iter().zip(&refs.lut).map(|(g, r)| (*g - *r).abs().max_element() as f64).collect();
        rows.push(Measurement::of("brdf lut", b, format!("{n} samples"), ms, &errors, ABS));
    }
    // The deterministic quadrature (the default table), on the same texels.
    let (table, ms) = timed(|| backend.brdf_table(sweep.lut_size, splitsum_shaders::brdf::microfacet::Masking::SmithSchlick))?;
    let errors: Vec<f64> = table.texels.iter().zip(&refs.lut).map(|(g, r)| (*g - *r).abs().max_element() as f64).collect();
    rows.push(Measurement::of("brdf lut (quadrature)", b, format!("{0}x{0}", sweep.lut_size), ms, &errors, ABS));
    let n = *sweep.samples.last().expect("samples");
    for &size in &sweep.lut_sizes {
        let (table, ms) = timed(|| backend.brdf_lut(size, n))?;
        let errors: Vec<f64> = refs.lut_points.iter().map(|(p, r)| (lut::sample(&table.texels, size, p.x, p.y) - *r).abs().max_element() as f64).collect();
        rows.push(Measurement::of("brdf lut lookup", b, format!("{size}x{size} at {n} samples"), ms, &errors, ABS));
    }
    Ok(rows)
}

fn prefilter_rows(backend: &Backend, b: &str, sweep: &Sweep, refs: &References, source: &Cube) -> Result<Vec<Measurement>> {
    let mut rows = Vec::new();
    let roughness: Vec<f32> = (0..sweep.mips).map(|m| RoughnessMapping::Linear.roughness(m, sweep.mips)).collect();
    let mut level = |n: u32, bias: f32, m: usize, size: u32, product: String, setting: String| -> Result<()> {
        let layout = CubeLayout::new(size, 1);
        let (cube, ms) = timed(|| backend.prefilter(source, layout, &[roughness[m]], n, bias))?;
        let errors: Vec<f64> = refs
            .prefilter_dirs
            .iter()
            .zip(&refs.prefilter[m])
            .map(|(&d, r)| rel(cubemap::sample_bilinear(&cube.texels, layout, 0, d).truncate(), *r))
            .collect();
        rows.push(Measurement::of(product, b, setting, ms, &errors, REL));
        Ok(())
    };
    let default_bias = Settings::default().lod_bias;
    for m in 1..sweep.mips as usize {
        let size = (sweep.specular_size >> m).max(1);
        for &n in &sweep.samples {
            level(n, default_bias, m, size, format!("prefilter r={:.2}", roughness[m]), format!("{n} samples, bias {default_bias}"))?;
        }
        for &n in &sweep.bias_samples {
            for &bias in &sweep.biases {
                level(n, bias, m, size, format!("prefilter r={:.2} bias sweep", roughness[m]), format!("{n} samples, bias {bias}"))?;
            }
        }
    }
    let n = sweep.bias_samples[sweep.bias_samples.len() - 1];
    for &size in &sweep.cube_sizes {
        level(n, default_bias, 1, size, format!("prefilter r={:.2} cube size", roughness[1]), format!("{size}x{size}, {n} samples"))?;
    }
    Ok(rows)
}

fn irradiance_rows(backend: &Backend, b: &str, sweep: &Sweep, refs: &References, source: &Cube) -> Result<Vec<Measurement>> {
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
        rows.push(Measurement::of("irradiance (convolution)", b, format!("{s}x{s} source"), ms, &errors, REL));
    }
    for &s in &sweep.sh_sources {
        let level = level_of_size(source.layout, s);
        let (sh, ms) = timed(|| backend.sh9(source, level))?;
        let coeffs = sh.as_vec4();
        let errors: Vec<f64> = refs.irradiance_dirs.iter().zip(&refs.irradiance).map(|(&d, r)| rel(sh9_irradiance(&coeffs, d), *r)).collect();
        rows.push(Measurement::of("irradiance (SH9)", b, format!("{s}x{s} source"), ms, &errors, REL));
    }
    Ok(rows)
}

fn shaded_rows(backend: &Backend, b: &str, sweep: &Sweep, refs: &References, env: &Environment) -> Result<Vec<Measurement>> {
    let mut rows = Vec::new();
    for (label, settings) in &sweep.qualities {
        let (baked, ms) = timed(|| bake::bake_for_display(backend, env, settings))?;
        let (spec, irr, table, shape) = (&baked.specular, &baked.irradiance, &baked.lut, baked.shape());
        for &(view, lo, hi) in &VIEWS {
            let errors: Vec<f64> = refs
                .shading
                .iter()
                .filter(|p| in_view(p, lo, hi))
                .map(|p| {
                    let s = shade::ibl_sample(shape, &spec.texels, &irr.texels, &table.texels, ShadeOptions::DEFAULT.flags, p.n, p.v, p.material.roughness);
                    rel(shade::ibl(ShadeOptions::DEFAULT, &p.material, p.n, p.v, s), p.full)
                })
                .collect();
            rows.push(Measurement::of(format!("shaded colour {view}"), b, label.clone(), ms, &errors, REL));
        }
    }
    Ok(rows)
}

/// For each product and backend, the measurement with the smallest mean error × time.
pub fn best_per_ms(rows: &[Measurement]) -> Vec<&Measurement> {
    let mut keys: Vec<(&str, &str)> = Vec::new();
    for r in rows.iter().filter(|r| r.time_ms.is_finite()) {
        let k = (r.product.as_str(), r.backend.as_str());
        if !keys.contains(&k) {
            keys.push(k);
        }
    }
    keys.iter()
        .filter_map(|(p, b)| {
            rows.iter()
                .filter(|r| r.product == *p && r.backend == *b && r.time_ms.is_finite())
                .min_by(|x, y| (x.mean_error * x.time_ms).total_cmp(&(y.mean_error * y.time_ms)))
        })
        .collect()
}

fn write_outputs(dir: &Path, name: &str, backends: &[Backend], sweep: &Sweep, rows: &[Measurement]) -> Result<()> {
    // CSV (the csv crate quotes what needs quoting; `cost::Calibration` reads it back).
    files::write_atomic(&dir.join("report.csv"), |w| {
        let mut csv = csv::Writer::from_writer(w);
        csv.write_record(["product", "backend", "setting", "time_ms", "mean_error", "max_error", "metric"])?;
        for r in rows {
            let (t, mean, max) = (format!("{:.4}", r.time_ms), format!("{:.6e}", r.mean_error), format!("{:.6e}", r.max_error));
            csv.write_record([r.product.as_str(), &r.backend, &r.setting, &t, &mean, &max, r.metric])?;
        }
        csv.flush()
    })?;

    // Markdown.
    let mut md = String::new();
    let _ = writeln!(md, "# splitsum: error against run time\n");
    let _ = writeln!(
        md,
        "Environment: {name}; source cube {0}x{0}; prefiltered cube {1}x{1}, {2} mips (roughness m/(M-1)).",
        sweep.source_size, sweep.specular_size, sweep.mips
    );
    let _ = writeln!(md, "Backends: {}.\n", backends.iter().map(|b| b.describe()).collect::<Vec<_>>().join("; "));
    let _ = writeln!(
        md,
        "References (f64, independent of the code under test): adaptive Gauss-Kronrod quadrature for the BRDF table; exact sums over every texel of the source for the prefilter and the irradiance; the full reflectance integral (no split) for the shaded colour. Errors are absolute for the table and relative luminance otherwise. Times are wall-clock, uploads and readbacks included.\n"
    );
    let mut products: Vec<&str> = Vec::new();
    for r in rows {
        if !products.contains(&r.product.as_str()) {
            products.push(&r.product);
        }
    }
    for product in &products {
        let _ = writeln!(md, "\n## {product}\n\n| backend | setting | time (ms) | mean error | max error |\n|---|---|---:|---:|---:|");
        for r in rows.iter().filter(|r| r.product == *product) {
            let t = if r.time_ms.is_finite() { format!("{:.1}", r.time_ms) } else { "-".into() };
            let _ = writeln!(md, "| {} | {} | {} | {:.2e} | {:.2e} |", r.backend, r.setting, t, r.mean_error, r.max_error);
        }
    }
    let _ = writeln!(
        md,
        "\n## Best error per millisecond (smallest mean error x time)\n\n| product | backend | setting | time (ms) | mean error |\n|---|---|---|---:|---:|"
    );
    for r in best_per_ms(rows) {
        let _ = writeln!(md, "| {} | {} | {} | {:.1} | {:.2e} |", r.product, r.backend, r.setting, r.time_ms, r.mean_error);
    }
    files::write_atomic(&dir.join("report.md"), |w| std::io::Write::write_all(w, md.as_bytes()))?;

    // Plot: the sample or size sweeps, one curve per product and backend.
    let mut series = Vec::new();
    let mut products: Vec<&str> = rows
        .iter()
        .filter(|r| r.time_ms.is_finite() && !r.product.contains("bias sweep") && !r.product.contains("cube size"))
        .map(|r| r.product.as_str())
        .collect();
    products.dedup();
    products.sort();
    products.dedup();
    for (pi, p) in products.iter().enumerate() {
        for (bi, b) in backends.iter().enumerate() {
            let name = b.describe();
            let points: Vec<(f64, f64)> = rows.iter().filter(|r| r.product == *p && r.backend == name).map(|r| (r.time_ms, r.mean_error)).collect();
            if !points.is_empty() {
                let short = if name.starts_with("gpu") { "gpu" } else { "cpu" };
                series.push(Series { label: format!("{p} ({short})"), points, color: plot::palette(pi), dashed: bi > 0 });
            }
        }
    }
    let canvas = plot::log_log("ERROR AGAINST RUN TIME", "TIME (MS)", "MEAN ERROR", &series, 1100, 640);
    files::write_png(&dir.join("error_vs_time.png"), canvas.width, canvas.height, &canvas.rgb)?;
    Ok(())
}
