//! In-memory images the backends exchange: the BRDF table, equirect environments and cube
//! maps (RGBA f32, laid out as `splitsum_shaders::cubemap::CubeLayout` says).

use splitsum_shaders::cubemap::CubeLayout;
use splitsum_shaders::glam::{Vec2, Vec4};
use splitsum_shaders::half::HALF_MAX;

/// The split-sum BRDF table: `size`×`size` `(scale, bias)` pairs, row `y` = roughness.
#[derive(Clone, Debug)]
pub struct Lut {
    /// Width and height.
    pub size: u32,
    /// Row-major texels.
    pub texels: Vec<Vec2>,
}

impl Lut {
    /// The table from `(A, B, _, _)` texels, as the backends make it.
    pub fn from_texels(size: u32, texels: &[Vec4]) -> Self {
        Self { size, texels: texels.iter().map(|t| t.truncate().truncate()).collect() }
    }
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

    /// Levels `first ..= last` as a cube of their own (level `first` becomes level 0).
    pub fn levels(&self, first: u32, last: u32) -> Cube {
        let layout = CubeLayout::new(self.layout.level_size(first), last - first + 1);
        let start = self.layout.level_offset(first) as usize;
        let end = self.layout.level_offset(last + 1) as usize;
        Cube { layout, texels: self.texels[start..end].to_vec() }
    }
}

/// Nine spherical-harmonic coefficients of radiance, RGB (see `splitsum_shaders::irradiance`).
#[derive(Clone, Debug, PartialEq)]
pub struct Sh9 {
    /// `L_lm` in the order `(0,0), (1,−1), (1,0), (1,1), (2,−2), (2,−1), (2,0), (2,1), (2,2)`.
    pub radiance: [[f64; 3]; 9],
}

impl Sh9 {
    /// Sums per-row partial sums (nine coefficients, then the row's solid angle in `[9].x`)
    /// in f64 and rescales so that the solid angles add up to exactly 4π.
    pub fn from_rows(rows: &[[Vec4; 10]]) -> Self {
        let mut radiance = [[0.0f64; 3]; 9];
        let mut omega = 0.0f64;
        for row in rows {
            for (k, c) in radiance.iter_mut().enumerate() {
                c[0] += row[k].x as f64;
                c[1] += row[k].y as f64;
                c[2] += row[k].z as f64;
            }
            omega += row[9].x as f64;
        }
        let scale = 4.0 * std::f64::consts::PI / omega;
        for c in radiance.iter_mut() {
            for v in c.iter_mut() {
                *v *= scale;
            }
        }
        Self { radiance }
    }

    /// The coefficients as the `Vec4` array `splitsum_shaders::irradiance::sh9_irradiance` takes.
    pub fn as_vec4(&self) -> [Vec4; 9] {
        self.radiance.map(|c| Vec4::new(c[0] as f32, c[1] as f32, c[2] as f32, 0.0))
    }
}

internal! {
    /// The mip chain of an RGBA8 image down to 1×1, level 0 first, by a 2×2 box filter
    /// (averaged in linear light when `srgb`). Odd sizes take the last row/column once.
    pub fn mip_chain_rgba8(width: u32, height: u32, rgba: &[u8], srgb: bool) -> Vec<(u32, u32, Vec<u8>)> {
        use splitsum_shaders::tonemap::{linear_to_srgb, srgb_to_linear};
        let decode = |v: u8, k: usize| if srgb && k < 3 { srgb_to_linear(v as f32 / 255.0) } else { v as f32 / 255.0 };
        let encode = |v: f32, k: usize| {
            let e = if srgb && k < 3 { linear_to_srgb(v) } else { v };
            (e.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
        };
        let mut levels = vec![(width, height, rgba.to_vec())];
        while let Some((w, h, data)) = levels.last().filter(|(w, h, _)| *w > 1 || *h > 1) {
            let (nw, nh) = ((w / 2).max(1), (h / 2).max(1));
            let mut next = vec![0u8; (4 * nw * nh) as usize];
            for y in 0..nh {
                for x in 0..nw {
                    for k in 0..4 {
                        let mut acc = 0.0;
                        for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                            let sx = (2 * x + dx).min(w - 1);
                            let sy = (2 * y + dy).min(h - 1);
                            acc += decode(data[(4 * (sy * w + sx)) as usize + k], k);
                        }
                        next[(4 * (y * nw + x)) as usize + k] = encode(acc / 4.0, k);
                    }
                }
            }
            levels.push((nw, nh, next));
        }
        levels
    }
}

/// Texel format of a written cube (KTX2, KTX 1.1 by its Vulkan twin: `crate::ktx2`).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Format {
    /// RGBA16F, or RGBA32F when a value exceeds the half-float range.
    Auto,
    /// Half floats; values above 65504 are clamped (and counted).
    Rgba16f,
    /// Single floats.
    Rgba32f,
    /// `E5B9G9R9_UFLOAT_PACK32`: four bytes a texel, RGB with a shared exponent (9-bit
    /// mantissas; Bevy's own environment maps), no alpha; values above 65408 are clamped
    /// (and counted).
    Rgb9e5,
}

splitsum_shaders::choice!(Format: Auto => "auto", Rgba16f => "rgba16f", Rgba32f => "rgba32f", Rgb9e5 => "rgb9e5");

impl Format {
    /// The format that writing `cube` with `self` uses.
    pub fn resolve(self, cube: &Cube) -> Format {
        match self {
            Format::Auto if max_value(cube) > HALF_MAX => Format::Rgba32f,
            Format::Auto => Format::Rgba16f,
            f => f,
        }
    }
}

/// The largest channel value of `cube`.
pub(crate) fn max_value(cube: &Cube) -> f32 {
    cube.texels.iter().map(|t| t.x.max(t.y).max(t.z).max(t.w)).fold(0.0, f32::max)
}
