//! What a renderer reads, in host memory ([`BakedEnvironment`]), and the bake that makes
//! it ([`for_display`]): the one bake sequence (`crate::bake`) run twice, the second time
//! on the residual of the source split for reading, whose brightest texels the shading
//! adds back exactly (`splitsum_shaders::excess`; book, "The sun read apart"). The viewer,
//! the web page, the scenes and the report read this; files for other engines hold the
//! whole environment ([`BakedEnvironment::whole_specular`]).

use crate::backend::{Backend, Kernels, with_kernels};
use crate::bake::{Baked, Made, Timing, bake_job, cube_source, empty_cube, empty_table, make, products, read, read_async};
use crate::environment::Environment;
use crate::error::Result;
use crate::estimate::Estimator;
use crate::product::Item;
use crate::settings::{InputShape, Job, Product, Products, Settings};
use crate::texture::{Cube, Lut};
use splitsum_shaders::cubemap::{self, CubeLayout};
use splitsum_shaders::glam::{Vec3, Vec4};
use splitsum_shaders::prefilter::RoughnessMapping;
use splitsum_shaders::shade::EnvironmentShape;
use std::collections::BTreeMap;

impl Baked {
    /// What a renderer reads: the products baked, the source cube's level 0 (the sharp sky)
    /// in place of the source cube, and the roughness of the specular mips.
    pub fn into_display(mut self, mapping: RoughnessMapping) -> BakedEnvironment {
        if let Some(Item::Cube(source)) = self.take(Product::SourceCube) {
            self.insert(Product::SourceCube, Item::Cube(source.levels(0, 0)));
        }
        let mut env = BakedEnvironment { cubes: BTreeMap::new(), tables: BTreeMap::new(), mapping, excess: Vec::new() };
        for (p, item) in Product::ALL.into_iter().filter_map(|p| self.take(p).map(|item| (p, item))) {
            match item {
                Item::Cube(c) => {
                    env.cubes.insert(p, c);
                }
                Item::Table(t) => {
                    env.tables.insert(p, t);
                }
                Item::Coefficients(_) => {}
            }
        }
        env
    }
}

/// What a renderer reads, in host memory: the cubes (the sharp sky, the specular,
/// irradiance and sheen cubes) and the tables (the BRDF table, the sheen tables) baked,
/// the roughness of the specular mips, and the excess list of a specular cube baked from
/// a split source ([`for_display`]). A product not baked reads as a 1×1 stand-in of zeros
/// (nothing reads it).
#[derive(Clone)]
pub struct BakedEnvironment {
    /// The cubes baked (the source cube: its level 0 only; the specular and irradiance
    /// cubes: the residual's, where `excess` is not empty).
    pub cubes: BTreeMap<Product, Cube>,
    /// The tables baked.
    pub tables: BTreeMap<Product, Lut>,
    /// Roughness of the specular mips.
    pub mapping: RoughnessMapping,
    /// The excess list (`splitsum_shaders::bright::ENTRY` texels an entry): the source's
    /// brightest texels above its threshold, which the shading adds back exactly
    /// (`splitsum_shaders::excess`); empty where the specular cube holds everything.
    pub excess: Vec<Vec4>,
}

static EMPTY_CUBE: std::sync::LazyLock<Cube> = std::sync::LazyLock::new(empty_cube);
static EMPTY_TABLE: std::sync::LazyLock<Lut> = std::sync::LazyLock::new(empty_table);

impl BakedEnvironment {
    /// The cube `p`, or a 1×1 stand-in of zeros.
    pub fn cube(&self, p: Product) -> &Cube {
        self.cubes.get(&p).unwrap_or(&EMPTY_CUBE)
    }

    /// The table `p`, or a 1×1 stand-in of zeros.
    pub fn table(&self, p: Product) -> &Lut {
        self.tables.get(&p).unwrap_or(&EMPTY_TABLE)
    }

    /// The display's exposure for this environment (`preview::auto_exposure`, the one
    /// rule: a white Lambert surface at 0.5 on average before the tone curve).
    pub fn auto_exposure(&self) -> f32 {
        crate::preview::auto_exposure(self.cube(Product::SourceCube))
    }

