//! The command line: parsing with clap (derive), one module per subcommand; what they
//! share (scene, quality and display flags, reading the environment) lives here.

mod bake;
mod bench;
mod default;
mod lut;
mod plan;
#[cfg(unix)]
mod processes;
mod render;
mod report;
mod view;

use crate::environment;
use crate::files;
use crate::ktx2::Format;
use crate::settings::{Field, Products, Settings, TableMethod, Target};
use crate::{Backend, BackendKind};
use anyhow::Context;
use clap::{Args, Parser, Subcommand};
use splitsum_shaders::brdf::microfacet::Masking;
use splitsum_shaders::choice::Choice;
use splitsum_shaders::prefilter::RoughnessMapping;
use splitsum_shaders::shade::{DiffuseModel, FresnelForm, SpecularModel};
use splitsum_shaders::tonemap::Tonemapper;
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
    Lut(lut::LutArgs),
    /// Bake an environment: prefiltered specular cube, irradiance cube and SH9, BRDF table.
    Bake(bake::BakeArgs),
    /// Time every product of a bake on each backend (a benchmark, not a test).
    Bench(bench::BenchArgs),
    /// Render the scene offscreen to a PNG or JPEG (works without a display, on lavapipe or the CPU).
    Render(render::RenderArgs),
    /// Open the interactive viewer (needs a display; `runner render` does without).
    View(view::ViewArgs),
    /// Measure error against run time of every product on every backend (report.md,
    /// report.csv, report.html and its figures).
    Report(report::ReportArgs),
    /// Show what a scene needs baked and why, what is left out and why, and the cost.
    Plan(plan::PlanArgs),
}

/// How a scene's bake is found or made.
#[derive(Args, Clone)]
pub struct SceneArgs {
    /// A scene file (TOML): bake only what it needs, from the cache when unchanged. The
    /// scene sets the environment, quality, camera, models, lights and output size.
    #[arg(long)]
    pub scene: Option<PathBuf>,
    /// Bake again even if the cache holds this bake, and run even if the bake is estimated
    /// to take over an hour.
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
    fn calibration(&self) -> anyhow::Result<crate::cost::Calibration> {
        match &self.calibration {
            None => Ok(crate::cost::Calibration::default()),
            Some(p) => {
                // A report.csv of the full sweep is about 40 KiB.
                let text = crate::files::read_text(p, 64 << 20)?;
                crate::cost::Calibration::from_report_csv(&text)
                    .ok_or_else(|| crate::Error::file(p, "is not a report.csv of `runner report` (no brdf lut, prefilter and irradiance rows)").into())
            }
        }
    }

    /// Loads the scene, plans it and bakes it (or takes it from the cache), saying which.
    fn bake(&self, scene_path: &std::path::Path, backend: &Backend) -> anyhow::Result<(crate::scene::Scene, crate::prepare::SceneBake)> {
        let scene = crate::scene::Scene::load(scene_path)?;
        let cache = crate::cache::Cache::new(self.cache.clone().unwrap_or_else(crate::cache::default_dir));
        let start = Instant::now();
        let sb = crate::prepare::bake_scene(backend, &scene, &self.calibration()?, Some(&cache), self.force)?;
        let short = &sb.key[..12];
        match &sb.outcome {
            crate::prepare::Outcome::CacheHit => println!("cache hit {short}: nothing to bake ({})", cache.entry(&sb.key).display()),
            crate::prepare::Outcome::Baked => {
                println!("baked {} on {} in {:.2} s; cached as {short}", scene_path.display(), backend.describe(), start.elapsed().as_secs_f64())
            }
            crate::prepare::Outcome::Forced => println!("baked again (--force) in {:.2} s; cached as {short}", start.elapsed().as_secs_f64()),
            crate::prepare::Outcome::Rebuilt(why) => println!("cache entry {short} rejected ({why}); baked again in {:.2} s", start.elapsed().as_secs_f64()),
        }
        Ok((scene, sb))
    }
}

