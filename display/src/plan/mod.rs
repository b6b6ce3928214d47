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
use splitsum::error::Result;
use splitsum::estimate::built_in_cost;
use splitsum::settings::{InputShape, Job, Product, Products, Settings, TableMethod};
use splitsum_shaders::prefilter::RoughnessMapping;
use splitsum_shaders::shade::SpecularModel;

mod decision;
pub use decision::{Cause, Decision, Mip, Setting, Subject};

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
/// `Environment::native_face_size`) and shape `shape` (for the resampling cost): one
/// function per decision below, each stating its [`Decision`]s.
pub fn plan(scene: &Scene, native: u32, shape: InputShape, cal: &Calibration) -> Result<Plan> {
    let mut d: Vec<Decision> = Vec::new();
    let uses = Uses::of(scene);
    let defaults = Settings::default();
    let mapping = defaults.resolve(shape, Products::ALL)?.mapping;
    let size = cube_size(scene, &uses, native, mapping, &mut d);
    let mips = mip_count(size);
    let source_size = native.max(size);
    let mut settings = Settings { size, source_size: Some(source_size), ..defaults };
    let roughness_of = |m: u32| mapping.roughness(m, mips);

    if uses.lit.is_empty() {
        d.push(Decision { subject: Subject::Everything, kept: false, cause: Cause::NothingLit });
    }
    let levels = specular_mips(scene, &uses, mapping, mips, &mut d);
    let specular = !levels.is_empty();
    let lut = brdf_table(&uses, &mut d);
    let irradiance = irradiance_cube(&uses, &mut d);
    let sheen_levels = sheen(scene, &uses, mips, &mut d)?;
    let sheen = !sheen_levels.is_empty();
    if !uses.lit.is_empty() {
        d.push(Decision { subject: Subject::Sh9, kept: false, cause: Cause::Sh9Unread });
    }
    let products =
        Products::of(&[]).with(Product::Specular, specular).with(Product::Irradiance, irradiance).with(Product::BrdfTable, lut).with(Product::Sheen, sheen);

    // Samples, bias, table, irradiance source.
    let q = &scene.quality;
    settings.lod_bias = q.lod_bias.unwrap_or(settings.lod_bias);
    // The roughness the scene's specular materials read: the ends of each range and every
    // calibrated band's middle inside it (a blurred sky reads its mip's roughness).
    let mut needed_r: Vec<f32> = Vec::new();
    for m in &uses.specular {
        let (a, b) = m.roughness.range();
        needed_r.extend([a, b].into_iter().chain(cal.prefilter.iter().map(|p| p.0).filter(|&r| r >= a && r <= b)).filter(|&r| r > 0.0));
    }
    if needed_r.is_empty() {
        needed_r = levels.iter().map(|&l| roughness_of(l)).filter(|&r| r > 0.0).collect();
    }
    if let Some(budget) = q.max_seconds {
        time_budget(&mut settings, shape, products, budget, cal, &needed_r, &levels, &mut d)?;
    }
    settings.samples = prefilter_samples(q, specular, cal, &needed_r, &mut d).unwrap_or(settings.samples);
    table_method(&mut settings, q, lut, &mut d);
    settings.irradiance_source = match q.irradiance_source {
        Some(s) => Some(s),
        None => irradiance_source(q, irradiance, cal, source_size, &mut d).or(settings.irradiance_source),
    };

    let job = settings.resolve(shape, products)?.with_levels(Product::Specular, levels)?.with_levels(Product::Sheen, sheen_levels)?;
    let cost = built_in_cost(&job);
    let full_cost = built_in_cost(&settings.resolve(shape, Products::DISPLAY)?);
    let default_cost = built_in_cost(&Settings::default().resolve(shape, Products::STANDARD)?);
    Ok(Plan { job, decisions: d, cost, full_cost, default_cost })
}

/// The scene's materials by what they read of the environment.
struct Uses<'a> {
    /// Lit by the environment (`ibl = true`).
    lit: Vec<&'a MaterialSpec>,
    /// With specular image-based light.
    specular: Vec<&'a MaterialSpec>,
    /// With Cook–Torrance (GGX) specular, which reads the BRDF table.
    ggx: Vec<&'a MaterialSpec>,
    /// Not wholly metal: with a diffuse term.
    diffuse: Vec<&'a MaterialSpec>,
    /// With sheen.
    sheen: Vec<&'a MaterialSpec>,
}

