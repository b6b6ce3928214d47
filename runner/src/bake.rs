//! Orchestration of an environment bake: environment → source cube and mips → prefiltered
//! specular cube, irradiance cube and SH9, plus the BRDF table; then the files. The math
//! is in `splitsum_shaders`; this module only sequences it, times it and writes results.

use crate::backend::Backend;
use crate::environment::{Environment, InputReport};
use crate::error::{Error, Result};
use crate::files;
use crate::ktx2::{self, Format};
use crate::preview;
use crate::texture::{Cube, Lut, Sh9};
use serde::Serialize;
use splitsum_shaders::brdf::microfacet::Masking;
use splitsum_shaders::cubemap::CubeLayout;
use splitsum_shaders::equirect;
use splitsum_shaders::irradiance::{SH9, SH9_COSINE};
use splitsum_shaders::prefilter::RoughnessMapping;
use splitsum_shaders::tonemap::Tonemapper;
use std::path::Path;
use std::time::Instant;

/// How roughness is spread over the specular mips (command-line form of
/// [`RoughnessMapping`]).
#[derive(Copy, Clone, Debug, PartialEq, Eq, clap::ValueEnum, Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Mapping {
    /// `r = m/(M−1)`.
    Linear,
    /// `r = (m/(M−1))²`.
    Quadratic,
    /// Mip 0 the mirror, mip 1 at `α = 2^(−M)`, then `α` in geometric progression up to
    /// `r = 1` at the last.
    Geometric,
}

impl From<Mapping> for RoughnessMapping {
    fn from(m: Mapping) -> Self {
        match m {
            Mapping::Linear => RoughnessMapping::Linear,
            Mapping::Quadratic => RoughnessMapping::Quadratic,
            Mapping::Geometric => RoughnessMapping::Geometric,
        }
    }
}

/// How the BRDF table is integrated.
#[derive(Copy, Clone, Debug, PartialEq, Eq, clap::ValueEnum, Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TableMethod {
    /// Deterministic Gauss–Legendre quadrature (`lut::integrate_brdf_quadrature`): within
    /// 10⁻⁵ of the f64 reference at every texel, about 550 evaluations per texel.
    Quadrature,
    /// Monte Carlo over `lut_samples` Hammersley points (Karis 2013; the seed method).
    Sampled,
}

impl TableMethod {
    /// The masking term a table of this method has unless one is asked for: the exact
    /// Smith term by quadrature, Smith–Schlick by sampling (the only one it has).
    pub fn default_masking(self) -> MaskingModel {
        match self {
            TableMethod::Quadrature => MaskingModel::Correlated,
            TableMethod::Sampled => MaskingModel::Schlick,
        }
    }
}

/// The masking–shadowing term the BRDF table is built with (command-line form of
/// `microfacet::Masking`).
#[derive(Copy, Clone, Debug, PartialEq, Eq, clap::ValueEnum, Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MaskingModel {
    /// Separable Smith–Schlick, `k = α/2` (UE4).
    Schlick,
    /// Exact height-correlated Smith (Heitz 2014; Filament, glTF Sample Viewer).
    Correlated,
}

impl From<MaskingModel> for Masking {
    fn from(m: MaskingModel) -> Self {
        match m {
            MaskingModel::Schlick => Masking::SmithSchlick,
            MaskingModel::Correlated => Masking::SmithCorrelated,
        }
    }
}

