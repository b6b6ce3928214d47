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
//! - with `[quality] max_seconds`, the samples and the irradiance source with the lowest
//!   predicted error over the roughness the scene reads whose estimate fits the budget;
//! - with `[quality] max_error`, each product gets the cheapest measured setting whose mean
//!   error meets it ([`Calibration`], from `runner report`); for the prefilter that error is
//!   the end-to-end measure's: the share of the shaded colour's error the bake adds, in the
//!   roughness bands the scene reads (`accuracy`, part (a)).

use crate::scene::{MaterialSpec, Scene};
use serde::Serialize;
use splitsum::cost::{Calibration, Cost};
use splitsum::estimate::built_in_cost;
use splitsum::error::Result;
use splitsum::settings::{InputShape, Job, Products, Settings, TableMethod};
use splitsum_shaders::shade::SpecularModel;

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

/// What to bake.
#[derive(Clone, Debug, Serialize)]
pub struct Plan {
    /// The bake: every setting resolved, the products and the specular mips it keeps (the
    /// others stay empty: nothing reads them).
    pub job: Job,
    /// Why each product is kept or left out, and each setting chosen.
    pub decisions: Vec<Decision>,
    /// The plan's cost.
    pub cost: Cost,
    /// A full bake's cost at the same settings (every product the display reads, every
    /// mip).
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
pub fn plan_for(scene: &Scene, env: &splitsum::environment::Environment, cal: &Calibration) -> Result<Plan> {
    plan(scene, env.native_face_size(), InputShape::of(env), cal)
}

/// Plans the bake of `scene` over an environment of face size `native` (see
/// `Environment::native_face_size`) and shape `shape` (for the resampling cost).
pub fn plan(scene: &Scene, native: u32, shape: InputShape, cal: &Calibration) -> Result<Plan> {
    let mut d: Vec<Decision> = Vec::new();
    let mut decide = |what: &str, kept: bool, why: String| d.push(Decision { what: what.into(), kept, why });
    let used = scene.used_materials();
    let lit: Vec<&MaterialSpec> = used.iter().copied().filter(|m| m.ibl).collect();
    let specular_ibl: Vec<&MaterialSpec> = lit.iter().copied().filter(|m| m.specular != SpecularModel::None).collect();
    let ggx: Vec<&MaterialSpec> = specular_ibl.iter().copied().filter(|m| m.specular == SpecularModel::CookTorrance).collect();
    let diffuse_ibl: Vec<&MaterialSpec> = lit.iter().copied().filter(|m| m.metallic.range().0 < 1.0).collect();
    let sheen_ibl: Vec<&MaterialSpec> = lit.iter().copied().filter(|m| m.has_sheen()).collect();
    let names = |v: &[&MaterialSpec]| v.iter().map(|m| m.name.as_str()).collect::<Vec<_>>().join(", ");

    // Cube size from the smallest roughness and the output resolution: the level that
    // roughness reads must resolve its lobe (or a pixel, whichever is wider).
    let r_min = specular_ibl.iter().map(|m| m.roughness.range().0).fold(1.0f32, f32::min);
    let pixel = (scene.camera.fov.to_radians() / scene.output.height as f32) as f64;
    let alpha = (r_min * r_min) as f64;
    let texel = if specular_ibl.is_empty() { pixel.max(0.25) } else { pixel.max(0.5 * alpha) };
    let defaults = Settings::default();
    let mapping = defaults.resolve(shape, Products::ALL)?.mapping;
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
    let source_size = native.max(size);
    let mut settings = Settings { size, source_size: Some(source_size), ..defaults };
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
    // Sheen: the Charlie cube's mips the sheen roughness reads (linear: lod = r·(M − 1), as
    // the glTF Sample Viewer reads it) and the sheen tables, only for materials with sheen.
    // A lit glTF model whose file has KHR_materials_sheen reads every sheen mip (its sheen
    // roughness comes from the file, factors and textures).
    let model_sheen = match scene.model_path() {
        Some(path) if lit.iter().any(|m| scene.objects.iter().any(|o| matches!(o, crate::scene::ObjectSpec::Gltf { material, .. } if *material == m.name))) => {
            crate::model::uses_sheen(&path)?.then_some(path)
        }
        _ => None,
    };
    let sheen_levels: Vec<u32> = {
        let mut read = std::collections::BTreeSet::new();
        let top = (mips - 1) as f32;
        let ranges = sheen_ibl.iter().map(|m| m.sheen_roughness.range()).chain(model_sheen.iter().map(|_| (0.0, 1.0)));
        for (a, b) in ranges {
            read.extend(((a.clamp(0.0, 1.0) * top).floor() as u32)..=((b.clamp(0.0, 1.0) * top).ceil() as u32).min(mips - 1));
        }
        read.into_iter().collect()
    };
    let sheen = !sheen_levels.is_empty();
    if sheen {
        let kept: Vec<String> = sheen_levels.iter().map(|&l| format!("{l} (r={:.2})", splitsum::settings::SHEEN_MAPPING.roughness(l, mips))).collect();
        let whose: Vec<String> = sheen_ibl.iter().map(|m| m.name.clone()).chain(model_sheen.iter().map(|p| format!("{} (KHR_materials_sheen)", p.display()))).collect();
        decide("sheen cube and tables", true, format!("sheen of {}; mips {}", whose.join(", "), kept.join(", ")));
    } else if !lit.is_empty() {
        decide("sheen cube and tables", false, "no lit material has sheen (sheen_color is black, and no model uses KHR_materials_sheen)".into());
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
    // A time budget: the lowest predicted error over the roughness the scene reads that fits
    // (estimated on lavapipe's built-in rates, for the levels the plan keeps).
    if let Some(budget) = q.max_seconds {
        let products = Products { specular, irradiance, sh9: false, lut, sheen };
        let seconds = |job: &splitsum::Job| job.clone().with_levels(levels.clone()).map_or(f64::INFINITY, |j| splitsum::estimate::step_seconds(&j, true).total());
        let (chosen, error, estimate) = splitsum::cost::for_budget_by(&settings, shape, products, budget, cal, Some(&needed_r), seconds)?;
        let fits = if estimate <= budget { "fits" } else { "is the cheapest measured, over" };
        decide(
            "time budget",
            true,
            format!("{} samples, irradiance from {}²: predicted error {error:.2e}, estimated {estimate:.2} s on lavapipe ({fits} {budget} s)", chosen.samples, chosen.irradiance_source.unwrap_or_default()),
        );
        settings.samples = chosen.samples;
        settings.irradiance_source = chosen.irradiance_source;
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
        settings.lut_method = TableMethod::Sampled;
    } else if let (Some(e), true) = (target, lut) {
        decide("BRDF table method", true, format!("quadrature: max error 1e-5 at every texel ≤ {e}"));
    }
    settings.lut_size = q.lut_size.unwrap_or(settings.lut_size);
    settings.irradiance_source = match (q.irradiance_source, target) {
        (Some(s), _) => Some(s),
        (None, Some(e)) if irradiance => {
            // Only the levels the source cube has.
            let sources: Vec<(u32, f64)> = cal.irradiance.iter().copied().filter(|&(s, _)| s <= source_size).collect();
            let (s, why) = cheapest(&sources, e, |s| format!("{s}×{s} source level"));
            decide("irradiance source", true, why);
            Some(s)
        }
        _ => settings.irradiance_source,
    };

    let products = Products { specular, irradiance, sh9: false, lut, sheen };
    let job = settings.resolve(shape, products)?.with_levels(levels)?.with_sheen_levels(sheen_levels)?;
    let cost = built_in_cost(&job);
    let full_cost = built_in_cost(&settings.resolve(shape, Products::DISPLAY)?);
    let default_cost = built_in_cost(&Settings::default().resolve(shape, Products::STANDARD)?);
    Ok(Plan { job, decisions: d, cost, full_cost, default_cost })
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
    let s = &plan.job;
    let p = s.products;
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
    let _ = writeln!(out, "            every displayed product and mip, same settings: {}", line(plan.full_cost));
    let _ = writeln!(out, "            `runner bake ENV` at its defaults:        {}", line(plan.default_cost));
    out
}
