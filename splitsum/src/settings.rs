//! What a bake makes and how: [`Settings`] (every knob, with the one set of defaults and
//! the one validation), [`Products`] (which products) and [`Target`] (whose conventions
//! the files follow).

use crate::adjustment::Adjustment;
pub use crate::environment::InputShape;
pub use crate::field::{Field, Step};
use crate::error::{Error, Result};
use crate::texture::Format;
use serde::{Deserialize, Serialize};
use splitsum_shaders::brdf::microfacet::Masking;
use splitsum_shaders::choice::Choice;
use splitsum_shaders::cubemap::CubeLayout;
use splitsum_shaders::equirect::Facing;
use splitsum_shaders::prefilter::{self, Lobe, RoughnessMapping};

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

    /// What the target's engine reads: Khronos a specular, an irradiance and a sheen cube
    /// and the tables (every folder of glTF-Sample-Environments has `charlie/sheen.ktx2`);
    /// Bevy the same without sheen (Bevy shades no sheen); Filament the specular cube and
    /// SH9 (its table, cloth's term included, is built in); splitsum everything but sheen,
    /// which a bake adds when asked ([`Products::with_sheen`]).
    pub fn products(self) -> Products {
        match self {
            Target::Splitsum => Products::STANDARD,
            Target::Khronos => Products { sheen: true, ..Products::DISPLAY },
            Target::Bevy => Products::DISPLAY,
            Target::Filament => Products { specular: true, irradiance: false, sh9: true, lut: false, sheen: false },
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

/// Serde for an optional [`Choice`]: by its name, or null.
pub mod named_option {
    use serde::{Deserialize, Deserializer, Serializer, de::Error as _};
    use splitsum_shaders::choice::Choice;

    /// Writes the choice's name, or null.
    pub fn serialize<S: Serializer, T: Choice>(v: &Option<T>, s: S) -> Result<S::Ok, S::Error> {
        match v {
            Some(v) => s.serialize_str(v.name()),
            None => s.serialize_none(),
        }
    }

    /// Reads a choice by name, or null.
    pub fn deserialize<'de, D: Deserializer<'de>, T: Choice>(d: D) -> Result<Option<T>, D::Error> {
        match Option::<String>::deserialize(d)? {
            None => Ok(None),
            Some(name) => T::from_name(&name).map(Some).ok_or_else(|| {
                let names: Vec<&str> = T::ALL.iter().map(|c| c.name()).collect();
                D::Error::custom(format!("unknown value {name:?}, expected one of {}", names.join(", ")))
            }),
        }
    }
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

/// Every knob of a bake, as a caller gives it. [`Settings::default`] is the one set of
/// defaults (the command line, the scene files and the library all start from it); a
/// field left `None` is derived from the others when the bake is resolved
/// ([`Settings::resolve`], the one validation): the source size from `size`, the mip count
/// from `size` and the target, the roughness mapping and the table's masking from the
/// target and the table method, the irradiance and SH9 source levels from the source size.
/// So `Settings { size: 512, ..Default::default() }` bakes 512² faces with 7 mips.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Settings {
    /// Whose conventions the files follow (an engine target fixes the facing, the
    /// roughness per mip, the mip count and the table's masking; see [`Target::fixed`]).
    #[serde(with = "named")]
    pub target: Target,
    /// Face size of mip 0 of the specular cube (a power of two).
    pub size: u32,
    /// Face size of the source cube the products are filtered from (a power of two, at
    /// least `size`) [`None`: `size`].
    pub source_size: Option<u32>,
    /// Mips of the specular cube, one roughness each [`None`: down to 8² faces
    /// ([`Settings::default_mips`]), or the target's count].
    pub mips: Option<u32>,
    /// Roughness of each mip [`None`: geometric, or the target's].
    #[serde(with = "named_option")]
    pub mapping: Option<RoughnessMapping>,
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
    /// Face size of the source level the irradiance convolution sums over [`None`: 16, or
    /// the source size if smaller].
    pub irradiance_source: Option<u32>,
    /// Face size of the source level projected onto SH9 [`None`: 32, or the source size if
    /// smaller].
    pub sh_source: Option<u32>,
    /// Width and height of the BRDF table.
    pub lut_size: u32,
    /// Samples per texel of the BRDF table (with `lut_method = sampled`).
    pub lut_samples: u32,
    /// How the BRDF table is integrated.
    #[serde(with = "named")]
    pub lut_method: TableMethod,
    /// The table's masking–shadowing term [`None`: the target's, else the exact
    /// height-correlated Smith by quadrature, Smith–Schlick sampled].
    #[serde(with = "named_option")]
    pub lut_masking: Option<Masking>,
    /// Texel format of the KTX2 files.
    #[serde(with = "named")]
    pub format: Format,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            target: Target::Splitsum,
            size: 256,
            source_size: None,
            mips: None,
            mapping: None,
            samples: 64,
            sample_growth: 2,
            exact_sums: true,
            lod_bias: 0.5,
            supersample_density: 2.0,
            irradiance_size: 32,
            irradiance_source: None,
            sh_source: None,
            lut_size: 256,
            lut_samples: 1024,
            lut_method: TableMethod::Quadrature,
            lut_masking: None,
            format: Format::Auto,
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

/// The irradiance convolution's source level unless one is asked for (or the source size,
/// if smaller): 16², whose error against the f64 sum is 0.67 % (`runner report`).
pub const DEFAULT_IRRADIANCE_SOURCE: u32 = 16;

/// The SH9 projection's source level unless one is asked for (or the source size, if
/// smaller): SH9's error is its band limit from 16² up.
pub const DEFAULT_SH_SOURCE: u32 = 32;

impl Settings {
    /// Checks every value as [`Settings::resolve`] does, for any environment (an error
    /// names the field: `Error::Setting`).
    pub fn validate(&self) -> Result<()> {
        self.resolve(InputShape::Unknown, Products::ALL).map(|_| ())
    }

    /// The bake these settings describe for an environment of `shape`, baking `products`:
    /// every derived value filled in, every value checked (the one validation; an error
    /// names the field), and everything downstream needs worked out once ([`Job`]).
    pub fn resolve(&self, shape: InputShape, products: Products) -> Result<Job> {
        let bad = |field: Field, problem: String| Error::setting(field, problem);
        let pow2 = |field: Field, v: u32, lo: u32, hi: u32| -> Result<()> {
            if !v.is_power_of_two() || v < lo || v > hi {
                return Err(bad(field, format!("must be a power of two from {lo} to {hi}, not {v}")));
            }
            Ok(())
        };
        let t = self.target;
        let fixed = t.fixed();
        pow2(Field::Size, self.size, 1, MAX_SIZE)?;
        let source_size = self.source_size.unwrap_or(self.size);
        pow2(Field::SourceSize, source_size, self.size, MAX_SIZE)?;
        pow2(Field::IrradianceSize, self.irradiance_size, 1, 256)?;
        let irradiance_source = self.irradiance_source.unwrap_or(DEFAULT_IRRADIANCE_SOURCE.min(source_size));
        pow2(Field::IrradianceSource, irradiance_source, 1, source_size.min(256))?;
        let sh_source = self.sh_source.unwrap_or(DEFAULT_SH_SOURCE.min(source_size));
        pow2(Field::ShSource, sh_source, 1, source_size)?;
        let differs = |field: Field, what: String| bad(field, format!("{what} for the {} target, whose engine reads its files that way", t.name()));
        let target_mips = fixed.mips.map(|m| m(self.size));
        let mips = match (self.mips, target_mips) {
            (Some(m), Some(n)) if m != n => return Err(differs(Field::Mips, format!("must be {n} for {0}² faces, not {m},", self.size))),
            (m, n) => m.or(n).unwrap_or_else(|| Self::default_mips(self.size)),
        };
        let max_mips = CubeLayout::full_chain(self.size);
        if mips == 0 || mips > max_mips {
            return Err(bad(Field::Mips, format!("must be from 1 to {max_mips} for {0}² faces, not {mips}", self.size)));
        }
        let mapping = match (self.mapping, fixed.mapping) {
            (Some(m), Some(f)) if m != f => return Err(differs(Field::Mapping, format!("must be {}, not {},", f.name(), m.name()))),
            (m, f) => m.or(f).unwrap_or(RoughnessMapping::Geometric),
        };
        if self.samples == 0 || self.samples > MAX_SAMPLES {
            return Err(bad(Field::Samples, format!("must be from 1 to {MAX_SAMPLES} (the most a mip takes), not {}", self.samples)));
        }
        if !(1..=4).contains(&self.sample_growth) {
            return Err(bad(Field::SampleGrowth, format!("must be from 1 to 4, not {}", self.sample_growth)));
        }
        if !(self.lod_bias.is_finite() && (-16.0..=16.0).contains(&self.lod_bias)) {
            return Err(bad(Field::LodBias, format!("must be within ±16, not {}", self.lod_bias)));
        }
        if !(self.supersample_density > 0.0 && self.supersample_density <= 16.0) {
            return Err(bad(Field::SupersampleDensity, format!("must be in (0, 16], not {}", self.supersample_density)));
        }
        if self.lut_size == 0 || self.lut_size > MAX_LUT_SIZE {
            return Err(bad(Field::LutSize, format!("must be from 1 to {}, not {}", MAX_LUT_SIZE, self.lut_size)));
        }
        if self.lut_samples == 0 {
            return Err(bad(Field::LutSamples, "must be at least 1, not 0".into()));
        }
        let lut_masking = match (self.lut_masking, fixed.lut_masking) {
            (Some(m), Some(f)) if m != f => return Err(differs(Field::LutMasking, format!("must be {}, not {},", f.name(), m.name()))),
            (m, f) => m.or(f).unwrap_or(self.lut_method.default_masking()),
        };
        if self.lut_method == TableMethod::Sampled && lut_masking != Masking::SmithSchlick {
            return Err(bad(Field::LutMasking, "correlated needs the quadrature table method (the sampled table is Smith–Schlick only)".into()));
        }
        if t == Target::Filament && self.format != Format::Auto {
            return Err(differs(Field::Format, format!("must be auto (cmgen's R11F_G11F_B10F), not {},", self.format.name())));
        }
        Ok(Job::new(self.clone(), JobValues { source_size, mips, mapping, irradiance_source, sh_source, lut_masking }, shape, products))
    }

    /// These settings with `target` (whose fixed values fill the fields left `None`).
    pub fn with_target(self, target: Target) -> Self {
        Self { target, ..self }
    }

    /// The defaults for an interactive display of an environment whose own face size is
    /// `native` (`Environment::native_face_size`): a 128² specular cube from 256 samples
    /// per texel, a 128² table, and the source cube as sharp as the environment.
    pub fn display(native: u32) -> Self {
        let size = 128;
        Self { size, source_size: Some(native.max(size)), samples: 256, lut_size: 128, lut_samples: 512, ..Self::default() }
    }

    /// The specular mip count for mip-0 faces of `size`: down to 8² faces, and at least two
    /// (the mirror and roughness 1) where the chain has them. With the geometric mapping
    /// this puts mip 1's GGX width at `α₁ = 2^(−M) = 4/size`: two of mip 1's texels. The one
    /// rule for the bake, the display and the planner.
    pub fn default_mips(size: u32) -> u32 {
        let chain = CubeLayout::full_chain(size.max(1));
        chain.saturating_sub(3).max(2).min(chain)
    }

    /// The fields a bake of `products` with these settings does not read (`cube_input`: from
    /// six faces, which are not resampled), each with why: a value given for one of them
    /// would change nothing, so a caller that was given one refuses it by name.
    pub fn unread(&self, products: Products, cube_input: bool) -> Vec<(Field, Unread)> {
        let mips = self.mips.or(self.target.fixed().mips.map(|m| m(self.size))).unwrap_or_else(|| Self::default_mips(self.size));
        let mut out = Vec::new();
        let mut add = |fields: &[Field], why: Unread| out.extend(fields.iter().map(|f| (*f, why)));
        if !products.lut {
            add(&[Field::LutSize, Field::LutMethod, Field::LutMasking, Field::LutSamples], Unread::NoTable);
        } else if self.lut_method == TableMethod::Quadrature {
            add(&[Field::LutSamples], Unread::QuadratureTable);
        }
        if !products.irradiance {
            add(&[Field::IrradianceSize, Field::IrradianceSource], Unread::NoIrradiance);
        }
        if !products.sh9 {
            add(&[Field::ShSource], Unread::NoSh9);
        }
        if cube_input {
            add(&[Field::SupersampleDensity], Unread::CubeInput);
        }
        if !products.specular || mips == 1 {
            add(&[Field::Samples, Field::SampleGrowth, Field::LodBias, Field::ExactSums], Unread::MirrorOnly);
        } else if mips == 2 {
            add(&[Field::SampleGrowth], Unread::NoGrowth);
        }
        out
    }
}

/// The values [`Settings::resolve`] derives.
struct JobValues {
    source_size: u32,
    mips: u32,
    mapping: RoughnessMapping,
    irradiance_source: u32,
    sh_source: u32,
    lut_masking: Masking,
}

/// A bake, resolved once from [`Settings`], the target and the environment's shape
/// ([`Settings::resolve`]): every value concrete, and what every step needs worked out (the
/// roughness, samples and exact-sum level of each mip, the source levels, the layouts, the
/// supersampling). The bake, its cost, the backends' jobs, the textures and the files all
/// read it; nothing downstream derives a setting again.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Job {
    /// The settings as given.
    #[serde(skip)]
    pub given: Settings,
    /// Whose conventions the files follow.
    #[serde(with = "named")]
    pub target: Target,
    /// Which way the equirect's centre faces in the cube (the target's).
    #[serde(with = "named")]
    pub facing: Facing,
    /// Whether six-face input is mirrored in x (the target's: cmgen's).
    pub mirror_faces: bool,
    /// The products baked.
    pub products: Products,
    /// The environment's shape.
    pub input: InputShape,
    /// Face size of mip 0 of the specular cube.
    pub size: u32,
    /// Face size of the source cube.
    pub source_size: u32,
    /// Specular mips.
    pub mips: u32,
    /// Roughness of each mip.
    #[serde(with = "named")]
    pub mapping: RoughnessMapping,
    /// GGX samples per texel of specular mip 1.
    pub samples: u32,
    /// Growth of the sample count per mip after mip 1.
    pub sample_growth: u32,
    /// Rough mips summed exactly where cheaper.
    pub exact_sums: bool,
    /// Source-level bias of the prefilter samples.
    pub lod_bias: f32,
    /// Supersampling density of the equirect resampling.
    pub supersample_density: f32,
    /// Face size of the irradiance cube.
    pub irradiance_size: u32,
    /// Face size of the irradiance convolution's source level.
    pub irradiance_source: u32,
    /// Face size of the SH9 projection's source level.
    pub sh_source: u32,
    /// Width and height of the BRDF table.
    pub lut_size: u32,
    /// Samples per texel of a sampled table.
    pub lut_samples: u32,
    /// How the table is integrated.
    #[serde(with = "named")]
    pub lut_method: TableMethod,
    /// The table's masking term.
    #[serde(with = "named")]
    pub lut_masking: Masking,
    /// KTX2 texel format.
    #[serde(with = "named")]
    pub format: Format,
    /// The specular levels baked (all, unless a plan keeps fewer; the others stay zero).
    pub levels: Vec<u32>,
    /// The sheen levels baked (all, unless a plan keeps fewer; the others stay zero).
    pub sheen_levels: Vec<u32>,
    /// Roughness of each specular mip.
    pub roughness_per_mip: Vec<f32>,
    /// Sheen roughness of each mip of the sheen cube ([`SHEEN_MAPPING`]; it has the
    /// specular cube's size and mips).
    pub sheen_roughness_per_mip: Vec<f32>,
    /// The source level each sheen mip is summed over exactly, or `prefilter::SAMPLED`.
    pub sheen_exact_levels: Vec<u32>,
    /// GGX samples per texel of each specular mip (capped at [`MAX_SAMPLES`]).
    pub samples_per_mip: Vec<u32>,
    /// The source level each mip is summed over exactly, or `prefilter::SAMPLED`.
    pub exact_levels: Vec<u32>,
    /// Equirect → cube supersamples per texel side (1 for a cube input).
    pub supersample: u32,
}

impl Job {
    fn new(given: Settings, v: JobValues, input: InputShape, products: Products) -> Self {
        let fixed = given.target.fixed();
        let mut job = Self {
            target: given.target,
            facing: fixed.facing,
            mirror_faces: fixed.mirror_faces,
            products,
            input,
            size: given.size,
            source_size: v.source_size,
            mips: v.mips,
            mapping: v.mapping,
            samples: given.samples,
            sample_growth: given.sample_growth,
            exact_sums: given.exact_sums,
            lod_bias: given.lod_bias,
            supersample_density: given.supersample_density,
            irradiance_size: given.irradiance_size,
            irradiance_source: v.irradiance_source,
            sh_source: v.sh_source,
            lut_size: given.lut_size,
            lut_samples: given.lut_samples,
            lut_method: given.lut_method,
            lut_masking: v.lut_masking,
            format: given.format,
            levels: (0..v.mips).collect(),
            sheen_levels: (0..v.mips).collect(),
            roughness_per_mip: (0..v.mips).map(|m| v.mapping.roughness(m, v.mips)).collect(),
            sheen_roughness_per_mip: (0..v.mips).map(|m| SHEEN_MAPPING.roughness(m, v.mips)).collect(),
            samples_per_mip: Vec::new(),
            exact_levels: Vec::new(),
            sheen_exact_levels: Vec::new(),
            supersample: match input {
                InputShape::Equirect { width, .. } => splitsum_shaders::equirect::supersampling(v.source_size, width, given.supersample_density),
                _ => 1,
            },
            given,
        };
        job.samples_per_mip = job.asked_samples_per_mip().into_iter().map(|n| n.min(MAX_SAMPLES as u64) as u32).collect();
        job.exact_levels = exact_levels(Lobe::Ggx, &job.roughness_per_mip, &job.samples_per_mip, job.exact_sums, job.source_layout());
        job.sheen_exact_levels = exact_levels(Lobe::Charlie, &job.sheen_roughness_per_mip, &job.samples_per_mip, job.exact_sums, job.source_layout());
        job
    }

    /// This job baking only `levels` of the specular cube (the others stay zero): what a
    /// scene's plan keeps. Refuses a level the cube does not have.
    pub fn with_levels(mut self, levels: Vec<u32>) -> Result<Self> {
        if let Some(&m) = levels.iter().find(|&&m| m >= self.mips) {
            return Err(Error::setting(Field::Mips, format!("has no mip {m} to bake (there are {})", self.mips)));
        }
        self.levels = levels;
        Ok(self)
    }

    /// This job baking only `levels` of the sheen cube (the others stay zero).
    pub fn with_sheen_levels(mut self, levels: Vec<u32>) -> Result<Self> {
        if let Some(&m) = levels.iter().find(|&&m| m >= self.mips) {
            return Err(Error::setting(Field::Mips, format!("has no sheen mip {m} to bake (there are {})", self.mips)));
        }
        self.sheen_levels = levels;
        Ok(self)
    }

    /// `samples × sample_growth^(m−1)` per mip, before the cap.
    fn asked_samples_per_mip(&self) -> Vec<u64> {
        (0..self.mips).map(|m| (self.samples as u64).saturating_mul((self.sample_growth as u64).saturating_pow(m.saturating_sub(1)))).collect()
    }

    /// Layout of the source cube, with its full mip chain.
    pub fn source_layout(&self) -> CubeLayout {
        CubeLayout::new(self.source_size, CubeLayout::full_chain(self.source_size))
    }

    /// Layout of the specular cube.
    pub fn specular_layout(&self) -> CubeLayout {
        CubeLayout::new(self.size, self.mips)
    }

    /// Layout of the irradiance cube.
    pub fn irradiance_layout(&self) -> CubeLayout {
        CubeLayout::new(self.irradiance_size, 1)
    }

    /// The source level the irradiance convolution sums over.
    pub fn irradiance_level(&self) -> u32 {
        level_of_size(self.source_layout(), self.irradiance_source)
    }

    /// The source level projected onto SH9.
    pub fn sh_level(&self) -> u32 {
        level_of_size(self.source_layout(), self.sh_source)
    }

    /// The BRDF table this job bakes, in words: `256² by quadrature (correlated)` or
    /// `256² × 1024 samples`.
    pub fn table_description(&self) -> String {
        match self.lut_method {
            TableMethod::Quadrature => format!("{}² by quadrature ({})", self.lut_size, self.lut_masking.name()),
            TableMethod::Sampled => format!("{}² × {} samples", self.lut_size, self.lut_samples),
        }
    }

    /// What this bake changes from what its settings ask: a mip's sample count capped at
    /// [`MAX_SAMPLES`], a source cube finer than the environment resolves.
    pub fn adjustments(&self) -> Vec<Adjustment> {
        let mut out = Vec::new();
        for (mip, asked) in self.asked_samples_per_mip().into_iter().enumerate() {
            // The mirror and a mip summed exactly take no samples.
            let sampled = self.roughness_per_mip[mip] > 0.0 && self.exact_levels[mip] == prefilter::SAMPLED;
            if sampled && self.products.specular && asked > self.samples_per_mip[mip] as u64 {
                out.push(Adjustment::SamplesCapped { mip: mip as u32, asked, used: self.samples_per_mip[mip] });
            }
        }
        if let InputShape::Equirect { width, height } = self.input {
            let resolves = (width / 4).max(8).next_power_of_two();
            if self.source_size > resolves {
                out.push(Adjustment::Upsampled { width, height, resolves, source_size: self.source_size });
            }
        }
        out
    }
}

/// How the sheen cube's mips map to sheen roughness, whatever the target: linear, as the
/// glTF Sample Viewer reads it (`getIBLRadianceCharlie`: `lod = sheenRoughness ·
/// (u_MipCount − 1)`) and glTF-IBL-Sampler writes it.
pub const SHEEN_MAPPING: RoughnessMapping = RoughnessMapping::Linear;

/// The source level each level of a `lobe` cube is summed over exactly, or
/// `prefilter::SAMPLED`: with `exact`, wherever that costs less than its samples
/// (`prefilter::exact_level`).
pub fn exact_levels(lobe: Lobe, roughness: &[f32], samples: &[u32], exact: bool, src: CubeLayout) -> Vec<u32> {
    roughness.iter().zip(samples).map(|(&r, &n)| if exact { prefilter::exact_level(lobe, r, n, src) } else { prefilter::SAMPLED }).collect()
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
    pub fn describe(self, target: Target, term: &dyn Fn(Field) -> String) -> String {
        let by = |what: &str| if target == Target::Splitsum { format!("this bake makes no {what}") } else { format!("the {} target makes no {what}", target.name()) };
        match self {
            Unread::QuadratureTable => format!("the quadrature table takes no sample count (only {} sampled does)", term(Field::LutMethod)),
            Unread::NoTable => by("BRDF table"),
            Unread::NoIrradiance => by("irradiance cube"),
            Unread::NoSh9 => by("SH9 coefficients"),
            Unread::CubeInput => "a cube map is read as it is, not resampled".into(),
            Unread::MirrorOnly => format!("with {} 1 the specular cube is the mirror alone, which takes no samples", term(Field::Mips)),
            Unread::NoGrowth => format!("with {} 2 no mip after mip 1 grows its sample count", term(Field::Mips)),
        }
    }
}

/// Which products to bake.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Products {
    /// The sheen cube (Charlie-prefiltered radiance) and the sheen tables.
    pub sheen: bool,
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
    pub const ALL: Products = Products { specular: true, irradiance: true, sh9: true, lut: true, sheen: true };
    /// Everything but sheen: splitsum's own folder unless sheen is asked for.
    pub const STANDARD: Products = Products { sheen: false, ..Products::ALL };
    /// What a renderer reads for materials without sheen: the specular cube, the
    /// irradiance cube and the BRDF table.
    pub const DISPLAY: Products = Products { specular: true, irradiance: true, sh9: false, lut: true, sheen: false };

    /// These products, and the sheen cube and tables if `sheen`.
    pub fn with_sheen(self, sheen: bool) -> Products {
        Products { sheen: self.sheen || sheen, ..self }
    }
}
