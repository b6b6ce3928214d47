//! The bake planner: from a scene, what to bake and why, what to leave out and why, at
//! which settings, and what it will cost.
//!
//! Rules (each a decision printed by `runner plan`):
//! - no material lit by the environment → nothing is baked (the sky needs only the source);
//! - no material with specular image-based light (specular `none`, or `ibl = false`) → no
//!   prefiltered cube and no BRDF table (unless the sky is shown blurred);
//! - only Phong/Blinn–Phong specular → no GGX BRDF table (it belongs to Cook–Torrance);
//! - metalness 1 everywhere → no irradiance (metals have no diffuse term);
//! - roughness used only within `[a, b]` → only the mips whose trilinear lookups serve
//!   `[a, b]` (the mips around `lod(a)` and `lod(b)` and those between), and those of the
//!   sky blur;
//! - the smallest roughness and the output resolution set the cube size: a texel need not
//!   be finer than a pixel, nor than half the narrowest lobe (`α = r²` radians), nor than
//!   the environment itself;
//! - SH9 is left out: the display reads the irradiance cube;
//! - with `[quality] max_error`, each product gets the cheapest measured setting whose mean
//!   error meets it ([`Calibration`], from `runner report`); for the prefilter that error is
//!   the end-to-end measure's: the share of the shaded colour's error the bake adds, in the
//!   roughness bands the scene reads (`accuracy`, part (a)).

use crate::bake::{Products, Settings};
use crate::scene::{MaterialSpec, Scene, SpecularArg};
use serde::Serialize;
use splitsum_shaders::cubemap::CubeLayout;
use splitsum_shaders::prefilter::RoughnessMapping;

/// Error of each product against its reference, per setting, and the cost rates of each
/// backend: what the planner chooses from. The built-in one is `runner report` on the two
/// vendored HDRIs with a 34 000 sun and without (the worse of the two), on lavapipe and
/// on 2 CPU cores, November 2026.
#[derive(Clone, Debug, Serialize)]
pub struct Calibration {
    /// Where the numbers come from.
    pub source: String,
    /// BRDF table: (samples, mean absolute error).
    pub lut: Vec<(u32, f64)>,
    /// The specular bake, end to end: (roughness at the middle of a band, [(samples at mip
    /// 1, mean relative error the bake adds to the shaded colour)]), from the report's
    /// `shaded colour r in [a, b): (a) bake` rows of the defaults at several sample counts.
    pub prefilter: Vec<(f32, Vec<(u32, f64)>)>,
    /// Irradiance convolution: (source face size, mean relative error).
    pub irradiance: Vec<(u32, f64)>,
    /// Nanoseconds per unit of work on (lavapipe, CPU): equirect supersample, prefilter
    /// sample, BRDF table sample, irradiance texel pair.
    pub ns: [(f64, f64); 4],
}

impl Default for Calibration {
    fn default() -> Self {
        Self {
            source: "built in: runner report on city.exr and courtyard.exr (the worse of the two), runner bench, lavapipe and 2 CPU cores".into(),
            lut: vec![(16, 1.98e-2), (64, 6.62e-3), (256, 2.56e-3), (1024, 8.86e-4), (4096, 2.93e-4)],
            // Bands [0.02, 0.05) … [0.75, 1] of `runner report` on city.exr and courtyard.exr
            // (the worse of the two), CPU backend.
            prefilter: vec![
                (0.035, vec![(16, 0.0618), (64, 0.0592), (256, 0.0586)]),
                (0.075, vec![(16, 0.357), (64, 0.359), (256, 0.357)]),
                (0.15, vec![(16, 0.0987), (64, 0.122), (256, 0.104)]),
                (0.275, vec![(16, 0.0998), (64, 0.0699), (256, 0.0596)]),
                (0.425, vec![(16, 0.0696), (64, 0.0527), (256, 0.0484)]),
                (0.625, vec![(16, 0.0411), (64, 0.0247), (256, 0.0245)]),
                (0.875, vec![(16, 0.0383), (64, 0.0353), (256, 0.0269)]),
            ],
            irradiance: vec![(4, 0.035), (8, 0.0181), (16, 0.0067), (32, 0.00168), (64, 0.00083)],
            // Rates from `runner bench` of the defaults on city.exr: 12.2 M prefilter samples in
            // 0.51 s / 0.82 s, 36 M table evaluations (quadrature) in 0.12 s / 0.33 s, 9.4 M
            // irradiance texel pairs in 0.077 s / 0.156 s.
            ns: [(139.0, 46.0), (41.5, 67.0), (3.3, 9.1), (8.2, 16.5)],
        }
    }
}

