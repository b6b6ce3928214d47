//! What a bake costs before it runs: the error model and cost rates a plan chooses from
//! ([`Calibration`]), and the time and memory of a resolved bake ([`estimate`],
//! [`step_seconds`]).

use crate::measured::{Knob, Measurement, Method, Part, Product};
use crate::settings::{InputShape, Job, Step, TableMethod};
use serde::Serialize;

/// Error of each product against its reference, per setting, and the cost rates of each
/// backend: what the planner chooses from. The built-in one is `runner report` on the two
/// vendored HDRIs with a 34 000 sun and without (the worse of the two), on lavapipe and
/// on 2 CPU cores, November 2026.
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
    /// Nanoseconds per unit of work on (lavapipe, CPU), per step (see `work`).
    pub ns: Rates,
}

/// Nanoseconds per unit of work of each step on (lavapipe, CPU).
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Rates(pub [(f64, f64); 7]);

impl std::ops::Index<Step> for Rates {
    type Output = (f64, f64);
    fn index(&self, s: Step) -> &(f64, f64) {
        &self.0[Step::ALL.iter().position(|x| *x == s).expect("every step is listed")]
    }
}

impl Default for Calibration {
    fn default() -> Self {
        Self {
            source: "built in: runner report on city.exr and courtyard.exr (the worse of the two), runner bench, lavapipe and 2 CPU cores".into(),
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
            // Rates from `runner bench` of the defaults on city.exr (December 2026): 3.5 M
            // equirect supersamples in 0.10 s / 0.10 s, 12.2 M prefilter samples in 0.31 s /
            // 0.32 s, 9.4 M irradiance texel pairs in 0.035 s / 0.010 s. An SH9 texel (nine
            // basis functions, one weighted add each) is taken at an irradiance pair's rate.
            // A table other than the embedded one is integrated once per process on the CPU
            // (`crate::table`), 36 M evaluations in 0.33 s, whichever backend bakes.
            // The sheen cube is taken at the specular cube's rate per sample (the same
            // loop); its tables are embedded, uploaded like the BRDF table.
            ns: Rates([(28.0, 29.0), (25.0, 26.0), (3.7, 1.1), (3.7, 1.1), (9.1, 9.1), (25.0, 26.0), (9.1, 9.1)]),
        }
    }
}

impl Calibration {
    /// The error model from `report.csv` of `runner report` (its first backend's rows),
    /// keeping the built-in cost rates; `None` if the text is not such a file or lacks
    /// the rows of a product.
    pub fn from_report_csv(text: &str) -> Option<Self> {
        Self::from_measurements(&crate::measured::read_csv(text).ok()?)
    }

