//! [`Target`]: whose conventions a bake's files follow, and what each target fixes
//! ([`Fixed`]: facing, roughness per mip, mip count, table masking) and reads.

use super::*;
use splitsum_shaders::brdf::microfacet::Masking;
use splitsum_shaders::cubemap::CubeLayout;
use splitsum_shaders::equirect::Facing;
use splitsum_shaders::prefilter::RoughnessMapping;

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

    /// What every material of the target's engine reads: Khronos and Bevy a specular and an
    /// irradiance cube and the table; Filament the specular cube and SH9 (its table, cloth's
    /// term included, is built in); splitsum everything but sheen. Sheen is read only by
    /// materials with `KHR_materials_sheen`: a bake adds it when asked
    /// ([`Products::with_sheen`]; khronos then writes the `charlie/` folder and tables of
    /// glTF-Sample-Environments' layout), as a scene's plan does for a sheen material.
    pub fn products(self) -> Products {
        match self {
            Target::Splitsum => Products::STANDARD,
            Target::Khronos | Target::Bevy => Products::DISPLAY,
            Target::Filament => Products::of(&[Product::Specular, Product::Sh9]),
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
