//! What a bake costs before it runs: the error model a plan chooses from ([`Calibration`]),
//! each step's work by kind ([`step_work`]), a device's limits on each kind
//! ([`measure_machine`]) and the bytes a bake holds, which `crate::estimate` turns into
//! seconds and memory; the one search for a time budget ([`for_budget_by`]).

use crate::measured::{Knob, Measurement, Method, Part, Quantity};
use crate::settings::{InputShape, Job, Product, TableMethod};
use splitsum_shaders::cubemap::CubeLayout;
use splitsum_shaders::{bright, prefilter};
use serde::Serialize;

/// Error of each product against its reference, per setting: what the planner chooses
/// from. The built-in one is `runner report` on the two vendored HDRIs with a 34 000 sun
/// and without (the worse of the two), on 2 CPU cores, November 2026. (What each choice
/// costs is `crate::estimate`'s.)
#[derive(Clone, Debug, Serialize)]
pub struct Calibration {
    /// Where the numbers come from.
    pub source: String,
    /// The specular bake, end to end: (roughness at the middle of a band, [(samples at mip
    /// 1, mean relative error the bake adds to the shaded colour)]), from the report's
    /// rows of the shaded colour's bake share for the defaults at several sample counts.
    pub prefilter: Vec<(f32, Vec<(u32, f64)>)>,
    /// Irradiance convolution: (source face size, mean relative error).
    pub irradiance: Vec<(u32, f64)>,
}

impl Default for Calibration {
    fn default() -> Self {
        Self {
            source: "built in: runner report on city.exr and courtyard.exr (the worse of the two), 2 CPU cores".into(),
            // Bands [0.02, 0.05) … [0.75, 1] of `runner report` on city.exr and courtyard.exr
            // (the worse of the two), CPU backend.
            prefilter: vec![
                (0.035, vec![(16, 0.0618), (64, 0.0592), (256, 0.0586)]),
                (0.075, vec![(16, 0.357), (64, 0.359), (256, 0.357)]),
                (0.15, vec![(16, 0.0987), (64, 0.122), (256, 0.104)]),
                (0.275, vec![(16, 0.0998), (64, 0.0699), (256, 0.0596)]),
                (0.425, vec![(16, 0.0696), (64, 0.0527), (256, 0.0484)]),
                (0.625, vec![(16, 0.0411), (64, 0.0247), (256, 0.0245)]),
                (0.875, vec![(16, 0.0383), (64, 0.0353), (256, 0.0269)]),
            ],
            irradiance: vec![(4, 0.035), (8, 0.0181), (16, 0.0067), (32, 0.00168), (64, 0.00083)],
        }
    }
}

impl Calibration {
    /// The error model from `report.csv` of `runner report` (its first backend's rows),
    /// `None` if the text is not such a file or lacks
    /// the rows of a product.
    pub fn from_report_csv(text: &str) -> Option<Self> {
        Self::from_measurements(&crate::measured::read_csv(text).ok()?)
    }

    /// The error model from a report's rows (its first backend's), by their columns:
    /// the irradiance convolution's error per source size, and the bake's share of the
    /// shaded colour's error per roughness band and sample count, for the defaults.
    pub fn from_measurements(rows: &[Measurement]) -> Option<Self> {
        let mut c = Calibration { source: "report.csv".into(), prefilter: vec![], irradiance: vec![] };
        let backend = &rows.iter().find(|r| !r.backend.is_empty())?.backend;
        for r in rows.iter().filter(|r| &r.backend == backend) {
            match (r.product, r.method, r.part) {
                (Quantity::Irradiance, Method::Defaults, Part::Total) if r.knob == Knob::SourceSize => {
                    c.irradiance.push((r.source_size?, r.mean_error));
                }
                (Quantity::ShadedColour, Method::Defaults, Part::Bake) => {
                    let (Some(lo), Some(hi), Some(n)) = (r.roughness_lo, r.roughness_hi, r.samples) else { continue };
                    let mid = 0.5 * (lo + hi);
                    match c.prefilter.iter_mut().find(|(x, _)| (*x - mid).abs() < 1e-3) {
                        Some((_, v)) => {
                            v.push((n, r.mean_error));
                            v.sort_by_key(|&(n, _)| n);
                        }
                        None => c.prefilter.push((mid, vec![(n, r.mean_error)])),
                    }
                }
                _ => {}
            }
        }
        c.irradiance.sort_by_key(|&(s, _)| s);
        c.prefilter.sort_by(|a, b| a.0.total_cmp(&b.0));
        (!c.prefilter.is_empty() && !c.irradiance.is_empty()).then_some(c)
    }

