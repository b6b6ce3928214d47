//! The one bake sequence: source cube, then the specular cube, the irradiance, SH9 and the
//! BRDF table that [`Products`] asks for, on any backend ([`Kernels`]). [`make`] leaves the
//! products where the backend made them (device buffers on the GPU, for
//! `crate::textures`); [`bake`] reads them into host memory ([`Baked`]) for files, reports
//! and the CPU rasteriser. Everything else (plans, caches, the display) calls these.

use crate::backend::{Backend, Kernels, Prefilter, with_kernels};
use crate::cost;
use crate::estimate::Estimator;
use crate::environment::Environment;
use crate::error::{Error, Result};
use crate::settings::{InputShape, Job, Products, Settings, Step};
use crate::texture::{Cube, Lut, Sh9};
use serde::Serialize;
use splitsum_shaders::cubemap::{self, CubeLayout};
use splitsum_shaders::prefilter::{Lobe, RoughnessMapping};
use splitsum_shaders::shade::EnvironmentShape;
use web_time::Instant;

/// Wall time of one step, and what was estimated for it as it started.
#[derive(Clone, Debug, Serialize)]
pub struct Timing {
    /// The step.
    pub step: Step,
    /// Seconds.
    pub seconds: f64,
    /// The estimate shown as the step started (`crate::estimate`), in seconds.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub estimate: Option<f64>,
}

/// The products of a bake: as a backend made them (`Made<K::Texels>`: host texels, or
/// device buffers), or read into host memory ([`Baked`]). Each is present where the job
/// asked for it.
pub struct Made<C, L = C> {
    /// The source cube with its mips (always made; absent where a bake read textures back
    /// and nothing kept it).
    pub source: Option<C>,
    /// The specular cube (`Job::specular_layout`).
    pub specular: Option<C>,
    /// The irradiance cube (`E/π`).
    pub irradiance: Option<C>,
    /// SH9 radiance coefficients.
    pub sh9: Option<Sh9>,
    /// The BRDF table, `(A, B, 0, 0)` per texel on a backend.
    pub lut: Option<L>,
    /// The sheen cube (Charlie-prefiltered radiance; `Job::specular_layout`, sheen
    /// roughness `Job::sheen_roughness_per_mip`).
    pub sheen: Option<C>,
    /// The sheen tables, `(Charlie table, sheen albedo, 0, 0)` per texel on a backend
    /// (`crate::table::SHEEN_TABLE_SIZE`²).
    pub sheen_tables: Option<L>,
    /// Wall time of each step.
    pub timings: Vec<Timing>,
}

/// The results of a bake, in host memory.
pub type Baked = Made<Cube, Lut>;

/// Runs `step` of `job` on `k` with its progress and estimate shown, records its wall time
/// (until the backend has finished it) beside the estimate, and teaches `est` by it.
fn timed<K: Kernels, T>(k: &K, timings: &mut Vec<Timing>, step: Step, job: &Job, est: &mut Estimator, f: impl FnOnce() -> Result<T>) -> Result<T> {
    let estimate = est.step(job, step);
    let _progress = crate::progress::step(step.name(), Some(estimate));
    let start = Instant::now();
    let r = f()?;
    k.finish()?;
    let seconds = start.elapsed().as_secs_f64();
    est.record(estimate.seconds, seconds);
    timings.push(Timing { step, seconds, estimate: Some(estimate.seconds) });
    Ok(r)
}

/// Runs estimated over this many seconds are refused unless forced.
pub const MAX_UNFORCED_SECONDS: f64 = 3600.0;

/// Refuses a run estimated (`estimates`, seconds per step at the built-in rates:
/// `crate::estimate::step_seconds`, the same everywhere) to take over an hour, unless
/// `force` (`Error::TooLong`, naming the estimate and its longest step).
pub fn check_duration(estimates: &cost::Seconds, force: bool) -> Result<()> {
    let total = estimates.total();
    if total <= MAX_UNFORCED_SECONDS || force {
        return Ok(());
    }
    let step = estimates.longest();
    Err(Error::TooLong { seconds: total, step, step_seconds: estimates[step] })
}

