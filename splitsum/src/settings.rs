//! What a bake makes and how: [`Settings`] (every knob, with the one set of defaults and
//! the one validation), [`Products`] (which products) and [`Target`] (whose conventions
//! the files follow).

use crate::adjustment::Adjustment;
use crate::error::{Error, Result};
use crate::ktx2::Format;
use serde::{Deserialize, Serialize};
use splitsum_shaders::brdf::microfacet::Masking;
use splitsum_shaders::choice::Choice;
use splitsum_shaders::cubemap::CubeLayout;
use splitsum_shaders::equirect::Facing;
use splitsum_shaders::prefilter::{self, RoughnessMapping};

/// How the BRDF table is integrated.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum TableMethod {
    /// Deterministic Gauss–Legendre quadrature (`lut::integrate_brdf_quadrature`): within
    /// 10⁻⁵ of the f64 reference at every texel, about 550 evaluations per texel.
    Quadrature,
    /// Monte Carlo over `lut_samples` Hammersley points (Karis 2013; the seed method).
    Sampled,
}

splitsum_shaders::choice!(TableMethod: Quadrature => "quadrature", Sampled => "sampled");

impl TableMethod {
    /// The masking term a table of this method has unless one is asked for: the exact
    /// Smith term by quadrature, Smith–Schlick by sampling (the only one it has).
    pub fn default_masking(self) -> Masking {
        match self {
            TableMethod::Quadrature => Masking::SmithCorrelated,
            TableMethod::Sampled => Masking::SmithSchlick,
        }
    }
}

/// Whose conventions a bake's files follow. Each engine target fixes, in
/// [`Target::fixed`], the settings its loader and shaders assume (the equirect's facing,
/// the roughness per mip, the mip count, the table's masking term) and, in
/// `crate::output`, the files, their names and formats. The README cites the engine lines.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
#[repr(u32)]
pub enum Target {
    /// splitsum's own folder: every product, EXR and PNG views, `bake.json`.
    Splitsum = 0,
    /// The Khronos glTF-IBL-Sampler's files, as the glTF Sample Viewer reads them.
    Khronos = 1,
    /// Bevy's `EnvironmentMapLight` (the glTF-IBL-Sampler conventions Bevy documents; KTX2
    /// with zstd, as Bevy's own environment maps).
    Bevy = 2,
    /// Filament's `IndirectLight` and `Skybox` (cmgen `--format=ktx --deploy`).
    Filament = 3,
}

splitsum_shaders::choice!(Target: Splitsum => "splitsum", Khronos => "khronos", Bevy => "bevy", Filament => "filament");

/// The settings an engine target fixes (`None`: any value).
#[derive(Copy, Clone, Debug)]
pub struct Fixed {
    /// Which way the equirect's centre faces.
    pub facing: Facing,
    /// Roughness per mip.
    pub mapping: Option<RoughnessMapping>,
    /// Mips for a given mip-0 face size.
    pub mips: Option<fn(u32) -> u32>,
    /// The table's masking term (where the target has a table).
    pub lut_masking: Option<Masking>,
    /// A cube input (six faces) is mirrored in `x` (`cubemap::mirrored_x_texel`), as cmgen
    /// mirrors every input; equirects are covered by `facing`.
    pub mirror_faces: bool,
}

impl Target {
    /// The settings this target fixes, with where each comes from.
    pub fn fixed(self) -> Fixed {
        match self {
            Target::Splitsum => Fixed { facing: Facing::NegZ, mapping: None, mips: None, lut_masking: None, mirror_faces: false },
            // glTF-IBL-Sampler `lib.cpp`: `_mipmapCount = floor(log2(_cubemapResolution))`,
            // `roughness = currentMipLevel / (outputMipLevels - 1)`; its table uses
            // `V_SmithGGXCorrelated` (`filter.frag`). Bevy reads mip
            // `perceptual_roughness * (levels - 1)` (`environment_map.wesl`).
            Target::Khronos | Target::Bevy => Fixed {
                facing: Facing::PosX,
                mapping: Some(RoughnessMapping::Linear),
                mips: Some(khronos_mips),
                lut_masking: Some(Masking::SmithCorrelated),
                mirror_faces: false,
            },
            // cmgen: levels from the base size down to 16² (`IBL_DEFAULT_MIN_LOD_SIZE`),
            // `lodToPerceptualRoughness`, every input mirrored (`g_mirror`); Filament's
            // engine carries its own DFG table.
            Target::Filament => {
                Fixed { facing: Facing::PosZ, mapping: Some(RoughnessMapping::Filament), mips: Some(filament_mips), lut_masking: None, mirror_faces: true }
            }
        }
    }

