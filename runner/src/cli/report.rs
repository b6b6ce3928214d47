//! `runner report`: error against run time of every product and of the shaded colour.

use super::*;
use splitsum::measured::{Knob, Measurement, Method, Metric, Quantity, Set};

#[derive(Args)]
pub(super) struct ReportArgs {
    /// The environment [default: the embedded courtyard].
    env: Option<PathBuf>,
    /// Output folder.
    #[arg(long, default_value = "report")]
    out: PathBuf,
    /// Smaller sweeps that finish in seconds (CI).
    #[arg(long)]
    quick: bool,
    /// Backends to measure (those that cannot be opened are skipped, with a note).
    #[arg(long, value_parser = choice::<BackendKind>(), num_args = 1.., default_values = ["gpu", "cpu"])]
    backends: Vec<BackendKind>,
    /// Also measure the shaded colour over the tuning set and the held-out set of
    /// environments (a few minutes more; with --quick, only the environments present).
    #[arg(long)]
    sets: bool,
    /// The folder of Blender's CC0 studio lights the sets read (`bash scripts/dev.sh
    /// environments` fetches them there).
    #[arg(long, default_value = "target/environments", requires = "sets")]
    environments: PathBuf,
    /// Measure only this set: iterate on the tuning set without looking at the held-out one.
    #[arg(long, value_parser = choice::<Set>(), requires = "sets")]
    set: Option<Set>,
}

pub(super) fn report(args: ReportArgs) -> anyhow::Result<()> {
    let (env, name) = load_environment(args.env.as_deref(), false)?;
    let mut backends = Vec::new();
    for kind in &args.backends {
        match Backend::open(*kind) {
            Ok(b) => backends.push(b),
            Err(e) => eprintln!("{kind:?}: skipped ({})", splitsum::error::chain(&e)),
        }
    }
    anyhow::ensure!(!backends.is_empty(), "no backend could be opened");
    let sweep = if args.quick { splitsum_report::sweep::Sweep::quick() } else { splitsum_report::sweep::Sweep::full() };
    let start = Instant::now();
    let out = files::OutputDir::begin(&args.out, "--out")?;
    let sets = args.sets.then(|| splitsum_report::sweep::Sets { dir: args.environments.clone(), present_only: args.quick, only: args.set });
    let costs = ladder_costs(&env, &backends, args.quick)?;
    let rows = crate::report::run(&env, &name, &backends, &sweep, sets.as_ref(), &costs, out.path())?;
    out.commit()?;
    println!("{} measurements in {:.1} s", rows.len(), start.elapsed().as_secs_f64());
    for (panel, r) in splitsum_report::pages::best_per_ms(&rows) {
        let ms = r.time_ms.unwrap_or(f64::NAN);
        println!("  best error per ms: {panel:<44} {:<4} {:<24} {ms:>9.1} ms  mean error {:.2e}", r.backend, r.setting(), r.mean_error);
    }
    println!("wrote {0}/report.html (open it in a browser), report.md, report.csv and the figures", args.out.display());
    Ok(())
}

/// What each rung of the shading ladder costs per shaded pixel on each backend (the
/// renderer is the display's, which the report crate does not depend on): the default bake
/// of `env` at 128² (64² with `quick`), frames of 256² (64²), best of three (one).
fn ladder_costs(env: &environment::Environment, backends: &[Backend], quick: bool) -> anyhow::Result<Vec<Measurement>> {
    use splitsum_shaders::shade::{LADDER_RUNGS, ShadeOptions};
    let _step = crate::progress::step("report: the shading ladder's cost per pixel", None);
    let (size, frame, repeats) = if quick { (64, 64, 1) } else { (128, 256, 3) };
    let mut rows = Vec::new();
    for backend in backends {
        let baked = splitsum::reading::bake_for_display(backend, env, &crate::settings::Settings { size, ..crate::settings::Settings::default() })?;
        let device = splitsum_report::measurement::Device::of(backend);
        // The rungs, and the quality mode below mip 1 (`--filtered`) for its cost beside them.
        let filtered =
            (Method::FilteredSampling, 1, ShadeOptions { flags: ShadeOptions::DEFAULT.flags | ShadeOptions::FILTERED_SAMPLING, ..ShadeOptions::DEFAULT });
        let rungs = (0..LADDER_RUNGS).map(|rung| {
            let fetches = 1 << rung;
            (splitsum_report::pages::rung_method(fetches), fetches, ShadeOptions::DEFAULT.with_fetches(fetches))
        });
        for (method, fetches, options) in rungs.chain([filtered]) {
            let ns = crate::render::shading_ns_per_pixel(backend, &baked, options, frame, repeats)?;
            rows.push(Measurement {
                knob: Knob::Fetches,
                fetches: Some(fetches),
                ns_per_pixel: Some(ns),
                mean_error: f64::NAN,
                max_error: f64::NAN,
                ..device.row(Quantity::ShadingCost, method, &[], Metric::RelativeLuminance)
            });
        }
    }
    Ok(rows)
}