impl<'a> Uses<'a> {
    fn of(scene: &'a Scene) -> Self {
        let lit: Vec<&MaterialSpec> = scene.used_materials().into_iter().filter(|m| m.ibl).collect();
        let specular: Vec<&MaterialSpec> = lit.iter().copied().filter(|m| m.specular != SpecularModel::None).collect();
        let ggx = specular.iter().copied().filter(|m| m.specular == SpecularModel::CookTorrance).collect();
        let diffuse = lit.iter().copied().filter(|m| m.metallic.range().0 < 1.0).collect();
        let sheen = lit.iter().copied().filter(|m| m.has_sheen()).collect();
        Uses { lit, specular, ggx, diffuse, sheen }
    }
}

fn names(v: &[&MaterialSpec]) -> Vec<String> {
    v.iter().map(|m| m.name.clone()).collect()
}

/// The cube size from the smallest roughness and the output resolution: the level that
/// roughness reads must resolve its lobe (or a pixel, whichever is wider).
fn cube_size(scene: &Scene, uses: &Uses<'_>, native: u32, mapping: RoughnessMapping, d: &mut Vec<Decision>) -> u32 {
    let r_min = uses.specular.iter().map(|m| m.roughness.range().0).fold(1.0f32, f32::min);
    let pixel = (scene.camera.fov.to_radians() / scene.output.height as f32) as f64;
    let alpha = (r_min * r_min) as f64;
    let texel = if uses.specular.is_empty() { pixel.max(0.25) } else { pixel.max(0.5 * alpha) };
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
    if !uses.specular.is_empty() {
        let cause = if scene.quality.size.is_some() {
            Cause::SizeAsked { size, mips }
        } else {
            let level = (mapping.lod(r_min, mips).floor() as u32).min(mips - 1);
            let output = (scene.output.width, scene.output.height, scene.camera.fov, pixel);
            Cause::SizeResolves { size, mips, roughness: r_min, level, level_size: size >> level, alpha, output, native }
        };
        d.push(Decision { subject: Subject::CubeSize, kept: true, cause });
    }
    size
}

/// The specular mips the scene reads: those trilinear lookups at the materials' roughness
/// ranges and the sky's blur touch.
fn specular_mips(scene: &Scene, uses: &Uses<'_>, mapping: RoughnessMapping, mips: u32, d: &mut Vec<Decision>) -> Vec<u32> {
    let lod_of = |r: f32| mapping.lod(r, mips);
    let roughness_of = |m: u32| mapping.roughness(m, mips);
    let mut read = std::collections::BTreeSet::new();
    let mut add_lods = |lo: f32, hi: f32| read.extend(lo.floor() as u32..=(hi.ceil() as u32).min(mips - 1));
    for m in &uses.specular {
        let (a, b) = m.roughness.range();
        add_lods(lod_of(a), lod_of(b));
    }
    if scene.sky_blur > 0.0 {
        let b = scene.sky_blur.min((mips - 1) as f32);
        add_lods(b, b);
    }
    let levels: Vec<u32> = read.into_iter().collect();
    if !levels.is_empty() {
        let cause = if uses.specular.is_empty() {
            Cause::SkyBlur(scene.sky_blur)
        } else {
            let lo = uses.specular.iter().map(|m| m.roughness.range().0).fold(1.0f32, f32::min);
            let hi = uses.specular.iter().map(|m| m.roughness.range().1).fold(0.0f32, f32::max);
            Cause::SpecularOf { materials: names(&uses.specular), roughness: (lo, hi) }
        };
        d.push(Decision { subject: Subject::SpecularCube, kept: true, cause });
        let with_r = |l: &u32| (*l, roughness_of(*l));
        let skipped: Vec<Mip> = (0..mips).filter(|l| !levels.contains(l)).map(|l| with_r(&l)).collect();
        d.push(Decision { subject: Subject::SpecularMips, kept: true, cause: Cause::MipsRead(levels.iter().map(with_r).collect()) });
        if !skipped.is_empty() {
            d.push(Decision { subject: Subject::SpecularMips, kept: false, cause: Cause::MipsUnread(skipped) });
        }
    } else if !uses.lit.is_empty() {
        d.push(Decision { subject: Subject::SpecularCube, kept: false, cause: Cause::NoSpecularLight });
    }
    levels
}

