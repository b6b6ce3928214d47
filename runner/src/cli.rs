//! The command line: parsing with clap, then orchestration of backends and files.

use anyhow::Context;
use clap::{Args, Parser, Subcommand};
use crate::files;
use crate::{Backend, BackendKind};
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
