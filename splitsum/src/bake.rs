//! The one bake sequence: source cube, then the specular cube, the irradiance, SH9 and the
//! BRDF table that [`Products`] asks for, on any backend ([`Kernels`]). [`make`] leaves the
//! products where the backend made them (device buffers on the GPU, for
//! `crate::textures`); [`bake`] reads them into host memory ([`Baked`]) for files, reports
//! and the CPU rasteriser. Everything else (plans, caches, the display) calls these.

use crate::backend::{Backend, Kernels, Prefilter, with_kernels};
use crate::cost::{self, Calibration, STEPS};
use crate::environment::Environment;
use crate::error::{Error, Result};
use crate::settings::{Products, Settings, TableMethod, exact_levels, level_of_size};
use crate::texture::{Cube, Lut, Sh9};
use serde::Serialize;
use splitsum_shaders::cubemap::{self, CubeLayout};
use splitsum_shaders::equirect;
use splitsum_shaders::prefilter::RoughnessMapping;
use splitsum_shaders::shade::EnvironmentShape;
use std::time::Instant;

/// Wall time of one product.
#[derive(Clone, Debug, Serialize)]
pub struct Timing {
    /// The product.
    pub product: &'static str,
    /// Seconds.
    pub seconds: f64,
}

/// The products as a backend made them (`T`: host texels, or device buffers).
pub struct Made<T> {
    /// The source cube with its full mip chain.
    pub source: T,
    /// Its layout.
    pub source_layout: CubeLayout,
    /// The specular cube (`Settings::specular_layout`).
    pub specular: Option<T>,
    /// The irradiance cube (`E/π`).
    pub irradiance: Option<T>,
    /// SH9 radiance coefficients.
    pub sh9: Option<Sh9>,
    /// The BRDF table, `(A, B, 0, 0)` per texel.
    pub lut: Option<T>,
    /// Wall time of each product.
    pub timings: Vec<Timing>,
}

/// The results of a bake, in host memory.
pub struct Baked {
    /// The source cube with its mips.
    pub source: Cube,
    /// The specular cube.
    pub specular: Option<Cube>,
    /// The irradiance cube (`E/π`).
    pub irradiance: Option<Cube>,
    /// SH9 radiance coefficients.
    pub sh9: Option<Sh9>,
    /// The BRDF table.
    pub lut: Option<Lut>,
    /// Wall time of each product.
    pub timings: Vec<Timing>,
}

/// Runs step `product` on `k`, estimated at `estimates` (see [`step_estimates`]), with its
/// progress shown, and records its wall time (until the backend has finished it).
fn timed<K: Kernels, T>(k: &K, timings: &mut Vec<Timing>, product: &'static str, estimates: &[f64; 4], f: impl FnOnce() -> Result<T>) -> Result<T> {
    let estimate = STEPS.iter().position(|s| *s == product).map(|k| estimates[k]);
    let _step = crate::progress::step(product, estimate);
    let start = Instant::now();
    let r = f()?;
    k.finish()?;
    timings.push(Timing { product, seconds: start.elapsed().as_secs_f64() });
    Ok(r)
}

/// Estimated seconds of each of `cost::STEPS` when baking `products` (and `levels` of the
/// specular cube) of `env` with `settings`, on the GPU (`gpu`) or the CPU (the built-in
/// calibration: lavapipe, 2 cores).
pub fn step_estimates(gpu: bool, env: &Environment, settings: &Settings, products: Products, levels: &[u32]) -> [f64; 4] {
    let width = match env {
        Environment::Equirect(e) => e.width,
        Environment::Cube(_) => 0,
    };
    cost::step_seconds(settings, products, levels, width, &Calibration::default(), gpu)
}

/// Runs estimated over this many seconds are refused unless forced.
pub const MAX_UNFORCED_SECONDS: f64 = 3600.0;

/// Refuses a run estimated (`estimates`, seconds per `cost::STEPS`) to take over an hour,
/// unless `force` (`Error::TooLong`, naming the estimate and its longest step).
pub fn check_duration(estimates: &[f64; 4], force: bool) -> Result<()> {
    let total: f64 = estimates.iter().sum();
    if total <= MAX_UNFORCED_SECONDS || force {
        return Ok(());
    }
    let (k, longest) = estimates.iter().copied().enumerate().max_by(|a, b| a.1.total_cmp(&b.1)).expect("four steps");
    Err(Error::TooLong { seconds: total, step: STEPS[k], step_seconds: longest })
}

