//! The one bake sequence: source cube, then the specular cube, the irradiance, SH9 and the
//! BRDF table that [`Products`] asks for, on any backend ([`Kernels`]). [`make`] leaves the
//! products where the backend made them (device buffers on the GPU, for
//! `crate::textures`); [`bake`] reads them into host memory ([`Baked`]) for files, reports
//! and the CPU rasteriser. Everything else (plans, caches, the display) calls these;
//! what a renderer reads is `crate::reading`'s, which runs this sequence twice.

use crate::backend::{Backend, Cpu, Kernels, Prefilter, with_kernels};
use crate::placement::{self, Place};
use crate::cost;
use crate::estimate::Estimator;
use crate::environment::Environment;
use crate::error::{Error, Result};
use crate::product::{Item, Layout};
use crate::settings::{InputShape, Job, Product, Products, Settings};
use crate::texture::{Cube, Lut, Sh9};
use serde::Serialize;
use splitsum_shaders::cubemap::{self, CubeLayout};
use std::collections::BTreeMap;
use web_time::Instant;

/// Wall time of one step, and what was estimated for it as it started.
#[derive(Clone, Debug, Serialize)]
pub struct Timing {
    /// The step.
    pub step: Product,
    /// Seconds.
    pub seconds: f64,
    /// The estimate shown as the step started (`crate::estimate`), in seconds.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub estimate: Option<f64>,
}

/// The products of a bake: as a backend made them (`Made<K::Texels>`: host texels, or
/// device buffers), or read into host memory ([`Baked`]). Each is present where the job
/// asked for it (the source cube: unless a bake read textures back and nothing kept it).
pub struct Made<C, L = C> {
    items: BTreeMap<Product, Item<C, L>>,
    /// Wall time of each step.
    pub timings: Vec<Timing>,
}

impl<C, L> Made<C, L> {
    internal! {
        /// Nothing made yet.
        pub fn new(timings: Vec<Timing>) -> Self {
            Self { items: BTreeMap::new(), timings }
        }
    }

    /// The cube `p` (`Product::layout`), if made.
    pub fn cube(&self, p: Product) -> Option<&C> {
        match self.items.get(&p) {
            Some(Item::Cube(c)) => Some(c),
            _ => None,
        }
    }

    /// The table `p`, if made.
    pub fn table(&self, p: Product) -> Option<&L> {
        match self.items.get(&p) {
            Some(Item::Table(t)) => Some(t),
            _ => None,
        }
    }

    /// The SH9 coefficients, if made.
    pub fn sh9(&self) -> Option<&Sh9> {
        match self.items.get(&Product::Sh9) {
            Some(Item::Coefficients(c)) => Some(c.as_ref()),
            _ => None,
        }
    }

    internal! {
        /// Adds (or replaces) product `p`.
        pub fn insert(&mut self, p: Product, item: Item<C, L>) {
            self.items.insert(p, item);
        }
    }

    internal! {
        /// Takes product `p` out.
        pub fn take(&mut self, p: Product) -> Option<Item<C, L>> {
            self.items.remove(&p)
        }
    }

    /// The products made, in the order of [`Product::ALL`].
    pub fn products(&self) -> impl Iterator<Item = Product> + '_ {
        self.items.keys().copied()
    }

    internal! {
        /// Each product made, in the order of [`Product::ALL`].
        pub fn items(&self) -> impl Iterator<Item = (Product, &Item<C, L>)> {
            self.items.iter().map(|(p, i)| (*p, i))
        }
    }
}

/// The results of a bake, in host memory.
pub type Baked = Made<Cube, Lut>;

/// Runs `step` of `job` on `k` with its progress and estimate shown, records its wall time
/// (until the backend has finished it) beside the estimate, and teaches `est` by it.
fn timed<K: Kernels, T>(k: &K, timings: &mut Vec<Timing>, step: Product, job: &Job, est: &mut Estimator, f: impl FnOnce() -> Result<T>) -> Result<T> {
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
    let place = placement::place_buffer(placement::texel_bytes(full_layout.texel_count() as u64), k.max_binding());
    if let Place::Host { .. } = place {
        placement::note(&format!("the mips of the {face}² cube"), place);
        let mut host = k.read(&full)?;
        Cpu.build_mips(&mut host, full_layout)?;
        full = k.upload("cube", &host)?;
    } else {
        k.build_mips(&mut full, full_layout)?;
    }
    let start = full_layout.level_offset(full_layout.level_of_size(size));
    Ok((k.slice(&full, start, full_layout.texel_count() - start)?, job.source_layout()))
}