/// Every knob of a bake.
#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
pub struct Settings {
    /// Face size of mip 0 of the specular cube (a power of two).
    pub size: u32,
    /// Face size of the source cube the products are filtered from (a power of two, at
    /// least `size`).
    pub source_size: u32,
    /// Mips of the specular cube, one roughness each.
    pub mips: u32,
    /// Roughness of each mip.
    pub mapping: Mapping,
    /// GGX samples per texel of specular mip 1 (the sharpest filtered mip).
    pub samples: u32,
    /// Factor by which the sample count grows per mip after mip 1 (1: the same count on
    /// every mip, the seed method). Mips shrink by 4 in texels, so a factor up to 4 keeps
    /// each mip's cost at most mip 1's, and rough lobes need the samples.
    pub sample_growth: u32,
    /// Sum a rough mip exactly over a coarse source level where that costs less than its
    /// samples (`prefilter::exact_level`); false: sample every mip (the seed method).
    pub exact_sums: bool,
    /// Added to the source level each prefilter sample reads (`½·log₂(Ωs/Ωp) + bias`).
    pub lod_bias: f32,
    /// Supersampling density of the equirect → cube resampling (points per source texel
    /// width at the equator).
    pub supersample_density: f32,
    /// Face size of the irradiance cube.
    pub irradiance_size: u32,
    /// Face size of the source level the irradiance convolution sums over.
    pub irradiance_source: u32,
    /// Face size of the source level projected onto SH9.
    pub sh_source: u32,
    /// Width and height of the BRDF table.
    pub lut_size: u32,
    /// Samples per texel of the BRDF table (with `lut_method = sampled`).
    pub lut_samples: u32,
    /// How the BRDF table is integrated.
    pub lut_method: TableMethod,
    /// The table's masking–shadowing term.
    pub lut_masking: MaskingModel,
    /// Texel format of the KTX2 files.
    pub format: Format,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            size: 256,
            source_size: 256,
            mips: 6,
            mapping: Mapping::Geometric,
            samples: 64,
            sample_growth: 2,
            exact_sums: true,
            lod_bias: 0.5,
            supersample_density: 2.0,
            irradiance_size: 32,
            irradiance_source: 16,
            sh_source: 32,
            lut_size: 256,
            lut_samples: 1024,
            lut_method: TableMethod::Quadrature,
            lut_masking: MaskingModel::Correlated,
            format: Format::Auto,
        }
    }
}

/// Largest cube face accepted.
pub const MAX_SIZE: u32 = 4096;

impl Settings {
    /// Checks every value, naming the flag that is out of range.
    pub fn validate(&self) -> Result<()> {
        let pow2 = |name: &str, v: u32, lo: u32, hi: u32| -> Result<()> {
            if !v.is_power_of_two() || v < lo || v > hi {
                return Err(Error::Invalid(format!("{name} must be a power of two from {lo} to {hi}, not {v}")));
            }
            Ok(())
        };
        pow2("--size", self.size, 1, MAX_SIZE)?;
        pow2("--source-size", self.source_size, self.size, MAX_SIZE)?;
        pow2("--irradiance-size", self.irradiance_size, 1, 256)?;
        pow2("--irradiance-source", self.irradiance_source, 1, self.source_size.min(256))?;
        pow2("--sh-source", self.sh_source, 1, self.source_size)?;
        let max_mips = CubeLayout::full_chain(self.size);
        if self.mips == 0 || self.mips > max_mips {
            return Err(Error::Invalid(format!("--mips must be from 1 to {max_mips} for --size {}, not {}", self.size, self.mips)));
        }
        if self.samples == 0 {
            return Err(Error::Invalid("--samples must be at least 1, not 0".into()));
        }
        if !(1..=4).contains(&self.sample_growth) {
            return Err(Error::Invalid(format!("--sample-growth must be from 1 to 4, not {}", self.sample_growth)));
        }
        if !(self.lod_bias.is_finite() && (-16.0..=16.0).contains(&self.lod_bias)) {
            return Err(Error::Invalid(format!("--lod-bias must be within ±16, not {}", self.lod_bias)));
        }
        if !(self.supersample_density > 0.0 && self.supersample_density <= 16.0) {
            return Err(Error::Invalid(format!("--supersample must be in (0, 16], not {}", self.supersample_density)));
        }
        if self.lut_size == 0 || self.lut_size > crate::backend::MAX_LUT_SIZE {
            return Err(Error::Invalid(format!("--lut-size must be from 1 to {}, not {}", crate::backend::MAX_LUT_SIZE, self.lut_size)));
        }
        if self.lut_samples == 0 {
            return Err(Error::Invalid("--lut-samples must be at least 1, not 0".into()));
        }
        if self.lut_method == TableMethod::Sampled && self.lut_masking != MaskingModel::Schlick {
            return Err(Error::Invalid("--lut-masking correlated needs --lut-method quadrature (the sampled table is Smith–Schlick only)".into()));
        }
        Ok(())
    }

