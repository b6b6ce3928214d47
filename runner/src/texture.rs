//! In-memory images the backends exchange: the BRDF table, equirect environments and cube
//! maps (RGBA f32, laid out as `splitsum_shaders::cubemap::CubeLayout` says).

use splitsum_shaders::cubemap::CubeLayout;
use splitsum_shaders::glam::{Vec2, Vec4};

/// The split-sum BRDF table: `size`×`size` `(scale, bias)` pairs, row `y` = roughness.
#[derive(Clone, Debug)]
pub struct Lut {
    /// Width and height.
    pub size: u32,
    /// Row-major texels.
    pub texels: Vec<Vec2>,
}

/// An equirectangular environment, RGBA f32 (alpha unused), row 0 at the zenith.
#[derive(Clone, Debug)]
pub struct Equirect {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Row-major texels.
    pub texels: Vec<Vec4>,
}

/// A cube map with `layout.levels` mips.
#[derive(Clone, Debug)]
pub struct Cube {
    /// Size and mip count.
    pub layout: CubeLayout,
    /// All levels, level 0 first.
    pub texels: Vec<Vec4>,
}

impl Cube {
    /// The texels of level `level`.
    pub fn level(&self, level: u32) -> &[Vec4] {
        let start = self.layout.level_offset(level) as usize;
        let s = self.layout.level_size(level) as usize;
        &self.texels[start..start + 6 * s * s]
    }
}