/// A `report.csv` row of the end-to-end measure's bake share for the defaults at some
/// sample count: product `shaded colour r in [a, b): (a) bake`, setting `defaults` or
/// `defaults, N samples`; gives the band's middle and `N`.
fn bake_share(product: &str, setting: &str) -> Option<(f32, u32)> {
    let band = product.strip_prefix("shaded colour r in [")?.strip_suffix(": (a) bake")?;
    let (a, rest) = band.split_once(", ")?;
    let b = rest.trim_end_matches([')', ']']);
    let (a, b): (f32, f32) = (a.parse().ok()?, b.parse().ok()?);
    let n = if setting == "defaults" { Settings::default().samples } else { setting.strip_prefix("defaults, ")?.strip_suffix(" samples")?.parse().ok()? };
    Some((0.5 * (a + b), n))
}

impl Calibration {
    /// Reads the error model from a `report.csv` of `runner report` (its first backend),
    /// keeping the built-in cost rates.
    pub fn from_report_csv(text: &str) -> Option<Self> {
        let mut c = Calibration { source: "report.csv".into(), lut: vec![], prefilter: vec![], irradiance: vec![], ..Default::default() };
        let mut backend: Option<String> = None;
        for line in text.lines().skip(1) {
            let f = crate::report::csv_fields(line);
            if f.len() < 7 {
                continue;
            }
            if backend.is_none() && f[3] != "NaN" {
                backend = Some(f[1].clone());
            }
            if Some(&f[1]) != backend.as_ref() {
                continue;
            }
            let err: f64 = f[4].parse().ok()?;
            let first_number = |s: &str| s.split(|ch: char| !ch.is_ascii_digit()).find(|t| !t.is_empty()).and_then(|t| t.parse::<u32>().ok());
            if f[0] == "brdf lut" {
                // The sampled table's rows (the quadrature's row has no sample count).
                if let Some(n) = first_number(&f[2]) {
                    c.lut.push((n, err));
                }
            } else if f[0] == "irradiance (convolution)" {
                c.irradiance.push((first_number(&f[2])?, err));
            } else if let Some((r, n)) = bake_share(&f[0], &f[2]) {
                match c.prefilter.iter_mut().find(|(x, _)| (*x - r).abs() < 1e-3) {
                    Some((_, v)) => {
                        v.push((n, err));
                        v.sort_by_key(|&(n, _)| n);
                    }
                    None => c.prefilter.push((r, vec![(n, err)])),
                }
            }
        }
        (!c.lut.is_empty() && !c.prefilter.is_empty() && !c.irradiance.is_empty()).then_some(c)
    }

    /// The bake's share of the shaded colour's error at `roughness` (the nearest band) with
    /// `samples` at mip 1.
    fn prefilter_error(&self, roughness: f32, samples: u32) -> f64 {
        // The measured roughness nearest to the one asked for.
        let table = &self.prefilter.iter().min_by(|a, b| (a.0 - roughness).abs().total_cmp(&(b.0 - roughness).abs())).expect("calibrated").1;
        interpolate(table, samples)
    }
}