/// What to look at and how.
#[derive(Args, Clone)]
pub struct LookArgs {
    /// Diffuse model.
    #[arg(long, value_parser = choice::<DiffuseModel>(), default_value = DiffuseModel::default().name())]
    pub diffuse: DiffuseModel,
    /// Specular model.
    #[arg(long, value_parser = choice::<SpecularModel>(), default_value = SpecularModel::default().name())]
    pub specular: SpecularModel,
    /// Fresnel form.
    #[arg(long, value_parser = choice::<FresnelForm>(), default_value = FresnelForm::default().name())]
    pub fresnel: FresnelForm,
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
    #[arg(long, value_parser = choice::<Tonemapper>(), default_value = Tonemapper::default().name())]
    pub tonemapper: Tonemapper,
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
            tonemapper: self.tonemapper,
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
    #[arg(long, default_value_t = DISPLAY.size)]
    pub size: u32,
    /// GGX samples per specular texel.
    #[arg(long, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..), default_value_t = DISPLAY.samples)]
    pub samples: u32,
    /// Replace NaN/inf texels instead of refusing the environment.
    #[arg(long)]
    pub sanitize: bool,
}

impl DisplayBakeArgs {
    /// Bake settings for the display of `env`: the source cube as sharp as the environment
    /// (a quarter of an equirect's width, up to 1024), the rest from the flags.
    pub fn settings(&self, env: &environment::Environment) -> Settings {
        Settings { size: self.size, samples: self.samples, ..Settings::display(env.native_face_size()) }
    }

    /// The display's bake of `env` on `backend` (`render` and `view`): what it adjusts
    /// stated, a bake estimated over an hour refused unless `force`; with its seconds.
    pub fn bake(&self, env: &environment::Environment, backend: &Backend, force: bool) -> anyhow::Result<(splitsum::reading::BakedEnvironment, f64)> {
        use crate::bake;
        let job = self.settings(env).resolve(crate::settings::InputShape::of(env), crate::settings::Products::DISPLAY)?;
        for a in job.adjustments() {
            eprintln!("note: {}", a.describe(&flag_of));
        }
        bake::check_duration(&splitsum::estimate::step_seconds(&job, backend.is_gpu()), force)?;
        let start = Instant::now();
        let (baked, _) = splitsum::reading::for_display(backend, env, &job)?;
        Ok((baked, start.elapsed().as_secs_f64()))
    }
}

