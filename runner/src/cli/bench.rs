//! `runner bench`: bake time per product on each backend, and peak memory.

use super::*;
use crate::bake;
use crate::settings::InputShape;

#[derive(Args)]
pub(super) struct BenchArgs {
    /// The environment (as for `bake`).
    env: PathBuf,
    #[command(flatten)]
    quality: QualityArgs,
    /// Backends to time.
    #[arg(long, value_parser = choice::<BackendKind>(), num_args = 1.., default_values = ["gpu", "cpu"])]
    backends: Vec<BackendKind>,
    /// Runs per backend; the table shows the fastest.
    #[arg(long, default_value_t = 1)]
    runs: u32,
    /// Run even if the bake is estimated to take over an hour.
    #[arg(long)]
    force: bool,
}

pub(super) fn bench(args: BenchArgs) -> anyhow::Result<()> {
    let settings = args.quality.settings();
    let source_size = settings.resolve(InputShape::Unknown, Products::ALL)?.source_size;
    let (env, _) = load_input(&args.env, false, source_size)?;
    let job = settings.resolve(InputShape::of(&env), Products::ALL)?;
    println!(
        "bench: {} at size {}, {} mips ({:?}), {:?} samples per mip, irradiance {}² from {}², SH9 from {}², table {}",
        args.env.display(),
        job.size,
        job.mips,
        job.mapping,
        job.samples_per_mip,
        job.irradiance_size,
        job.irradiance_source,
        job.sh_source,
        job.table_description()
    );
    for kind in &args.backends {
        let backend = match Backend::open(*kind) {
            Ok(b) => b,
            Err(e) => {
                println!("{kind:?}: skipped ({e})");
                continue;
            }
        };
        bake::check_duration(&bake::step_estimates(backend.is_gpu(), &job), args.force)?;
        let mut best: Vec<bake::Timing> = Vec::new();
        for _ in 0..args.runs.max(1) {
            let baked = bake::bake_job(&backend, &env, &job)?;
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
            println!("  {:<12} {:>9.3} s", t.step.name(), t.seconds);
        }
        println!("  {:<12} {:>9.3} s", "total", best.iter().map(|t| t.seconds).sum::<f64>());
    }
    if let Some(peak) = peak_memory() {
        println!("peak memory of this process (VmHWM, all backends so far): {:.0} MiB", peak as f64 / 1048576.0);
    }
    Ok(())
}