    /// The bake's share of the shaded colour's error at `roughness` (the nearest band) with
    /// `samples` at mip 1.
    pub fn prefilter_error(&self, roughness: f32, samples: u32) -> f64 {
        // The measured roughness nearest to the one asked for.
        let table = &self.prefilter.iter().min_by(|a, b| (a.0 - roughness).abs().total_cmp(&(b.0 - roughness).abs())).expect("calibrated").1;
        interpolate(table, samples)
    }
}

/// Log–log interpolation of `(setting, error)` pairs at `x` (clamped to the table).
pub fn interpolate(table: &[(u32, f64)], x: u32) -> f64 {
    let x = x as f64;
    if x <= table[0].0 as f64 {
        return table[0].1;
    }
    for w in table.windows(2) {
        let (x0, y0, x1, y1) = (w[0].0 as f64, w[0].1, w[1].0 as f64, w[1].1);
        if x <= x1 {
            let t = (x.ln() - x0.ln()) / (x1.ln() - x0.ln());
            return (y0.ln() + t * (y1.ln() - y0.ln())).exp();
        }
    }
    table[table.len() - 1].1
}

/// Estimated cost.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct Cost {
    /// Seconds on lavapipe.
    pub gpu_seconds: f64,
    /// Seconds on 2 CPU cores.
    pub cpu_seconds: f64,
    /// Bytes of the data in memory (the environment as read, the products and their sums).
    pub bytes: u64,
}

impl Cost {
    /// Estimated peak resident memory of the process, in bytes: the data, plus the program
    /// itself (8 MiB) on the CPU; on lavapipe the data twice (host copies and device
    /// buffers, both in host memory) plus the driver (118 MiB). Measured with
    /// `/usr/bin/time` on `runner lut --size 16` (the baselines) and `runner bake` of
    /// courtyard.exr at its defaults: 57 MiB on the CPU, 227 MiB on lavapipe, against
    /// 8 + 55 and 118 + 2·55 estimated.
    pub fn peak_bytes(&self, gpu: bool) -> u64 {
        const MIB: u64 = 1 << 20;
        if gpu { 118 * MIB + 2 * self.bytes } else { 8 * MIB + self.bytes }
    }
}

/// A number per step of a bake (seconds, units of work), indexed by [`Product`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct PerStep(pub [f64; Product::COUNT]);

/// Seconds of each step.
pub type Seconds = PerStep;

impl std::ops::Index<Product> for PerStep {
    type Output = f64;
    fn index(&self, s: Product) -> &f64 {
        &self.0[s.index()]
    }
}

impl std::ops::IndexMut<Product> for PerStep {
    fn index_mut(&mut self, s: Product) -> &mut f64 {
        &mut self.0[s.index()]
    }
}

impl PerStep {
    /// The sum over the steps.
    pub fn total(&self) -> f64 {
        self.0.iter().sum()
    }

    /// The step with the largest value.
    pub fn longest(&self) -> Product {
        Product::ALL.into_iter().max_by(|a, b| self[*a].total_cmp(&self[*b])).expect("a bake has steps")
    }
}

/// The bytes of `job`'s products in memory ([`bytes`]), its source cube included.
pub fn product_bytes(job: &Job) -> u64 {
    Product::ALL.iter().map(|p| bytes(*p, job)).sum()
}

