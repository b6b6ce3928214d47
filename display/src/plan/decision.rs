//! A plan's decisions as types: what each is about ([`Subject`]) and why ([`Cause`]),
//! rendered to words only at the edge (`runner plan`, `plan.json`).

use serde::Serialize;

/// What a decision of the plan is about: a product or a setting.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Subject {
    /// Every product at once (nothing is lit by the environment).
    Everything,
    /// The specular cube's face size and mips.
    CubeSize,
    /// The prefiltered specular cube.
    SpecularCube,
    /// Which of its mips are baked.
    SpecularMips,
    /// The split-sum BRDF table.
    BrdfTable,
    /// The irradiance cube.
    IrradianceCube,
    /// The sheen cube and the sheen tables.
    Sheen,
    /// The SH9 coefficients.
    Sh9,
    /// The settings a time budget chose.
    TimeBudget,
    /// The prefilter's sample count.
    PrefilterSamples,
    /// How the BRDF table is integrated.
    TableMethod,
    /// The source level of the irradiance convolution.
    IrradianceSource,
}

impl Subject {
    /// The subject in words, as `runner plan` and `plan.json` show it.
    pub fn name(self) -> &'static str {
        match self {
            Subject::Everything => "everything",
            Subject::CubeSize => "cube size",
            Subject::SpecularCube => "prefiltered specular cube",
            Subject::SpecularMips => "specular mips",
            Subject::BrdfTable => "BRDF table",
            Subject::IrradianceCube => "irradiance cube",
            Subject::Sheen => "sheen cube and tables",
            Subject::Sh9 => "SH9",
            Subject::TimeBudget => "time budget",
            Subject::PrefilterSamples => "prefilter samples",
            Subject::TableMethod => "BRDF table method",
            Subject::IrradianceSource => "irradiance source",
        }
    }
}

/// A mip and the roughness it holds.
pub type Mip = (u32, f32);

/// A measured setting a quality target chose: a sample count or a source level.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum Setting {
    /// GGX samples per texel.
    Samples(u32),
    /// A source level of this face size.
    SourceLevel(u32),
}

/// Why a decision went as it did.
#[derive(Clone, Debug, PartialEq)]
pub enum Cause {
    /// `[quality] size` sets the cube size.
    SizeAsked {
        /// Face size.
        size: u32,
        /// Mips.
        mips: u32,
    },
    /// The cube size the smallest roughness and a pixel need.
    SizeResolves {
        /// Face size.
        size: u32,
        /// Mips.
        mips: u32,
        /// The smallest roughness of a specular material.
        roughness: f32,
        /// The mip it reads, and that mip's face size.
        level: u32,
        /// That mip's face size.
        level_size: u32,
        /// Half its lobe, `α` radians.
        alpha: f64,
        /// The output's width and height, its vertical field of view (degrees) and a
        /// pixel's angle (radians).
        output: (u32, u32, f32, f64),
        /// The environment's face size.
        native: u32,
    },
    /// No material is lit by the environment.
    NothingLit,
    /// Specular image-based light of these materials, over this roughness range.
    SpecularOf {
        /// The materials.
        materials: Vec<String>,
        /// Their roughness range.
        roughness: (f32, f32),
    },
    /// Only the sky's blur reads the cube.
    SkyBlur(f32),
    /// These mips are baked.
    MipsRead(Vec<Mip>),
    /// These mips are read by nothing.
    MipsUnread(Vec<Mip>),
    /// No material has specular image-based light and the sky is sharp.
    NoSpecularLight,
    /// Cook–Torrance image-based light of these materials.
    CookTorranceOf(Vec<String>),
    /// Only Phong or Blinn–Phong specular, to which the GGX table does not apply.
    OnlyPhong,
    /// No specular image-based light, so no table.
    NoSpecularTable,
    /// Diffuse image-based light of these materials.
    DiffuseOf(Vec<String>),
    /// Every lit material is metal.
    AllMetal,
    /// Sheen of these materials (and models), over these mips.
    SheenOf {
        /// The materials, and models with `KHR_materials_sheen`.
        whose: Vec<String>,
        /// The sheen mips read.
        mips: Vec<Mip>,
    },
    /// No lit material has sheen.
    NoSheen,
    /// The display reads the irradiance cube, not SH9.
    Sh9Unread,
    /// The budget's choice: the lowest predicted error whose estimate fits (or the
    /// cheapest, over the budget).
    Budget {
        /// Samples chosen.
        samples: u32,
        /// Irradiance source chosen.
        irradiance_source: u32,
        /// Predicted error.
        error: f64,
        /// Estimated seconds on lavapipe.
        estimate: f64,
        /// The budget, seconds.
        budget: f64,
    },
    /// The cheapest measured setting whose mean error meets the target.
    Cheapest {
        /// The setting.
        setting: Setting,
        /// Its mean error.
        error: f64,
        /// The target.
        target: f64,
    },
    /// No measured setting meets the target: the most accurate.
    MostAccurate {
        /// The setting.
        setting: Setting,
        /// Its mean error, above the target.
        error: f64,
        /// The target.
        target: f64,
    },
    /// The table by quadrature, within 10⁻⁵ everywhere, which meets the target.
    Quadrature {
        /// The target.
        target: f64,
    },
}

