//! `runner bake`: an environment, or a scene's plan, into an output folder.

use super::*;
use crate::settings::InputShape;
use crate::{bake, output};

#[derive(Args)]
pub(super) struct BakeArgs {
    /// The environment: an equirectangular .hdr or .exr, or a folder holding six faces
    /// px nx py ny pz nz (.hdr or .exr) in Vulkan/KTX2 orientation (or --scene).
    #[arg(required_unless_present = "scene")]
    env: Option<PathBuf>,
    #[command(flatten)]
    scene: SceneArgs,
    /// Output folder (created if missing).
    #[arg(long, default_value = "out")]
    out: PathBuf,
    #[command(flatten)]
    quality: QualityArgs,
    /// Where to bake.
    #[arg(long, value_parser = choice::<BackendKind>(), default_value = "gpu")]
    backend: BackendKind,
    /// Replace NaN and -inf texels by 0 and +inf by the channel's largest finite value
    /// instead of refusing the file.
    #[arg(long)]
    sanitize: bool,
}

pub(super) fn bake_command(args: BakeArgs, given: &[String]) -> anyhow::Result<()> {
    if let Some(scene_path) = &args.scene.scene {
        if args.env.is_some() {
            return Err(Usage::new("give either ENV or --scene, not both (the scene names its environment)").into());
        }
        refuse_beside_scene(given, &SCENE_FLAGS)?;
        let out = files::OutputDir::begin(&args.out, "--out")?;
        let backend = Backend::open(args.backend)?;
        let (_, sb) = args.scene.bake(scene_path, &backend)?;
        write_scene_bake(&out, &sb, &args.quality.format)?;
        out.commit()?;
        return Ok(());
    }
    let env_path = args.env.clone().expect("clap requires ENV without --scene");
    let settings = args.quality.settings();
    // An engine target bakes only what its engine reads.
    let products = settings.target.products();
    // The flags are checked before anything is read or written.
    let source_size = settings.resolve(InputShape::Unknown, products)?.source_size;
    refuse_unread(given, &settings, products, env_path.is_dir())?;
    let out = files::OutputDir::begin(&args.out, "--out")?;
    let (env, input) = load_input(&env_path, args.sanitize, source_size)?;
    let job = settings.resolve(InputShape::of(&env), products)?;
    let backend = Backend::open(args.backend)?;
    bake::check_duration(&bake::step_estimates(backend.is_gpu(), &job), args.scene.force)?;
    println!("baking {} on {} for {}", env_path.display(), backend.describe(), job.target.name());
    for a in job.adjustments() {
        eprintln!("note: {}", a.describe(&flag_of));
    }
    let baked = bake::bake_job(&backend, &env, &job)?;
    let about = output::About { environment: env_path.display().to_string(), backend: backend.describe(), input: Some(input) };
    let name = out.target().file_name().map_or_else(|| "ibl".into(), |n| n.to_string_lossy().into_owned());
    let manifest = output::write_into(out.path(), &name, &baked, &job, about)?;
    out.commit()?;
    for t in &manifest.timings {
        println!("  {:<12} {:>9.3} s", t.step.name(), t.seconds);
    }
    println!("  {:<12} {:>9.3} s", "total", manifest.timings.iter().map(|t| t.seconds).sum::<f64>());
    if let Some(e) = manifest.sh9_vs_convolution {
        println!(
            "  sh9.json (9 coefficients, a band-limited stand-in for irradiance.ktx2) against the convolution: max relative error {:.1} %, rms {:.1} % over the irradiance texels; small bright sources exceed what 9 coefficients hold, prefer irradiance.ktx2",
            100.0 * e.max_relative,
            100.0 * e.rms_relative
        );
    }
    println!("wrote {} files to {}", manifest.files.len() + 1, args.out.display());
    Ok(())
}

/// Writes a scene's bake: KTX2 of the products the plan kept, the table as EXR, and
/// `plan.json` (decisions, settings, levels, cache key). `specular.ktx2` holds the baked
/// mips `first ..= last` only (its mip 0 is level `first`; roughness per mip in
/// `plan.json`; levels in between that the plan skips are zero).
fn write_scene_bake(out: &files::OutputDir, sb: &crate::prepare::SceneBake, format: &Format) -> anyhow::Result<()> {
    let dir = out.path();
    let p = &sb.plan;
    let job = &p.job;
    let mut written = Vec::new();
    let mut specular_roughness = Vec::new();
    if let (true, Some(&first), Some(&last)) = (job.products.specular, job.levels.first(), job.levels.last()) {
        crate::ktx2::write(&dir.join("specular.ktx2"), &sb.env.specular.levels(first, last), *format)?;
        specular_roughness = (first..=last).map(|l| if job.levels.contains(&l) { Some(job.roughness_per_mip[l as usize]) } else { None }).collect();
        written.push("specular.ktx2");
    }
    if job.products.irradiance {
        crate::ktx2::write(&dir.join("irradiance.ktx2"), &sb.env.irradiance, *format)?;
        written.push("irradiance.ktx2");
    }
    if job.products.lut {
        files::write_lut_exr(&dir.join("brdf_lut.exr"), &sb.env.lut)?;
        written.push("brdf_lut.exr");
    }
    #[derive(serde::Serialize)]
    struct PlanFile<'a> {
        key: &'a str,
        plan: &'a crate::plan::Plan,
        /// Roughness of each mip of specular.ktx2 (null: skipped, zero).
        specular_roughness_per_mip: Vec<Option<f32>>,
        timings: &'a [bake::Timing],
        files: &'a [&'a str],
    }
    let file = PlanFile { key: &sb.key, plan: p, specular_roughness_per_mip: specular_roughness, timings: &sb.timings, files: &written };
    let json = serde_json::to_string_pretty(&file).expect("serialisable");
    files::write_atomic(&dir.join("plan.json"), |w| std::io::Write::write_all(w, json.as_bytes()))?;
    if written.is_empty() {
        println!("the plan bakes nothing for this scene: wrote only plan.json (its decisions) to {}", out.target().display());
    } else {
        println!("wrote {} and plan.json to {}", written.join(", "), out.target().display());
    }
    Ok(())
}