/// The work of one step, by kind: what the cost model of `runner bench` counts.
///
/// Texel reads are counted exactly from the job (a cube lookup reads 8 texels where it
/// blends two levels, 4 at one, a sample below the horizon none: each level's samples are
/// counted one by one, `prefilter::sample_texels`; an equirect area sample at least 4, a
/// mip texel 4, a term of an exact sum 1), but for the sheen ring's chords, which depend on
/// the sky: their expected count for entries spread over the sphere
/// (`bright::ring_tile_expected`).
/// Floating-point operations are estimates, counted by reading the shared functions once:
/// about 140 per GGX sample (the half vector ≈ 50, the lookup ≈ 70, the compensated sum
/// ≈ 20; a Charlie sample ≈ 330, its three Newton steps ≈ 190 in place of the half vector's
/// 50), 40 per term of a split source's excess list (a dot product, a power, a compensated
/// sum; 20 where the level reads the power from its density table), 25 per ring chord, 80
/// per equirect area sample, 90 per term of an exact GGX sum (texel direction, solid angle,
/// weight, compensated sum; 140 for Charlie's, whose weight is a power), 31 per irradiance
/// term (its direction and solid angle read from a table: weight 7, compensated sums 24),
/// 130 per SH9 texel. Bytes are the texels read and written (16 each).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Work {
    /// Texel reads inside filtered lookups (trilinear cube lookups, equirect area samples,
    /// mip reduction).
    pub filtered_reads: f64,
    /// Texel reads of whole levels in order (exact sums, irradiance, SH9).
    pub summed_reads: f64,
    /// Floating-point operations (estimated, see above).
    pub flops: f64,
    /// Bytes read and written.
    pub bytes: f64,
}

pub use crate::product::Pass;

/// The work of one step: a [`Work`] per pass, the passes run one after another (a
/// prefiltered cube's split and levels), each as long as its own slowest kind
/// ([`Machine::limit`]).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct StepWork {
    /// The passes, in order.
    pub passes: Vec<(Pass, Work)>,
}

impl StepWork {
    /// The work of all passes together.
    pub fn total(&self) -> Work {
        let mut t = Work::default();
        for (_, w) in &self.passes {
            t += *w;
        }
        t
    }
}

impl std::ops::AddAssign for Work {
    fn add_assign(&mut self, o: Work) {
        self.filtered_reads += o.filtered_reads;
        self.summed_reads += o.summed_reads;
        self.flops += o.flops;
        self.bytes += o.bytes;
    }
}

