//! The command line: parsing with clap, then orchestration of backends and files.

use crate::bake::{self, Mapping, MaskingModel, Products, Settings, TableMethod};
use crate::environment;
use crate::files;
use crate::ktx2::Format;
use crate::scene::{DiffuseArg, FresnelArg, SpecularArg, TonemapArg};
use crate::{Backend, BackendKind};
use anyhow::Context;
use clap::{Args, Parser, Subcommand};
use std::path::PathBuf;
use std::time::Instant;

#[derive(Parser)]
#[command(name = "runner", version, about = "splitsum: physically based image-based lighting, baked on the GPU with rust-gpu and checked on the CPU")]
pub struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Bake the split-sum BRDF integration table (scale and bias to F0) to a 2-channel EXR.
    Lut(LutArgs),
    /// Bake an environment: prefiltered specular cube, irradiance cube and SH9, BRDF table.
    Bake(BakeArgs),
    /// Time every product of a bake on each backend (a benchmark, not a test).
    Bench(BenchArgs),
    /// Render the scene offscreen to a PNG (works without a display, on lavapipe or the CPU).
    Render(RenderArgs),
    /// Open the interactive viewer (needs a display; `runner render` does without).
    View(ViewArgs),
    /// Measure error against run time of every product on every backend (report.md,
    /// report.csv, error_vs_time.png).
    Report(ReportArgs),
    /// Show what a scene needs baked and why, what is left out and why, and the cost.
    Plan(PlanArgs),
}

/// How a scene's bake is found or made.
#[derive(Args, Clone)]
pub struct SceneArgs {
    /// A scene file (TOML): bake only what it needs, from the cache when unchanged. The
    /// scene sets the environment, quality, camera, models, lights and output size.
    #[arg(long)]
    pub scene: Option<PathBuf>,
    /// Bake again even if the cache holds this bake.
    #[arg(long)]
    pub force: bool,
    /// The cache folder [default: $SPLITSUM_CACHE, $XDG_CACHE_HOME/splitsum or ~/.cache/splitsum].
    #[arg(long)]
    pub cache: Option<PathBuf>,
    /// Error and cost measurements to plan with (a report.csv of `runner report`)
    /// [default: built in].
    #[arg(long)]
    pub calibration: Option<PathBuf>,
}

impl SceneArgs {
    fn calibration(&self) -> anyhow::Result<crate::plan::Calibration> {
        match &self.calibration {
            None => Ok(crate::plan::Calibration::default()),
            Some(p) => {
                let text = std::fs::read_to_string(p).map_err(|e| crate::Error::file(p, format!("cannot read: {e}")))?;
                crate::plan::Calibration::from_report_csv(&text)
                    .ok_or_else(|| crate::Error::file(p, "is not a report.csv of `runner report` (no brdf lut, prefilter and irradiance rows)").into())
            }
        }
    }

    /// Loads the scene, plans it and bakes it (or takes it from the cache), saying which.
    fn bake(&self, scene_path: &std::path::Path, backend: &Backend) -> anyhow::Result<(crate::scene::Scene, bake::SceneBake)> {
        let scene = crate::scene::Scene::load(scene_path)?;
        let cache = crate::cache::Cache::new(self.cache.clone().unwrap_or_else(crate::cache::default_dir));
        let start = Instant::now();
        let sb = bake::bake_scene(backend, &scene, &self.calibration()?, Some(&cache), self.force)?;
        let short = &sb.key[..12];
        match &sb.outcome {
            bake::Outcome::CacheHit => println!("cache hit {short}: nothing to bake ({})", cache.entry(&sb.key).display()),
            bake::Outcome::Baked => {
                println!("baked {} on {} in {:.2} s; cached as {short}", scene_path.display(), backend.describe(), start.elapsed().as_secs_f64())
            }
            bake::Outcome::Forced => println!("baked again (--force) in {:.2} s; cached as {short}", start.elapsed().as_secs_f64()),
            bake::Outcome::Rebuilt(why) => println!("cache entry {short} rejected ({why}); baked again in {:.2} s", start.elapsed().as_secs_f64()),
        }
        Ok((scene, sb))
    }
}

#[derive(Args)]
struct PlanArgs {
    /// The scene file.
    scene: PathBuf,
    /// Error and cost measurements to plan with (a report.csv) [default: built in].
    #[arg(long)]
    calibration: Option<PathBuf>,
}

#[derive(Args)]
struct ReportArgs {
    /// The environment [default: the embedded courtyard].
    env: Option<PathBuf>,
    /// Output folder.
    #[arg(long, default_value = "report")]
    out: PathBuf,
    /// Smaller sweeps that finish in seconds (CI).
    #[arg(long)]
    quick: bool,
    /// Backends to measure (those that cannot be opened are skipped, with a note).
    #[arg(long, value_enum, num_args = 1.., default_values_t = [BackendKind::Gpu, BackendKind::Cpu])]
    backends: Vec<BackendKind>,
}

