//! `runner lut`: the split-sum BRDF table alone.

use super::*;
use crate::settings::Product;

#[derive(Args)]
pub(super) struct LutArgs {
    /// Table width and height: column x holds NdotV = (x+0.5)/S, row y roughness = (y+0.5)/S.
    #[arg(long, default_value_t = 256)]
    size: u32,
    /// Deterministic quadrature (within 1e-5 of the f64 reference) or Hammersley sampling.
    #[arg(long, value_parser = choice::<TableMethod>(), default_value = TableMethod::Quadrature.name())]
    method: TableMethod,
    /// Masking–shadowing term: the exact height-correlated Smith or Smith–Schlick (k = α/2)
    /// [default: correlated; schlick with --method sampled].
    #[arg(long, value_parser = choice::<Masking>())]
    masking: Option<Masking>,
    /// Hammersley points per texel (with --method sampled).
    #[arg(long, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..), default_value_t = 1024)]
    samples: u32,
    /// Where to bake: auto (the GPU; the CPU where the best adapter is a software
    /// rasteriser such as lavapipe, or there is none), gpu (the best adapter, even a
    /// software one), cpu.
    #[arg(long, value_parser = choice::<BackendKind>(), default_value = "auto")]
    backend: BackendKind,
    /// Output OpenEXR file (R = scale, G = bias, 32-bit float).
    #[arg(long, default_value = "lut.exr")]
    out: PathBuf,
    /// Also write an 8-bit PNG preview of the table (R = scale, G = bias, stored linearly)
    /// to this file.
    #[arg(long, value_name = "FILE")]
    png: Option<PathBuf>,
    /// Run even if the table is estimated to take over an hour.
    #[arg(long)]
    force: bool,
}

pub(super) fn lut(args: LutArgs, given: &[String]) -> anyhow::Result<()> {
    if args.method != TableMethod::Sampled && given.iter().any(|f| f == "--samples") {
        return Err(Usage::new("--samples sets the sampled table's count; the quadrature table (--method quadrature, the default) takes none: drop --samples, or add --method sampled").into());
    }
    files::check_output_file(&args.out, files::FileKind::Exr, "--out")?;
    let png = args.png.clone();
    if let Some(p) = &png {
        files::check_output_file(p, files::FileKind::Png, "--png")?;
        if same_file(p, &args.out) {
            return Err(
                Usage::new(format!("--png {} and --out {} name the same file: give the preview a name of its own", p.display(), args.out.display())).into()
            );
        }
    }
    // The table's flags, named as this command names them.
    let lut_flag = |f: Field| match f {
        Field::LutSize => "--size".to_string(),
        Field::LutSamples => "--samples".to_string(),
        Field::LutMethod => "--method".to_string(),
        Field::LutMasking => "--masking".to_string(),
        f => flag_of(f),
    };
    let in_flags = |e| in_flags(e, &lut_flag);
    let settings = Settings { lut_size: args.size, lut_samples: args.samples, lut_method: args.method, lut_masking: args.masking, ..Settings::default() };
    let only_table = Products::of(&[Product::BrdfTable]);
    let job = settings.resolve(crate::settings::InputShape::Unknown, only_table).map_err(in_flags)?;
    let backend = Backend::open(args.backend)?;
    let start = Instant::now();
    // A table alone needs no source cube: its own step's estimate is the run's.
    let mut table = crate::cost::PerStep::default();
    table[Product::BrdfTable] = splitsum::estimate::step_seconds(&job, backend.is_gpu())[Product::BrdfTable];
    crate::bake::check_duration(&table, args.force).map_err(in_flags)?;
    let lut = match job.lut_method {
        TableMethod::Quadrature => backend.brdf_table(job.lut_size, job.lut_masking),
        TableMethod::Sampled => backend.brdf_lut(job.lut_size, job.lut_samples),
    }
    .map_err(in_flags)?;
    let secs = start.elapsed().as_secs_f64();
    files::write_lut_exr(&args.out, &lut).context("writing the BRDF table")?;
    println!("brdf lut {} on {}: bake {:.3} s", job.table_description(), backend.describe(), secs);
    println!("wrote {}", args.out.display());
    if let Some(p) = png {
        files::write_png(&p, lut.size, lut.size, &files::lut_preview(&lut))?;
        println!("wrote {}", p.display());
    }
    Ok(())
}

/// Whether `a` and `b` name the same file (the same path as written, or the same existing
/// file by another path).
fn same_file(a: &std::path::Path, b: &std::path::Path) -> bool {
    a == b || matches!((std::fs::canonicalize(a), std::fs::canonicalize(b)), (Ok(x), Ok(y)) if x == y)
}