    /// The specular mip count for mip-0 faces of `size`: down to 8² faces, and at least two
    /// (the mirror and roughness 1) where the chain has them. With the geometric mapping
    /// this puts mip 1's GGX width at `α₁ = 2^(−M) = 4/size`: two of mip 1's texels. The one
    /// rule for the bake, the display and the planner.
    pub fn default_mips(size: u32) -> u32 {
        let chain = CubeLayout::full_chain(size.max(1));
        chain.saturating_sub(3).max(2).min(chain)
    }

    /// These settings with the mip count held within the specular cube's chain (for small
    /// `size`s, as the report's quick sweep uses).
    pub fn fitted(self) -> Self {
        let mips = self.mips.min(CubeLayout::full_chain(self.size)).max(1);
        Self { mips, irradiance_source: self.irradiance_source.min(self.source_size), sh_source: self.sh_source.min(self.source_size), ..self }
    }

    /// Roughness of each specular mip.
    pub fn roughness(&self) -> Vec<f32> {
        let m: RoughnessMapping = self.mapping.into();
        (0..self.mips).map(|i| m.roughness(i, self.mips)).collect()
    }

    /// The BRDF table these settings bake, in words: `256² by quadrature (Correlated)` or
    /// `256² × 1024 samples`.
    pub fn table_description(&self) -> String {
        match self.lut_method {
            TableMethod::Quadrature => format!("{}² by quadrature ({:?})", self.lut_size, self.lut_masking),
            TableMethod::Sampled => format!("{}² × {} samples", self.lut_size, self.lut_samples),
        }
    }

    /// GGX samples of each specular mip: `samples × sample_growth^(m−1)` from mip 1 on
    /// (mip 0 is the mirror unless the mapping says otherwise), at most 2²⁰.
    pub fn samples_per_mip(&self) -> Vec<u32> {
        (0..self.mips).map(|m| (self.samples as u64 * (self.sample_growth as u64).pow(m.saturating_sub(1))).min(1 << 20) as u32).collect()
    }

    /// Every mip of the specular cube: `0 .. mips`.
    pub fn all_levels(&self) -> Vec<u32> {
        (0..self.mips).collect()
    }

    /// Layout of the specular cube.
    pub fn specular_layout(&self) -> CubeLayout {
        CubeLayout::new(self.size, self.mips)
    }
}

/// The source level whose faces are `face` wide.
pub fn level_of_size(layout: CubeLayout, face: u32) -> u32 {
    (0..layout.levels).find(|&l| layout.level_size(l) <= face).unwrap_or(layout.levels - 1)
}

/// Which products to bake.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Products {
    /// The prefiltered specular cube.
    pub specular: bool,
    /// The irradiance cube.
    pub irradiance: bool,
    /// The SH9 coefficients.
    pub sh9: bool,
    /// The BRDF table.
    pub lut: bool,
}

impl Products {
    /// Everything.
    pub const ALL: Products = Products { specular: true, irradiance: true, sh9: true, lut: true };
}

/// Wall time of one product.
#[derive(Clone, Debug, Serialize)]
pub struct Timing {
    /// The product.
    pub product: &'static str,
    /// Seconds.
    pub seconds: f64,
}

/// The results of a bake.
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

/// Runs step `product`, estimated at `estimates` (see [`step_estimates`]), with its
/// progress shown, and records its wall time.
fn timed<T>(timings: &mut Vec<Timing>, product: &'static str, estimates: &[f64; 4], f: impl FnOnce() -> Result<T>) -> Result<T> {
    let estimate = crate::plan::STEPS.iter().position(|s| *s == product).map(|k| estimates[k]);
    let _step = crate::progress::step(product, estimate);
    let start = Instant::now();
    let r = f()?;
    timings.push(Timing { product, seconds: start.elapsed().as_secs_f64() });
    Ok(r)
}