/// The work of the step in `job`, by kind (see [`Work`] for what each kind counts), pass
/// by pass: a prefiltered cube's split, then each level's own pass and its excess list's.
/// The BRDF table is a constant (`crate::table`): the defaults' is uploaded (its bytes
/// only); another is integrated once per process, counted here as
/// `lut::QUADRATURE_MEAN_EVALUATIONS` (or the samples) of about 60 operations per texel.
pub fn work(p: Product, job: &Job) -> StepWork {
    let mut w = Work::default();
    if !job.products.has(p) {
        return StepWork::default();
    }
    let source = job.source_layout();
    let faces = |size: u32| 6.0 * (size as f64).powi(2);
    match p {
        Product::SourceCube => {
            let level0 = faces(job.source_size);
            if let InputShape::Equirect { width, height } = job.input {
                let points = level0 * (job.supersample as f64).powi(2);
                w.filtered_reads += 4.0 * points + (width as f64) * (height as f64);
                w.flops += 80.0 * points;
            }
            let mips = (source.texel_count() as f64 - level0).max(0.0);
            w.filtered_reads += 4.0 * mips;
            w.flops += 20.0 * mips;
            w.bytes += 16.0 * (w.filtered_reads + source.texel_count() as f64);
        }
        p if p.lobe().is_some() => {
            let cube = &job.prefiltered[&p];
            let lobe = p.lobe().expect("a prefiltered cube has a lobe");
            let layout = job.specular_layout();
            let split = crate::backend::split::split_size_of(lobe, &cube.roughness_per_mip, &cube.levels, source.size);
            let ring = cube.levels.iter().copied().find(|&l| crate::backend::split::is_ring(lobe, cube.roughness_per_mip[l as usize]));
            let mut passes = Vec::new();
            if let Some(t) = split {
                // The split (`split::prefilter`): the split level's luminances and split, the
                // source's level 0 copied where it is finer (the entries' centroids), the
                // residual's mips; the ring's table, a cone per tile (four corner
                // directions, ≈ 100) and a test per tile and entry (≈ 25).
                let mut w = Work::default();
                w.summed_reads += 2.0 * faces(t) + if t < source.size { faces(source.size) } else { 0.0 };
                w.filtered_reads += 4.0 * (CubeLayout::new(t, CubeLayout::full_chain(t)).texel_count() as f64 - faces(t));
                if let Some(l) = ring {
                    let tiles = 6.0 * (bright::ring_tiles(layout.level_size(l)) as f64).powi(2);
                    w.flops += tiles * (100.0 + 25.0 * crate::backend::split::TEXELS as f64);
                }
                w.bytes += 16.0 * (w.filtered_reads + w.summed_reads);
                passes.push((Pass::Split, w));
            }
            for &l in &cube.levels {
                // The level's own pass (the source or the residual, sampled or summed
                // exactly), then where it splits the excess list's: over the level's
                // texels, or a pass that reads the residual traced at a coarser size.
                let (mut w, mut excess, mut excess_pass) = (Work::default(), Work::default(), Pass::Excess);
                let size = layout.level_size(l);
                let texels = faces(size);
                let m = l as usize;
                let r = cube.roughness_per_mip[m];
                let traced = split.and_then(|t| crate::backend::split::traced_size(lobe, r, size, source.size, t));
                let at = traced.map_or(texels, faces);
                if lobe.is_mirror(r) {
                    w.filtered_reads += texels;
                } else if cube.exact_levels[m] != prefilter::SAMPLED {
                    let terms = at * faces(source.level_size(cube.exact_levels[m]));
                    w.summed_reads += terms;
                    w.flops += p.flops_per_exact_term() * terms;
                } else {
                    // Each sample's lookup reads 8 texels, 4 at a clamped level, none below
                    // the horizon (`prefilter::sample_texels`), in the residual where the
                    // level reads it.
                    let n = job.samples_per_mip[m];
                    let (read_size, read_levels) = match split.filter(|_| crate::backend::split::uses_split(lobe, r, source.size)) {
                        Some(t) => (t, CubeLayout::full_chain(t)),
                        None => (source.size, source.levels),
                    };
                    let reads: u32 = prefilter::lobe_samples(lobe, n, r, read_size, job.lod_bias).map(|g| prefilter::sample_texels(g, read_levels)).sum();
                    w.filtered_reads += at * reads as f64;
                    w.flops += p.flops_per_sample() * at * n as f64;
                }
                if traced.is_some() {
                    // Each texel reads the traced level bilinearly.
                    excess.filtered_reads += 4.0 * texels;
                }
                if let Some(t) = split.filter(|_| traced.is_some() && crate::backend::split::is_ring(lobe, r)) {
                    // The ring's chords: each texel reads its tile's header and entries, the
                    // expected count for entries of the split level's mean solid angle
                    // (`bright::ring_tile_expected`); a chord term reads its entry and
                    // excess, ≈ 25 operations (a dot product, a square root, a compensated sum).
                    // The six faces are rotations of one another: one face's sum, six times.
                    let tiles = bright::ring_tiles(size);
                    let per_tile = (size.min(bright::RING_TILE) as f64).powi(2);
                    let omega = 4.0 * std::f32::consts::PI / (6.0 * (t as f32).powi(2));
                    let entries = crate::backend::split::TEXELS;
                    let chords: f64 = (0..tiles * tiles)
                        .map(|i| bright::ring_tile_expected(0, i % tiles, i / tiles, size, entries, omega) as f64)
                        .sum::<f64>()
                        * 6.0
                        * per_tile;
                    excess.summed_reads += texels + 2.0 * chords;
                    excess.flops += 25.0 * chords;
                    excess_pass = Pass::Chords;
                } else if bright::splits(lobe, r, source.size) {
                    // The excess list: at most `split::TEXELS` terms a texel, two texels each,
                    // and where the level has a density table a third, its entry, in place of
                    // the power.
                    let terms = texels * crate::backend::split::TEXELS as f64;
                    let tabulated = bright::tabulates(lobe.alpha(r));
                    excess.summed_reads += if tabulated { 3.0 } else { 2.0 } * terms;
                    excess.flops += if tabulated { 20.0 } else { 40.0 } * terms;
                }
                w.bytes += 16.0 * (texels + w.filtered_reads + w.summed_reads);
                passes.push((Pass::Own, w));
                if excess != Work::default() {
                    excess.bytes += 16.0 * (excess.filtered_reads + excess.summed_reads);
                    passes.push((excess_pass, excess));
                }
            }
            return StepWork { passes };
        }
        Product::Irradiance => {
            // Each term reads the texel and its geometry (`cubemap::level_geometry`).
            let terms = faces(job.irradiance_size) * faces(job.irradiance_source);
            w.summed_reads += 2.0 * terms;
            w.flops += 31.0 * terms;
            w.bytes += 16.0 * (terms + faces(job.irradiance_size));
        }
        Product::Sh9 => {
            let texels = faces(job.sh_source);
            w.summed_reads += texels;
            w.flops += 130.0 * texels;
            w.bytes += 16.0 * texels;
        }
        Product::BrdfTable => {
            let texels = (job.lut_size as f64).powi(2);
            if crate::table::TableKey::of(job) != crate::table::TableKey::EMBEDDED {
                let per_texel = match job.lut_method {
                    TableMethod::Quadrature => splitsum_shaders::lut::QUADRATURE_MEAN_EVALUATIONS,
                    TableMethod::Sampled => job.lut_samples,
                };
                w.flops += 60.0 * texels * per_texel as f64;
            }
            w.bytes += 16.0 * texels;
        }
        Product::SheenTables => w.bytes += 16.0 * (crate::table::SHEEN_TABLE_SIZE as f64).powi(2),
        _ => unreachable!("{p} is a prefiltered cube, matched above"),
    }
    StepWork { passes: vec![(Pass::Own, w)] }
}

