//! What each step of a bake will take on the device at hand, and how sure that is: the
//! progress shows it as each step starts, `runner bake` and `runner bench` beside the time
//! measured, and `--budget` chooses by it.
//!
//! The cost model counts each step's work by kind (`cost::step_work`: filtered texel reads,
//! summed texel reads, floating-point operations) and the calibration kernel measures what
//! the device does per second of each kind *now*, under whatever load the machine carries
//! (`cost::measure_machine`, about 0.1 s before the first bake of a process on 2 CPU
//! cores, 0.3 s on lavapipe; none for a bake too small to show an estimate). The least
//! time a step can take is the sum over its passes (a prefiltered cube's split and levels,
//! each level's excess list apart) of each pass's slowest kind of work at those rates (its
//! limit); a step reaches a share of that limit that depends on its code more than on the
//! device or the load, so
//!
//! ```text
//!     estimate(step) = Σ over its passes of limit(pass) / share(step, pass) · c
//! ```
//!
//! where the limit is at the rates the device reaches unloaded, divided by the share of the
//! processors this process gets now where the work runs on them ([`availability`]), the
//! shares measured by `runner bench` here (`Product::share`), and `c`
//! the geometric mean of measured/estimated over the steps already done in this process,
//! shrunk towards 1 as if one more step had been exactly right: a load that changes after
//! the calibration moves the later estimates with it. How sure: before any step has been
//! timed, the 90th percentile of the model's error measured quiet ([`MODEL_SPREAD`]) or
//! under load ([`LOADED_SPREAD`]); after, the larger of that and how far the steps done
//! were off.

use crate::cost::{Machine, step_work};
use crate::settings::{Job, Product};

// What progress shows of an estimate, and from how long a step on: progress's own (it
// depends on nothing here; the cost model this module reads depends on the backends,
// which speak through progress).
pub use crate::progress::Estimate;
use crate::progress::SHOWN;

/// How far a step's estimate may be off before any step of this process has been timed,
/// on a quiet machine: the 90th percentile of |estimate/measured − 1| over the steps shown
/// in three quiet runs of the six configurations on both backends (32 %, 96 steps).
pub const MODEL_SPREAD: f64 = 0.3;

/// The same where the process gets less than [`LOADED`] of its processors: the 90th
/// percentile with `stress-ng --cpu 4` beside the runs (51 %, 107 steps).
pub const LOADED_SPREAD: f64 = 0.5;

/// The share of its processors below which the machine counts as loaded.
pub const LOADED: f64 = 0.8;

/// Steps shorter than this (seconds) teach the estimator nothing: their time is mostly
/// fixed costs (a dispatch, an upload, a scheduler's slice) the limits do not model.
pub const SHORTEST: f64 = 0.05;

/// Where an estimator's rates come from.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum Rates {
    /// Measured on this device by the calibration kernel, in `seconds`.
    Measured {
        /// How long the calibration ran.
        seconds: f64,
    },
    /// The built-in rates of 2 CPU cores or lavapipe: nothing measured here.
    BuiltIn,
}

/// Estimates the steps of bakes on one device, and learns from each step timed.
#[derive(Clone, Debug)]
pub struct Estimator {
    machine: Machine,
    /// The share of its processors this process gets (1 on a quiet machine, and for a
    /// hardware GPU, whose work is not the processors').
    availability: f64,
    gpu: bool,
    /// Σ ln(measured/estimated) over the steps timed, and their count.
    log_ratio: f64,
    timed: f64,
    /// The largest |measured/estimated − 1| so far.
    worst: f64,
    /// Where the rates come from.
    pub rates: Rates,
}

impl Estimator {
    /// An estimator from `machine`'s measured rates, for a GPU (`gpu`) or the CPU.
    pub fn new(machine: Machine, gpu: bool, rates: Rates) -> Self {
        Self { machine, availability: 1.0, gpu, log_ratio: 0.0, timed: 0.0, worst: 0.0, rates }
    }

    /// The estimator with the share of its processors this process gets (see
    /// [`availability`]): every estimate is divided by it.
    pub fn with_availability(self, availability: f64) -> Self {
        Self { availability: availability.clamp(0.02, 1.0), ..self }
    }

    /// An estimator from the built-in rates of lavapipe (`gpu`) or 2 CPU cores, measured
    /// quiet on the machines of this project: a library bake that shows no progress uses
    /// these, and measures nothing.
    pub fn built_in(gpu: bool) -> Self {
        Self::new(if gpu { BUILT_IN_LAVAPIPE } else { BUILT_IN_CPU }, gpu, Rates::BuiltIn)
    }