#[derive(Args)]
struct ViewArgs {
    /// The environment (equirect .hdr/.exr or a six-face folder) [default: the embedded courtyard].
    env: Option<PathBuf>,
    #[command(flatten)]
    scene: SceneArgs,
    /// Window width.
    #[arg(long, default_value_t = 960)]
    width: u32,
    /// Window height.
    #[arg(long, default_value_t = 540)]
    height: u32,
    /// Close the window after this many seconds.
    #[arg(long)]
    exit_after: Option<f64>,
    #[command(flatten)]
    look: LookArgs,
    #[command(flatten)]
    bake: DisplayBakeArgs,
}

/// What to look at and how.
#[derive(Args, Clone)]
pub struct LookArgs {
    /// Diffuse model.
    #[arg(long, value_enum, default_value_t = DiffuseArg::Lambert)]
    pub diffuse: DiffuseArg,
    /// Specular model.
    #[arg(long, value_enum, default_value_t = SpecularArg::CookTorrance)]
    pub specular: SpecularArg,
    /// Fresnel form.
    #[arg(long, value_enum, default_value_t = FresnelArg::Schlick)]
    pub fresnel: FresnelArg,
    /// Turn image-based lighting off.
    #[arg(long)]
    pub no_ibl: bool,
    /// Turn the direct lights off.
    #[arg(long)]
    pub no_lights: bool,
    /// Exposure in stops, added to the automatic exposure of the environment.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub exposure: f32,
    /// Tone curve.
    #[arg(long, value_enum, default_value_t = TonemapArg::Aces)]
    pub tonemapper: TonemapArg,
    /// Blur of the sky behind the scene, in specular mips (0 = sharp).
    #[arg(long, default_value_t = 0.0)]
    pub sky_blur: f32,
    /// Camera orbit angle, degrees.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub yaw: f32,
    /// Camera elevation, degrees.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub pitch: f32,
    /// A glTF 2.0 model (.gltf or .glb) to show beside the spheres [default: the bundled
    /// textured torus].
    #[arg(long)]
    pub model: Option<PathBuf>,
    /// Show no model.
    #[arg(long, conflicts_with = "model")]
    pub no_model: bool,
    /// Hide the sphere grid.
    #[arg(long)]
    pub no_grid: bool,
    #[command(flatten)]
    pub shading: crate::scene::ShadingChoices,
}

impl LookArgs {
    /// The view these flags describe, with `auto_exposure` from the environment.
    pub fn view(&self, auto_exposure: f32) -> crate::render::ViewState {
        use splitsum_shaders::shade::ShadeOptions;
        let flags = self.shading.flags(!self.no_ibl, !self.no_lights);
        let mut view = crate::render::ViewState {
            spheres: !self.no_grid,
            show_model: !self.no_model,
            yaw: self.yaw.to_radians(),
            pitch: self.pitch.to_radians(),
            exposure: auto_exposure * 2f32.powf(self.exposure),
            tonemapper: self.tonemapper.curve(),
            sky_blur: self.sky_blur,
            options: ShadeOptions { diffuse: self.diffuse.code(), specular: self.specular.code(), fresnel: self.fresnel.code(), flags },
            ..Default::default()
        };
        view.frame_contents();
        view
    }

    /// The model to show, placed beside the grid (or centred without it), if any.
    pub fn load_model(&self) -> anyhow::Result<Option<crate::model::Model>> {
        if self.no_model {
            return Ok(None);
        }
        let mut m = match &self.model {
            Some(p) => crate::model::load(p)?,
            None => crate::model::embedded_sample()?,
        };
        let (centre, size) = crate::model::PLACE_BESIDE_GRID;
        m.fit(centre, size);
        Ok(Some(m))
    }
}

/// The display's bake: quicker defaults than `bake`, for an interactive start.
#[derive(Args, Clone)]
pub struct DisplayBakeArgs {
    /// Face size of the specular cube.
    #[arg(long, default_value_t = 128)]
    pub size: u32,
    /// GGX samples per specular texel.
    #[arg(long, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..), default_value_t = 256)]
    pub samples: u32,
    /// Replace NaN/inf texels instead of refusing the environment.
    #[arg(long)]
    pub sanitize: bool,
}

impl DisplayBakeArgs {
    /// Bake settings for the display of `env`: the source cube as sharp as the environment
    /// (a quarter of an equirect's width, up to 1024), the rest from the flags.
    pub fn settings(&self, env: &environment::Environment) -> Settings {
        let mips = Settings::default_mips(self.size);
        let native = crate::plan::native_face_size(env);
        Settings { size: self.size, source_size: native.max(self.size), mips, samples: self.samples, lut_size: 128, lut_samples: 512, ..Settings::default() }
    }
}

