//! The names a bake's messages use, as types: the fields of `Settings` (so that every
//! message can name a field in its reader's terms: the library its name, the command line
//! its flag, a scene its key) and the steps of a bake (progress, timings, estimates).

use serde::Serialize;

/// A field of `Settings`, for messages in the caller's own terms: the library names
/// fields, the command line their flags, a scene file its `[quality]` keys.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum Field {
    /// `Settings::target`.
    Target,
    /// `Settings::size`.
    Size,
    /// `Settings::source_size`.
    SourceSize,
    /// `Settings::mips`.
    Mips,
    /// `Settings::mapping`.
    Mapping,
    /// `Settings::samples`.
    Samples,
    /// `Settings::sample_growth`.
    SampleGrowth,
    /// `Settings::exact_sums`.
    ExactSums,
    /// `Settings::lod_bias`.
    LodBias,
    /// `Settings::supersample_density`.
    SupersampleDensity,
    /// `Settings::irradiance_size`.
    IrradianceSize,
    /// `Settings::irradiance_source`.
    IrradianceSource,
    /// `Settings::sh_source`.
    ShSource,
    /// `Settings::lut_size`.
    LutSize,
    /// `Settings::lut_samples`.
    LutSamples,
    /// `Settings::lut_method`.
    LutMethod,
    /// `Settings::lut_masking`.
    LutMasking,
    /// `Settings::format`.
    Format,
}

impl Field {
    /// Every field.
    pub const ALL: [Field; 18] = [
        Field::Target,
        Field::Size,
        Field::SourceSize,
        Field::Mips,
        Field::Mapping,
        Field::Samples,
        Field::SampleGrowth,
        Field::ExactSums,
        Field::LodBias,
        Field::SupersampleDensity,
        Field::IrradianceSize,
        Field::IrradianceSource,
        Field::ShSource,
        Field::LutSize,
        Field::LutSamples,
        Field::LutMethod,
        Field::LutMasking,
        Field::Format,
    ];

    /// The field's name in `Settings` (and in scene files and `bake.json`).
    pub fn name(self) -> &'static str {
        match self {
            Field::Target => "target",
            Field::Size => "size",
            Field::SourceSize => "source_size",
            Field::Mips => "mips",
            Field::Mapping => "mapping",
            Field::Samples => "samples",
            Field::SampleGrowth => "sample_growth",
            Field::ExactSums => "exact_sums",
            Field::LodBias => "lod_bias",
            Field::SupersampleDensity => "supersample_density",
            Field::IrradianceSize => "irradiance_size",
            Field::IrradianceSource => "irradiance_source",
            Field::ShSource => "sh_source",
            Field::LutSize => "lut_size",
            Field::LutSamples => "lut_samples",
            Field::LutMethod => "lut_method",
            Field::LutMasking => "lut_masking",
            Field::Format => "format",
        }
    }
}

impl std::fmt::Display for Field {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A step of a bake, in the order they run.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Step {
    /// The source cube with its mips (resampled from an equirect, or reduced faces).
    SourceCube,
    /// The GGX-prefiltered specular cube.
    Specular,
    /// The irradiance cube.
    Irradiance,
    /// The SH9 coefficients.
    Sh9,
    /// The split-sum BRDF table.
    BrdfTable,
    /// The Charlie-prefiltered sheen cube.
    Sheen,
    /// The sheen tables (the Charlie table and the sheen albedo).
    SheenTables,
}

impl Step {
    /// Every step, in the order a bake runs them.
    pub const ALL: [Step; 7] = [Step::SourceCube, Step::Specular, Step::Irradiance, Step::Sh9, Step::BrdfTable, Step::Sheen, Step::SheenTables];

    /// The step's name, as progress and timings show it.
    pub fn name(self) -> &'static str {
        match self {
            Step::SourceCube => "source cube",
            Step::Specular => "specular",
            Step::Irradiance => "irradiance",
            Step::Sh9 => "sh9",
            Step::BrdfTable => "brdf lut",
            Step::Sheen => "sheen",
            Step::SheenTables => "sheen tables",
        }
    }

    /// The fields that set the step's cost.
    pub fn cost_fields(self) -> &'static [Field] {
        match self {
            Step::SourceCube => &[Field::SourceSize, Field::SupersampleDensity],
            Step::Specular => &[Field::Samples, Field::SampleGrowth, Field::Size],
            Step::Irradiance => &[Field::IrradianceSize, Field::IrradianceSource],
            Step::Sh9 => &[Field::ShSource],
            Step::BrdfTable => &[Field::LutSize, Field::LutSamples],
            Step::Sheen => &[Field::Samples, Field::SampleGrowth, Field::Size],
            Step::SheenTables => &[],
        }
    }
}

impl std::fmt::Display for Step {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}