/// The source cube of `env` for `settings` with its full mip chain: resampled from an
/// equirect, or the given faces reduced to `settings.source_size` through their mip chain.
pub fn source_cube<K: Kernels>(k: &K, env: &Environment, settings: &Settings) -> Result<(K::Texels, CubeLayout)> {
    let size = settings.source_size;
    let layout = CubeLayout::new(size, CubeLayout::full_chain(size));
    match env {
        Environment::Equirect(e) => {
            let n = equirect::supersampling(size, e.width, settings.supersample_density);
            Ok((k.equirect_to_cube(e, size, n, settings.facing)?, layout))
        }
        Environment::Cube(c) => {
            let s = c.layout.size;
            let full_layout = CubeLayout::new(s, CubeLayout::full_chain(s));
            let mut texels = if settings.target.fixed().mirror_faces {
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
            cube_source(k, k.upload("cube faces", &texels)?, c.layout.size, settings)
        }
    }
}

/// The source cube of `settings` from a cube whose faces are `face` wide: `full` holds its
/// level 0 in a buffer of its full mip chain; the chain is filtered and the levels from
/// `settings.source_size` down are kept.
pub fn cube_source<K: Kernels>(k: &K, mut full: K::Texels, face: u32, settings: &Settings) -> Result<(K::Texels, CubeLayout)> {
    let size = settings.source_size;
    if face < size {
        return Err(Error::setting("source_size", format!("{size} is larger than the cube's {face}×{face} faces; upsampling adds nothing")));
    }
    let full_layout = CubeLayout::new(face, CubeLayout::full_chain(face));
    k.build_mips(&mut full, full_layout)?;
    let start = full_layout.level_offset(level_of_size(full_layout, size));
    Ok((k.slice(&full, start, full_layout.texel_count() - start)?, CubeLayout::new(size, CubeLayout::full_chain(size))))
}

/// Bakes `products` (and `levels` of the specular cube; the others stay zero) from a
/// source cube already on backend `k`.
pub fn products<K: Kernels>(
    k: &K,
    source: K::Texels,
    source_layout: CubeLayout,
    settings: &Settings,
    products: Products,
    levels: &[u32],
    estimates: &[f64; 4],
    mut timings: Vec<Timing>,
) -> Result<Made<K::Texels>> {
    let s = settings;
    let specular = if products.specular {
        let (roughness, samples) = (s.roughness(), s.samples_per_mip());
        let exact = exact_levels(&roughness, &samples, s.exact_sums, source_layout);
        let job = Prefilter { layout: s.specular_layout(), roughness: &roughness, levels, samples: &samples, exact: &exact, lod_bias: s.lod_bias };
        Some(timed(k, &mut timings, "specular", estimates, || k.prefilter(&source, source_layout, &job))?)
    } else {
        None
    };
    let irradiance = if products.irradiance {
        let level = level_of_size(source_layout, s.irradiance_source);
        Some(timed(k, &mut timings, "irradiance", estimates, || k.irradiance(&source, source_layout, level, s.irradiance_size))?)
    } else {
        None
    };
    let sh9 = if products.sh9 {
        let level = level_of_size(source_layout, s.sh_source);
        Some(timed(k, &mut timings, "sh9", estimates, || k.sh9(&source, source_layout, level))?)
    } else {
        None
    };
    let lut = if products.lut {
        Some(timed(k, &mut timings, "brdf lut", estimates, || match s.lut_method {
            TableMethod::Quadrature => k.brdf_table(s.lut_size, s.lut_masking),
            TableMethod::Sampled => k.brdf_lut(s.lut_size, s.lut_samples),
        })?)
    } else {
        None
    };
    Ok(Made { source, source_layout, specular, irradiance, sh9, lut, timings })
}

/// Validates `settings`, then bakes `products` (and `levels` of the specular cube) of
/// `env` on backend `k`, leaving them there.
pub fn make<K: Kernels>(k: &K, gpu: bool, env: &Environment, settings: &Settings, products: Products, levels: &[u32]) -> Result<Made<K::Texels>> {
    settings.validate()?;
    if let Some(&m) = levels.iter().find(|&&m| m >= settings.mips) {
        return Err(Error::setting("mips", format!("has no mip {m} to bake (there are {})", settings.mips)));
    }
    let est = step_estimates(gpu, env, settings, products, levels);
    let mut timings = Vec::new();
    let (source, layout) = timed(k, &mut timings, "source cube", &est, || source_cube(k, env, settings))?;
    self::products(k, source, layout, settings, products, levels, &est, timings)
}

/// `made` read into host memory.
pub fn read<K: Kernels>(k: &K, made: Made<K::Texels>, settings: &Settings) -> Result<Baked> {
    let cube = |layout: CubeLayout, t: &K::Texels| -> Result<Cube> { Ok(Cube { layout, texels: k.read(t)? }) };
    Ok(Baked {
        source: cube(made.source_layout, &made.source)?,
        specular: made.specular.as_ref().map(|t| cube(settings.specular_layout(), t)).transpose()?,
        irradiance: made.irradiance.as_ref().map(|t| cube(CubeLayout::new(settings.irradiance_size, 1), t)).transpose()?,
        sh9: made.sh9,
        lut: made.lut.as_ref().map(|t| -> Result<Lut> { Ok(Lut::from_texels(settings.lut_size, &k.read(t)?)) }).transpose()?,
        timings: made.timings,
    })
}

/// Bakes `products` of `env` with `settings` on `backend`, every specular mip, into host
/// memory.
pub fn bake(backend: &Backend, env: &Environment, settings: &Settings, products: Products) -> Result<Baked> {
    bake_levels(backend, env, settings, products, &settings.all_levels())
}

/// As [`bake`], baking only `levels` of the specular cube (the others stay zero).
pub fn bake_levels(backend: &Backend, env: &Environment, settings: &Settings, products: Products, levels: &[u32]) -> Result<Baked> {
    let gpu = backend.is_gpu();
    with_kernels!(backend, k => read(k, make(k, gpu, env, settings, products, levels)?, settings))
}

/// A 1×1 cube of zeros: the stand-in for a product a plan leaves out (nothing reads it).
pub fn empty_cube() -> Cube {
    Cube { layout: CubeLayout::new(1, 1), texels: vec![Default::default(); 6] }
}

impl Baked {
    /// What a renderer reads, with stand-ins for the products not baked (nothing reads
    /// them) and the source cube's level 0 (the sharp sky).
    pub fn into_display(self, mapping: RoughnessMapping) -> BakedEnvironment {
        let source = self.source.levels(0, 0);
        BakedEnvironment {
            source,
            specular: self.specular.unwrap_or_else(empty_cube),
            irradiance: self.irradiance.unwrap_or_else(empty_cube),
            lut: self.lut.unwrap_or(Lut { size: 1, texels: vec![Default::default()] }),
            mapping,
        }
    }
}

/// What a renderer reads, in host memory: the sharp sky, the specular cube, the irradiance
/// cube and the BRDF table.
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
    /// Roughness of the specular mips.
    pub mapping: RoughnessMapping,
}

