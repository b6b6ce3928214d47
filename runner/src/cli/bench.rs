//! `runner bench`: bake time per step on each backend against its estimate (as the
//! progress showed it) and against the cost model (each step's work counted from the job,
//! the device's limits measured by the calibration kernel), and peak memory.

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
    /// Time budgets (seconds) for the budget-to-error curve: for each, the settings
    /// `--budget` would choose on each backend, their predicted error, estimated and
    /// measured time.
    #[arg(long, value_delimiter = ',', value_name = "SECONDS")]
    budgets: Vec<f64>,
    /// Run even if the bake is estimated to take over an hour.
    #[arg(long)]
    force: bool,
    /// Bake the sheen cube and tables too (their steps timed and modelled like the others).
    #[arg(long)]
    sheen: bool,
    /// Time whole processes instead, as a user runs them: a child `runner bake ENV` with
    /// these quality flags on each backend, N times after a warm-up, its wall time and its
    /// peak memory as the kernel counts it (medians)
    #[arg(long, value_name = "N")]
    processes: Option<u32>,
    /// With --processes: another program's commands (a shell command line each, run one
    /// after another in a scratch folder, with $INPUT the environment's absolute path)
    /// that take their turn with each run, for the median of the pairs' wall ratios, which
    /// load on a shared machine leaves standing
    #[arg(long, value_name = "COMMAND", requires = "processes")]
    versus: Vec<String>,
    /// With --processes: write the table, the command line, date, machine and commit to
    /// this Markdown file (for the guide to include); only a file runner bench wrote is
    /// replaced
    #[arg(long, value_name = "FILE", requires = "processes")]
    figures: Option<PathBuf>,
}

pub(super) fn bench(args: BenchArgs, raw: &[std::ffi::OsString]) -> anyhow::Result<()> {
    if let Some(runs) = args.processes {
        #[cfg(unix)]
        return super::processes::run(&super::processes::Plan {
            env: &args.env,
            quality: super::processes::quality_tokens(raw),
            sheen: args.sheen,
            backends: &args.backends,
            runs,
            versus: &args.versus,
            figures: args.figures.as_deref(),
        });
        #[cfg(not(unix))]
        anyhow::bail!("--processes {runs}: whole-process timing needs a Unix system (wait4)");
    }
    let settings = args.quality.settings();
    // What `runner bake` makes for this target, and the sheen products with `--sheen`.
    let products = settings.target.products().with_sheen(args.sheen);
    let source_size = settings.resolve(InputShape::Unknown, products)?.source_size;
    let (env, _) = load_input(&args.env, false, source_size)?;
    let job = settings.resolve(InputShape::of(&env), products)?;
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
                println!("{kind:?}: skipped ({})", splitsum::error::chain(&e));
                continue;
            }
        };
        bake::check_duration(&splitsum::estimate::step_seconds(&job, backend.is_gpu()), args.force)?;
        // The fastest run of each step, with the estimate shown as that run's step started
        // (the estimator learns from every run: later runs are estimated by what the
        // earlier ones took, as in a batch).
        let mut best: Vec<bake::Timing> = Vec::new();
        for _ in 0..args.runs.max(1) {
            let baked = bake::bake_job(&backend, &env, &job)?;
            if best.is_empty() {
                best = baked.timings;
            } else {
                for (b, t) in best.iter_mut().zip(baked.timings) {
                    if t.seconds < b.seconds {
                        *b = t;
                    }
                }
            }
        }
        println!("{}", backend.describe());
        let machine = splitsum::cost::measure_machine(&backend, splitsum::cost::Calibrating::THOROUGH)?;
        println!(
            "  limits by the calibration kernel: {:.2} G filtered texel reads/s, {:.2} G summed texel reads/s, {:.1} GFLOP/s",
            machine.filtered_reads * 1e-9,
            machine.summed_reads * 1e-9,
            machine.flops * 1e-9
        );
        println!(
            "  {:<12} {:>9} {:>10} {:>7} {:>10} {:>10} {:>9} {:>8} {:>10} {:>9}  bound by",
            "step", "seconds", "estimate", "off", "filt. M", "summ. M", "GFLOP", "MB", "limit s", "of limit"
        );
        let work = splitsum::cost::step_work(&job);
        for t in &best {
            let step = &work.iter().find(|(s, _)| *s == t.step).expect("every step").1;
            let (limit, bound) = machine.limit(step);
            let w = step.total();
            let fraction = if t.seconds > 0.0 && limit > 0.0 { format!("{:.0} %", 100.0 * limit / t.seconds) } else { "-".into() };
            let (estimate, off) = match t.estimate {
                Some(e) => (format!("{e:.3}"), if t.seconds > 0.0 { format!("{:+.0} %", 100.0 * (e / t.seconds - 1.0)) } else { "-".into() }),
                None => ("-".into(), "-".into()),
            };
            println!(
                "  {:<12} {:>9.3} {:>10} {:>7} {:>10.1} {:>10.1} {:>9.2} {:>8.1} {:>10.4} {:>9}  {}",
                t.step.name(),
                t.seconds,
                estimate,
                off,
                w.filtered_reads * 1e-6,
                w.summed_reads * 1e-6,
                w.flops * 1e-9,
                w.bytes * 1e-6,
                limit,
                fraction,
                if limit > 0.0 { bound } else { "-" }
            );
        }
        println!("  {:<12} {:>9.3} s", "total", best.iter().map(|t| t.seconds).sum::<f64>());
        if !args.budgets.is_empty() {
            println!("  budget-to-error curve (predicted error: the built-in error model, end to end)");
            println!("  {:>9} {:>8} {:>11} {:>10} {:>11} {:>10}", "budget s", "samples", "irradiance", "error", "estimate s", "bake s");
            for &budget in &args.budgets {
                let estimator = splitsum::estimate::for_backend(&backend)?;
                let (chosen, error, estimate) =
                    splitsum::estimate::for_budget(&settings, InputShape::of(&env), products, budget, &estimator, &splitsum::cost::Calibration::default())?;
                let job = chosen.resolve(InputShape::of(&env), products)?;
                let seconds: f64 = bake::bake_job(&backend, &env, &job)?.timings.iter().map(|t| t.seconds).sum();
                println!("  {budget:>9} {:>8} {:>10}² {:>9.1} % {estimate:>11.3} {seconds:>10.3}", chosen.samples, job.irradiance_source, 100.0 * error);
            }
        }
    }
    if let Some(peak) = peak_memory() {
        println!("peak memory of this process (VmHWM, all backends so far): {:.0} MiB", peak as f64 / 1048576.0);
    }
    Ok(())
}