/// Log–log interpolation of `(setting, error)` pairs at `x` (clamped to the table).
fn interpolate(table: &[(u32, f64)], x: u32) -> f64 {
    let x = x as f64;
    if x <= table[0].0 as f64 {
        return table[0].1;
    }
    for w in table.windows(2) {
        let (x0, y0, x1, y1) = (w[0].0 as f64, w[0].1, w[1].0 as f64, w[1].1);
        if x <= x1 {
            let t = (x.ln() - x0.ln()) / (x1.ln() - x0.ln());
            return (y0.ln() + t * (y1.ln() - y0.ln())).exp();
        }
    }
    table[table.len() - 1].1
}

/// One decision of the plan.
#[derive(Clone, Debug, Serialize)]
pub struct Decision {
    /// The product or setting.
    pub what: String,
    /// Baked (or chosen) rather than left out.
    pub kept: bool,
    /// Why.
    pub why: String,
}

/// Estimated cost.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct Cost {
    /// Seconds on lavapipe.
    pub gpu_seconds: f64,
    /// Seconds on 2 CPU cores.
    pub cpu_seconds: f64,
    /// Bytes of the data in memory (the environment as read, the products and their sums).
    pub bytes: u64,
}

impl Cost {
    /// Estimated peak resident memory of the process, in bytes: the data, plus the program
    /// itself (8 MiB) on the CPU; on lavapipe the data twice (host copies and device
    /// buffers, both in host memory) plus the driver (118 MiB). Measured with
    /// `/usr/bin/time` on `runner lut --size 16` (the baselines) and `runner bake` of
    /// courtyard.exr at its defaults: 57 MiB on the CPU, 227 MiB on lavapipe, against
    /// 8 + 55 and 118 + 2·55 estimated.
    pub fn peak_bytes(&self, gpu: bool) -> u64 {
        const MIB: u64 = 1 << 20;
        if gpu { 118 * MIB + 2 * self.bytes } else { 8 * MIB + self.bytes }
    }
}

/// What to bake.
#[derive(Clone, Debug, Serialize)]
pub struct Plan {
    /// Every setting.
    pub settings: Settings,
    /// Which products.
    pub products: Products,
    /// The specular mips to bake (the others stay empty: nothing reads them).
    pub levels: Vec<u32>,
    /// Why each product is kept or left out, and each setting chosen.
    pub decisions: Vec<Decision>,
    /// The plan's cost.
    pub cost: Cost,
    /// A full bake's cost at the same settings (every product, every mip).
    pub full_cost: Cost,
    /// The cost of `runner bake ENV` at its defaults (every product at 256²): what baking
    /// without a plan costs.
    pub default_cost: Cost,
}

/// Mips of a specular cube of face size `size`: the bake's own rule
/// ([`Settings::default_mips`]).
pub fn mip_count(size: u32) -> u32 {
    Settings::default_mips(size)
}

/// Plans the bake of `scene` over the loaded environment `env`.
pub fn plan_for(scene: &Scene, env: &crate::environment::Environment, cal: &Calibration) -> Plan {
    let width = match env {
        crate::environment::Environment::Equirect(e) => e.width,
        crate::environment::Environment::Cube(c) => 4 * c.layout.size,
    };
    plan(scene, native_face_size(env), width, cal)
}

/// The environment's own resolution as a cube face size (a quarter of an equirect's width,
/// as a power of two, at most `environment::NATIVE_FACE`).
pub fn native_face_size(env: &crate::environment::Environment) -> u32 {
    match env {
        crate::environment::Environment::Equirect(e) => (e.width / 4).max(8).next_power_of_two().min(crate::environment::NATIVE_FACE),
        crate::environment::Environment::Cube(c) => c.layout.size.min(crate::environment::NATIVE_FACE),
    }
}