/// The bytes the product holds in memory while `job` bakes it: a prefiltered level
/// with its sums (3 × RGBA per texel) and the result, a table's texels and sums, the
/// irradiance with its sums, the source cube.
pub fn bytes(p: Product, job: &Job) -> u64 {
    if !job.products.has(p) {
        return 0;
    }
    let faces = |size: u32| 6 * (size as u64).pow(2);
    match p {
        Product::SourceCube => job.source_layout().texel_count() as u64 * 16,
        p if p.lobe().is_some() => job.prefiltered[&p].levels.iter().map(|&l| faces(job.specular_layout().level_size(l)) * 64).sum(),
        Product::Irradiance => faces(job.irradiance_size) * 64,
        Product::Sh9 => 0,
        Product::BrdfTable => (job.lut_size as u64).pow(2) * 24,
        Product::SheenTables => (crate::table::SHEEN_TABLE_SIZE as u64).pow(2) * 24,
        _ => unreachable!("{p} is a prefiltered cube, matched above"),
    }
}

/// The work of each step of `job` ([`work`]), in the order of [`Product::ALL`].
pub fn step_work(job: &Job) -> [(Product, StepWork); Product::COUNT] {
    Product::ALL.map(|p| (p, work(p, job)))
}

/// What a device does per second on each kind of [`Work`], measured by the calibration
/// kernel (`splitsum_shaders::calibrate`) on that device: the cost model's limits.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Machine {
    /// Texel reads per second inside trilinear cube lookups.
    pub filtered_reads: f64,
    /// Texel reads per second of a level summed in order.
    pub summed_reads: f64,
    /// Floating-point operations per second (dependent multiply–adds).
    pub flops: f64,
}

impl Machine {
    /// The least time a step's work `w` can take on this machine: the sum over its passes
    /// of each pass's slowest kind of work at the measured rate (within a pass the kinds
    /// are taken to overlap, as a GPU's memory and arithmetic do), and the kind that bounds
    /// the most of that time.
    pub fn limit(&self, w: &StepWork) -> (f64, &'static str) {
        const KINDS: [&str; 3] = ["filtered reads", "summed reads", "arithmetic"];
        let mut by_kind = [0.0f64; 3];
        for (_, p) in &w.passes {
            let (t, k) = self.pass_limit(p);
            by_kind[k] += t;
        }
        let k = (0..3).max_by(|&a, &b| by_kind[a].total_cmp(&by_kind[b])).expect("three kinds");
        (by_kind.iter().sum(), KINDS[k])
    }

    /// The least time one pass's work `p` can take: its slowest kind at the measured rate,
    /// and that kind's index (filtered reads, summed reads, arithmetic).
    pub fn pass_limit(&self, p: &Work) -> (f64, usize) {
        let times = [p.filtered_reads / self.filtered_reads, p.summed_reads / self.summed_reads, p.flops / self.flops];
        let k = (0..3).max_by(|&a, &b| times[a].total_cmp(&times[b])).expect("three kinds");
        (times[k], k)
    }
}