/// The quality knobs of a bake.
#[derive(Args, Clone)]
pub struct QualityArgs {
    /// Face size of mip 0 of the specular cube (a power of two).
    #[arg(long, default_value_t = DEFAULT.size)]
    pub size: u32,
    /// Face size of the source cube the products are filtered from [default: --size].
    #[arg(long)]
    pub source_size: Option<u32>,
    /// Whose conventions the files follow: splitsum's folder, or what the Khronos
    /// glTF-IBL-Sampler (glTF Sample Viewer), Bevy or Filament's cmgen write and their
    /// engines read (README, "Engine targets"). An engine target fixes the equirect's
    /// facing, the roughness per mip, the mip count and the table's masking term.
    #[arg(long, value_parser = choice::<Target>(), default_value = DEFAULT.target.name())]
    pub target: Target,
    /// Specular mips, one roughness each [default: down to 8×8 faces; the target's count
    /// for an engine target].
    #[arg(long)]
    pub mips: Option<u32>,
    /// How roughness is spread over the mips [default: geometric; the target's for an
    /// engine target].
    #[arg(long, value_parser = choice::<RoughnessMapping>())]
    pub mapping: Option<RoughnessMapping>,
    /// GGX samples per texel of specular mip 1 (the default, with --sample-growth 2, is the
    /// best end-to-end error per millisecond measured by `runner report` on city.exr).
    #[arg(long, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..), default_value_t = DEFAULT.samples)]
    pub samples: u32,
    /// Factor by which the sample count grows per mip after mip 1 (1 = the same on every mip).
    #[arg(long, default_value_t = DEFAULT.sample_growth)]
    pub sample_growth: u32,
    /// Sample every mip, even the rough ones that an exact sum over a coarse source level
    /// would bake for less.
    #[arg(long)]
    pub sampled_only: bool,
    /// Bias added to the source mip each prefilter sample reads (0.5: the best error at 1024
    /// samples in `runner report`, on city.exr's sun and on courtyard.exr).
    #[arg(long, default_value_t = DEFAULT.lod_bias, allow_negative_numbers = true)]
    pub lod_bias: f32,
    /// Equirect → cube supersampling: points per source texel width.
    #[arg(long, default_value_t = DEFAULT.supersample_density)]
    pub supersample: f32,
    /// Face size of the irradiance cube.
    #[arg(long, default_value_t = DEFAULT.irradiance_size)]
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
    #[arg(long, default_value_t = DEFAULT.lut_size)]
    pub lut_size: u32,
    /// Samples per texel of the BRDF table (with --lut-method sampled).
    #[arg(long, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..), default_value_t = DEFAULT.lut_samples)]
    pub lut_samples: u32,
    /// How the BRDF table is integrated: deterministic quadrature (within 1e-5) or sampling.
    #[arg(long, value_parser = choice::<TableMethod>(), default_value = DEFAULT.lut_method.name())]
    pub lut_method: TableMethod,
    /// The table's masking–shadowing term.
    /// [default: correlated; schlick with --lut-method sampled]
    #[arg(long, value_parser = choice::<Masking>())]
    pub lut_masking: Option<Masking>,
    /// KTX2 texel format; auto = RGBA16F unless a value exceeds 65504, then RGBA32F.
    #[arg(long, value_parser = choice::<Format>(), default_value = DEFAULT.format.name())]
    pub format: Format,
}

impl QualityArgs {
    /// The bake settings these flags describe (what a flag leaves out, the library derives
    /// from the others and the target; a flag that contradicts the target is refused by
    /// `Settings::resolve`, by its name).
    pub fn settings(&self) -> Settings {
        Settings {
            target: self.target,
            size: self.size,
            source_size: self.source_size,
            mips: self.mips,
            mapping: self.mapping,
            samples: self.samples,
            sample_growth: self.sample_growth,
            exact_sums: !self.sampled_only,
            lod_bias: self.lod_bias,
            supersample_density: self.supersample,
            irradiance_size: self.irradiance_size,
            irradiance_source: self.irradiance_source,
            sh_source: self.sh_source,
            lut_size: self.lut_size,
            lut_samples: self.lut_samples,
            lut_method: self.lut_method,
            lut_masking: self.lut_masking,
            format: self.format,
        }
    }
}

/// The one set of defaults, `splitsum::Settings::default()`, as the flags show them.
static DEFAULT: std::sync::LazyLock<Settings> = std::sync::LazyLock::new(Settings::default);

/// The display's quicker defaults, `splitsum::Settings::display`, as the flags show them.
static DISPLAY: std::sync::LazyLock<Settings> = std::sync::LazyLock::new(|| Settings::display(0));

/// Clap's parser for a [`Choice`]: its names, listed in the help.
pub(crate) fn choice<T: Choice + Send + Sync>() -> impl clap::builder::TypedValueParser<Value = T> {
    use clap::builder::TypedValueParser;
    clap::builder::PossibleValuesParser::new(T::ALL.iter().map(|c| c.name())).map(|name| T::from_name(&name).expect("clap accepts only the listed names"))
}