    /// The correction `c` of the model (see the module's header).
    fn correction(&self) -> f64 {
        (self.log_ratio / (self.timed + 1.0)).exp()
    }

    /// The estimate of each step of `job`, in the order of [`Product::ALL`].
    pub fn steps(&self, job: &Job) -> [(Product, Estimate); Product::COUNT] {
        let c = self.correction();
        let base = if self.availability < LOADED { LOADED_SPREAD } else { MODEL_SPREAD };
        let within = if self.rates == Rates::BuiltIn { f64::INFINITY } else { base.max(self.worst) };
        let work = step_work(job);
        let mut out = Product::ALL.map(|s| (s, Estimate { seconds: 0.0, within }));
        for (k, (step, w)) in work.iter().enumerate() {
            let seconds: f64 = w.passes.iter().map(|(pass, p)| self.machine.pass_limit(p).0 / step.share(*pass, self.gpu)).sum();
            out[k] = (*step, Estimate { seconds: seconds / self.availability * c, within });
        }
        out
    }

    /// The estimate of step `step` of `job`.
    pub fn step(&self, job: &Job, step: Product) -> Estimate {
        self.steps(job).into_iter().find(|(s, _)| *s == step).expect("every step").1
    }

    /// The total of `job`'s steps, in seconds.
    pub fn total(&self, job: &Job) -> f64 {
        self.steps(job).iter().map(|(_, e)| e.seconds).sum()
    }

    /// Learns from a step estimated at `estimated` seconds that took `measured`.
    pub fn record(&mut self, estimated: f64, measured: f64) {
        if estimated < SHORTEST || measured < SHORTEST || !(estimated.is_finite() && measured.is_finite()) {
            return;
        }
        self.worst = self.worst.max((measured / estimated - 1.0).abs());
        self.log_ratio += (measured / estimated).ln();
        self.timed += 1.0;
    }
}

/// Estimated seconds of each step of `job` at the built-in rates of lavapipe (`gpu`) or
/// 2 CPU cores, measured quiet ([`Estimator::built_in`]): what the planner
/// compares and the hour limit refuses, the same on every machine.
pub fn step_seconds(job: &Job, gpu: bool) -> crate::cost::Seconds {
    let mut out = crate::cost::PerStep::default();
    for (step, e) in Estimator::built_in(gpu).steps(job) {
        out[step] = e.seconds;
    }
    out
}

/// Estimated time (at the built-in rates, [`step_seconds`]) and memory of `job`: the
/// products and their sums, plus the environment as read (RGBA f32, with its row pyramid:
/// `12·width²` bytes).
pub fn built_in_cost(job: &Job) -> crate::cost::Cost {
    let width = match job.input {
        crate::settings::InputShape::Equirect { width, .. } => width as u64,
        _ => 0,
    };
    crate::cost::Cost { gpu_seconds: step_seconds(job, true).total(), cpu_seconds: step_seconds(job, false).total(), bytes: crate::cost::product_bytes(job) + 12 * width.pow(2) }
}

/// The settings a bake within `budget` seconds should use, with their estimated seconds
/// by `estimator` (this device's measured rates): `cost::for_budget_by` over every calibrated
/// roughness band.
pub fn for_budget(given: &crate::settings::Settings, shape: crate::settings::InputShape, products: crate::settings::Products, budget: f64, estimator: &Estimator, cal: &crate::cost::Calibration) -> crate::error::Result<(crate::settings::Settings, f64, f64)> {
    crate::cost::for_budget_by(given, shape, products, budget, cal, None, |job| estimator.total(job))
}

/// The limits of 2 CPU cores of the development machines, unloaded (the estimator's
/// calibration, by processor time, six runs on a quiet machine, December 2026: 0.15–0.20 G
/// filtered reads/s, 1.48–1.66 G summed reads/s, 24–26 GFLOP/s; medians, rounded).
const BUILT_IN_CPU: Machine = Machine { filtered_reads: 0.17e9, summed_reads: 1.5e9, flops: 24e9 };

/// The limits of lavapipe on 2 cores of the development machines, likewise (0.13–0.20 G,
/// 0.25–0.31 G, 9.6–11.8 GFLOP/s).
const BUILT_IN_LAVAPIPE: Machine = Machine { filtered_reads: 0.155e9, summed_reads: 0.30e9, flops: 11e9 };

/// The estimators of this process, by backend identity: measured once, then taught by every
/// step timed on that backend.
static KEPT: std::sync::Mutex<Vec<(String, Estimator)>> = std::sync::Mutex::new(Vec::new());