/// The source cube of `env` for `job` with its full mip chain: resampled from an
/// equirect, or the given faces reduced to `job.source_size` through their mip chain.
pub fn source_cube<K: Kernels>(k: &K, env: &Environment, job: &Job) -> Result<(K::Texels, CubeLayout)> {
    match env {
        Environment::Equirect(e) => Ok((k.equirect_to_cube(e, job.source_size, job.supersample, job.facing)?, job.source_layout())),
        Environment::Cube(c) => {
            let s = c.layout.size;
            let full_layout = CubeLayout::new(s, CubeLayout::full_chain(s));
            let mut texels = if job.mirror_faces {
                // The faces as the target's baker reads them: mirrored in x (a permutation).
                (0..6 * s * s)
                    .map(|k| {
                        let (f, x, y) = cubemap::mirrored_x_texel(k / (s * s), k % s, (k / s) % s, s);
                        c.texels[c.layout.index(0, f, x, y) as usize]
                    })
                    .collect()
            } else {
                c.texels.clone()
            };
            texels.resize(full_layout.texel_count() as usize, Default::default());
            cube_source(k, k.upload("cube faces", &texels)?, c.layout.size, job)
        }
    }
}

/// The source cube of `job` from a cube whose faces are `face` wide: `full` holds its
/// level 0 in a buffer of its full mip chain; the chain is filtered and the levels from
/// `job.source_size` down are kept.
pub fn cube_source<K: Kernels>(k: &K, mut full: K::Texels, face: u32, job: &Job) -> Result<(K::Texels, CubeLayout)> {
    let size = job.source_size;
    if face < size {
        return Err(Error::setting(
            crate::settings::Field::SourceSize,
            format!("{size} is larger than the cube's {face}×{face} faces; upsampling adds nothing"),
        ));
    }
    let full_layout = CubeLayout::new(face, CubeLayout::full_chain(face));
    k.build_mips(&mut full, full_layout)?;
    let start = full_layout.level_offset(crate::settings::level_of_size(full_layout, size));
    Ok((k.slice(&full, start, full_layout.texel_count() - start)?, job.source_layout()))
}

/// Bakes the products of `job` from a source cube already on backend `k`, each step
/// estimated by `est`.
pub fn products<K: Kernels>(k: &K, source: K::Texels, source_layout: CubeLayout, job: &Job, est: &mut Estimator, mut timings: Vec<Timing>) -> Result<Made<K::Texels>> {
    let p = job.products;
    let specular = if p.specular {
        let pf = prefilter_of(job, Lobe::Ggx);
        Some(timed(k, &mut timings, Step::Specular, job, est, || k.prefilter(&source, source_layout, &pf))?)
    } else {
        None
    };
    let irradiance = if p.irradiance {
        Some(timed(k, &mut timings, Step::Irradiance, job, est, || k.irradiance(&source, source_layout, job.irradiance_level(), job.irradiance_size))?)
    } else {
        None
    };
    let sh9 = if p.sh9 { Some(timed(k, &mut timings, Step::Sh9, job, est, || k.sh9(&source, source_layout, job.sh_level()))?) } else { None };
    let lut = if p.lut {
        // A constant (`crate::table`): embedded or computed once per process, then uploaded.
        Some(timed(k, &mut timings, Step::BrdfTable, job, est, || k.upload("brdf table", &crate::table::texels(crate::table::TableKey::of(job))?))?)
    } else {
        None
    };
    let (sheen, sheen_tables) = if p.sheen {
        let pf = prefilter_of(job, Lobe::Charlie);
        let cube = timed(k, &mut timings, Step::Sheen, job, est, || k.prefilter(&source, source_layout, &pf))?;
        // Constants, as the BRDF table: computed once per process, then uploaded.
        let tables = timed(k, &mut timings, Step::SheenTables, job, est, || k.upload("sheen tables", &crate::table::sheen_texels()))?;
        (Some(cube), Some(tables))
    } else {
        (None, None)
    };
    Ok(Made { source: Some(source), specular, irradiance, sh9, lut, sheen, sheen_tables, timings })
}

/// What the prefilter of `job`'s `lobe` cube computes: the specular cube (GGX) or the
/// sheen cube (Charlie), with the same layout and samples per mip.
fn prefilter_of(job: &Job, lobe: Lobe) -> Prefilter<'_> {
    let (roughness, levels, exact) = match lobe {
        Lobe::Ggx => (&job.roughness_per_mip, &job.levels, &job.exact_levels),
        Lobe::Charlie => (&job.sheen_roughness_per_mip, &job.sheen_levels, &job.sheen_exact_levels),
    };
    Prefilter { lobe, layout: job.specular_layout(), roughness, levels, samples: &job.samples_per_mip, exact, lod_bias: job.lod_bias }
}