    /// The error model from a report's rows (its first backend's), by their columns:
    /// the irradiance convolution's error per source size, and the bake's share of the
    /// shaded colour's error per roughness band and sample count, for the defaults.
    pub fn from_measurements(rows: &[Measurement]) -> Option<Self> {
        let mut c = Calibration { source: "report.csv".into(), prefilter: vec![], irradiance: vec![], ..Default::default() };
        let backend = &rows.iter().find(|r| !r.backend.is_empty())?.backend;
        for r in rows.iter().filter(|r| &r.backend == backend) {
            match (r.product, r.method, r.part) {
                (Product::Irradiance, Method::Defaults, Part::Total) if r.knob == Knob::SourceSize => {
                    c.irradiance.push((r.source_size?, r.mean_error));
                }
                (Product::ShadedColour, Method::Defaults, Part::Bake) => {
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

/// A number per step of a bake (seconds, units of work), indexed by [`Step`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct PerStep(pub [f64; 7]);

/// Seconds of each step.
pub type Seconds = PerStep;

impl std::ops::Index<Step> for PerStep {
    type Output = f64;
    fn index(&self, s: Step) -> &f64 {
        &self.0[Step::ALL.iter().position(|x| *x == s).expect("every step is listed")]
    }
}

impl std::ops::IndexMut<Step> for PerStep {
    fn index_mut(&mut self, s: Step) -> &mut f64 {
        &mut self.0[Step::ALL.iter().position(|x| *x == s).expect("every step is listed")]
    }
}

impl PerStep {
    /// The sum over the steps.
    pub fn total(&self) -> f64 {
        self.0.iter().sum()
    }

    /// The step with the largest value.
    pub fn longest(&self) -> Step {
        Step::ALL.into_iter().max_by(|a, b| self[*a].total_cmp(&self[*b])).expect("seven steps")
    }
}

/// Units of work of each step (equirect supersamples, prefilter samples or an eighth of
/// an exact sum's terms, irradiance texel pairs, SH9 texels, BRDF table evaluations) of
/// `job`, and the bytes of its products in memory.
fn work(job: &Job) -> (PerStep, u64) {
    let mut work = PerStep::default();
    let mut bytes = 0u64;
    let source = job.source_layout();
    if let InputShape::Equirect { .. } | InputShape::Unknown = job.input {
        work[Step::SourceCube] = 6.0 * (job.source_size as f64).powi(2) * (job.supersample as f64).powi(2);
    }
    bytes += source.texel_count() as u64 * 16;
    for cube in prefiltered_cubes(job) {
        let out = job.specular_layout();
        for &l in cube.levels {
            let texels = 6.0 * (out.level_size(l) as f64).powi(2);
            let r = cube.roughness[l as usize];
            if !cube.lobe.is_mirror(r) {
                // An exact sum's 6t² terms cost about an eighth of a sample each.
                let per_texel = if cube.exact[l as usize] != splitsum_shaders::prefilter::SAMPLED {
                    6.0 * (source.level_size(cube.exact[l as usize]) as f64).powi(2) / 8.0
                } else {
                    job.samples_per_mip[l as usize] as f64
                };
                work[cube.step] += texels * per_texel;
            }
            // The sums (3 × RGBA per texel) and the result.
            bytes += texels as u64 * 64;
        }
    }
    if job.products.sheen {
        // The sheen tables are embedded (`crate::table`): uploaded, not integrated.
        bytes += (crate::table::SHEEN_TABLE_SIZE as u64).pow(2) * 24;
    }
    if job.products.lut {
        // The embedded table is uploaded, not integrated (`crate::table`).
        let per_texel = match job.lut_method {
            _ if crate::table::TableKey::of(job) == crate::table::TableKey::EMBEDDED => 0,
            TableMethod::Quadrature => splitsum_shaders::lut::QUADRATURE_MEAN_EVALUATIONS,
            TableMethod::Sampled => job.lut_samples,
        };
        work[Step::BrdfTable] = (job.lut_size as f64).powi(2) * per_texel as f64;
        bytes += (job.lut_size as u64).pow(2) * 24;
    }
    if job.products.irradiance {
        work[Step::Irradiance] = 6.0 * (job.irradiance_size as f64).powi(2) * 6.0 * (job.irradiance_source as f64).powi(2);
        bytes += 6 * (job.irradiance_size as u64).pow(2) * 64;
    }
    if job.products.sh9 {
        work[Step::Sh9] = 6.0 * (job.sh_source as f64).powi(2);
    }
    (work, bytes)
}

/// Estimated seconds of each step of `job`, on lavapipe (`gpu`) or on 2 CPU cores.
pub fn step_seconds(job: &Job, cal: &Calibration, gpu: bool) -> Seconds {
    let (work, _) = work(job);
    let mut out = PerStep::default();
    for s in Step::ALL {
        let (g, c) = cal.ns[s];
        out[s] = work[s] * if gpu { g } else { c } * 1e-9;
    }
    out
}

/// Estimated time and memory of `job`: the products and their sums, plus the environment
/// as read (RGBA f32, with its row pyramid: `12·width²` bytes).
pub fn estimate(job: &Job, cal: &Calibration) -> Cost {
    let (_, bytes) = work(job);
    let width = match job.input {
        InputShape::Equirect { width, .. } => width as u64,
        _ => 0,
    };
    Cost { gpu_seconds: step_seconds(job, cal, true).total(), cpu_seconds: step_seconds(job, cal, false).total(), bytes: bytes + 12 * width.pow(2) }
}

/// The work of one step, by kind: what the cost model of `runner bench` counts.
///
/// Texel reads are counted exactly from the job (a trilinear cube lookup reads 8 texels,
/// an equirect area sample at least 4, a mip texel 4, a term of an exact sum 1).
/// Floating-point operations are estimates, counted by reading the shared functions once:
/// about 140 per GGX sample (the half vector ≈ 50, the lookup ≈ 70, the compensated sum
/// ≈ 20; a Charlie sample ≈ 330, its three Newton steps ≈ 190 in place of the half vector's
/// 50), 80 per equirect area sample, 90 per term of an exact specular sum (texel
/// direction, solid angle, weight, compensated sum), 31 per irradiance term (its direction
/// and solid angle read from a table: weight 7, compensated sums 24), 130 per SH9 texel. Bytes are the texels read and written (16 each).
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

impl std::ops::AddAssign for Work {
    fn add_assign(&mut self, o: Work) {
        self.filtered_reads += o.filtered_reads;
        self.summed_reads += o.summed_reads;
        self.flops += o.flops;
        self.bytes += o.bytes;
    }
}

/// The work of each step of `job`, in the order of [`Step::ALL`]. The BRDF table is a
/// constant (`crate::table`): the defaults' is uploaded (its bytes only); another is
/// integrated once per process, counted here as `lut::QUADRATURE_MEAN_EVALUATIONS` (or
/// the samples) of about 60 operations per texel.
pub fn step_work(job: &Job) -> [(Step, Work); 7] {
    let mut out = Step::ALL.map(|s| (s, Work::default()));
    fn at(out: &mut [(Step, Work); 7], s: Step) -> &mut Work {
        &mut out.iter_mut().find(|(x, _)| *x == s).expect("every step").1
    }
    let source = job.source_layout();
    {
        let w = at(&mut out, Step::SourceCube);
        let level0 = 6.0 * (job.source_size as f64).powi(2);
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
    for cube in prefiltered_cubes(job) {
        let w = at(&mut out, cube.step);
        let layout = job.specular_layout();
        for &l in cube.levels {
            let texels = 6.0 * (layout.level_size(l) as f64).powi(2);
            let m = l as usize;
            if cube.lobe.is_mirror(cube.roughness[m]) {
                w.filtered_reads += texels;
            } else if cube.exact[m] != splitsum_shaders::prefilter::SAMPLED {
                let terms = texels * 6.0 * (source.level_size(cube.exact[m]) as f64).powi(2);
                w.summed_reads += terms;
                w.flops += 90.0 * terms;
            } else {
                let samples = texels * job.samples_per_mip[m] as f64;
                w.filtered_reads += 8.0 * samples;
                w.flops += if cube.lobe == splitsum_shaders::prefilter::Lobe::Charlie { 330.0 } else { 140.0 } * samples;
            }
            w.bytes += 16.0 * texels;
        }
        w.bytes += 16.0 * (w.filtered_reads + w.summed_reads);
    }
    if job.products.irradiance {
        let w = at(&mut out, Step::Irradiance);
        // Each term reads the texel and its geometry (`cubemap::level_geometry`).
        let terms = 6.0 * (job.irradiance_size as f64).powi(2) * 6.0 * (job.irradiance_source as f64).powi(2);
        w.summed_reads += 2.0 * terms;
        w.flops += 31.0 * terms;
        w.bytes += 16.0 * (terms + 6.0 * (job.irradiance_size as f64).powi(2));
    }
    if job.products.sh9 {
        let w = at(&mut out, Step::Sh9);
        let texels = 6.0 * (job.sh_source as f64).powi(2);
        w.summed_reads += texels;
        w.flops += 130.0 * texels;
        w.bytes += 16.0 * texels;
    }
    if job.products.lut {
        let w = at(&mut out, Step::BrdfTable);
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
    if job.products.sheen {
        let w = at(&mut out, Step::SheenTables);
        w.bytes += 16.0 * (crate::table::SHEEN_TABLE_SIZE as f64).powi(2);
    }
    out
}

/// One prefiltered cube of a job, as the cost model walks it.
struct PrefilteredCube<'a> {
    step: Step,
    lobe: splitsum_shaders::prefilter::Lobe,
    levels: &'a [u32],
    roughness: &'a [f32],
    exact: &'a [u32],
}

/// The prefiltered cubes `job` bakes: the specular cube, the sheen cube.
fn prefiltered_cubes(job: &Job) -> Vec<PrefilteredCube<'_>> {
    use splitsum_shaders::prefilter::Lobe;
    let mut out = Vec::new();
    if job.products.specular {
        out.push(PrefilteredCube { step: Step::Specular, lobe: Lobe::Ggx, levels: &job.levels, roughness: &job.roughness_per_mip, exact: &job.exact_levels });
    }
    if job.products.sheen {
        out.push(PrefilteredCube { step: Step::Sheen, lobe: Lobe::Charlie, levels: &job.sheen_levels, roughness: &job.sheen_roughness_per_mip, exact: &job.sheen_exact_levels });
    }
    out
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
    /// The least time `w` can take on this machine: its slowest kind of work at the
    /// measured rate (the kinds are taken to overlap, as a GPU's memory and arithmetic do),
    /// and which kind that is.
    pub fn limit(&self, w: &Work) -> (f64, &'static str) {
        [(w.filtered_reads / self.filtered_reads, "filtered reads"), (w.summed_reads / self.summed_reads, "summed reads"), (w.flops / self.flops, "arithmetic")]
            .into_iter()
            .max_by(|a, b| a.0.total_cmp(&b.0))
            .expect("three kinds")
    }
}

/// Runs the calibration kernel on `backend` and returns its rates: each kind of work on a
/// 128² cube with its mip chain (values from a fixed hash, positive and finite), timed
/// after a first run that warms the pipeline and caches; the fastest of four runs is kept.
pub fn measure_machine(backend: &crate::backend::Backend) -> crate::error::Result<Machine> {
    use crate::backend::{Backend, Kernels};
    use splitsum_shaders::calibrate::Rate;
    use splitsum_shaders::cubemap::CubeLayout;
    use splitsum_shaders::glam::Vec4;
    fn rate<K: Kernels>(k: &K, rate: Rate, size: u32, count: u32) -> crate::error::Result<f64> {
        let layout = CubeLayout::new(128, CubeLayout::full_chain(128));
        let texels: Vec<Vec4> = (0..layout.texel_count())
            .map(|i| {
                let h = i.wrapping_mul(2_654_435_761);
                Vec4::new((h >> 8 & 255) as f32 / 64.0, (h >> 16 & 255) as f32 / 64.0, (h >> 24) as f32 / 64.0, 1.0)
            })
            .collect();
        let src = k.upload("calibration cube", &texels)?;
        let mut best = f64::INFINITY;
        for run in 0..5 {
            k.finish()?;
            let t = web_time::Instant::now();
            let out = k.calibrate(&src, layout, rate, size, count)?;
            k.finish()?;
            if run > 0 {
                best = best.min(t.elapsed().as_secs_f64());
            }
            drop(out);
        }
        Ok(6.0 * (size as f64).powi(2) * count as f64 * rate.per_step() as f64 / best)
    }
    let measure = |k: &dyn Fn(Rate, u32, u32) -> crate::error::Result<f64>| -> crate::error::Result<Machine> {
        Ok(Machine { filtered_reads: k(Rate::Filtered, 64, 128)?, summed_reads: k(Rate::Summed, 32, 8192)?, flops: k(Rate::Arithmetic, 64, 1024)? })
    };
    match backend {
        Backend::Gpu(g) => measure(&|r, s, c| rate(&**g, r, s, c)),
        Backend::Cpu => measure(&|r, s, c| rate(&crate::backend::Cpu, r, s, c)),
    }
}

/// The share of its limits a bake reaches, for turning the cost model's limits into a time
/// estimate on a device measured only by the calibration kernel: a little under what the
/// default bake of city.exr reaches as a whole (`runner bench`, December 2026: the sum of
/// its steps' limits over its time, 0.66 on lavapipe and 0.69 on 2 CPU cores).
pub const SHARE_OF_LIMIT: f64 = 0.6;

/// The settings a bake within `budget` seconds on `machine` should use: [`for_budget_by`]
/// over every calibrated roughness band, each candidate's time estimated from the cost
/// model's limits on `machine` at [`SHARE_OF_LIMIT`].
pub fn for_budget(given: &crate::settings::Settings, shape: InputShape, products: crate::settings::Products, budget: f64, machine: &Machine, cal: &Calibration) -> crate::error::Result<(crate::settings::Settings, f64, f64)> {
    let seconds = |job: &Job| step_work(job).iter().map(|(_, w)| machine.limit(w).0).sum::<f64>() / SHARE_OF_LIMIT;
    for_budget_by(given, shape, products, budget, cal, None, seconds)
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
            let error = if products.specular { specular_error } else { 0.0 } + if products.irradiance { irradiance_error } else { 0.0 };
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