#[derive(Args)]
struct RenderArgs {
    /// The environment (equirect .hdr/.exr or a six-face folder) [default: the embedded courtyard].
    env: Option<PathBuf>,
    #[command(flatten)]
    scene: SceneArgs,
    /// Output image: .png, or .jpg (JPEG, quality 95).
    #[arg(long, default_value = "frame.png")]
    out: PathBuf,
    /// Width in pixels.
    #[arg(long, default_value_t = 960)]
    width: u32,
    /// Height in pixels.
    #[arg(long, default_value_t = 540)]
    height: u32,
    /// Bake and render on the GPU, or bake and render on the CPU (the reference renderer).
    #[arg(long, value_enum, default_value_t = BackendKind::Gpu)]
    backend: BackendKind,
    #[command(flatten)]
    look: LookArgs,
    #[command(flatten)]
    bake: DisplayBakeArgs,
}

/// The quality knobs of a bake.
#[derive(Args, Clone)]
pub struct QualityArgs {
    /// Face size of mip 0 of the specular cube (a power of two).
    #[arg(long, default_value_t = 256)]
    pub size: u32,
    /// Face size of the source cube the products are filtered from [default: --size].
    #[arg(long)]
    pub source_size: Option<u32>,
    /// Specular mips, one roughness each [default: down to 8×8 faces].
    #[arg(long)]
    pub mips: Option<u32>,
    /// How roughness is spread over the mips.
    #[arg(long, value_enum, default_value_t = Mapping::Geometric)]
    pub mapping: Mapping,
    /// GGX samples per texel of specular mip 1 (the default, with --sample-growth 2, is the
    /// best end-to-end error per millisecond measured by `runner report` on city.exr).
    #[arg(long, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..), default_value_t = 64)]
    pub samples: u32,
    /// Factor by which the sample count grows per mip after mip 1 (1 = the same on every mip).
    #[arg(long, default_value_t = 2)]
    pub sample_growth: u32,
    /// Sample every mip, even the rough ones that an exact sum over a coarse source level
    /// would bake for less.
    #[arg(long)]
    pub sampled_only: bool,
    /// Bias added to the source mip each prefilter sample reads (0.5: the best error at 1024
    /// samples in `runner report`, on city.exr's sun and on courtyard.exr).
    #[arg(long, default_value_t = 0.5, allow_negative_numbers = true)]
    pub lod_bias: f32,
    /// Equirect → cube supersampling: points per source texel width.
    #[arg(long, default_value_t = 2.0)]
    pub supersample: f32,
    /// Face size of the irradiance cube.
    #[arg(long, default_value_t = 32)]
    pub irradiance_size: u32,
    /// Face size of the source mip the irradiance convolution sums over [default: 16, or
    /// the source size if smaller].
    #[arg(long)]
    pub irradiance_source: Option<u32>,
    /// Face size of the source mip projected onto SH9 (SH9's error is its band limit from
    /// 16² up) [default: 32, or the source size if smaller].
    #[arg(long)]
    pub sh_source: Option<u32>,
    /// Width and height of the BRDF table.
    #[arg(long, default_value_t = 256)]
    pub lut_size: u32,
    /// Samples per texel of the BRDF table (with --lut-method sampled).
    #[arg(long, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..), default_value_t = 1024)]
    pub lut_samples: u32,
    /// How the BRDF table is integrated: deterministic quadrature (within 1e-5) or sampling.
    #[arg(long, value_enum, default_value_t = TableMethod::Quadrature)]
    pub lut_method: TableMethod,
    /// The table's masking–shadowing term.
    /// [default: correlated; schlick with --lut-method sampled]
    #[arg(long, value_enum)]
    pub lut_masking: Option<MaskingModel>,
    /// KTX2 texel format; auto = RGBA16F unless a value exceeds 65504, then RGBA32F.
    #[arg(long, value_enum, default_value_t = Format::Auto)]
    pub format: Format,
}

impl QualityArgs {
    /// The bake settings these flags describe.
    pub fn settings(&self) -> Settings {
        let mips = self.mips.unwrap_or_else(|| Settings::default_mips(self.size));
        let source_size = self.source_size.unwrap_or(self.size);
        let d = Settings::default();
        Settings {
            size: self.size,
            source_size,
            mips,
            mapping: self.mapping,
            samples: self.samples,
            sample_growth: self.sample_growth,
            exact_sums: !self.sampled_only,
            lod_bias: self.lod_bias,
            supersample_density: self.supersample,
            irradiance_size: self.irradiance_size,
            // Defaults that exceed a small source are fitted to it; given values are checked.
            irradiance_source: self.irradiance_source.unwrap_or(d.irradiance_source.min(source_size)),
            sh_source: self.sh_source.unwrap_or(d.sh_source.min(source_size)),
            lut_size: self.lut_size,
            lut_samples: self.lut_samples,
            lut_method: self.lut_method,
            lut_masking: self.lut_masking.unwrap_or(self.lut_method.default_masking()),
            format: self.format,
        }
    }
}