/// Bakes the products of `job` from a source cube already on backend `k`, each step
/// estimated by `est`: every product of `job.products` after the source cube, in the order
/// of [`Product::ALL`], each where `crate::placement` places it: on `k`, or on the CPU
/// (the source cube read back once, each result uploaded) where a buffer of the step is
/// larger than `k` binds.
pub fn products<K: Kernels>(k: &K, source: K::Texels, source_layout: CubeLayout, job: &Job, est: &mut Estimator, timings: Vec<Timing>) -> Result<Made<K::Texels>> {
    let mut made = Made::new(timings);
    let mut host_source: Option<Vec<splitsum_shaders::glam::Vec4>> = None;
    for p in job.products.iter().filter(|p| *p != Product::SourceCube) {
        let place = placement::place(p, job, k.max_binding());
        let item = timed(k, &mut made.timings, p, job, est, || {
            placement::run(
                place,
                || format!("the {p} step"),
                || make_product(k, p, &source, source_layout, job),
                || {
                    let host = match &mut host_source {
                        Some(h) => h,
                        None => host_source.insert(k.read(&source)?),
                    };
                    Ok(match make_product(&Cpu, p, host, source_layout, job)? {
                        Item::Cube(t) => Item::Cube(k.upload(p.name(), &t)?),
                        Item::Table(t) => Item::Table(k.upload(p.name(), &t)?),
                        Item::Coefficients(c) => Item::Coefficients(c),
                    })
                },
            )
        })?;
        made.insert(p, item);
    }
    made.insert(Product::SourceCube, Item::Cube(source));
    Ok(made)
}

/// Makes product `p` of `job` on backend `k` from the source cube `source` (made first,
/// by [`source_cube`]): a prefiltered cube of any lobe by the backend's prefilter.
fn make_product<K: Kernels>(k: &K, p: Product, source: &K::Texels, source_layout: CubeLayout, job: &Job) -> Result<Item<K::Texels>> {
    Ok(match p {
        p if p.lobe().is_some() => Item::Cube(crate::backend::split::prefilter(k, source, source_layout, &prefilter(job, p))?),
        Product::Irradiance => Item::Cube(k.irradiance(source, source_layout, job.irradiance_level(), job.irradiance_size)?),
        Product::Sh9 => Item::Coefficients(Box::new(k.sh9(source, source_layout, job.sh_level())?)),
        // Constants (`crate::table`): embedded or computed once per process, then uploaded.
        Product::BrdfTable => Item::Table(k.upload("brdf table", &crate::table::texels(crate::table::TableKey::of(job))?)?),
        Product::SheenTables => Item::Table(k.upload("sheen tables", &crate::table::sheen_texels())?),
        Product::SourceCube => unreachable!("the source cube is made first, by source_cube"),
        _ => unreachable!("{p} is a prefiltered cube, made above"),
    })
}

/// What the backends' prefilter computes for the prefiltered cube `p` of `job`.
pub fn prefilter(job: &Job, p: Product) -> Prefilter<'_> {
    let cube = &job.prefiltered[&p];
    Prefilter {
        what: p.name(),
        lobe: p.lobe().expect("a prefiltered cube has a lobe"),
        layout: job.specular_layout(),
        roughness: &cube.roughness_per_mip,
        levels: &cube.levels,
        samples: &job.samples_per_mip,
        exact: &cube.exact_levels,
        lod_bias: job.lod_bias,
    }
}

/// Bakes `job` from `env` on backend `k`, leaving the products there; each step
/// estimated by `est`.
pub fn make<K: Kernels>(k: &K, est: &mut Estimator, env: &Environment, job: &Job) -> Result<Made<K::Texels>> {
    let mut timings = Vec::new();
    let place = placement::place(Product::SourceCube, job, k.max_binding());
    let what = || match env {
        Environment::Equirect(e) => format!("resampling the {}×{} equirect (its row pyramid)", e.width, e.height),
        Environment::Cube(c) => format!("the mips of the {}² cube", c.layout.size),
    };
    let (source, layout) = timed(k, &mut timings, Product::SourceCube, job, est, || {
        placement::run(
            place,
            what,
            || source_cube(k, env, job),
            || {
                let (t, layout) = source_cube(&Cpu, env, job)?;
                Ok((k.upload("source cube", &t)?, layout))
            },
        )
    })?;
    self::products(k, source, layout, job, est, timings)
}

/// `made` read into host memory, each product in its `Product::layout`.
pub fn read<K: Kernels>(k: &K, made: Made<K::Texels>, job: &Job) -> Result<Baked> {
    let mut baked = Baked::new(made.timings);
    for (p, item) in made.items {
        let host = match (item, job.layout(p)) {
            (Item::Cube(t), Layout::Cube(layout)) => Item::Cube(Cube { layout, texels: k.read(&t)? }),
            (Item::Table(t), Layout::Table(size)) => Item::Table(Lut::from_texels(size, &k.read(&t)?)),
            (Item::Coefficients(c), _) => Item::Coefficients(c),
            _ => unreachable!("{p} was made in its own layout"),
        };
        baked.insert(p, host);
    }
    Ok(baked)
}

/// [`read`] on the GPU without blocking: what a web page does after [`make`] (in a browser
/// a readback completes only when the page's event loop runs). SH9 is read back inside
/// [`make`], and so cannot be baked there.
pub async fn read_async(g: &crate::backend::Gpu, made: Made<crate::backend::gpu::Texels>, job: &Job) -> Result<Baked> {
    let mut baked = Baked::new(made.timings);
    for (p, item) in made.items {
        let host = match (item, job.layout(p)) {
            (Item::Cube(t), Layout::Cube(layout)) => Item::Cube(Cube { layout, texels: g.read_texels_async(&t).await? }),
            (Item::Table(t), Layout::Table(size)) => Item::Table(Lut::from_texels(size, &g.read_texels_async(&t).await?)),
            (Item::Coefficients(c), _) => Item::Coefficients(c),
            _ => unreachable!("{p} was made in its own layout"),
        };
        baked.insert(p, host);
    }
    Ok(baked)
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