/// The estimator of `backend`'s steps. Where progress is shown (the command line), this
/// device's rates, measured by a short calibration run the first time in the process (a
/// step of its own in the progress) and kept, with what the steps since taught it; in a
/// library that shows no progress, the built-in rates (nothing is measured, no time spent).
///
/// Where the work runs on this machine's processors (the CPU backend, a software GPU such
/// as lavapipe), the calibration is timed by the processor time the process gets, which
/// is what the device does unloaded, and the share of the processors the process gets now
/// is measured apart ([`availability`]): on a loaded machine a few milliseconds of wall
/// time are either a lucky run that nothing preempted or one that waited, while processor
/// time over threads that spin for 40 ms averages the scheduler's share. A hardware GPU
/// is timed by the wall clock.
pub fn for_backend(backend: &crate::backend::Backend) -> crate::error::Result<Estimator> {
    if !crate::progress::shown() {
        return Ok(Estimator::built_in(backend.is_gpu()));
    }
    let id = backend.identity();
    if let Some((_, e)) = KEPT.lock().unwrap_or_else(|e| e.into_inner()).iter().find(|(k, _)| *k == id) {
        return Ok(e.clone());
    }
    let _step = crate::progress::step("calibrating (this device's rates now, for the estimates)", None);
    let start = web_time::Instant::now();
    let threads = processor_threads(backend);
    let clock = match threads {
        Some(threads) if crate::cost::process_cpu_seconds().is_some() => crate::cost::Clock::Cpu { threads },
        _ => crate::cost::Clock::Wall,
    };
    let how = crate::cost::Calibrating { run_seconds: if backend.is_gpu() { 0.02 } else { 0.005 }, runs: 3, clock };
    let machine = crate::cost::measure_machine(backend, how)?;
    let share = match (clock, threads) {
        (crate::cost::Clock::Cpu { .. }, Some(t)) => availability(t),
        _ => 1.0,
    };
    let e = Estimator::new(machine, backend.is_gpu(), Rates::Measured { seconds: start.elapsed().as_secs_f64() }).with_availability(share);
    keep(backend, e.clone());
    Ok(e)
}

/// The threads of this process that run `backend`'s work: rayon's for the CPU backend, a
/// software GPU's (lavapipe and llvmpipe run one per processor, or `LP_NUM_THREADS`);
/// `None` for a hardware GPU.
fn processor_threads(backend: &crate::backend::Backend) -> Option<u32> {
    match backend {
        crate::backend::Backend::Cpu => Some(rayon::current_num_threads() as u32),
        crate::backend::Backend::Gpu(g) if g.is_software() => Some(
            std::env::var("LP_NUM_THREADS")
                .ok()
                .and_then(|v| v.parse().ok())
                .filter(|&n: &u32| n > 0)
                .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get() as u32)),
        ),
        crate::backend::Backend::Gpu(_) => None,
    }
}

/// The share of `threads` processors this process gets now, from 0 to 1 (1 on a quiet
/// machine; 1/3 for two threads beside four busy processes on two cores): `threads`
/// threads spin for 40 ms of wall time, each counting the processor time it got, while
/// this thread counts the other processes' runnable tasks every 2 ms: the larger of what
/// the spinners got and the processors' fair share among them and the `threads`, at the
/// median count. Over a window this short the scheduler hands out its slices
/// unevenly: two spinners beside `stress-ng --cpu 2` on two cores got 0.29–0.50 each in
/// 40 ms, where a bake's steps got 0.46–0.47 of their quiet speed, and on a quiet machine
/// 0.55–1.0; the count (2 others and 2 threads on 2 processors: 0.5; quiet, 1) does not
/// vary so. Where the count is not known, or gives less than the spinners got (in a
/// container `/proc/stat` may count the host's tasks), the spinners' share.
pub fn availability(threads: u32) -> f64 {
    #[cfg(all(unix, not(target_arch = "wasm32")))]
    {
        fn thread_seconds() -> f64 {
            let mut t = libc::timespec { tv_sec: 0, tv_nsec: 0 };
            // SAFETY: clock_gettime writes the timespec it is given; the clock is valid.
            unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut t) };
            t.tv_sec as f64 + t.tv_nsec as f64 * 1e-9
        }
        const WINDOW: std::time::Duration = std::time::Duration::from_millis(40);
        let (got, mut counts): (f64, Vec<u32>) = std::thread::scope(|s| {
            let spinners: Vec<_> = (0..threads.max(1))
                .map(|_| {
                    s.spawn(|| {
                        let (start, cpu) = (std::time::Instant::now(), thread_seconds());
                        while start.elapsed() < WINDOW {
                            std::hint::spin_loop();
                        }
                        (thread_seconds() - cpu) / start.elapsed().as_secs_f64()
                    })
                })
                .collect();
            let mut counts = Vec::new();
            while spinners.iter().any(|h| !h.is_finished()) {
                std::thread::sleep(std::time::Duration::from_millis(2));
                counts.extend(others_runnable());
            }
            (spinners.into_iter().map(|h| h.join().unwrap_or(1.0)).sum(), counts)
        });
        let spun = got / threads.max(1) as f64;
        counts.sort_unstable();
        let processors = std::thread::available_parallelism().map_or(1, |n| n.get()) as f64;
        let fair = counts.get(counts.len() / 2).map_or(0.0, |&n| processors / (n + threads.max(1)) as f64);
        spun.max(fair).clamp(0.02, 1.0)
    }
    #[cfg(not(all(unix, not(target_arch = "wasm32"))))]
    {
        let _ = threads;
        1.0
    }
}