#[derive(Args)]
struct BakeArgs {
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
    #[arg(long, value_enum, default_value_t = BackendKind::Gpu)]
    backend: BackendKind,
    /// Replace NaN and -inf texels by 0 and +inf by the channel's largest finite value
    /// instead of refusing the file.
    #[arg(long)]
    sanitize: bool,
}

#[derive(Args)]
struct BenchArgs {
    /// The environment (as for `bake`).
    env: PathBuf,
    #[command(flatten)]
    quality: QualityArgs,
    /// Backends to time.
    #[arg(long, value_enum, num_args = 1.., default_values_t = [BackendKind::Gpu, BackendKind::Cpu])]
    backends: Vec<BackendKind>,
    /// Runs per backend; the table shows the fastest.
    #[arg(long, default_value_t = 1)]
    runs: u32,
    /// Run even if the bake is estimated to take over an hour.
    #[arg(long)]
    force: bool,
}

#[derive(Args)]
struct LutArgs {
    /// Table width and height: column x holds NdotV = (x+0.5)/S, row y roughness = (y+0.5)/S.
    #[arg(long, default_value_t = 256)]
    size: u32,
    /// Deterministic quadrature (within 1e-5 of the f64 reference) or Hammersley sampling.
    #[arg(long, value_enum, default_value_t = TableMethod::Quadrature)]
    method: TableMethod,
    /// Masking–shadowing term: the exact height-correlated Smith or Smith–Schlick (k = α/2)
    /// [default: correlated; schlick with --method sampled].
    #[arg(long, value_enum)]
    masking: Option<MaskingModel>,
    /// Hammersley points per texel (with --method sampled).
    #[arg(long, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..), default_value_t = 1024)]
    samples: u32,
    /// Where to bake.
    #[arg(long, value_enum, default_value_t = BackendKind::Gpu)]
    backend: BackendKind,
    /// Output OpenEXR file (R = scale, G = bias, 32-bit float).
    #[arg(long, default_value = "lut.exr")]
    out: PathBuf,
    /// Also write an 8-bit PNG preview beside it (same name, .png).
    #[arg(long)]
    png: bool,
    /// Run even if the table is estimated to take over an hour.
    #[arg(long)]
    force: bool,
}

/// With `--scene`, the scene file sets everything but where and how to run: refuses any
/// other flag in `given`, naming them and the scene tables that set them.
fn refuse_beside_scene(given: &[String], allowed: &[&str]) -> anyhow::Result<()> {
    let extra: Vec<&str> = given.iter().map(String::as_str).filter(|f| !allowed.contains(f) && *f != "--scene" && *f != "--env").collect();
    anyhow::ensure!(
        extra.is_empty(),
        "with --scene, the scene file sets the environment, [quality], [camera], [output] and the materials: drop {} (or edit the scene)",
        extra.join(", ")
    );
    Ok(())
}

/// The flags that still apply beside `--scene`: where and how to run, and the cache.
const SCENE_FLAGS: [&str; 6] = ["--force", "--cache", "--calibration", "--out", "--backend", "--format"];

/// Parses `args` (the program name first) and runs the command.
pub fn run<I, T>(args: I) -> anyhow::Result<()>
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    use clap::{CommandFactory, FromArgMatches};
    let matches = Cli::command().try_get_matches_from(args)?;
    let cli = Cli::from_arg_matches(&matches)?;
    // The flags written on the command line (not defaulted), as the user wrote them.
    let given: Vec<String> = matches
        .subcommand()
        .map(|(name, sub)| {
            let command = Cli::command();
            let args: Vec<String> = command
                .find_subcommand(name)
                .map(|c| c.get_arguments().filter_map(|a| a.get_long().map(|l| (a.get_id().to_string(), l))).map(|(id, _)| id).collect())
                .unwrap_or_default();
            sub.ids()
                .filter(|id| args.iter().any(|a| a == id.as_str()))
                .filter(|id| sub.value_source(id.as_str()) == Some(clap::parser::ValueSource::CommandLine))
                .map(|id| format!("--{}", id.as_str().replace('_', "-")))
                .collect()
        })
        .unwrap_or_default();
    match cli.command {
        Some(Command::Lut(args)) => lut(args),
        Some(Command::Bake(args)) => bake_command(args, &given),
        Some(Command::Bench(args)) => bench(args),
        Some(Command::Render(args)) => render(args, &given),
        Some(Command::View(args)) => view(args, &given),
        Some(Command::Report(args)) => report(args),
        Some(Command::Plan(args)) => plan_command(args),
        None => default_run(),
    }
}