/// Estimated seconds of each of `plan::STEPS` when baking `products` (and `levels` of the
/// specular cube) of `env` with `settings` on `backend` (the built-in calibration: lavapipe
/// for the GPU backend, 2 cores for the CPU).
pub fn step_estimates(backend: &Backend, env: &Environment, settings: &Settings, products: Products, levels: &[u32]) -> [f64; 4] {
    let width = match env {
        Environment::Equirect(e) => e.width,
        Environment::Cube(_) => 0,
    };
    crate::plan::step_seconds(settings, products, levels, width, &crate::plan::Calibration::default(), matches!(backend, Backend::Gpu(_)))
}

/// Runs estimated over this many seconds are refused unless forced.
pub const MAX_UNFORCED_SECONDS: f64 = 3600.0;

/// The flags that set the cost of each of `plan::STEPS`, for [`check_duration`]'s message.
const STEP_FLAGS: [&str; 4] =
    ["--source-size and --supersample", "--samples, --sample-growth and --size", "--lut-size and --lut-samples", "--irradiance-size and --irradiance-source"];

/// Refuses a run estimated (`estimates`, seconds per `plan::STEPS`) to take over an hour,
/// unless `force`: naming the estimate, its longest step and the flags that set it
/// (`flags`, per step: [`STEP_FLAGS`] for a bake).
pub fn check_duration(estimates: &[f64; 4], flags: &[&str; 4], force: bool) -> Result<()> {
    let total: f64 = estimates.iter().sum();
    if total <= MAX_UNFORCED_SECONDS || force {
        return Ok(());
    }
    let (k, longest) = estimates.iter().copied().enumerate().max_by(|a, b| a.1.total_cmp(&b.1)).expect("four steps");
    Err(Error::Invalid(format!(
        "this bake is estimated to take {} ({} of it for the {}); lower {} (scene: [quality]), or pass --force to run it anyway",
        crate::progress::seconds(total),
        crate::progress::seconds(longest),
        crate::plan::STEPS[k],
        flags[k]
    )))
}

/// [`check_duration`] of baking `products` (and `levels` of the specular cube) of `env`
/// with `settings` on `backend`.
pub fn check_bake_duration(backend: &Backend, env: &Environment, settings: &Settings, products: Products, levels: &[u32], force: bool) -> Result<()> {
    check_duration(&step_estimates(backend, env, settings, products, levels), &STEP_FLAGS, force)
}

/// The source cube of `env` for `settings`: resampled from an equirect, or the given faces
/// reduced to `settings.source_size` through their mip chain.
pub fn source_cube(backend: &Backend, env: &Environment, settings: &Settings) -> Result<Cube> {
    let size = settings.source_size;
    match env {
        Environment::Equirect(e) => {
            let n = equirect::supersampling(size, e.width, settings.supersample_density);
            backend.equirect_to_cube(e, size, n)
        }
        Environment::Cube(c) => {
            let f = c.layout.size;
            if f < size {
                return Err(Error::Invalid(format!("--source-size {size} is larger than the cube's {f}×{f} faces; upsampling adds nothing")));
            }
            let mut full = Cube { layout: CubeLayout::new(f, CubeLayout::full_chain(f)), texels: c.texels.clone() };
            full.texels.resize(full.layout.texel_count() as usize, Default::default());
            backend.build_mips(&mut full)?;
            let first = level_of_size(full.layout, size);
            let layout = CubeLayout::new(size, CubeLayout::full_chain(size));
            let start = full.layout.level_offset(first) as usize;
            Ok(Cube { layout, texels: full.texels[start..].to_vec() })
        }
    }
}

/// The BRDF table `settings` asks for: by quadrature or by sampling.
pub fn brdf_table(backend: &Backend, settings: &Settings) -> Result<Lut> {
    match settings.lut_method {
        TableMethod::Quadrature => backend.brdf_table(settings.lut_size, settings.lut_masking.into()),
        TableMethod::Sampled => backend.brdf_lut(settings.lut_size, settings.lut_samples),
    }
}