/// Plans the bake of `scene` over an environment of face size `native` (see
/// [`native_face_size`]) and equirect width `width` (for the resampling cost).
pub fn plan(scene: &Scene, native: u32, width: u32, cal: &Calibration) -> Plan {
    let mut d: Vec<Decision> = Vec::new();
    let mut decide = |what: &str, kept: bool, why: String| d.push(Decision { what: what.into(), kept, why });
    let used = scene.used_materials();
    let lit: Vec<&MaterialSpec> = used.iter().copied().filter(|m| m.ibl).collect();
    let specular_ibl: Vec<&MaterialSpec> = lit.iter().copied().filter(|m| m.specular != SpecularArg::None).collect();
    let ggx: Vec<&MaterialSpec> = specular_ibl.iter().copied().filter(|m| m.specular == SpecularArg::CookTorrance).collect();
    let diffuse_ibl: Vec<&MaterialSpec> = lit.iter().copied().filter(|m| m.metallic.range().0 < 1.0).collect();
    let names = |v: &[&MaterialSpec]| v.iter().map(|m| m.name.as_str()).collect::<Vec<_>>().join(", ");

    // Cube size from the smallest roughness and the output resolution: the level that
    // roughness reads must resolve its lobe (or a pixel, whichever is wider).
    let r_min = specular_ibl.iter().map(|m| m.roughness.range().0).fold(1.0f32, f32::min);
    let pixel = (scene.camera.fov.to_radians() / scene.output.height as f32) as f64;
    let alpha = (r_min * r_min) as f64;
    let texel = if specular_ibl.is_empty() { pixel.max(0.25) } else { pixel.max(0.5 * alpha) };
    let defaults = Settings::default();
    let mapping: RoughnessMapping = defaults.mapping.into();
    let finest_read = |size: u32| -> u32 {
        let mips = mip_count(size);
        size >> (mapping.lod(r_min, mips).floor() as u32).min(mips - 1)
    };
    let mut wanted = 8u32;
    // A blurred sky reads mip `sky_blur` (fractional): the cube needs the mips above it.
    let blur_mips = if scene.sky_blur > 0.0 { scene.sky_blur.ceil() as u32 + 1 } else { 0 };
    while wanted < 4096 && (std::f64::consts::FRAC_PI_2 / (finest_read(wanted) as f64) > texel || mip_count(wanted) < blur_mips) {
        wanted *= 2;
    }
    let size = scene.quality.size.unwrap_or(wanted.min(native));
    let mips = mip_count(size);
    let mut settings = Settings {
        size,
        source_size: native.max(size),
        mips,
        irradiance_source: defaults.irradiance_source.min(native.max(size)),
        sh_source: defaults.sh_source.min(native.max(size)),
        ..defaults
    };
    if !specular_ibl.is_empty() {
        let why = if scene.quality.size.is_some() {
            "as [quality] size asks".to_string()
        } else {
            let level = (mapping.lod(r_min, mips).floor() as u32).min(mips - 1);
            format!(
                "the smallest roughness {r_min} reads mip {level} ({0}², texel {1:.4} rad), which must resolve half its lobe (α = {alpha:.4} rad) or a pixel of {2}×{3} at {4}° ({pixel:.4} rad); the environment has {native}²",
                size >> level,
                std::f64::consts::FRAC_PI_2 / (size >> level) as f64,
                scene.output.width,
                scene.output.height,
                scene.camera.fov,
            )
        };
        decide("cube size", true, format!("{size}×{size} × {mips} mips: {why}"));
    }

    // Quality: explicit settings, else the cheapest measured ones meeting max_error.
    let q = &scene.quality;
    let target = q.max_error;
    let roughness_of = |m: u32| mapping.roughness(m, mips);
    let lod_of = |r: f32| mapping.lod(r, mips);

    // Specular mips.
    // The mips that trilinear lookups at levels of detail `lo ..= hi` read.
    let mut read = std::collections::BTreeSet::new();
    let mut add_lods = |lo: f32, hi: f32| read.extend(lo.floor() as u32..=(hi.ceil() as u32).min(mips - 1));
    for m in &specular_ibl {
        let (a, b) = m.roughness.range();
        add_lods(lod_of(a), lod_of(b));
    }
    if scene.sky_blur > 0.0 {
        let b = scene.sky_blur.min((mips - 1) as f32);
        add_lods(b, b);
    }
    let levels: Vec<u32> = read.into_iter().collect();

    let specular = !levels.is_empty();
    if lit.is_empty() {
        decide("everything", false, "no material is lit by the environment (all have ibl = false, or no objects): the sky needs only the source cube".into());
    }
    if specular {
        let why = if specular_ibl.is_empty() {
            format!("only for the sky's blur {}", scene.sky_blur)
        } else {
            let lo = specular_ibl.iter().map(|m| m.roughness.range().0).fold(1.0f32, f32::min);
            let hi = specular_ibl.iter().map(|m| m.roughness.range().1).fold(0.0f32, f32::max);
            format!("specular image-based light of {} (roughness {lo}–{hi})", names(&specular_ibl))
        };
        decide("prefiltered specular cube", true, why);
        let all: Vec<u32> = (0..mips).collect();
        let skipped: Vec<String> = all.iter().filter(|l| !levels.contains(l)).map(|&l| format!("{l} (r={:.2})", roughness_of(l))).collect();
        let kept: Vec<String> = levels.iter().map(|&l| format!("{l} (r={:.2})", roughness_of(l))).collect();
        decide("specular mips", true, format!("baked: {}", kept.join(", ")));
        if !skipped.is_empty() {
            decide("specular mips", false, format!("{}: no material roughness or sky blur reads them", skipped.join(", ")));
        }
    } else if !lit.is_empty() {
        decide("prefiltered specular cube", false, "no material has specular image-based light (specular = none or ibl = false) and the sky is sharp".into());
    }
    let lut = !ggx.is_empty();
    if lut {
        decide("BRDF table", true, format!("Cook–Torrance image-based light of {}", names(&ggx)));
    } else if !specular_ibl.is_empty() {
        decide("BRDF table", false, "only Phong/Blinn–Phong specular: the GGX table does not apply to them".into());
    } else if !lit.is_empty() {
        decide("BRDF table", false, "no specular image-based light".into());
    }
    let irradiance = !diffuse_ibl.is_empty();
    if irradiance {
        decide("irradiance cube", true, format!("diffuse image-based light of {}", names(&diffuse_ibl)));
    } else if !lit.is_empty() {
        decide("irradiance cube", false, "every lit material is metal (metallic = 1): no diffuse term".into());
    }
    if !lit.is_empty() {
        decide("SH9", false, "the display reads the irradiance cube; SH9 is for `runner bake ENV`".into());
    }

    // Samples, bias, table, irradiance source.
    settings.lod_bias = q.lod_bias.unwrap_or(settings.lod_bias);
    // The roughness the scene's specular materials read: the ends of each range and every
    // calibrated band's middle inside it (a blurred sky reads its mip's roughness).
    let mut needed_r: Vec<f32> = Vec::new();
    for m in &specular_ibl {
        let (a, b) = m.roughness.range();
        needed_r.extend([a, b].into_iter().chain(cal.prefilter.iter().map(|p| p.0).filter(|&r| r >= a && r <= b)).filter(|&r| r > 0.0));
    }
    if needed_r.is_empty() {
        needed_r = levels.iter().map(|&l| roughness_of(l)).filter(|&r| r > 0.0).collect();
    }
    settings.samples = match (q.samples, target) {
        (Some(n), _) => n,
        (None, Some(e)) if specular => {
            let table: Vec<(u32, f64)> =
                cal.prefilter[0].1.iter().map(|&(n, _)| (n, needed_r.iter().map(|&r| cal.prefilter_error(r, n)).fold(0.0, f64::max))).collect();
            let (n, why) = cheapest(&table, e, |n| n.to_string());
            decide("prefilter samples", true, why);
            n
        }
        _ => settings.samples,
    };
    // The table: by quadrature (within 1e-5 of the reference, which meets any target)
    // unless the scene asks for a sample count, which means the sampled (seed) table.
    if let Some(n) = q.lut_samples {
        settings.lut_samples = n;
        settings.lut_method = crate::bake::TableMethod::Sampled;
        settings.lut_masking = settings.lut_method.default_masking();
    } else if let (Some(e), true) = (target, lut) {
        decide("BRDF table method", true, format!("quadrature: max error 1e-5 at every texel ≤ {e}"));
    }
    settings.lut_size = q.lut_size.unwrap_or(settings.lut_size);
    settings.irradiance_source = match (q.irradiance_source, target) {
        (Some(s), _) => s,
        (None, Some(e)) if irradiance => {
            // Only the levels the source cube has.
            let sources: Vec<(u32, f64)> = cal.irradiance.iter().copied().filter(|&(s, _)| s <= settings.source_size).collect();
            let (s, why) = cheapest(&sources, e, |s| format!("{s}×{s} source level"));
            decide("irradiance source", true, why);
            s
        }
        _ => settings.irradiance_source,
    };

    let products = Products { specular, irradiance, sh9: false, lut };
    let cost = estimate(&settings, products, &levels, width, cal);
    let all_levels: Vec<u32> = (0..mips).collect();
    let full_cost = estimate(&settings, Products::ALL, &all_levels, width, cal);
    let default_settings = Settings::default();
    let default_levels: Vec<u32> = (0..default_settings.mips).collect();
    let default_cost = estimate(&default_settings, Products::ALL, &default_levels, width, cal);
    Plan { settings, products, levels, decisions: d, cost, full_cost, default_cost }
}