impl std::fmt::Display for Setting {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Setting::Samples(n) => write!(f, "{n}"),
            Setting::SourceLevel(s) => write!(f, "{s}×{s} source level"),
        }
    }
}

fn mips(list: &[Mip]) -> String {
    list.iter().map(|(l, r)| format!("{l} (r={r:.2})")).collect::<Vec<_>>().join(", ")
}

impl std::fmt::Display for Cause {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Cause::SizeAsked { size, mips } => write!(f, "{size}×{size} × {mips} mips: as [quality] size asks"),
            Cause::SizeResolves { size, mips, roughness, level, level_size, alpha, output: (w, h, fov, pixel), native } => write!(
                f,
                "{size}×{size} × {mips} mips: the smallest roughness {roughness} reads mip {level} ({level_size}², texel {:.4} rad), which must resolve half its lobe (α = {alpha:.4} rad) or a pixel of {w}×{h} at {fov}° ({pixel:.4} rad); the environment has {native}²",
                std::f64::consts::FRAC_PI_2 / *level_size as f64,
            ),
            Cause::NothingLit => f.write_str("no material is lit by the environment (all have ibl = false, or no objects): the sky needs only the source cube"),
            Cause::SpecularOf { materials, roughness: (lo, hi) } => write!(f, "specular image-based light of {} (roughness {lo}–{hi})", materials.join(", ")),
            Cause::SkyBlur(b) => write!(f, "only for the sky's blur {b}"),
            Cause::MipsRead(m) => write!(f, "baked: {}", mips(m)),
            Cause::MipsUnread(m) => write!(f, "{}: no material roughness or sky blur reads them", mips(m)),
            Cause::NoSpecularLight => f.write_str("no material has specular image-based light (specular = none or ibl = false) and the sky is sharp"),
            Cause::CookTorranceOf(m) => write!(f, "Cook–Torrance image-based light of {}", m.join(", ")),
            Cause::OnlyPhong => f.write_str("only Phong/Blinn–Phong specular: the GGX table does not apply to them"),
            Cause::NoSpecularTable => f.write_str("no specular image-based light"),
            Cause::DiffuseOf(m) => write!(f, "diffuse image-based light of {}", m.join(", ")),
            Cause::AllMetal => f.write_str("every lit material is metal (metallic = 1): no diffuse term"),
            Cause::SheenOf { whose, mips: m } => write!(f, "sheen of {}; mips {}", whose.join(", "), mips(m)),
            Cause::NoSheen => f.write_str("no lit material has sheen (sheen_color is black, and no model uses KHR_materials_sheen)"),
            Cause::Sh9Unread => f.write_str("the display reads the irradiance cube; SH9 is for `runner bake ENV`"),
            Cause::Budget { samples, irradiance_source, error, estimate, budget } => {
                let fits = if estimate <= budget { "fits" } else { "is the cheapest measured, over" };
                write!(
                    f,
                    "{samples} samples, irradiance from {irradiance_source}²: predicted error {error:.2e}, estimated {estimate:.2} s on lavapipe ({fits} {budget} s)"
                )
            }
            Cause::Cheapest { setting, error, target } => write!(f, "{setting}: the cheapest measured, mean error {error:.2e} ≤ {target}"),
            Cause::MostAccurate { setting, error, target } => {
                write!(f, "{setting}: the most accurate measured; its mean error {error:.2e} is still above {target}")
            }
            Cause::Quadrature { target } => write!(f, "quadrature: max error 1e-5 at every texel ≤ {target}"),
        }
    }
}

/// One decision of the plan.
#[derive(Clone, Debug)]
pub struct Decision {
    /// The product or setting.
    pub subject: Subject,
    /// Baked (or chosen) rather than left out.
    pub kept: bool,
    /// Why.
    pub cause: Cause,
}

/// As `plan.json` records it: `what`, `kept` and `why` in words.
impl Serialize for Decision {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let mut d = s.serialize_struct("Decision", 3)?;
        d.serialize_field("what", self.subject.name())?;
        d.serialize_field("kept", &self.kept)?;
        d.serialize_field("why", &self.cause.to_string())?;
        d.end()
    }
}