/// Bakes `products` of `env` with `settings` on `backend`.
pub fn bake(backend: &Backend, env: &Environment, settings: &Settings, products: Products) -> Result<Baked> {
    settings.validate()?;
    let mut timings = Vec::new();
    let all = settings.all_levels();
    let est = step_estimates(backend, env, settings, products, &all);
    let source = timed(&mut timings, "source cube", &est, || source_cube(backend, env, settings))?;
    let specular = if products.specular {
        Some(timed(&mut timings, "specular", &est, || {
            backend.prefilter_levels(
                &source,
                settings.specular_layout(),
                &settings.roughness(),
                &all,
                &settings.samples_per_mip(),
                settings.exact_sums,
                settings.lod_bias,
            )
        })?)
    } else {
        None
    };
    let irradiance = if products.irradiance {
        let level = level_of_size(source.layout, settings.irradiance_source);
        Some(timed(&mut timings, "irradiance", &est, || backend.irradiance(&source, level, settings.irradiance_size))?)
    } else {
        None
    };
    let sh9 = if products.sh9 {
        let level = level_of_size(source.layout, settings.sh_source);
        Some(timed(&mut timings, "sh9", &est, || backend.sh9(&source, level))?)
    } else {
        None
    };
    let lut = if products.lut { Some(timed(&mut timings, "brdf lut", &est, || brdf_table(backend, settings))?) } else { None };
    Ok(Baked { source, specular, irradiance, sh9, lut, timings })
}

/// One written file.
#[derive(Clone, Debug, Serialize)]
pub struct OutputFile {
    /// Name inside the output folder.
    pub name: String,
    /// What it holds.
    pub what: String,
    /// How writing it changed values (KTX2 only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub written: Option<ktx2::Written>,
}

/// `bake.json`: what was baked, how, from what, and how long it took.
#[derive(Clone, Debug, Serialize)]
pub struct Manifest {
    /// The environment file.
    pub environment: String,
    /// The backend.
    pub backend: String,
    /// Every setting.
    pub settings: Settings,
    /// Roughness of each specular mip.
    pub roughness_per_mip: Vec<f32>,
    /// GGX samples per texel of each specular mip (mip 0, the mirror, is copied).
    pub samples_per_mip: Vec<u32>,
    /// What the default settings measure end to end (`runner report`), for reference.
    pub accuracy: &'static str,
    /// What reading the environment found.
    pub input: InputSummary,
    /// Wall time per product.
    pub timings: Vec<Timing>,
    /// How far SH9 irradiance is from the convolution, over the irradiance cube's texels.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sh9_vs_convolution: Option<ShError>,
    /// The files.
    pub files: Vec<OutputFile>,
    /// Conventions of the outputs.
    pub conventions: Vec<&'static str>,
}

/// Relative error of SH9 irradiance against the convolution (luminance), over every texel
/// of the irradiance cube.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct ShError {
    /// Largest relative error.
    pub max_relative: f64,
    /// Root-mean-square relative error.
    pub rms_relative: f64,
}

/// Compares SH9 irradiance with the irradiance cube texel by texel.
pub fn sh9_error(sh: &Sh9, irradiance: &Cube) -> ShError {
    use splitsum_shaders::{cubemap, irradiance::sh9_irradiance, tonemap::luminance};
    let coeffs = sh.as_vec4();
    let s = irradiance.layout.size;
    let (mut max, mut sum2, mut n) = (0.0f64, 0.0f64, 0usize);
    for face in 0..6 {
        for y in 0..s {
            for x in 0..s {
                let want = luminance(irradiance.texels[irradiance.layout.index(0, face, x, y) as usize].truncate()) as f64;
                let got = luminance(sh9_irradiance(&coeffs, cubemap::texel_dir(face, x, y, s))) as f64;
                if want > 0.0 {
                    let r = (got - want).abs() / want;
                    max = max.max(r);
                    sum2 += r * r;
                    n += 1;
                }
            }
        }
    }
    ShError { max_relative: max, rms_relative: (sum2 / n.max(1) as f64).sqrt() }
}

/// [`InputReport`] for the manifest.
#[derive(Clone, Debug, Serialize)]
pub struct InputSummary {
    /// Negative values set to 0.
    pub negative_texels: u64,
    /// Values above 10²⁰ clamped.
    pub clamped_texels: u64,
    /// NaN texels (replaced when sanitised).
    pub nan_texels: u64,
    /// Infinite texels (replaced when sanitised).
    pub infinite_texels: u64,
    /// Largest finite value.
    pub max_value: f32,
}