/// The first (cheapest) setting of `table` whose error meets `target`, else the last (the
/// most accurate measured), with the reason in words (`show` names a setting).
fn cheapest(table: &[(u32, f64)], target: f64, show: impl Fn(u32) -> String) -> (u32, String) {
    match table.iter().find(|(_, e)| *e <= target) {
        Some(&(s, e)) => (s, format!("{}: the cheapest measured, mean error {e:.2e} ≤ {target}", show(s))),
        None => {
            let &(s, e) = table.last().expect("calibrated");
            (s, format!("{}: the most accurate measured; its mean error {e:.2e} is still above {target}", show(s)))
        }
    }
}

/// The steps of a bake the cost model knows, in the order they run, with the index of
/// their rate in [`Calibration::ns`].
pub const STEPS: [&str; 4] = ["source cube", "specular", "brdf lut", "irradiance"];

/// Units of work of each of [`STEPS`] (equirect supersamples, prefilter samples, BRDF
/// table evaluations, irradiance texel pairs) and the bytes of the products in memory.
fn work(s: &Settings, products: Products, levels: &[u32], width: u32) -> ([f64; 4], u64) {
    let mut work = [0.0f64; 4];
    let mut bytes = 0u64;
    let n = splitsum_shaders::equirect::supersampling(s.source_size, width.max(1), s.supersample_density) as f64;
    let source = CubeLayout::new(s.source_size, CubeLayout::full_chain(s.source_size));
    work[0] = 6.0 * (s.source_size as f64).powi(2) * n * n;
    bytes += source.texel_count() as u64 * 16;
    if products.specular {
        let out = s.specular_layout();
        let mapping: RoughnessMapping = s.mapping.into();
        let samples = s.samples_per_mip();
        for &l in levels {
            let texels = 6.0 * (out.level_size(l) as f64).powi(2);
            let r = mapping.roughness(l, s.mips);
            if r > 0.0 {
                let n = samples[l as usize];
                // An exact sum's 6t² terms cost about an eighth of a sample each.
                let per_texel = if s.exact_sums && splitsum_shaders::prefilter::prefers_exact(r, n, s.source_size) {
                    6.0 * (splitsum_shaders::prefilter::exact_source_size(r, s.source_size) as f64).powi(2) / 8.0
                } else {
                    n as f64
                };
                work[1] += texels * per_texel;
            }
            // The sums (3 × RGBA per texel) and the result.
            bytes += texels as u64 * 64;
        }
    }
    if products.lut {
        let per_texel = match s.lut_method {
            crate::bake::TableMethod::Quadrature => splitsum_shaders::lut::QUADRATURE_MEAN_EVALUATIONS,
            crate::bake::TableMethod::Sampled => s.lut_samples,
        };
        work[2] = (s.lut_size as f64).powi(2) * per_texel as f64;
        bytes += (s.lut_size as u64).pow(2) * 24;
    }
    if products.irradiance {
        work[3] = 6.0 * (s.irradiance_size as f64).powi(2) * 6.0 * (s.irradiance_source as f64).powi(2);
        bytes += 6 * (s.irradiance_size as u64).pow(2) * 64;
    }
    (work, bytes)
}