impl BakedEnvironment {
    /// An exposure at which a white Lambert surface shows, on average, at 0.5 before the
    /// tone curve: `0.5 / mean(E/π)`. The mean of `E/π` over all normals is the
    /// solid-angle-weighted mean of the radiance (`∫ max(0, n·l) dn = π` for every `l`), so
    /// it is read from the source cube and does not depend on which products a plan bakes.
    pub fn auto_exposure(&self) -> f32 {
        let s = self.source.layout.size;
        let (mut sum, mut weight) = (0.0f64, 0.0f64);
        for (i, c) in self.source.level(0).iter().enumerate() {
            let (x, y) = (i as u32 % s, (i as u32 / s) % s);
            let w = splitsum_shaders::cubemap::texel_solid_angle(x, y, s) as f64;
            sum += w * splitsum_shaders::tonemap::luminance(c.truncate()) as f64;
            weight += w;
        }
        let mean = sum / weight.max(f64::MIN_POSITIVE);
        if mean > 0.0 { (0.5 / mean) as f32 } else { 1.0 }
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
        }
    }
}

/// Bakes what a renderer reads ([`Products::DISPLAY`]) of `env` on `backend`.
pub fn bake_for_display(backend: &Backend, env: &Environment, settings: &Settings) -> Result<BakedEnvironment> {
    Ok(bake(backend, env, settings, Products::DISPLAY)?.into_display(settings.mapping))
}

/// The source cube of `env` for `settings` (with its full mip chain) on `backend`, in
/// host memory.
pub fn host_source_cube(backend: &Backend, env: &Environment, settings: &Settings) -> Result<Cube> {
    with_kernels!(backend, k => {
        let (t, layout) = source_cube(k, env, settings)?;
        Ok(Cube { layout, texels: k.read(&t)? })
    })
}