/// The BRDF table: for Cook–Torrance image-based light only.
fn brdf_table(uses: &Uses<'_>, d: &mut Vec<Decision>) -> bool {
    let cause = if !uses.ggx.is_empty() {
        Cause::CookTorranceOf(names(&uses.ggx))
    } else if !uses.specular.is_empty() {
        Cause::OnlyPhong
    } else if !uses.lit.is_empty() {
        Cause::NoSpecularTable
    } else {
        return false;
    };
    let kept = !uses.ggx.is_empty();
    d.push(Decision { subject: Subject::BrdfTable, kept, cause });
    kept
}

/// The irradiance cube: for materials with a diffuse term.
fn irradiance_cube(uses: &Uses<'_>, d: &mut Vec<Decision>) -> bool {
    let kept = !uses.diffuse.is_empty();
    if kept {
        d.push(Decision { subject: Subject::IrradianceCube, kept, cause: Cause::DiffuseOf(names(&uses.diffuse)) });
    } else if !uses.lit.is_empty() {
        d.push(Decision { subject: Subject::IrradianceCube, kept, cause: Cause::AllMetal });
    }
    kept
}

/// Sheen: the Charlie cube's mips the sheen roughness reads (linear: lod = r·(M − 1), as
/// the glTF Sample Viewer reads it) and the sheen tables, only for materials with sheen. A
/// lit glTF model whose file has `KHR_materials_sheen` reads every sheen mip (its sheen
/// roughness comes from the file, factors and textures).
fn sheen(scene: &Scene, uses: &Uses<'_>, mips: u32, d: &mut Vec<Decision>) -> Result<Vec<u32>> {
    let model_sheen = match scene.model_path() {
        Some(path)
            if uses.lit.iter().any(|m| scene.objects.iter().any(|o| matches!(o, crate::scene::ObjectSpec::Gltf { material, .. } if *material == m.name))) =>
        {
            crate::model::uses_sheen(&path)?.then_some(path)
        }
        _ => None,
    };
    let mut read = std::collections::BTreeSet::new();
    let top = (mips - 1) as f32;
    let ranges = uses.sheen.iter().map(|m| m.sheen_roughness.range()).chain(model_sheen.iter().map(|_| (0.0, 1.0)));
    for (a, b) in ranges {
        read.extend(((a.clamp(0.0, 1.0) * top).floor() as u32)..=((b.clamp(0.0, 1.0) * top).ceil() as u32).min(mips - 1));
    }
    let levels: Vec<u32> = read.into_iter().collect();
    if !levels.is_empty() {
        let mips_read = levels.iter().map(|&l| (l, Product::Sheen.mapping(RoughnessMapping::Linear).roughness(l, mips))).collect();
        let whose = names(&uses.sheen).into_iter().chain(model_sheen.iter().map(|p| format!("{} (KHR_materials_sheen)", p.display()))).collect();
        d.push(Decision { subject: Subject::Sheen, kept: true, cause: Cause::SheenOf { whose, mips: mips_read } });
    } else if !uses.lit.is_empty() {
        d.push(Decision { subject: Subject::Sheen, kept: false, cause: Cause::NoSheen });
    }
    Ok(levels)
}

/// A time budget: the lowest predicted error over the roughness the scene reads that fits
/// (estimated on lavapipe's built-in rates, for the levels the plan keeps).
fn time_budget(
    settings: &mut Settings,
    shape: InputShape,
    products: Products,
    budget: f64,
    cal: &Calibration,
    needed_r: &[f32],
    levels: &[u32],
    d: &mut Vec<Decision>,
) -> Result<()> {
    let seconds = |job: &splitsum::Job| {
        job.clone().with_levels(Product::Specular, levels.to_vec()).map_or(f64::INFINITY, |j| splitsum::estimate::step_seconds(&j, true).total())
    };
    let (chosen, error, estimate) = splitsum::cost::for_budget_by(settings, shape, products, budget, cal, Some(needed_r), seconds)?;
    let cause = Cause::Budget { samples: chosen.samples, irradiance_source: chosen.irradiance_source.unwrap_or_default(), error, estimate, budget };
    d.push(Decision { subject: Subject::TimeBudget, kept: true, cause });
    settings.samples = chosen.samples;
    settings.irradiance_source = chosen.irradiance_source;
    Ok(())
}

