//! The command line: parsing with clap, then orchestration of backends and files.

use anyhow::Context;
use clap::{Args, Parser, Subcommand};
use crate::bake::{self, Mapping, Products, Settings};
use crate::environment;
use crate::files;
use crate::ktx2::Format;
use crate::{Backend, BackendKind};
use splitsum_shaders::cubemap::CubeLayout;
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
}

/// The quality knobs of a bake.
#[derive(Args, Clone)]
pub struct QualityArgs {
    /// Face size of the source cube and of mip 0 of the specular cube (a power of two).
    #[arg(long, default_value_t = 256)]
    pub size: u32,
    /// Specular mips, one roughness each [default: down to 8×8 faces].
    #[arg(long)]
    pub mips: Option<u32>,
    /// How roughness is spread over the mips.
    #[arg(long, value_enum, default_value_t = Mapping::Linear)]
    pub mapping: Mapping,
    /// GGX samples per specular texel.
    #[arg(long, default_value_t = 1024)]
    pub samples: u32,
    /// Bias added to the source mip each prefilter sample reads.
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    pub lod_bias: f32,
    /// Equirect → cube supersampling: points per source texel width.
    #[arg(long, default_value_t = 2.0)]
    pub supersample: f32,
    /// Face size of the irradiance cube.
    #[arg(long, default_value_t = 32)]
    pub irradiance_size: u32,
    /// Face size of the source mip the irradiance convolution sums over.
    #[arg(long, default_value_t = 32)]
    pub irradiance_source: u32,
    /// Face size of the source mip projected onto SH9.
    #[arg(long, default_value_t = 64)]
    pub sh_source: u32,
    /// Width and height of the BRDF table.
    #[arg(long, default_value_t = 256)]
    pub lut_size: u32,
    /// Samples per texel of the BRDF table.
    #[arg(long, default_value_t = 1024)]
    pub lut_samples: u32,
    /// KTX2 texel format; auto = RGBA16F unless a value exceeds 65504, then RGBA32F.
    #[arg(long, value_enum, default_value_t = Format::Auto)]
    pub format: Format,
}

impl QualityArgs {
    /// The bake settings these flags describe.
    pub fn settings(&self) -> Settings {
        let mips = self.mips.unwrap_or_else(|| CubeLayout::full_chain(self.size.max(1)).saturating_sub(3).max(1));
        Settings {
            size: self.size,
            mips,
            mapping: self.mapping,
            samples: self.samples,
            lod_bias: self.lod_bias,
            supersample_density: self.supersample,
            irradiance_size: self.irradiance_size,
            irradiance_source: self.irradiance_source,
            sh_source: self.sh_source,
            lut_size: self.lut_size,
            lut_samples: self.lut_samples,
            format: self.format,
        }
    }
}

#[derive(Args)]
struct BakeArgs {
    /// The environment: an equirectangular .hdr or .exr, or a folder holding six faces
    /// px nx py ny pz nz (.hdr or .exr) in Vulkan/KTX2 orientation.
    env: PathBuf,
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
}

#[derive(Args)]
struct LutArgs {
    /// Table width and height: column x holds NdotV = (x+0.5)/S, row y roughness = (y+0.5)/S.
    #[arg(long, default_value_t = 256)]
    size: u32,
    /// Hammersley points per texel.
    #[arg(long, default_value_t = 1024)]
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
}

/// Parses `args` (the program name first) and runs the command.
pub fn run<I, T>(args: I) -> anyhow::Result<()>
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    let cli = Cli::try_parse_from(args)?;
    match cli.command {
        Some(Command::Lut(args)) => lut(args),
        Some(Command::Bake(args)) => bake_command(args),
        Some(Command::Bench(args)) => bench(args),
        None => lut(LutArgs {
            size: 256,
            samples: 1024,
            backend: BackendKind::Gpu,
            out: PathBuf::from("lut.exr"),
            png: true,
        }),
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
    let lut = backend.brdf_lut(args.size, args.samples)?;
    let secs = start.elapsed().as_secs_f64();
    files::write_lut_exr(&args.out, &lut).context("writing the BRDF table")?;
    println!(
        "brdf lut {}x{} at {} samples/texel on {}: bake {:.3} s",
        args.size,
        args.size,
        args.samples,
        backend.describe(),
        secs
    );
    println!("wrote {}", args.out.display());
    if let Some(p) = png {
        files::write_png(&p, lut.size, lut.size, &files::lut_preview(&lut))?;
        println!("wrote {}", p.display());
    }
    Ok(())
}

fn bake_command(args: BakeArgs) -> anyhow::Result<()> {
    let settings = args.quality.settings();
    settings.validate()?;
    std::fs::create_dir_all(&args.out).map_err(|e| crate::Error::file(&args.out, format!("cannot create the output folder: {e}")))?;
    files::check_writable(&args.out.join("bake.json"))?;
    let (env, input) = environment::load(&args.env, args.sanitize)?;
    if input.negative > 0 {
        eprintln!("note: {}: {} texels had negative values, set to 0", args.env.display(), input.negative);
    }
    if input.sanitized && (input.nan > 0 || input.infinite > 0) {
        eprintln!("note: {}: replaced {} NaN and {} infinite texels (--sanitize)", args.env.display(), input.nan, input.infinite);
    }
    let backend = Backend::open(args.backend)?;
    println!("baking {} on {}", args.env.display(), backend.describe());
    let baked = bake::bake(&backend, &env, &settings, Products::ALL)?;
    let manifest = bake::Manifest {
        environment: args.env.display().to_string(),
        backend: backend.describe(),
        settings: settings.clone(),
        roughness_per_mip: settings.roughness(),
        input: (&input).into(),
        timings: Vec::new(),
        sh9_vs_convolution: None,
        files: Vec::new(),
        conventions: bake::CONVENTIONS.to_vec(),
    };
    let manifest = bake::write(&args.out, &baked, &settings, manifest)?;
    for t in &manifest.timings {
        println!("  {:<12} {:>9.3} s", t.product, t.seconds);
    }
    println!("  {:<12} {:>9.3} s", "total", manifest.timings.iter().map(|t| t.seconds).sum::<f64>());
    if let Some(e) = manifest.sh9_vs_convolution {
        println!(
            "  SH9 irradiance vs the convolution: max relative error {:.1} %, rms {:.1} %",
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
    let (env, _) = environment::load(&args.env, false)?;
    println!(
        "bench: {} at size {}, {} mips, {} samples/texel, irradiance {}² from {}², SH9 from {}², LUT {}² × {}",
        args.env.display(),
        settings.size,
        settings.mips,
        settings.samples,
        settings.irradiance_size,
        settings.irradiance_source,
        settings.sh_source,
        settings.lut_size,
        settings.lut_samples
    );
    for kind in &args.backends {
        let backend = match Backend::open(*kind) {
            Ok(b) => b,
            Err(e) => {
                println!("{kind:?}: skipped ({e})");
                continue;
            }
        };
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
    Ok(())
}