fn lut(args: LutArgs) -> anyhow::Result<()> {
    files::check_writable(&args.out)?;
    let png = args.png.then(|| args.out.with_extension("png"));
    if let Some(p) = &png {
        files::check_writable(p)?;
    }
    let backend = Backend::open(args.backend)?;
    let start = Instant::now();
    let masking = args.masking.unwrap_or(args.method.default_masking());
    let settings = Settings { lut_size: args.size, lut_samples: args.samples, lut_method: args.method, lut_masking: masking, ..Settings::default() };
    if args.samples == 0 {
        anyhow::bail!("--samples must be at least 1");
    }
    if settings.lut_method == TableMethod::Sampled && settings.lut_masking != MaskingModel::Schlick {
        anyhow::bail!("--masking correlated needs --method quadrature (the sampled table is Smith–Schlick only)");
    }
    let only_table = Products { specular: false, irradiance: false, sh9: false, lut: true };
    let mut estimate = crate::plan::step_seconds(&settings, only_table, &[], 0, &crate::plan::Calibration::default(), matches!(backend, Backend::Gpu(_)));
    estimate[0] = 0.0; // the cost model's source cube: a table needs none
    bake::check_duration(&estimate, args.force).map_err(|e| anyhow::anyhow!(e.to_string().replace("--lut-size and --lut-samples", "--size and --samples")))?;
    let lut = bake::brdf_table(&backend, &settings)?;
    let secs = start.elapsed().as_secs_f64();
    files::write_lut_exr(&args.out, &lut).context("writing the BRDF table")?;
    println!("brdf lut {} on {}: bake {:.3} s", settings.table_description(), backend.describe(), secs);
    println!("wrote {}", args.out.display());
    if let Some(p) = png {
        files::write_png(&p, lut.size, lut.size, &files::lut_preview(&lut))?;
        println!("wrote {}", p.display());
    }
    Ok(())
}