/// The prefilter's samples: as `[quality] samples` says, else the cheapest measured count
/// whose error over the roughness the scene reads meets `max_error`.
fn prefilter_samples(q: &crate::scene::QualitySpec, specular: bool, cal: &Calibration, needed_r: &[f32], d: &mut Vec<Decision>) -> Option<u32> {
    match (q.samples, q.max_error) {
        (Some(n), _) => Some(n),
        (None, Some(e)) if specular => {
            let table: Vec<(u32, f64)> =
                cal.prefilter[0].1.iter().map(|&(n, _)| (n, needed_r.iter().map(|&r| cal.prefilter_error(r, n)).fold(0.0, f64::max))).collect();
            let (n, cause) = cheapest(&table, e, Setting::Samples);
            d.push(Decision { subject: Subject::PrefilterSamples, kept: true, cause });
            Some(n)
        }
        _ => None,
    }
}

/// The table: by quadrature (within 1e-5 of the reference, which meets any target) unless
/// the scene asks for a sample count, which means the sampled (seed) table.
fn table_method(settings: &mut Settings, q: &crate::scene::QualitySpec, lut: bool, d: &mut Vec<Decision>) {
    if let Some(n) = q.lut_samples {
        settings.lut_samples = n;
        settings.lut_method = TableMethod::Sampled;
    } else if let (Some(target), true) = (q.max_error, lut) {
        d.push(Decision { subject: Subject::TableMethod, kept: true, cause: Cause::Quadrature { target } });
    }
    settings.lut_size = q.lut_size.unwrap_or(settings.lut_size);
}

/// The irradiance source for `max_error`: the cheapest measured level the source cube has.
fn irradiance_source(q: &crate::scene::QualitySpec, irradiance: bool, cal: &Calibration, source_size: u32, d: &mut Vec<Decision>) -> Option<u32> {
    let e = q.max_error.filter(|_| irradiance)?;
    let sources: Vec<(u32, f64)> = cal.irradiance.iter().copied().filter(|&(s, _)| s <= source_size).collect();
    let (s, cause) = cheapest(&sources, e, Setting::SourceLevel);
    d.push(Decision { subject: Subject::IrradianceSource, kept: true, cause });
    Some(s)
}

/// The first (cheapest) setting of `table` whose error meets `target`, else the last (the
/// most accurate measured), with why.
fn cheapest(table: &[(u32, f64)], target: f64, setting: impl Fn(u32) -> Setting) -> (u32, Cause) {
    match table.iter().find(|(_, e)| *e <= target) {
        Some(&(s, error)) => (s, Cause::Cheapest { setting: setting(s), error, target }),
        None => {
            let &(s, error) = table.last().expect("calibrated");
            (s, Cause::MostAccurate { setting: setting(s), error, target })
        }
    }
}

/// The plan as text, for `runner plan`.
pub fn describe(plan: &Plan, scene: &str, environment: &str) -> String {
    use std::fmt::Write as _;
    let mut out = String::new();
    let _ = writeln!(out, "plan for {scene} (environment: {environment})");
    for d in plan.decisions.iter().filter(|d| d.kept) {
        let _ = writeln!(out, "  bake   {:<26} {}", d.subject.name(), d.cause);
    }
    for d in plan.decisions.iter().filter(|d| !d.kept) {
        let _ = writeln!(out, "  skip   {:<26} {}", d.subject.name(), d.cause);
    }
    let s = &plan.job;
    let p = s.products;
    let mut kept = vec![format!("source {}²", s.source_size)];
    if p.has(Product::Specular) {
        kept.push(format!("specular {}² × {} mips ({:?}), {} samples, bias {}", s.size, s.mips, s.mapping, s.samples, s.lod_bias));
    }
    if p.has(Product::BrdfTable) {
        kept.push(format!("table {}", s.table_description()));
    }
    if p.has(Product::Irradiance) {
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