    /// The specular buffer the shaders read ([`EnvironmentShape::excess_entries`]): the
    /// specular cube, then the excess list.
    pub fn specular_buffer(&self) -> std::borrow::Cow<'_, [Vec4]> {
        let cube = &self.cube(Product::Specular).texels;
        if self.excess.is_empty() {
            return std::borrow::Cow::Borrowed(cube);
        }
        std::borrow::Cow::Owned(cube.iter().chain(&self.excess).copied().collect())
    }

    /// The whole prefiltered specular cube, for a file: where the cube was baked from a
    /// split source, each texel of each of `levels` (those baked) the residual's plus the
    /// excess's exact terms at its mip's roughness
    /// (`splitsum_shaders::excess::prefiltered_excess`; at roughness 0 a texel's own
    /// excess, whole).
    pub fn whole_specular(&self, levels: &[u32]) -> std::borrow::Cow<'_, Cube> {
        let cube = self.cube(Product::Specular);
        if self.excess.is_empty() {
            return std::borrow::Cow::Borrowed(cube);
        }
        let layout = cube.layout;
        let entries = self.excess.len() as u32 / splitsum_shaders::bright::ENTRY;
        let mut texels = cube.texels.clone();
        for &m in levels.iter().filter(|&&m| m < layout.levels) {
            let r = self.mapping.roughness(m, layout.levels);
            add_per_texel(&mut texels, layout, m, |d| splitsum_shaders::excess::prefiltered_excess(&self.excess, 0, entries, d, r, Vec3::ZERO));
        }
        std::borrow::Cow::Owned(Cube { layout, texels })
    }

    /// The whole irradiance cube, for a file: where it was baked from a split source, each
    /// texel the residual's plus the excess's (`splitsum_shaders::excess::irradiance`).
    pub fn whole_irradiance(&self) -> std::borrow::Cow<'_, Cube> {
        let cube = self.cube(Product::Irradiance);
        if self.excess.is_empty() {
            return std::borrow::Cow::Borrowed(cube);
        }
        let entries = self.excess.len() as u32 / splitsum_shaders::bright::ENTRY;
        let mut texels = cube.texels.clone();
        add_per_texel(&mut texels, cube.layout, 0, |d| splitsum_shaders::excess::irradiance(&self.excess, 0, entries, d).extend(0.0));
        std::borrow::Cow::Owned(Cube { layout: cube.layout, texels })
    }

    /// The shapes the shaders need.
    pub fn shape(&self) -> EnvironmentShape {
        let (source, specular, irradiance, sheen) =
            (self.cube(Product::SourceCube), self.cube(Product::Specular), self.cube(Product::Irradiance), self.cube(Product::Sheen));
        EnvironmentShape {
            specular_size: specular.layout.size,
            specular_levels: specular.layout.levels,
            mapping: self.mapping as u32,
            irradiance_size: irradiance.layout.size,
            lut_size: self.table(Product::BrdfTable).size,
            source_size: source.layout.size,
            irradiance_levels: irradiance.layout.levels,
            sheen_size: sheen.layout.size,
            sheen_levels: sheen.layout.levels,
            sheen_mapping: Product::Sheen.mapping(self.mapping) as u32,
            sheen_table_size: self.table(Product::SheenTables).size,
            excess_entries: self.excess.len() as u32 / splitsum_shaders::bright::ENTRY,
        }
    }
}

/// Adds `f(d)` to each texel of level `level` of `texels` (in `layout`), `d` its direction.
fn add_per_texel(texels: &mut [Vec4], layout: CubeLayout, level: u32, f: impl Fn(Vec3) -> Vec4 + Sync) {
    use rayon::prelude::*;
    let s = layout.level_size(level);
    let start = layout.level_offset(level) as usize;
    texels[start..start + (cubemap::FACES * s * s) as usize].par_iter_mut().enumerate().for_each(|(i, t)| {
        *t += f(cubemap::texel_geometry(i as u32, s).truncate());
    });
}

/// Bakes what a renderer reads ([`Products::DISPLAY`]) of `env` on `backend`
/// ([`for_display`]).
pub fn bake_for_display(backend: &Backend, env: &Environment, settings: &Settings) -> Result<BakedEnvironment> {
    let job = settings.resolve(InputShape::of(env), Products::DISPLAY)?;
    Ok(for_display(backend, env, &job)?.0)
}

