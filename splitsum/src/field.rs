//! The names a bake's messages use, as types: the fields of `Settings` (so that every
//! message can name a field in its reader's terms: the library its name, the command line
//! its flag, a scene its key). A bake's steps are its products (`crate::product`).


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