impl From<&InputReport> for InputSummary {
    fn from(r: &InputReport) -> Self {
        Self { negative_texels: r.negative, clamped_texels: r.clamped, nan_texels: r.nan, infinite_texels: r.infinite, max_value: r.max_value }
    }
}

/// The SH9 file: radiance coefficients and the `E/π` coefficients derived from them.
#[derive(Serialize)]
struct ShFile<'a> {
    convention: &'a str,
    order: [&'a str; 9],
    radiance: [[f64; 3]; 9],
    irradiance_over_pi: [[f64; 3]; 9],
}

/// Writes every baked product into `dir` (created if missing), each file atomically, and
/// `bake.json` last.
pub fn write(dir: &Path, baked: &Baked, settings: &Settings, manifest_base: Manifest) -> Result<Manifest> {
    let _step = crate::progress::step("writing the files", None);
    std::fs::create_dir_all(dir).map_err(|e| Error::file(dir, format!("cannot create the output folder: {e}")))?;
    let mut manifest = manifest_base;
    let mut files_out = Vec::new();
    let mut add = |name: &str, what: String, written: Option<ktx2::Written>| {
        files_out.push(OutputFile { name: name.to_string(), what, written });
    };
    let exposure = preview::auto_exposure(baked.source.level(0));
    let save_png = |name: &str, pic: &preview::Picture| -> Result<()> {
        files::write_png(&dir.join(name), pic.width, pic.height, &pic.to_rgb8(exposure, Tonemapper::Aces))
    };
    save_png("preview_source.png", &preview::cross(&baked.source, 0, settings.source_size.min(256)))?;
    add("preview_source.png", "the source cube, tonemapped (ACES, auto exposure), as a cross".into(), None);
    if let Some(spec) = &baked.specular {
        let w = ktx2::write(&dir.join("specular.ktx2"), spec, settings.format)?;
        report_clamp("specular.ktx2", &w);
        add("specular.ktx2", "GGX-prefiltered radiance, one roughness per mip (roughness_per_mip)".into(), Some(w));
        for m in 0..spec.layout.levels {
            let name = format!("specular_mip{m}.exr");
            files::write_cube_level_exr(&dir.join(&name), spec, m, &format!("prefiltered radiance at roughness {}", settings.roughness()[m as usize]))?;
            add(&name, format!("mip {m} as EXR for inspection"), None);
        }
        save_png("preview_specular.png", &preview::mip_strip(spec, 64))?;
        add("preview_specular.png", "every specular mip as a cross, roughness rising to the right".into(), None);
    }
    if let Some(irr) = &baked.irradiance {
        let w = ktx2::write(&dir.join("irradiance.ktx2"), irr, settings.format)?;
        report_clamp("irradiance.ktx2", &w);
        add("irradiance.ktx2", "irradiance divided by π (cosine-weighted mean radiance)".into(), Some(w));
        files::write_cube_level_exr(&dir.join("irradiance.exr"), irr, 0, "irradiance / pi")?;
        add("irradiance.exr", "the irradiance cube as EXR for inspection".into(), None);
        save_png("preview_irradiance.png", &preview::cross(irr, 0, 64))?;
        add("preview_irradiance.png", "the irradiance cube as a cross".into(), None);
    }
    if let Some(sh) = &baked.sh9 {
        let file = ShFile {
            convention: "real SH (Sloan 2008), radiance L_lm = sum L Y_lm dOmega; E(n)/pi = sum (A_l/pi) L_lm Y_lm(n), A_l/pi = 1, 2/3, 1/4",
            order: ["0,0", "1,-1", "1,0", "1,1", "2,-2", "2,-1", "2,0", "2,1", "2,2"],
            radiance: sh.radiance,
            irradiance_over_pi: std::array::from_fn(|k| sh.radiance[k].map(|v| v * SH9_COSINE[k] as f64)),
        };
        let json = serde_json::to_string_pretty(&file).expect("serialisable");
        files::write_atomic(&dir.join("sh9.json"), |w| std::io::Write::write_all(w, json.as_bytes()))?;
        add("sh9.json", format!("{SH9} spherical-harmonic coefficients of radiance and of E/π"), None);
    }
    if let Some(lut) = &baked.lut {
        files::write_lut_exr(&dir.join("brdf_lut.exr"), lut)?;
        files::write_png(&dir.join("brdf_lut.png"), lut.size, lut.size, &files::lut_preview(lut))?;
        add("brdf_lut.exr", "split-sum BRDF table: R = scale, G = bias; x = n·v, y = roughness".into(), None);
        add("brdf_lut.png", "its 8-bit preview".into(), None);
    }
    manifest.files = files_out;
    manifest.timings = baked.timings.clone();
    if let (Some(sh), Some(irr)) = (&baked.sh9, &baked.irradiance) {
        manifest.sh9_vs_convolution = Some(sh9_error(sh, irr));
    }
    let json = serde_json::to_string_pretty(&manifest).expect("serialisable");
    files::write_atomic(&dir.join("bake.json"), |w| std::io::Write::write_all(w, json.as_bytes()))?;
    Ok(manifest)
}