    /// What the target's engine reads: Khronos and Bevy a specular and an irradiance cube
    /// and the table; Filament the specular cube and SH9 (its table is built in).
    pub fn products(self) -> Products {
        match self {
            Target::Splitsum => Products::ALL,
            Target::Khronos | Target::Bevy => Products { specular: true, irradiance: true, sh9: false, lut: true },
            Target::Filament => Products { specular: true, irradiance: false, sh9: true, lut: false },
        }
    }
}

/// glTF-IBL-Sampler's mip count: `floor(log₂ size)`, at least 1.
fn khronos_mips(size: u32) -> u32 {
    size.max(2).ilog2()
}

/// cmgen's mip count: from `size` down to 16² faces, `log₂ size + 1 − 4`, or the whole
/// chain for faces of 16² or less.
fn filament_mips(size: u32) -> u32 {
    let chain = CubeLayout::full_chain(size.max(1));
    if size > 16 { chain - 4 } else { chain }
}

/// Serde for a [`Choice`]: by its name.
pub mod named {
    use serde::{Deserialize, Deserializer, Serializer, de::Error as _};
    use splitsum_shaders::choice::Choice;

    /// Writes the choice's name.
    pub fn serialize<S: Serializer, T: Choice>(v: &T, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(v.name())
    }

    /// Reads a choice by name, listing the names on a mismatch.
    pub fn deserialize<'de, D: Deserializer<'de>, T: Choice>(d: D) -> Result<T, D::Error> {
        let name = String::deserialize(d)?;
        T::from_name(&name).ok_or_else(|| {
            let names: Vec<&str> = T::ALL.iter().map(|c| c.name()).collect();
            D::Error::custom(format!("unknown value {name:?}, expected one of {}", names.join(", ")))
        })
    }
}

/// Every knob of a bake. [`Settings::default`] is the one set of defaults (the CLI, the
/// scene files and the library all start from it); [`Settings::validate`] the one check.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Settings {
    /// Face size of mip 0 of the specular cube (a power of two).
    pub size: u32,
    /// Face size of the source cube the products are filtered from (a power of two, at
    /// least `size`).
    pub source_size: u32,
    /// Mips of the specular cube, one roughness each.
    pub mips: u32,
    /// Roughness of each mip.
    #[serde(with = "named")]
    pub mapping: RoughnessMapping,
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
    #[serde(with = "named")]
    pub lut_method: TableMethod,
    /// The table's masking–shadowing term.
    #[serde(with = "named")]
    pub lut_masking: Masking,
    /// Texel format of the KTX2 files.
    #[serde(with = "named")]
    pub format: Format,
    /// Which way the equirect's centre faces in the cube (`-z`: splitsum's).
    #[serde(with = "named")]
    pub facing: Facing,
    /// Whose conventions the files follow.
    #[serde(with = "named")]
    pub target: Target,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            size: 256,
            source_size: 256,
            mips: 6,
            mapping: RoughnessMapping::Geometric,
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
            lut_masking: Masking::SmithCorrelated,
            format: Format::Auto,
            facing: Facing::NegZ,
            target: Target::Splitsum,
        }
    }
}

/// Largest cube face accepted.
pub const MAX_SIZE: u32 = 4096;

/// The most GGX samples a texel of one specular mip takes (2²⁰): beyond it a sampled mip's
/// error is far below the half float it is stored in.
pub const MAX_SAMPLES: u32 = 1 << 20;

/// Largest BRDF table accepted (a 4096² table is 128 MiB; beyond that nothing gains).
pub const MAX_LUT_SIZE: u32 = 4096;