fn bake_command(args: BakeArgs, given: &[String]) -> anyhow::Result<()> {
    if let Some(scene_path) = &args.scene.scene {
        anyhow::ensure!(args.env.is_none(), "give either ENV or --scene, not both (the scene names its environment)");
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
    settings.validate()?;
    let out = files::OutputDir::begin(&args.out, "--out")?;
    let (env, input) = load_input(&env_path, args.sanitize, settings.source_size)?;
    let backend = Backend::open(args.backend)?;
    let all: Vec<u32> = (0..settings.mips).collect();
    bake::check_duration(&bake::step_estimates(&backend, &env, &settings, Products::ALL, &all), args.scene.force)?;
    println!("baking {} on {}", env_path.display(), backend.describe());
    let baked = bake::bake(&backend, &env, &settings, Products::ALL)?;
    let manifest = bake::Manifest {
        environment: env_path.display().to_string(),
        backend: backend.describe(),
        settings: settings.clone(),
        roughness_per_mip: settings.roughness(),
        samples_per_mip: settings.samples_per_mip(),
        accuracy: bake::DEFAULTS_ACCURACY,
        input: (&input).into(),
        timings: Vec::new(),
        sh9_vs_convolution: None,
        files: Vec::new(),
        conventions: bake::CONVENTIONS.to_vec(),
    };
    let manifest = bake::write(out.path(), &baked, &settings, manifest)?;
    out.commit()?;
    for t in &manifest.timings {
        println!("  {:<12} {:>9.3} s", t.product, t.seconds);
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

fn bench(args: BenchArgs) -> anyhow::Result<()> {
    let settings = args.quality.settings();
    settings.validate()?;
    let (env, _) = load_input(&args.env, false, settings.source_size)?;
    println!(
        "bench: {} at size {}, {} mips ({:?}), {:?} samples per mip, irradiance {}² from {}², SH9 from {}², table {}",
        args.env.display(),
        settings.size,
        settings.mips,
        settings.mapping,
        settings.samples_per_mip(),
        settings.irradiance_size,
        settings.irradiance_source,
        settings.sh_source,
        settings.table_description()
    );
    for kind in &args.backends {
        let backend = match Backend::open(*kind) {
            Ok(b) => b,
            Err(e) => {
                println!("{kind:?}: skipped ({e})");
                continue;
            }
        };
        let all: Vec<u32> = (0..settings.mips).collect();
        bake::check_duration(&bake::step_estimates(&backend, &env, &settings, Products::ALL, &all), args.force)?;
        let mut best: Vec<bake::Timing> = Vec::new();
        for _ in 0..args.runs.max(1) {
            let baked = bake::bake(&backend, &env, &settings, Products::ALL)?;
            if best.is_empty() {
                best = baked.timings;
            } else {
                for (b, t) in best.iter_mut().zip(baked.timings) {
                    b.seconds = b.seconds.min(t.seconds);
                }
            }
        }
        println!("{}", backend.describe());
        for t in &best {
            println!("  {:<12} {:>9.3} s", t.product, t.seconds);
        }
        println!("  {:<12} {:>9.3} s", "total", best.iter().map(|t| t.seconds).sum::<f64>());
    }
    if let Some(peak) = peak_memory() {
        println!("peak memory of this process (VmHWM, all backends so far): {:.0} MiB", peak as f64 / 1048576.0);
    }
    Ok(())
}

/// The peak resident memory of this process in bytes, as the kernel counts it (`VmHWM` in
/// `/proc/self/status`; Linux only).
fn peak_memory() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// Reads the environment at `path` for cubes of faces up to `face`
/// (`environment::load_for`), saying on stderr what reading it changed.
pub fn load_input(path: &std::path::Path, sanitize: bool, face: u32) -> anyhow::Result<(environment::Environment, environment::InputReport)> {
    let (env, input) = {
        let _step = crate::progress::step(&format!("reading {}", path.display()), None);
        environment::load_for(path, sanitize, face)?
    };
    let p = path.display();
    if input.negative > 0 {
        eprintln!("note: {p}: {} texels had negative values, set to 0", input.negative);
    }
    if input.clamped > 0 {
        eprintln!("note: {p}: {} texels were brighter than 1e20 and were clamped to it", input.clamped);
    }
    if input.sanitized && (input.nan > 0 || input.infinite > 0) {
        eprintln!("note: {p}: replaced {} NaN and {} infinite texels (--sanitize)", input.nan, input.infinite);
    }
    let (w, h) = input.original;
    match &env {
        environment::Environment::Equirect(e) if e.width < w => {
            eprintln!("note: {p}: {w}×{h} read as {}×{} (area-weighted): a cube of {face}² faces resolves no more (--source-size)", e.width, e.height)
        }
        environment::Environment::Cube(c) if c.layout.size < w => {
            eprintln!("note: {p}: faces of {w}² read as {}² (the cube's own mip filter): the bake uses no more (--source-size)", c.layout.size)
        }
        _ => {}
    }
    Ok((env, input))
}

/// The environment at `path` (for the display and the planner: cubes up to
/// `environment::NATIVE_FACE`), or the embedded default.
pub fn load_environment(path: Option<&std::path::Path>, sanitize: bool) -> anyhow::Result<(environment::Environment, String)> {
    match path {
        Some(p) => Ok((load_input(p, sanitize, environment::NATIVE_FACE)?.0, p.display().to_string())),
        None => Ok((environment::embedded_default()?, "the embedded courtyard (CC0)".to_string())),
    }
}

fn render(args: RenderArgs, given: &[String]) -> anyhow::Result<()> {
    let format = files::picture_format(&args.out, "--out")?;
    files::check_writable(&args.out)?;
    if let Some(scene_path) = &args.scene.scene {
        anyhow::ensure!(args.env.is_none(), "give either ENV or --scene, not both (the scene names its environment)");
        refuse_beside_scene(given, &SCENE_FLAGS)?;
        let backend = Backend::open(args.backend)?;
        let (scene, sb) = args.scene.bake(scene_path, &backend)?;
        let view = scene.view(sb.env.auto_exposure());
        let model = scene.model()?;
        let (w, h) = (scene.output.width, scene.output.height);
        let start = Instant::now();
        let pixels = render_frame(&backend, &sb.env, &view.frame(sb.env.shape(), w, h, true), model.as_ref())?;
        files::write_rgb8(&args.out, w, h, &crate::render::to_rgb8(&pixels), format)?;
        println!("rendered {w}×{h} in {:.3} s: {}", start.elapsed().as_secs_f64(), view.summary());
        println!("wrote {}", args.out.display());
        return Ok(());
    }
    crate::render::check_size(args.width, args.height)?;
    let (env, name) = load_environment(args.env.as_deref(), args.bake.sanitize)?;
    let backend = Backend::open(args.backend)?;
    let settings = args.bake.settings(&env);
    bake::check_duration(&bake::step_estimates(&backend, &env, &settings, bake::DISPLAY_PRODUCTS, &(0..settings.mips).collect::<Vec<_>>()), args.scene.force)?;
    let start = Instant::now();
    let baked = bake::bake_for_display(&backend, &env, &settings)?;
    let bake_secs = start.elapsed().as_secs_f64();
    let view = args.look.view(baked.auto_exposure());
    let model = args.look.load_model()?;
    let start = Instant::now();
    let frame = view.frame(baked.shape(), args.width, args.height, true);
    let pixels = render_frame(&backend, &baked, &frame, model.as_ref())?;
    let render_secs = start.elapsed().as_secs_f64();
    files::write_rgb8(&args.out, args.width, args.height, &crate::render::to_rgb8(&pixels), format)?;
    println!("{name} on {}: bake {bake_secs:.2} s, render {render_secs:.3} s", backend.describe());
    println!("{}", view.summary());
    println!("wrote {}", args.out.display());
    Ok(())
}

fn view(args: ViewArgs, given: &[String]) -> anyhow::Result<()> {
    if args.scene.scene.is_some() {
        anyhow::ensure!(args.env.is_none(), "give either ENV or --scene, not both (the scene names its environment)");
        refuse_beside_scene(given, &["--force", "--cache", "--calibration", "--exit-after"])?;
    }
    if !crate::view::display_available() {
        anyhow::bail!("no display (neither DISPLAY nor WAYLAND_DISPLAY is set); `runner render --out frame.png` renders without one");
    }
    if let Some(scene_path) = &args.scene.scene {
        let backend = Backend::open(BackendKind::Gpu)?;
        let (scene, sb) = args.scene.bake(scene_path, &backend)?;
        let Backend::Gpu(gpu) = backend else { unreachable!("opened as GPU") };
        let state = scene.view(sb.env.auto_exposure());
        let model = scene.model()?;
        let options = crate::view::ViewOptions {
            exit_after: args.exit_after.map(std::time::Duration::from_secs_f64),
            size: (scene.output.width, scene.output.height),
            ..Default::default()
        };
        crate::view::run(*gpu, &sb.env, model.as_ref(), state, options)?;
        return Ok(());
    }
    crate::render::check_size(args.width, args.height)?;
    let (env, name) = load_environment(args.env.as_deref(), args.bake.sanitize)?;
    let backend = Backend::open(BackendKind::Gpu)?;
    let settings = args.bake.settings(&env);
    bake::check_duration(&bake::step_estimates(&backend, &env, &settings, bake::DISPLAY_PRODUCTS, &(0..settings.mips).collect::<Vec<_>>()), args.scene.force)?;
    let start = Instant::now();
    let baked = bake::bake_for_display(&backend, &env, &settings)?;
    println!("{name} baked on {} in {:.2} s", backend.describe(), start.elapsed().as_secs_f64());
    let Backend::Gpu(gpu) = backend else { unreachable!("opened as GPU") };
    let state = args.look.view(baked.auto_exposure());
    let model = args.look.load_model()?;
    let options = crate::view::ViewOptions {
        exit_after: args.exit_after.map(std::time::Duration::from_secs_f64),
        exit_after_frames: None,
        on_presented: None,
        size: (args.width, args.height),
    };
    crate::view::run(*gpu, &baked, model.as_ref(), state, options)?;
    Ok(())
}

/// `runner` with no arguments: bake the embedded environment and show the sphere grid in a
/// window, or, where there is no display (or no GPU), render it to `splitsum.png`.
fn default_run() -> anyhow::Result<()> {
    let (env, name) = load_environment(None, false)?;
    let backend = match Backend::open(BackendKind::Gpu) {
        Ok(b) => b,
        Err(e) => {
            eprintln!("{e}\nfalling back to the CPU backend");
            Backend::Cpu
        }
    };
    let display = DisplayBakeArgs { size: 128, samples: 256, sanitize: false };
    let start = Instant::now();
    let baked = bake::bake_for_display(&backend, &env, &display.settings(&env))?;
    println!("baked {name} on {} in {:.2} s", backend.describe(), start.elapsed().as_secs_f64());
    let look = LookArgs {
        diffuse: DiffuseArg::Lambert,
        specular: SpecularArg::CookTorrance,
        fresnel: FresnelArg::Schlick,
        no_ibl: false,
        no_lights: false,
        exposure: 0.0,
        tonemapper: TonemapArg::Aces,
        sky_blur: 0.0,
        yaw: 0.0,
        pitch: 0.0,
        model: None,
        no_model: true,
        no_grid: false,
        shading: Default::default(),
    };
    let state = look.view(baked.auto_exposure());
    let backend = match backend {
        Backend::Gpu(gpu) if crate::view::display_available() => {
            let options = crate::view::ViewOptions { size: (960, 540), ..Default::default() };
            let gpu = *gpu;
            match crate::view::run(gpu, &baked, None, state.clone(), options) {
                Ok(()) => return Ok(()),
                Err(e) => {
                    eprintln!("{e}; rendering to a file instead");
                    Backend::open(BackendKind::Gpu).unwrap_or(Backend::Cpu)
                }
            }
        }
        b => b,
    };
    let (w, h) = (960, 540);
    let out = PathBuf::from("splitsum.png");
    files::check_writable(&out)?;
    let pixels = match &backend {
        Backend::Gpu(g) => {
            let scene = crate::render::GpuScene::new(g, &baked);
            scene.render_offscreen(g, &state.frame(scene.shape, w, h, true), None)?
        }
        Backend::Cpu => crate::render::render_cpu(&baked, &state.frame(baked.shape(), w, h, true)),
    };
    files::write_png(&out, w, h, &crate::render::to_rgb8(&pixels))?;
    let shown = std::fs::canonicalize(&out).unwrap_or(out);
    println!("no display here: rendered the sphere grid ({w}×{h}) to {}", shown.display());
    println!("{}", state.summary());
    Ok(())
}

fn report(args: ReportArgs) -> anyhow::Result<()> {
    let (env, name) = load_environment(args.env.as_deref(), false)?;
    let mut backends = Vec::new();
    for kind in &args.backends {
        match Backend::open(*kind) {
            Ok(b) => backends.push(b),
            Err(e) => eprintln!("{kind:?}: skipped ({e})"),
        }
    }
    anyhow::ensure!(!backends.is_empty(), "no backend could be opened");
    let sweep = if args.quick { crate::report::Sweep::quick() } else { crate::report::Sweep::full() };
    let start = Instant::now();
    let out = files::OutputDir::begin(&args.out, "--out")?;
    let rows = crate::report::run(&env, &name, &backends, &sweep, out.path())?;
    out.commit()?;
    println!("{} measurements in {:.1} s", rows.len(), start.elapsed().as_secs_f64());
    for r in crate::report::best_per_ms(&rows) {
        println!("  best error per ms: {:<28} {:<8} {:<24} {:>9.1} ms  mean error {:.2e}", r.product, &r.backend[..3], r.setting, r.time_ms, r.mean_error);
    }
    println!("wrote {}/report.md, report.csv, error_vs_time.png", args.out.display());
    Ok(())
}

/// Renders `frame` (with `model`, if any) on `backend`: the GPU renderer, or the CPU
/// reference renderer.
fn render_frame(
    backend: &Backend,
    env: &crate::render::BakedEnvironment,
    frame: &splitsum_shaders::scene::Frame,
    model: Option<&crate::model::Model>,
) -> anyhow::Result<Vec<splitsum_shaders::glam::Vec4>> {
    Ok(match (backend, model) {
        (Backend::Gpu(g), m) => {
            let scene = crate::render::GpuScene::new(g, env);
            let gm = m.map(|m| crate::render::GpuModel::new(g, &scene, m));
            scene.render_offscreen(g, frame, gm.as_ref())?
        }
        (Backend::Cpu, Some(m)) => crate::raster::render(env, frame, m),
        (Backend::Cpu, None) => crate::render::render_cpu(env, frame),
    })
}

fn plan_command(args: PlanArgs) -> anyhow::Result<()> {
    let scene = crate::scene::Scene::load(&args.scene)?;
    let cal = SceneArgs { scene: None, force: false, cache: None, calibration: args.calibration.clone() }.calibration()?;
    let env_path = scene.environment.as_ref().map(|p| scene.resolve(p));
    let (env, name) = load_environment(env_path.as_deref(), scene.sanitize)?;
    let plan = crate::plan::plan_for(&scene, &env, &cal);
    print!("{}", crate::plan::describe(&plan, &args.scene.display().to_string(), &name));
    Ok(())
}

/// Writes a scene's bake: KTX2 of the products the plan kept, the table as EXR, and
/// `plan.json` (decisions, settings, levels, cache key). `specular.ktx2` holds the baked
/// mips `first ..= last` only (its mip 0 is level `first`; roughness per mip in
/// `plan.json`; levels in between that the plan skips are zero).
fn write_scene_bake(out: &files::OutputDir, sb: &bake::SceneBake, format: &Format) -> anyhow::Result<()> {
    let dir = out.path();
    let p = &sb.plan;
    let mut written = Vec::new();
    let all_roughness = p.settings.roughness();
    let mut specular_roughness = Vec::new();
    if let (true, Some(&first), Some(&last)) = (p.products.specular, p.levels.first(), p.levels.last()) {
        crate::ktx2::write(&dir.join("specular.ktx2"), &sb.env.specular.levels(first, last), *format)?;
        specular_roughness = (first..=last).map(|l| if p.levels.contains(&l) { Some(all_roughness[l as usize]) } else { None }).collect();
        written.push("specular.ktx2");
    }
    if p.products.irradiance {
        crate::ktx2::write(&dir.join("irradiance.ktx2"), &sb.env.irradiance, *format)?;
        written.push("irradiance.ktx2");
    }
    if p.products.lut {
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