fn report_clamp(name: &str, w: &ktx2::Written) {
    if w.clamped > 0 {
        eprintln!(
            "warning: {name}: {} values above the half-float maximum 65504 (largest {:.4e}) were clamped to 65504; use --format rgba32f to keep them",
            w.clamped, w.max_value
        );
    } else if w.vk_format == ktx2::VK_FORMAT_R32G32B32A32_SFLOAT && w.max_value > ktx2::HALF_MAX {
        eprintln!("note: {name}: values reach {:.4e}, beyond half floats: written as RGBA32F", w.max_value);
    }
}

/// What `runner report` measured for the default settings (city.exr, 1024×512 with a
/// 34 000 sun; the figures the README quotes), stated in every manifest.
pub const DEFAULTS_ACCURACY: &str = "defaults (256² cube, 6 mips, geometric roughness, 64 GGX samples at mip 1 doubling per mip, the r = 1 mip summed exactly, dominant-direction lookup, table by quadrature with exact Smith) on city.exr: shaded colour against the full reflectance integral (exact Smith, f64), mean relative error 16 % over roughness 0.02-1 and all views (the seed method: 32 %), of which the bake adds 5-10 % per view band and the split-sum approximation 7-39 %; prefiltered lookup at any roughness 7.2 % mean (seed 12.6 %); BRDF table max error 6.2e-6; bake 0.92 s on lavapipe, 1.65 s on 2 CPU cores (runner report, runner bench)";

/// The conventions stated in every manifest.
pub const CONVENTIONS: [&str; 5] = [
    "cube faces +X -X +Y -Y +Z -Z, Vulkan/KTX2 orientation (OpenGL 4.6 table 8.19)",
    "equirect: image centre looks down -Z, +Y up; u = 0.5 + atan2(x, -z)/2pi, v = polar angle/pi",
    "specular mip m holds roughness roughness_per_mip[m] (alpha = roughness^2), GGX with n = v = r",
    "irradiance values are E/pi: a Lambert surface of albedo rho reflects rho times the value",
    "half-float overflow: values above 65504 are clamped and counted (format rgba16f) or kept in rgba32f (format auto)",
];

/// What the display reads: the specular cube, the irradiance cube and the BRDF table.
pub const DISPLAY_PRODUCTS: Products = Products { specular: true, irradiance: true, sh9: false, lut: true };

/// Bakes what the display reads ([`DISPLAY_PRODUCTS`]) of `env`.
pub fn bake_for_display(backend: &Backend, env: &Environment, settings: &Settings) -> Result<crate::render::BakedEnvironment> {
    let baked = bake(backend, env, settings, DISPLAY_PRODUCTS)?;
    Ok(crate::render::BakedEnvironment {
        source: baked.source,
        specular: baked.specular.expect("baked"),
        irradiance: baked.irradiance.expect("baked"),
        lut: baked.lut.expect("baked"),
        mapping: settings.mapping.into(),
    })
}

/// What happened to a scene's bake.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// Found in the cache: nothing baked.
    CacheHit,
    /// Baked (and stored, when there is a cache).
    Baked,
    /// The cache held an entry that could not be used (why); baked again.
    Rebuilt(String),
    /// `--force`: baked again regardless of the cache.
    Forced,
}