/// Bakes `job` from `env` on backend `k`, leaving the products there; each step
/// estimated by `est`.
pub fn make<K: Kernels>(k: &K, est: &mut Estimator, env: &Environment, job: &Job) -> Result<Made<K::Texels>> {
    let mut timings = Vec::new();
    let (source, layout) = timed(k, &mut timings, Step::SourceCube, job, est, || source_cube(k, env, job))?;
    self::products(k, source, layout, job, est, timings)
}

/// `made` read into host memory.
pub fn read<K: Kernels>(k: &K, made: Made<K::Texels>, job: &Job) -> Result<Baked> {
    let cube = |layout: CubeLayout, t: &K::Texels| -> Result<Cube> { Ok(Cube { layout, texels: k.read(t)? }) };
    Ok(Baked {
        source: made.source.as_ref().map(|t| cube(job.source_layout(), t)).transpose()?,
        specular: made.specular.as_ref().map(|t| cube(job.specular_layout(), t)).transpose()?,
        irradiance: made.irradiance.as_ref().map(|t| cube(job.irradiance_layout(), t)).transpose()?,
        sh9: made.sh9,
        lut: made.lut.as_ref().map(|t| -> Result<Lut> { Ok(Lut::from_texels(job.lut_size, &k.read(t)?)) }).transpose()?,
        sheen: made.sheen.as_ref().map(|t| cube(job.specular_layout(), t)).transpose()?,
        sheen_tables: made.sheen_tables.as_ref().map(|t| -> Result<Lut> { Ok(Lut::from_texels(crate::table::SHEEN_TABLE_SIZE, &k.read(t)?)) }).transpose()?,
        timings: made.timings,
    })
}

/// Bakes `products` of `env` with `settings` on `backend`, into host memory.
pub fn bake(backend: &Backend, env: &Environment, settings: &Settings, products: Products) -> Result<Baked> {
    let job = settings.resolve(InputShape::of(env), products)?;
    bake_job(backend, env, &job)
}

/// Bakes `job` (resolved for `env`) on `backend`, into host memory; its steps estimated by
/// `backend`'s estimator (`crate::estimate::for_job`), which learns from them.
pub fn bake_job(backend: &Backend, env: &Environment, job: &Job) -> Result<Baked> {
    let mut est = crate::estimate::for_job(backend, job)?;
    let baked = with_kernels!(backend, k => read(k, make(k, &mut est, env, job)?, job));
    crate::estimate::keep(backend, est);
    baked
}

/// A 1×1 cube of zeros: the stand-in for a product a plan leaves out (nothing reads it).
pub fn empty_cube() -> Cube {
    Cube { layout: CubeLayout::new(1, 1), texels: vec![Default::default(); 6] }
}

/// A 1×1 table of zeros: the stand-in for a table a plan leaves out.
pub fn empty_table() -> Lut {
    Lut { size: 1, texels: vec![Default::default()] }
}

impl Baked {
    /// What a renderer reads, with stand-ins for the products not baked (nothing reads
    /// them) and the source cube's level 0 (the sharp sky).
    pub fn into_display(self, mapping: RoughnessMapping) -> BakedEnvironment {
        let source = self.source.as_ref().map_or_else(empty_cube, |s| s.levels(0, 0));
        BakedEnvironment {
            source,
            specular: self.specular.unwrap_or_else(empty_cube),
            irradiance: self.irradiance.unwrap_or_else(empty_cube),
            lut: self.lut.unwrap_or_else(empty_table),
            sheen: self.sheen.unwrap_or_else(empty_cube),
            sheen_tables: self.sheen_tables.unwrap_or_else(empty_table),
            mapping,
        }
    }
}

/// What a renderer reads, in host memory: the sharp sky, the specular cube, the irradiance
/// cube, the BRDF table, and the sheen cube and tables.
#[derive(Clone)]
pub struct BakedEnvironment {
    /// The source cube's level 0 (the sharp sky).
    pub source: Cube,
    /// Prefiltered specular cube.
    pub specular: Cube,
    /// Irradiance cube (`E/π`).
    pub irradiance: Cube,
    /// BRDF table.
    pub lut: Lut,
    /// Sheen cube (a 1×1 stand-in where nothing reads it).
    pub sheen: Cube,
    /// Sheen tables (the Charlie table, the sheen albedo; a 1×1 stand-in where nothing
    /// reads them).
    pub sheen_tables: Lut,
    /// Roughness of the specular mips.
    pub mapping: RoughnessMapping,
}