/// Estimated seconds of each of [`STEPS`] that `products` run, on lavapipe (`gpu`) or on
/// 2 CPU cores.
pub fn step_seconds(s: &Settings, products: Products, levels: &[u32], width: u32, cal: &Calibration, gpu: bool) -> [f64; 4] {
    let (work, _) = work(s, products, levels, width);
    std::array::from_fn(|k| work[k] * if gpu { cal.ns[k].0 } else { cal.ns[k].1 } * 1e-9)
}

/// Estimated time and memory of baking `products` (and `levels` of the specular cube)
/// from an equirect `width` wide: the products and their sums, plus the environment as
/// read (RGBA f32, with its row pyramid: `12·width²` bytes).
pub fn estimate(s: &Settings, products: Products, levels: &[u32], width: u32, cal: &Calibration) -> Cost {
    let (_, bytes) = work(s, products, levels, width);
    let gpu = step_seconds(s, products, levels, width, cal, true).iter().sum();
    let cpu = step_seconds(s, products, levels, width, cal, false).iter().sum();
    Cost { gpu_seconds: gpu, cpu_seconds: cpu, bytes: bytes + 12 * (width as u64).pow(2) }
}

/// The plan as text, for `runner plan`.
pub fn describe(plan: &Plan, scene: &str, environment: &str) -> String {
    use std::fmt::Write as _;
    let mut out = String::new();
    let _ = writeln!(out, "plan for {scene} (environment: {environment})");
    for d in plan.decisions.iter().filter(|d| d.kept) {
        let _ = writeln!(out, "  bake   {:<26} {}", d.what, d.why);
    }
    for d in plan.decisions.iter().filter(|d| !d.kept) {
        let _ = writeln!(out, "  skip   {:<26} {}", d.what, d.why);
    }
    let s = &plan.settings;
    let p = plan.products;
    let mut kept = vec![format!("source {}²", s.source_size)];
    if p.specular {
        kept.push(format!("specular {}² × {} mips ({:?}), {} samples, bias {}", s.size, s.mips, s.mapping, s.samples, s.lod_bias));
    }
    if p.lut {
        kept.push(format!("table {}", s.table_description()));
    }
    if p.irradiance {
        kept.push(format!("irradiance {}² from {}²", s.irradiance_size, s.irradiance_source));
    }
    let _ = writeln!(out, "  settings: {}", kept.join("; "));
    let mib = |b: u64| b as f64 / 1048576.0;
    let line = |c: Cost| {
        format!(
            "{:.2} s and {:.0} MiB on lavapipe, {:.2} s and {:.0} MiB on 2 CPU cores",
            c.gpu_seconds,
            mib(c.peak_bytes(true)),
            c.cpu_seconds,
            mib(c.peak_bytes(false))
        )
    };
    let _ = writeln!(out, "  estimate: {}", line(plan.cost));
    let _ = writeln!(out, "            every product and mip at these settings: {}", line(plan.full_cost));
    let _ = writeln!(out, "            `runner bake ENV` at its defaults:        {}", line(plan.default_cost));
    out
}