/// How long the calibration kernel runs for a [`measure_machine`], and by which clock.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Calibrating {
    /// Seconds of one timed run of each kind of work (the work is doubled until a run
    /// takes half of it: these runs warm the pipeline and caches).
    pub run_seconds: f64,
    /// Timed runs of each kind; the fastest is kept.
    pub runs: u32,
    /// How a run is timed.
    pub clock: Clock,
}

/// How a calibration run is timed.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum Clock {
    /// Wall time: what the device does now, whatever else runs.
    Wall,
    /// The processor time this process spent, over the `threads` that do the work: what
    /// the device does with the processors to itself, whatever else runs (on a loaded
    /// machine, wall time over runs of a few milliseconds is either a lucky unloaded run or
    /// a preempted one; `crate::estimate` measures the share of the processors this process
    /// gets apart). Where a process's time is not known (a browser), wall time.
    Cpu {
        /// The threads that run the work (rayon's, or the software driver's).
        threads: u32,
    },
}

impl Calibrating {
    /// `runner bench`'s limits: runs of 50 ms by the wall clock, the fastest of four.
    pub const THOROUGH: Calibrating = Calibrating { run_seconds: 0.05, runs: 4, clock: Clock::Wall };
}

/// The processor time this process has used (user and system, every thread), in seconds.
pub fn process_cpu_seconds() -> Option<f64> {
    #[cfg(all(unix, not(target_arch = "wasm32")))]
    {
        let mut usage = std::mem::MaybeUninit::<libc::rusage>::zeroed();
        // SAFETY: getrusage writes the struct it is given; RUSAGE_SELF is always valid.
        if unsafe { libc::getrusage(libc::RUSAGE_SELF, usage.as_mut_ptr()) } != 0 {
            return None;
        }
        // SAFETY: initialised by the successful call.
        let u = unsafe { usage.assume_init() };
        let t = |v: libc::timeval| v.tv_sec as f64 + v.tv_usec as f64 * 1e-6;
        Some(t(u.ru_utime) + t(u.ru_stime))
    }
    #[cfg(not(all(unix, not(target_arch = "wasm32"))))]
    None
}

/// Runs the calibration kernel on `backend` and returns its rates: each kind of work on a
/// 128² cube with its mip chain (values from a fixed hash, positive and finite), the work
/// per run doubled (in steps per texel up to `math::CHUNK`, then in texels) until a run
/// takes half of `how.run_seconds`, then timed `how.runs` times by `how.clock`; the fastest
/// run is kept.
pub fn measure_machine(backend: &crate::backend::Backend, how: Calibrating) -> crate::error::Result<Machine> {
    use crate::backend::{Backend, Kernels};
    use splitsum_shaders::calibrate::Rate;
    use splitsum_shaders::glam::Vec4;
    fn rate<K: Kernels>(k: &K, rate: Rate, how: Calibrating) -> crate::error::Result<f64> {
        let layout = CubeLayout::new(128, CubeLayout::full_chain(128));
        let texels: Vec<Vec4> = (0..layout.texel_count())
            .map(|i| {
                let h = i.wrapping_mul(2_654_435_761);
                Vec4::new((h >> 8 & 255) as f32 / 64.0, (h >> 16 & 255) as f32 / 64.0, (h >> 24) as f32 / 64.0, 1.0)
            })
            .collect();
        let src = k.upload("calibration cube", &texels)?;
        // (wall seconds, seconds by `how.clock`)
        let run = |size: u32, count: u32| -> crate::error::Result<(f64, f64)> {
            k.finish()?;
            let cpu = process_cpu_seconds();
            let t = web_time::Instant::now();
            let out = k.calibrate(&src, layout, rate, size, count)?;
            k.finish()?;
            let wall = t.elapsed().as_secs_f64();
            let timed = match (how.clock, cpu, process_cpu_seconds()) {
                (Clock::Cpu { threads }, Some(a), Some(b)) => (b - a) / threads.max(1) as f64,
                _ => wall,
            };
            drop(out);
            Ok((wall, timed))
        };
        // Lavapipe stops an invocation's loops after 65 535 iterations (docs/HAZARDS.md):
        // at most one chunk of steps per texel, then more texels.
        let (mut size, mut count) = (16u32, 16u32);
        while run(size, count)?.0 < 0.5 * how.run_seconds && size < 512 {
            if count < splitsum_shaders::math::CHUNK { count *= 2 } else { size *= 2 }
        }
        let mut best = f64::INFINITY;
        for _ in 0..how.runs.max(1) {
            best = best.min(run(size, count)?.1);
        }
        Ok(6.0 * (size as f64).powi(2) * count as f64 * rate.per_step() as f64 / best.max(1e-9))
    }
    // On a GPU the kind measured first is measured again last, the faster kept: on
    // lavapipe the first tenth of a second of a process's work runs slower (its filtered
    // reads came out at 0.21–0.26 G/s, measured again 0.24–0.30 G/s, by `THOROUGH` after
    // both 0.28–0.30 G/s; kept, 0.27–0.29 G/s). The CPU's agree within 1 %.
    let measure = |k: &dyn Fn(Rate) -> crate::error::Result<f64>, again: bool| -> crate::error::Result<Machine> {
        let first = k(Rate::Filtered)?;
        let (summed_reads, flops) = (k(Rate::Summed)?, k(Rate::Arithmetic)?);
        let filtered_reads = if again { first.max(k(Rate::Filtered)?) } else { first };
        Ok(Machine { filtered_reads, summed_reads, flops })
    };
    match backend {
        Backend::Gpu(g) => measure(&|r| rate(&**g, r, how), true),
        Backend::Cpu => measure(&|r| rate(&crate::backend::Cpu, r, how), false),
    }
}