/// Bakes `job` of `env` on `backend` as a renderer reads it, with the wall time of each
/// step: every product but the specular and irradiance cubes from the source, then the
/// source's level 0 split ([`split_for_reading`]) and those two baked from the residual,
/// its excess list beside them for the shading to add back exactly
/// (`splitsum_shaders::excess`).
/// A sun of 10⁴–10⁶ then reaches a lookup through its exact terms, not through a blend of
/// two prefiltered mips (book, "Decision records").
pub fn for_display(backend: &Backend, env: &Environment, job: &Job) -> Result<(BakedEnvironment, Vec<Timing>)> {
    let mut baked = bake_job(backend, env, &all_but_split(job))?;
    let mut excess = Vec::new();
    if reads_split(job) {
        let source = baked.cube(Product::SourceCube).expect("every bake makes the source cube");
        let rest = residual_job(job);
        let mut est = crate::estimate::for_job(backend, &rest)?;
        let made = with_kernels!(backend, k => {
            let (made, list) = make_residual(k, &mut est, source, &rest)?;
            Ok((read(k, made, &rest)?, list))
        });
        crate::estimate::keep(backend, est);
        let (made, list) = made?;
        add_split(&mut baked, made);
        excess = list;
    }
    let timings = baked.timings.clone();
    let mut display = baked.into_display(job.mapping);
    display.excess = excess;
    Ok((display, timings))
}

/// [`for_display`] on the GPU without blocking (a web page's bake; see [`read_async`]).
pub async fn for_display_async(g: &crate::backend::Gpu, est: &mut Estimator, env: &Environment, job: &Job) -> Result<BakedEnvironment> {
    let first = all_but_split(job);
    let mut baked = read_async(g, make(g, est, env, &first)?, &first).await?;
    let mut excess = Vec::new();
    if reads_split(job) {
        let source = baked.cube(Product::SourceCube).expect("every bake makes the source cube");
        let rest = residual_job(job);
        let (made, list) = make_residual(g, est, source, &rest)?;
        add_split(&mut baked, read_async(g, made, &rest).await?);
        excess = list;
    }
    let mut display = baked.into_display(job.mapping);
    display.excess = excess;
    Ok(display)
}

/// The products [`for_display`] bakes from the residual, where `job` asks for them.
const SPLIT: [Product; 2] = [Product::Specular, Product::Irradiance];

/// Whether `job` bakes a product that [`for_display`] bakes from the residual.
fn reads_split(job: &Job) -> bool {
    SPLIT.iter().any(|&p| job.products.has(p))
}

/// `job` less those products: what [`for_display`] bakes from the whole source.
fn all_but_split(job: &Job) -> Job {
    Job { products: SPLIT.iter().fold(job.products, |set, &p| set.without(p)), ..job.clone() }
}

/// The job that bakes those of `job`'s products from the residual's faces, the faces
/// taken as they are (the residual is in the cube's own orientation).
fn residual_job(job: &Job) -> Job {
    let products = SPLIT.iter().fold(Products::SOURCE, |set, &p| set.with(p, job.products.has(p)));
    Job { products, mirror_faces: false, ..job.clone() }
}

/// The products of `rest` ([`residual_job`]) made on `k` from the residual of `source`
/// (the baked source cube), left where `k` made them, and the excess list split off it
/// ([`split_for_reading`]).
fn make_residual<K: Kernels>(k: &K, est: &mut Estimator, source: &Cube, rest: &Job) -> Result<(Made<K::Texels>, Vec<Vec4>)> {
    let size = source.layout.size;
    let (mut residual, list) = split_for_reading(source);
    // Level 0 in a buffer of its full mip chain, which `cube_source` builds.
    residual.resize(CubeLayout::new(size, CubeLayout::full_chain(size)).texel_count() as usize, Vec4::ZERO);
    let (texels, layout) = cube_source(k, k.upload("residual", &residual)?, size, rest)?;
    let mut made = products(k, texels, layout, rest, est, Vec::new())?;
    // The residual's source cube stays where it was made: nothing reads it.
    made.take(Product::SourceCube);
    Ok((made, list))
}

/// The residual's products `rest` and their steps' times put into `baked`.
fn add_split(baked: &mut Baked, mut rest: Baked) {
    baked.timings.extend(rest.timings.iter().cloned());
    baked.timings.sort_by_key(|t| t.step);
    for p in SPLIT {
        if let Some(item) = rest.take(p) {
            baked.insert(p, item);
        }
    }
}

/// `source`'s level 0 split for the shading to add its brightest texels back
/// (`crate::backend::split::split_level` at `split::TEXELS`, as the sheen's source is):
/// the residual level and the excess list.
pub fn split_for_reading(source: &Cube) -> (Vec<Vec4>, Vec<Vec4>) {
    let level = source.level(0);
    crate::backend::split::split_level(level, source.layout.size, level, source.layout.size)
}