/// The flag that sets `field` (bake, bench and the display's quality flags), for messages
/// in the user's own terms.
pub(crate) fn flag(field: Field) -> &'static str {
    match field {
        Field::Target => "--target",
        Field::Size => "--size",
        Field::SourceSize => "--source-size",
        Field::Mips => "--mips",
        Field::Mapping => "--mapping",
        Field::Samples => "--samples",
        Field::SampleGrowth => "--sample-growth",
        Field::ExactSums => "--sampled-only",
        Field::LodBias => "--lod-bias",
        Field::SupersampleDensity => "--supersample",
        Field::IrradianceSize => "--irradiance-size",
        Field::IrradianceSource => "--irradiance-source",
        Field::ShSource => "--sh-source",
        Field::LutSize => "--lut-size",
        Field::LutSamples => "--lut-samples",
        Field::LutMethod => "--lut-method",
        Field::LutMasking => "--lut-masking",
        Field::Format => "--format",
    }
}

/// [`flag`] as an owned string, as `Adjustment::describe` and `Unread::describe` take it.
pub(crate) fn flag_of(field: Field) -> String {
    flag(field).to_string()
}

/// A request refused as written: a flag, its value, flags that contradict each other, the
/// target or the scene, a scene file's fields, an output path that may not be replaced, a
/// bake estimated over an hour without `--force`. Nothing was done. The process exits with
/// [`USAGE_EXIT`], as for clap's own errors; see [`exit_code`].
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct Usage(String);

impl Usage {
    /// A refused request, in the user's terms.
    pub fn new(message: impl Into<String>) -> Self {
        Self(message.into())
    }
}

/// Exit status of a request refused as written ([`Usage`], clap's errors).
pub const USAGE_EXIT: i32 = 2;
/// Exit status of work that failed: an input that cannot be read or decoded, no GPU, a
/// device error, a full disk.
pub const FAILURE_EXIT: i32 = 1;

/// The one exit-code rule: [`USAGE_EXIT`] for a request refused as written (before any
/// work: nothing was written), [`FAILURE_EXIT`] for work that failed; 130 after an
/// interruption (`files::remove_staging_on_interrupt`); 0 on success.
pub fn exit_code(e: &anyhow::Error) -> i32 {
    if e.downcast_ref::<Usage>().is_some() || e.downcast_ref::<clap::Error>().is_some() {
        return USAGE_EXIT;
    }
    match e.downcast_ref::<splitsum::Error>() {
        Some(splitsum::Error::Setting { .. } | splitsum::Error::Invalid(_) | splitsum::Error::TooLong { .. }) => USAGE_EXIT,
        _ => FAILURE_EXIT,
    }
}

/// A library error in the user's terms: a setting by the flag `flag` names for it, a refused
/// long bake with the flags that set its cost and `--force`, unreadable texels with
/// `--sanitize`.
pub(crate) fn in_flags(e: splitsum::Error, flag: &dyn Fn(Field) -> String) -> anyhow::Error {
    match e {
        splitsum::Error::Setting { field, problem } => Usage::new(format!("{} {problem}", flag(field))).into(),
        splitsum::Error::TooLong { step, .. } => {
            let flags: Vec<String> = step.cost_fields().iter().map(|f| flag(*f)).collect();
            Usage::new(format!("{e}; lower {} (scene: [quality]), or pass --force to run it anyway", flags.join(" and "))).into()
        }
        splitsum::Error::Invalid(m) => Usage::new(m).into(),
        splitsum::Error::NonFinite { .. } => anyhow::anyhow!("{e}: pass --sanitize to do so"),
        splitsum::Error::NoAdapter { .. } => anyhow::anyhow!("{e}\n  (`--backend cpu` bakes on the CPU)"),
        e => e.into(),
    }
}

/// Refuses, by name, a flag in `given` that sets a setting this bake does not read
/// (`Settings::unread`): it would change nothing.
fn refuse_unread(given: &[String], settings: &Settings, products: Products, cube_input: bool) -> anyhow::Result<()> {
    for (field, why) in settings.unread(products, cube_input) {
        let flag = flag_of(field);
        if given.contains(&flag) {
            return Err(Usage::new(format!("{flag} has no effect here: {}; drop it", why.describe(settings.target, &flag_of))).into());
        }
    }
    Ok(())
}