/// The tasks of other processes runnable on this machine now: Linux's `procs_running`
/// (`/proc/stat`) less this process's threads that are runnable (`/proc/self/task`: the
/// spinners, the reader itself, and any pool thread still spinning before it sleeps,
/// which under load stays runnable for tens of milliseconds); `None` where either is not
/// known.
fn others_runnable() -> Option<u32> {
    let stat = std::fs::read_to_string("/proc/stat").ok()?;
    let all: u32 = stat.lines().find_map(|l| l.strip_prefix("procs_running ")).and_then(|n| n.trim().parse().ok())?;
    let mut own = 0u32;
    for task in std::fs::read_dir("/proc/self/task").ok()? {
        let stat = std::fs::read_to_string(task.ok()?.path().join("stat")).ok()?;
        // The state follows the command's closing parenthesis.
        own += (stat.rsplit(')').next()?.trim_start().starts_with('R')) as u32;
    }
    Some(all.saturating_sub(own))
}

/// The estimator for `job` on `backend`: [`for_backend`]'s, but without a calibration
/// where `job` is estimated, at the built-in rates, under half of [`SHOWN`] in all (a
/// tiny bake, whose steps would show no estimate: measuring the device would take longer
/// than the bake).
pub fn for_job(backend: &crate::backend::Backend, job: &Job) -> crate::error::Result<Estimator> {
    let kept = KEPT.lock().unwrap_or_else(|e| e.into_inner()).iter().any(|(k, _)| *k == backend.identity());
    if !kept && Estimator::built_in(backend.is_gpu()).total(job) < 0.5 * SHOWN {
        return Ok(Estimator::built_in(backend.is_gpu()));
    }
    for_backend(backend)
}

/// Keeps `est` as `backend`'s estimator for the rest of the process.
pub fn keep(backend: &crate::backend::Backend, est: Estimator) {
    if !crate::progress::shown() || est.rates == Rates::BuiltIn {
        return;
    }
    let id = backend.identity();
    let mut kept = KEPT.lock().unwrap_or_else(|e| e.into_inner());
    match kept.iter_mut().find(|(k, _)| *k == id) {
        Some((_, e)) => *e = est,
        None => kept.push((id, est)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The correction is the geometric mean of measured/estimated with one exact step as
    /// its prior: after one step off by a factor r, the next estimates move by √r; steps
    /// under [`SHORTEST`] teach nothing; the stated spread is the worst step seen.
    #[test]
    fn the_correction_is_the_shrunk_geometric_mean_of_the_steps_seen() {
        let machine = Machine { filtered_reads: 1e9, summed_reads: 1e9, flops: 1e10 };
        let job = crate::Settings::default().resolve(crate::environment::InputShape::Equirect { width: 1024, height: 512 }, crate::Products::STANDARD).unwrap();
        let mut e = Estimator::new(machine, false, Rates::Measured { seconds: 0.0 });
        let before = e.step(&job, Product::Specular);
        assert_eq!(before.within, MODEL_SPREAD);
        e.record(0.04, 1.0);
        assert_eq!(e.step(&job, Product::Specular), before, "a step under 50 ms teaches nothing");
        e.record(1.0, 4.0);
        let after = e.step(&job, Product::Specular);
        assert!((after.seconds / before.seconds - 2.0).abs() < 1e-12, "{} / {}", after.seconds, before.seconds);
        assert!((after.within - 3.0).abs() < 1e-12);
        assert!(Estimator::built_in(true).step(&job, Product::Specular).within.is_infinite(), "built-in rates claim no bound");
    }
}
