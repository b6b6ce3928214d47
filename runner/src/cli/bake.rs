//! `runner bake`: an environment, or a scene's plan, into an output folder.

use super::*;
use crate::settings::{InputShape, Product};
use crate::{bake, output};

#[derive(Args)]
pub(super) struct BakeArgs {
    /// The environment: an equirectangular .hdr or .exr, or a folder holding six faces
    /// px nx py ny pz nz (.hdr or .exr) in Vulkan/KTX2 orientation (or --scene). Several
    /// are baked as a batch on one device, each into --out/NAME (its file name without
    /// the extension).
    #[arg(required_unless_present = "scene")]
    env: Vec<PathBuf>,
    #[command(flatten)]
    scene: SceneArgs,
    /// Output folder (created if missing); for a batch, the folder that holds one per
    /// environment.
    #[arg(long, default_value = "out")]
    out: PathBuf,
    #[command(flatten)]
    quality: QualityArgs,
    /// Where to bake: auto (the GPU; the CPU where the best adapter is a software
    /// rasteriser such as lavapipe, or there is none), gpu (the best adapter, even a
    /// software one), cpu.
    #[arg(long, value_parser = choice::<BackendKind>(), default_value = "auto")]
    backend: BackendKind,
    /// A time budget per bake, in seconds, on this device: the specular sample count and
    /// the irradiance source are chosen for the lowest predicted error whose estimate fits
    /// (the cost model's limits, measured by the calibration kernel first).
    #[arg(long, value_name = "SECONDS")]
    budget: Option<f64>,
    /// Replace NaN and -inf texels by 0 and +inf by the channel's largest finite value
    /// instead of refusing the file.
    #[arg(long)]
    sanitize: bool,
    /// Also bake the sheen products (`KHR_materials_sheen`): the Charlie-prefiltered cube
    /// and the sheen tables (`sheen.ktx2`, `sheen_tables.exr`; for the khronos target
    /// `charlie/sheen.ktx2`, `lut_charlie.png` and `lut_sheen_E.png`, the full
    /// glTF-Sample-Environments layout). Only materials with sheen read them; a --scene
    /// bakes them when one of its materials has sheen. bevy and filament have no sheen files.
    #[arg(long)]
    sheen: bool,
}

/// What a bake writes: what the target's engine reads ([`splitsum::Target::products`]),
/// and the sheen products with `--sheen` (refused where the target has no sheen files).
fn products_of(settings: &splitsum::Settings, sheen: bool) -> anyhow::Result<splitsum::Products> {
    let products = settings.target.products();
    match settings.target {
        splitsum::Target::Bevy | splitsum::Target::Filament if sheen => Err(Usage::new(format!(
            "--sheen: the {} target has no sheen files ({})",
            settings.target.name(),
            if settings.target == splitsum::Target::Bevy {
                "Bevy shades no sheen"
            } else {
                "Filament's cloth reads the specular cube and the cloth term of the DFG table built into the engine"
            }
        ))
        .into()),
        _ => Ok(products.with_sheen(sheen)),
    }
}