impl Settings {
    /// Checks every value; an error names the field (`Error::Setting`).
    pub fn validate(&self) -> Result<()> {
        let pow2 = |field: &'static str, v: u32, lo: u32, hi: u32| -> Result<()> {
            if !v.is_power_of_two() || v < lo || v > hi {
                return Err(Error::setting(field, format!("must be a power of two from {lo} to {hi}, not {v}")));
            }
            Ok(())
        };
        pow2("size", self.size, 1, MAX_SIZE)?;
        pow2("source_size", self.source_size, self.size, MAX_SIZE)?;
        pow2("irradiance_size", self.irradiance_size, 1, 256)?;
        pow2("irradiance_source", self.irradiance_source, 1, self.source_size.min(256))?;
        pow2("sh_source", self.sh_source, 1, self.source_size)?;
        let max_mips = CubeLayout::full_chain(self.size);
        if self.mips == 0 || self.mips > max_mips {
            return Err(Error::setting("mips", format!("must be from 1 to {max_mips} for {0}² faces, not {1}", self.size, self.mips)));
        }
        if self.samples == 0 || self.samples > MAX_SAMPLES {
            return Err(Error::setting("samples", format!("must be from 1 to {MAX_SAMPLES} (the most a mip takes), not {}", self.samples)));
        }
        if !(1..=4).contains(&self.sample_growth) {
            return Err(Error::setting("sample_growth", format!("must be from 1 to 4, not {}", self.sample_growth)));
        }
        if !(self.lod_bias.is_finite() && (-16.0..=16.0).contains(&self.lod_bias)) {
            return Err(Error::setting("lod_bias", format!("must be within ±16, not {}", self.lod_bias)));
        }
        if !(self.supersample_density > 0.0 && self.supersample_density <= 16.0) {
            return Err(Error::setting("supersample_density", format!("must be in (0, 16], not {}", self.supersample_density)));
        }
        if self.lut_size == 0 || self.lut_size > MAX_LUT_SIZE {
            return Err(Error::setting("lut_size", format!("must be from 1 to {}, not {}", MAX_LUT_SIZE, self.lut_size)));
        }
        if self.lut_samples == 0 {
            return Err(Error::setting("lut_samples", "must be at least 1, not 0"));
        }
        if self.lut_method == TableMethod::Sampled && self.lut_masking != Masking::SmithSchlick {
            return Err(Error::setting("lut_masking", "correlated needs the quadrature table method (the sampled table is Smith–Schlick only)"));
        }
        self.check_target()
    }

    /// These settings with `target` and the values it fixes (the mip count for the
    /// current `size`).
    pub fn with_target(self, target: Target) -> Self {
        let f = target.fixed();
        Self {
            target,
            facing: f.facing,
            mapping: f.mapping.unwrap_or(self.mapping),
            mips: f.mips.map_or(self.mips, |m| m(self.size)),
            lut_masking: f.lut_masking.unwrap_or(self.lut_masking),
            ..self
        }
    }

    /// Every value the target fixes agrees with it (`Error::Setting` naming the field).
    fn check_target(&self) -> Result<()> {
        let t = self.target;
        let f = t.fixed();
        let differs = |field: &'static str, what: String| {
            Err(Error::setting(field, format!("{what} for the {} target, whose engine reads its files that way", t.name())))
        };
        if self.facing != f.facing {
            return differs("facing", format!("must be {}, not {},", f.facing.name(), self.facing.name()));
        }
        if let Some(m) = f.mapping.filter(|&m| m != self.mapping) {
            return differs("mapping", format!("must be {}, not {},", m.name(), self.mapping.name()));
        }
        if let Some(n) = f.mips.map(|m| m(self.size)).filter(|&n| n != self.mips) {
            return differs("mips", format!("must be {n} for {0}² faces, not {1},", self.size, self.mips));
        }
        if let Some(m) = f.lut_masking.filter(|&m| m != self.lut_masking) {
            return differs("lut_masking", format!("must be {}, not {},", m.name(), self.lut_masking.name()));
        }
        if t == Target::Filament && self.format != Format::Auto {
            return differs("format", format!("must be auto (cmgen's R11F_G11F_B10F), not {},", self.format.name()));
        }
        Ok(())
    }

    /// The defaults for an interactive display of an environment whose own face size is
    /// `native` (`Environment::native_face_size`): a 128² specular cube from 256 samples
    /// per texel, a 128² table, and the source cube as sharp as the environment.
    pub fn display(native: u32) -> Self {
        let size = 128;
        Self { size, source_size: native.max(size), mips: Self::default_mips(size), samples: 256, lut_size: 128, lut_samples: 512, ..Self::default() }
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
        (0..self.mips).map(|i| self.mapping.roughness(i, self.mips)).collect()
    }

    /// The BRDF table these settings bake, in words: `256² by quadrature (correlated)` or
    /// `256² × 1024 samples`.
    pub fn table_description(&self) -> String {
        match self.lut_method {
            TableMethod::Quadrature => format!("{}² by quadrature ({})", self.lut_size, self.lut_masking.name()),
            TableMethod::Sampled => format!("{}² × {} samples", self.lut_size, self.lut_samples),
        }
    }

    /// GGX samples of each specular mip: `samples × sample_growth^(m−1)` from mip 1 on
    /// (mip 0 is the mirror unless the mapping says otherwise), at most 2²⁰.
    pub fn samples_per_mip(&self) -> Vec<u32> {
        self.asked_samples_per_mip().into_iter().map(|n| n.min(MAX_SAMPLES as u64) as u32).collect()
    }

    /// `samples × sample_growth^(m−1)` per mip, before the cap.
    fn asked_samples_per_mip(&self) -> Vec<u64> {
        (0..self.mips).map(|m| (self.samples as u64).saturating_mul((self.sample_growth as u64).saturating_pow(m.saturating_sub(1)))).collect()
    }

    /// The fields a bake of `products` with these settings does not read (`cube_input`: from
    /// six faces, which are not resampled), each with why: a value given for one of them
    /// would change nothing, so a caller that was given one refuses it by name.
    pub fn unread(&self, products: Products, cube_input: bool) -> Vec<(&'static str, Unread)> {
        let mut out = Vec::new();
        let mut add = |fields: &[&'static str], why: Unread| out.extend(fields.iter().map(|f| (*f, why)));
        if !products.lut {
            add(&["lut_size", "lut_method", "lut_masking", "lut_samples"], Unread::NoTable);
        } else if self.lut_method == TableMethod::Quadrature {
            add(&["lut_samples"], Unread::QuadratureTable);
        }
        if !products.irradiance {
            add(&["irradiance_size", "irradiance_source"], Unread::NoIrradiance);
        }
        if !products.sh9 {
            add(&["sh_source"], Unread::NoSh9);
        }
        if cube_input {
            add(&["supersample_density"], Unread::CubeInput);
        }
        if !products.specular || self.mips == 1 {
            add(&["samples", "sample_growth", "lod_bias", "exact_sums"], Unread::MirrorOnly);
        } else if self.mips == 2 {
            add(&["sample_growth"], Unread::NoGrowth);
        }
        out
    }

    /// What a bake of `env` with these settings changes from what they ask: a mip's sample
    /// count capped at [`MAX_SAMPLES`], a source cube finer than the environment resolves.
    pub fn adjustments(&self, env: &crate::environment::Environment) -> Vec<Adjustment> {
        let mut out = Vec::new();
        let (roughness, samples) = (self.roughness(), self.samples_per_mip());
        let source = CubeLayout::new(self.source_size, CubeLayout::full_chain(self.source_size));
        let exact = exact_levels(&roughness, &samples, self.exact_sums, source);
        for (mip, asked) in self.asked_samples_per_mip().into_iter().enumerate() {
            // The mirror and a mip summed exactly take no samples.
            let sampled = roughness[mip] > 0.0 && exact[mip] == prefilter::SAMPLED;
            if sampled && asked > samples[mip] as u64 {
                out.push(Adjustment::SamplesCapped { mip: mip as u32, asked, used: samples[mip] });
            }
        }
        if let crate::environment::Environment::Equirect(e) = env {
            let resolves = env.resolves();
            if self.source_size > resolves {
                out.push(Adjustment::Upsampled { width: e.width, height: e.height, resolves, source_size: self.source_size });
            }
        }
        out
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

/// The source level each specular level is summed over exactly, or `prefilter::SAMPLED`:
/// with `exact`, wherever that costs less than its samples (`prefilter::exact_level`).
pub fn exact_levels(roughness: &[f32], samples: &[u32], exact: bool, src: CubeLayout) -> Vec<u32> {
    roughness.iter().zip(samples).map(|(&r, &n)| if exact { prefilter::exact_level(r, n, src) } else { prefilter::SAMPLED }).collect()
}

/// The source level whose faces are `face` wide (or the smallest there is).
pub fn level_of_size(layout: CubeLayout, face: u32) -> u32 {
    (0..layout.levels).find(|&l| layout.level_size(l) <= face).unwrap_or(layout.levels - 1)
}

/// Why a bake does not read a setting ([`Settings::unread`]).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Unread {
    /// The table is integrated by quadrature, which takes no sample count.
    QuadratureTable,
    /// No BRDF table is baked.
    NoTable,
    /// No irradiance cube is baked.
    NoIrradiance,
    /// No SH9 is baked.
    NoSh9,
    /// The input is a cube: nothing is resampled.
    CubeInput,
    /// The specular cube has only the mirror mip (or none), which takes no samples.
    MirrorOnly,
    /// With two mips, no mip after mip 1 grows its sample count.
    NoGrowth,
}

impl Unread {
    /// Why, naming settings through `term` (as [`Adjustment::describe`]) and the target.
    pub fn describe(self, target: Target, term: &dyn Fn(&'static str) -> String) -> String {
        let by = |what: &str| if target == Target::Splitsum { format!("this bake makes no {what}") } else { format!("the {} target makes no {what}", target.name()) };
        match self {
            Unread::QuadratureTable => format!("the quadrature table takes no sample count (only {} sampled does)", term("lut_method")),
            Unread::NoTable => by("BRDF table"),
            Unread::NoIrradiance => by("irradiance cube"),
            Unread::NoSh9 => by("SH9 coefficients"),
            Unread::CubeInput => "a cube map is read as it is, not resampled".into(),
            Unread::MirrorOnly => format!("with {} 1 the specular cube is the mirror alone, which takes no samples", term("mips")),
            Unread::NoGrowth => format!("with {} 2 no mip after mip 1 grows its sample count", term("mips")),
        }
    }
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
    /// What a renderer reads: the specular cube, the irradiance cube and the BRDF table.
    pub const DISPLAY: Products = Products { specular: true, irradiance: true, sh9: false, lut: true };
}