/// A scene's bake: the plan, the products and how they were obtained.
pub struct SceneBake {
    /// The plan.
    pub plan: crate::plan::Plan,
    /// The products the display reads (stand-ins for what the plan left out).
    pub env: crate::render::BakedEnvironment,
    /// Cache key.
    pub key: String,
    /// Cache hit, baked, or rebuilt.
    pub outcome: Outcome,
    /// Wall time per product (empty on a cache hit).
    pub timings: Vec<Timing>,
}

/// A 1×1 cube of zeros: the stand-in for a product a plan leaves out (nothing reads it).
pub fn empty_cube() -> Cube {
    Cube { layout: CubeLayout::new(1, 1), texels: vec![Default::default(); 6] }
}

/// Bakes what `plan` keeps of `env` into what the display reads.
pub fn bake_plan(backend: &Backend, env: &Environment, plan: &crate::plan::Plan) -> Result<(crate::render::BakedEnvironment, Vec<Timing>)> {
    let s = &plan.settings;
    s.validate()?;
    let mut timings = Vec::new();
    let est = step_estimates(backend, env, s, plan.products, &plan.levels);
    let source = timed(&mut timings, "source cube", &est, || source_cube(backend, env, s))?;
    let specular = if plan.products.specular {
        timed(&mut timings, "specular", &est, || {
            backend.prefilter_levels(&source, s.specular_layout(), &s.roughness(), &plan.levels, &s.samples_per_mip(), s.exact_sums, s.lod_bias)
        })?
    } else {
        empty_cube()
    };
    let irradiance = if plan.products.irradiance {
        let level = level_of_size(source.layout, s.irradiance_source);
        timed(&mut timings, "irradiance", &est, || backend.irradiance(&source, level, s.irradiance_size))?
    } else {
        empty_cube()
    };
    let lut =
        if plan.products.lut { timed(&mut timings, "brdf lut", &est, || brdf_table(backend, s))? } else { Lut { size: 1, texels: vec![Default::default()] } };
    let source = Cube { layout: CubeLayout::new(source.layout.size, 1), texels: source.level(0).to_vec() };
    Ok((crate::render::BakedEnvironment { source, specular, irradiance, lut, mapping: s.mapping.into() }, timings))
}

/// Plans `scene` and bakes it, or takes it from `cache` when an entry for exactly this
/// input, plan, backend and shader build is there (`force` bakes regardless).
pub fn bake_scene(
    backend: &Backend,
    scene: &crate::scene::Scene,
    cal: &crate::plan::Calibration,
    cache: Option<&crate::cache::Cache>,
    force: bool,
) -> Result<SceneBake> {
    let env_path = scene.environment.as_ref().map(|p| scene.resolve(p));
    let (env, _) = match &env_path {
        Some(p) => crate::environment::load(p, scene.sanitize)?,
        None => (crate::environment::embedded_default()?, Default::default()),
    };
    let identity = crate::environment::identity(env_path.as_deref())?;
    let plan = crate::plan::plan_for(scene, &env, cal);
    let plan_json = serde_json::to_string(&(&plan.settings, &plan.products, &plan.levels, scene.sanitize)).expect("serialisable");
    let key = crate::cache::key(&identity, &plan_json, &backend.identity());
    let mut outcome = if force { Outcome::Forced } else { Outcome::Baked };
    // Held until this bake is stored: a concurrent run of the same key waits, then hits.
    let _lock = cache.map(|c| c.lock(&key)).transpose()?;
    if let (Some(c), false) = (cache, force) {
        match c.get(&key) {
            crate::cache::Lookup::Hit(env) => return Ok(SceneBake { plan, env: *env, key, outcome: Outcome::CacheHit, timings: Vec::new() }),
            crate::cache::Lookup::Miss => {}
            crate::cache::Lookup::Rejected(why) => outcome = Outcome::Rebuilt(why),
        }
    }
    check_bake_duration(backend, &env, &plan.settings, plan.products, &plan.levels, force)?;
    let (baked, timings) = bake_plan(backend, &env, &plan)?;
    if let Some(c) = cache {
        c.put(&key, &baked)?;
    }
    Ok(SceneBake { plan, env: baked, key, outcome, timings })
}