/// The one search for a time budget: among the specular sample counts and irradiance
/// source sizes the error model `cal` measured, the pair with the lowest predicted error
/// whose time, by `seconds`, fits `budget`. The predicted error is the specular bake's
/// share of the shaded colour's error, its mean over `roughness` (the values a scene reads;
/// every calibrated band if `None`), plus the irradiance's. Returns the settings, the
/// predicted error and the estimated seconds; when nothing fits, the cheapest pair, whose
/// estimate then exceeds `budget`.
pub fn for_budget_by(
    given: &crate::settings::Settings,
    shape: InputShape,
    products: crate::settings::Products,
    budget: f64,
    cal: &Calibration,
    roughness: Option<&[f32]>,
    seconds: impl Fn(&Job) -> f64,
) -> crate::error::Result<(crate::settings::Settings, f64, f64)> {
    // Sample counts within the measured range only: the error model is flat outside it.
    let measured: Vec<u32> = cal.prefilter.iter().flat_map(|(_, t)| t.iter().map(|&(n, _)| n)).collect();
    let (lo, hi) = (measured.iter().copied().min().unwrap_or(64), measured.iter().copied().max().unwrap_or(64));
    let mut samples: Vec<u32> = measured.iter().copied().chain([8, 16, 32, 64, 128, 256, 512, 1024]).filter(|&n| n >= lo && n <= hi).collect();
    samples.sort_unstable();
    samples.dedup();
    let bands: Vec<f32> = match roughness {
        Some(r) if !r.is_empty() => r.to_vec(),
        _ => cal.prefilter.iter().map(|(r, _)| *r).collect(),
    };
    let source = given.resolve(shape, products)?.source_size;
    let sources: Vec<(u32, f64)> = cal.irradiance.iter().copied().filter(|&(s, _)| s <= source).collect();
    let mut best: Option<(crate::settings::Settings, f64, f64)> = None;
    let mut cheapest: Option<(crate::settings::Settings, f64, f64)> = None;
    for &n in &samples {
        for &(s, irradiance_error) in &sources {
            let settings = crate::settings::Settings { samples: n, irradiance_source: Some(s), ..given.clone() };
            let Ok(job) = settings.resolve(shape, products) else { continue };
            let seconds = seconds(&job);
            let specular_error = bands.iter().map(|r| cal.prefilter_error(*r, n)).sum::<f64>() / bands.len().max(1) as f64;
            let error = if products.has(Product::Specular) { specular_error } else { 0.0 } + if products.has(Product::Irradiance) { irradiance_error } else { 0.0 };
            let candidate = (settings, error, seconds);
            if seconds <= budget && best.as_ref().is_none_or(|b| error < b.1 || (error == b.1 && seconds < b.2)) {
                best = Some(candidate.clone());
            }
            if cheapest.as_ref().is_none_or(|c| seconds < c.2) {
                cheapest = Some(candidate);
            }
        }
    }
    Ok(best.or(cheapest).expect("at least one candidate resolves"))
}