pub(super) fn bake_command(args: BakeArgs, given: &[String]) -> anyhow::Result<()> {
    let started = Instant::now();
    if let Some(scene_path) = &args.scene.scene {
        if !args.env.is_empty() {
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
    if args.env.len() > 1 {
        return batch_command(args, given);
    }
    let env_path = args.env[0].clone();
    let mut settings = args.quality.settings();
    // An engine target bakes only what its engine reads.
    let products = products_of(&settings, args.sheen)?;
    // The flags are checked before anything is read or written.
    let source_size = settings.resolve(InputShape::Unknown, products)?.source_size;
    refuse_unread(given, &settings, products, env_path.is_dir())?;
    let out = files::OutputDir::begin(&args.out, "--out")?;
    // The device starts (its pipelines built) while the input is read.
    let (read, backend) = std::thread::scope(|s| {
        let opening = s.spawn(|| Backend::open(args.backend));
        let read = load_input(&env_path, args.sanitize, source_size);
        (read, opening.join().expect("opening the backend panicked"))
    });
    let (env, input) = read?;
    let backend = backend?;
    if let Some(budget) = args.budget {
        settings = within_budget(&settings, InputShape::of(&env), products, budget, &backend, given, started)?;
    }
    let job = settings.resolve(InputShape::of(&env), products)?;
    bake::check_duration(&splitsum::estimate::step_seconds(&job, backend.is_gpu()), args.scene.force)?;
    println!("baking {} on {} for {}", env_path.display(), backend.describe(), job.target.name());
    for a in job.adjustments() {
        eprintln!("note: {}", a.describe(&flag_of));
    }
    let baked = bake::bake_job(&backend, &env, &job)?;
    let about = output::About { environment: env_path.display().to_string(), backend: backend.describe(), input: Some(input) };
    let manifest = write_bake(out, &baked, &job, about)?;
    for t in &manifest.timings {
        match t.estimate {
            Some(e) if e >= splitsum::progress::SHOWN || t.seconds >= splitsum::progress::SHOWN => {
                println!("  {:<12} {:>9.3} s (estimated {e:.3} s)", t.step.name(), t.seconds)
            }
            _ => println!("  {:<12} {:>9.3} s", t.step.name(), t.seconds),
        }
    }
    println!("  {:<12} {:>9.3} s", "total", manifest.timings.iter().map(|t| t.seconds).sum::<f64>());
    if let Some(budget) = args.budget {
        println!("budget {budget} s: this run took {:.2} s until its files were written", started.elapsed().as_secs_f64());
    }
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

/// The settings for a bake within `budget` seconds of this run on `backend`
/// (`splitsum::estimate::for_budget`, by this device's estimator), stated; refuses `--budget`
/// beside a flag it would choose. The budget counts what the run has spent since `started`
/// (starting the device, reading the input, the calibration of the estimator): the bake
/// gets what is left. Writing the files comes after and is not counted (it is said so).
fn within_budget(
    settings: &splitsum::Settings,
    shape: InputShape,
    products: splitsum::Products,
    budget: f64,
    backend: &Backend,
    given: &[String],
    started: Instant,
) -> anyhow::Result<splitsum::Settings> {
    if !(budget > 0.0 && budget.is_finite()) {
        return Err(Usage::new(format!("--budget must be a positive number of seconds, not {budget}")).into());
    }
    for f in [flag_of(splitsum::Field::Samples), flag_of(splitsum::Field::IrradianceSource)] {
        if given.contains(&f) {
            return Err(Usage::new(format!("--budget chooses {f} itself: give one or the other")).into());
        }
    }
    let estimator = splitsum::estimate::for_backend(backend)?;
    let spent = started.elapsed().as_secs_f64();
    let left = budget - spent;
    let (chosen, error, seconds) =
        splitsum::estimate::for_budget(settings, shape, products, left.max(0.0), &estimator, &splitsum::cost::Calibration::default())?;
    let within = estimator.steps(&chosen.resolve(shape, products)?).iter().map(|(_, e)| e.within).fold(0.0, f64::max);
    let fits = if seconds <= left { "fits" } else { "is the cheapest, and still over" };
    println!(
        "budget {budget} s on {}: {spent:.2} s went to starting the device, reading the input and measuring its rates; {} samples at mip 1, irradiance from {}², predicted error {:.1} %, bake estimated {seconds:.2} s ±{:.0} % ({fits} the {:.2} s left; writing the files comes after)",
        backend.describe(),
        chosen.samples,
        chosen.irradiance_source.unwrap_or_default(),
        100.0 * error,
        100.0 * within,
        left.max(0.0)
    );
    Ok(chosen)
}

/// Writes `baked` into the output folder `out` and commits it.
fn write_bake(out: files::OutputDir, baked: &splitsum::Baked, job: &splitsum::Job, about: output::About) -> anyhow::Result<output::Manifest> {
    let name = out.target().file_name().map_or_else(|| "ibl".into(), |n| n.to_string_lossy().into_owned());
    let manifest = output::write_into(out.path(), &name, baked, job, about)?;
    out.commit()?;
    Ok(manifest)
}

/// `runner bake A B … --out DIR`: every environment on one device with one set of
/// pipelines (`splitsum::bake_batch`: the next input read while one bakes, the files
/// written while the next bakes), each into `DIR/NAME`. Every output folder is checked
/// before anything is read; an environment that fails is reported and the others go on.
fn batch_command(args: BakeArgs, given: &[String]) -> anyhow::Result<()> {
    let settings = args.quality.settings();
    let products = products_of(&settings, args.sheen)?;
    settings.resolve(InputShape::Unknown, products)?;
    refuse_unread(given, &settings, products, args.env.iter().all(|p| p.is_dir()))?;
    let mut names: std::collections::BTreeMap<String, &PathBuf> = Default::default();
    let mut outs = Vec::new();
    for p in &args.env {
        let name = p.file_stem().map(|n| n.to_string_lossy().into_owned()).filter(|n| !n.is_empty() && n != "." && n != "..");
        let name = name.ok_or_else(|| Usage::new(format!("ENV {} names no file or folder to name its output after", p.display())))?;
        if let Some(first) = names.insert(name.clone(), p) {
            return Err(Usage::new(format!(
                "ENV {} and {} would both be written to --out {}: give environments with different names (or bake them in two runs)",
                first.display(),
                p.display(),
                args.out.join(&name).display()
            ))
            .into());
        }
        outs.push(std::sync::Mutex::new(Some(files::OutputDir::begin(&args.out.join(&name), "--out")?)));
    }
    let backend = Backend::open(args.backend)?;
    println!("baking {} environments on {} for {} into {}", args.env.len(), backend.describe(), settings.target.name(), args.out.display());
    let start = Instant::now();
    let results = splitsum::bake_batch(&backend, &args.env, &settings, products, args.sanitize, |index, path, batched| -> anyhow::Result<()> {
        let out = outs[index].lock().unwrap_or_else(|e| e.into_inner()).take().expect("each output once");
        let b = batched.map_err(crate::cli::bake_error)?;
        for a in &b.adjustments {
            eprintln!("note: {}: {}", path.display(), a.describe(&flag_of));
        }
        let about = output::About { environment: path.display().to_string(), backend: backend.describe(), input: Some(b.input) };
        let manifest = write_bake(out, &b.baked, &b.job, about)?;
        let bake: f64 = manifest.timings.iter().map(|t| t.seconds).sum();
        println!(
            "  {}: baked in {bake:.3} s, {} files in {}",
            path.display(),
            manifest.files.len() + 1,
            args.out.join(path.file_stem().unwrap_or_default()).display()
        );
        Ok(())
    })?;
    let failed: Vec<String> = results.iter().zip(&args.env).filter_map(|(r, p)| r.as_ref().err().map(|e| format!("{}: {e:#}", p.display()))).collect();
    let done = args.env.len() - failed.len();
    println!(
        "{done} of {} environments baked in {:.2} s ({:.3} s each)",
        args.env.len(),
        start.elapsed().as_secs_f64(),
        start.elapsed().as_secs_f64() / done.max(1) as f64
    );
    if !failed.is_empty() {
        return Err(anyhow::anyhow!("{} of {} environments failed (the others are written):\n  {}", failed.len(), args.env.len(), failed.join("\n  ")));
    }
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
    let specular = &job.prefiltered[&Product::Specular];
    if let (true, Some(&first), Some(&last)) = (job.products.has(Product::Specular), specular.levels.first(), specular.levels.last()) {
        crate::ktx2::write(&dir.join("specular.ktx2"), &sb.env.whole_specular(&specular.levels).levels(first, last), *format)?;
        specular_roughness = (first..=last).map(|l| if specular.levels.contains(&l) { Some(specular.roughness_per_mip[l as usize]) } else { None }).collect();
        written.push("specular.ktx2");
    }
    if job.products.has(Product::Irradiance) {
        crate::ktx2::write(&dir.join("irradiance.ktx2"), &sb.env.whole_irradiance(), *format)?;
        written.push("irradiance.ktx2");
    }
    if job.products.has(Product::BrdfTable) {
        files::write_lut_exr(&dir.join("brdf_lut.exr"), sb.env.table(Product::BrdfTable))?;
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
