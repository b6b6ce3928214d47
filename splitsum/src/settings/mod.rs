//! What a bake makes and how: [`Settings`] (every knob, with the one set of defaults and
//! the one validation), [`Products`] (which products) and [`Target`] (whose conventions
//! the files follow).

pub use crate::environment::InputShape;
pub use crate::field::Field;
pub use crate::product::{Product, Products};
use crate::error::{Error, Result};
use crate::texture::Format;
use serde::{Deserialize, Serialize};
use splitsum_shaders::brdf::microfacet::Masking;
use splitsum_shaders::choice::Choice;
use splitsum_shaders::cubemap::CubeLayout;
use splitsum_shaders::prefilter::RoughnessMapping;

mod job;
mod target;
pub use job::{Job, exact_levels};
use job::JobValues;
pub use target::{Fixed, Target};

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
///
/// ```
/// use splitsum::environment::InputShape;
/// use splitsum::{Field, Products, Settings, Target};
/// let job = Settings { size: 512, ..Settings::default() }.resolve(InputShape::Unknown, Products::STANDARD)?;
/// assert_eq!((job.size, job.mips), (512, 7));
/// // An engine target fills in what its engine assumes: glTF-IBL-Sampler's floor(log2 size) mips.
/// let khronos = Settings::default().with_target(Target::Khronos).resolve(InputShape::Unknown, Target::Khronos.products())?;
/// assert_eq!(khronos.mips, 8);
/// // Errors name the field.
/// let e = Settings { size: 48, ..Settings::default() }.resolve(InputShape::Unknown, Products::STANDARD).unwrap_err();
/// assert!(matches!(e, splitsum::Error::Setting { field: Field::Size, .. }), "{e}");
/// # Ok::<(), splitsum::Error>(())
/// ```
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
        if !products.has(Product::BrdfTable) {
            add(&[Field::LutSize, Field::LutMethod, Field::LutMasking, Field::LutSamples], Unread::NoTable);
        } else if self.lut_method == TableMethod::Quadrature {
            add(&[Field::LutSamples], Unread::QuadratureTable);
        }
        if !products.has(Product::Irradiance) {
            add(&[Field::IrradianceSize, Field::IrradianceSource], Unread::NoIrradiance);
        }
        if !products.has(Product::Sh9) {
            add(&[Field::ShSource], Unread::NoSh9);
        }
        if cube_input {
            add(&[Field::SupersampleDensity], Unread::CubeInput);
        }
        if !products.has(Product::Specular) || mips == 1 {
            add(&[Field::Samples, Field::SampleGrowth, Field::LodBias, Field::ExactSums], Unread::MirrorOnly);
        } else if mips == 2 {
            add(&[Field::SampleGrowth], Unread::NoGrowth);
        }
        out
    }
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
    /// Why, naming settings through `term` (as [`Adjustment::describe`](crate::adjustment::Adjustment::describe)) and the target.
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