/// [`in_flags`] for a bake's flags.
pub(crate) fn bake_error(e: splitsum::Error) -> anyhow::Error {
    in_flags(e, &flag_of)
}

/// With `--scene`, the scene file sets everything but where and how to run: refuses any
/// other flag in `given`, naming them and the scene tables that set them.
fn refuse_beside_scene(given: &[String], allowed: &[&str]) -> anyhow::Result<()> {
    let extra: Vec<&str> = given.iter().map(String::as_str).filter(|f| !allowed.contains(f) && *f != "--scene" && *f != "--env").collect();
    if !extra.is_empty() {
        return Err(Usage::new(format!(
            "with --scene, the scene file sets the environment, [quality], [camera], [output] and the materials: drop {} (or edit the scene)",
            extra.join(", ")
        ))
        .into());
    }
    Ok(())
}

/// The flags that still apply beside `--scene`: where and how to run, and the cache.
const SCENE_FLAGS: [&str; 6] = ["--force", "--cache", "--calibration", "--out", "--backend", "--format"];

/// Parses `args` (the program name first) as [`run`] does, and runs nothing: whether a
/// command line is one the runner takes, as written (the README's commands are checked
/// with it).
pub fn parses<I, T>(args: I) -> Result<(), clap::Error>
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    use clap::CommandFactory;
    Cli::command().try_get_matches_from(args).map(|_| ())
}

/// Parses `args` (the program name first) and runs the command.
/// The command-line reference as Markdown: `runner --help` and every subcommand's, as the
/// binary prints them. The guide's `book/src/cli.md` is this text, and a test
/// (`tests/book.rs`) fails when the two differ, so the chapter cannot drift from the flags.
pub fn reference_markdown() -> String {
    use clap::CommandFactory;
    let mut command = Cli::command();
    command.build();
    let mut out = String::from(
        "# The command line\n\n<!-- Generated from the clap definitions (runner::cli::reference_markdown); \
         regenerate with SPLITSUM_BLESS=1 cargo test --release -p splitsum-tests --test suite book -->\n\n\
         Every subcommand's `--help`, as `runner` prints it. [Commands, baking and the defaults](commands.md) \
         says what the defaults are and why.\n",
    );
    let mut section = |name: &str, help: String| {
        out.push_str(&format!("\n## `{name}`\n\n```text\n{}\n```\n", help.trim_end()));
    };
    section("runner", command.render_long_help().to_string());
    for sub in command.get_subcommands_mut().filter(|s| s.get_name() != "help") {
        let name = format!("runner {}", sub.get_name());
        section(&name, sub.render_long_help().to_string());
    }
    out
}

pub fn run<I, T>(args: I) -> anyhow::Result<()>
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    use clap::{CommandFactory, FromArgMatches};
    crate::bars::install();
    crate::files::remove_staging_on_interrupt();
    let raw: Vec<std::ffi::OsString> = args.into_iter().map(Into::into).collect();
    let matches = Cli::command().try_get_matches_from(&raw)?;
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
    let result = match cli.command {
        Some(Command::Lut(args)) => lut::lut(args, &given),
        Some(Command::Bake(args)) => bake::bake_command(args, &given),
        Some(Command::Bench(args)) => bench::bench(args, &raw),
        Some(Command::Render(args)) => render::render(args, &given),
        Some(Command::View(args)) => view::view(args, &given),
        Some(Command::Report(args)) => report::report(args),
        Some(Command::Plan(args)) => plan::plan_command(args),
        None => default::default_run(),
    };
    // The library speaks of fields; say the flags the user wrote.
    result.map_err(|e| match e.downcast::<splitsum::Error>() {
        Ok(e) => bake_error(e),
        Err(e) => e,
    })
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
    for a in input.adjustments(&env) {
        eprintln!("note: {}: {}", path.display(), a.describe(&flag_of));
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