impl BakedEnvironment {
    /// The display's exposure for this environment (`preview::auto_exposure`, the one
    /// rule: a white Lambert surface at 0.5 on average before the tone curve).
    pub fn auto_exposure(&self) -> f32 {
        crate::preview::auto_exposure(&self.source)
    }

    /// The shapes the shaders need.
    pub fn shape(&self) -> EnvironmentShape {
        EnvironmentShape {
            specular_size: self.specular.layout.size,
            specular_levels: self.specular.layout.levels,
            mapping: self.mapping as u32,
            irradiance_size: self.irradiance.layout.size,
            lut_size: self.lut.size,
            source_size: self.source.layout.size,
            source_levels: 1,
            irradiance_levels: self.irradiance.layout.levels,
            sheen_size: self.sheen.layout.size,
            sheen_levels: self.sheen.layout.levels,
            sheen_mapping: crate::settings::SHEEN_MAPPING as u32,
            sheen_table_size: self.sheen_tables.size,
        }
    }
}

/// Bakes what a renderer reads ([`Products::DISPLAY`]) of `env` on `backend`.
pub fn bake_for_display(backend: &Backend, env: &Environment, settings: &Settings) -> Result<BakedEnvironment> {
    let job = settings.resolve(InputShape::of(env), Products::DISPLAY)?;
    Ok(bake_job(backend, env, &job)?.into_display(job.mapping))
}

/// The source cube of `env` for `settings` (with its full mip chain) on `backend`, in
/// host memory.
pub fn host_source_cube(backend: &Backend, env: &Environment, settings: &Settings) -> Result<Cube> {
    let job = settings.resolve(InputShape::of(env), Products::DISPLAY)?;
    with_kernels!(backend, k => {
        let (t, layout) = source_cube(k, env, &job)?;
        Ok(Cube { layout, texels: k.read(&t)? })
    })
}

/// One environment of a batch ([`bake_batch`]), read and baked.
pub struct Batched {
    /// What was found and changed while reading it.
    pub input: crate::environment::InputReport,
    /// The bake resolved for it.
    pub job: Job,
    /// What reading and baking changed from what was given (to state and record).
    pub adjustments: Vec<crate::adjustment::Adjustment>,
    /// Its products, in host memory.
    pub baked: Baked,
}

/// Bakes `products` of every environment in `paths` with `settings` on `backend`: one
/// device and one set of pipelines for all, the next input read (on a thread of its own)
/// while the current one bakes, and each bake handed to `deliver` on a third thread (so
/// writing it overlaps the next bake). An input that fails to read or bake is handed over as
/// its error and the others go on; `deliver` gets the input's index in `paths` and its path.
/// Returns what `deliver` returned, in the order of `paths`.
/// The settings are checked once, before anything is read.
pub fn bake_batch<R: Send>(
    backend: &Backend,
    paths: &[std::path::PathBuf],
    settings: &Settings,
    products: Products,
    sanitize: bool,
    deliver: impl Fn(usize, &std::path::Path, Result<Batched>) -> R + Sync,
) -> Result<Vec<R>> {
    use std::sync::mpsc::sync_channel;
    let face = settings.resolve(InputShape::Unknown, products)?.source_size;
    let (read_tx, read_rx) = sync_channel(1);
    let (baked_tx, baked_rx) = sync_channel::<(usize, Result<Batched>)>(1);
    std::thread::scope(|s| {
        s.spawn(move || {
            for (i, p) in paths.iter().enumerate() {
                if read_tx.send((i, crate::environment::load_for(p, sanitize, face))).is_err() {
                    break;
                }
            }
        });
        let deliver = &deliver;
        let writer = s.spawn(move || baked_rx.into_iter().map(|(i, b)| deliver(i, &paths[i], b)).collect::<Vec<R>>());
        for (i, read) in read_rx {
            let batched = read.and_then(|(env, input)| {
                let job = settings.resolve(InputShape::of(&env), products)?;
                let baked = bake_job(backend, &env, &job)?;
                let adjustments = input.adjustments(&env).into_iter().chain(job.adjustments()).collect();
                Ok(Batched { input, job, adjustments, baked })
            });
            if baked_tx.send((i, batched)).is_err() {
                break;
            }
        }
        drop(baked_tx);
        Ok(writer.join().expect("the batch's writer thread panicked"))
    })
}
