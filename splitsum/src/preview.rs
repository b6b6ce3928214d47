//! Tonemapped 8-bit previews of cubes and environments, laid out for people: a cube as a
//! horizontal cross (`+Y` above `+Z`; `−X +Z +X −Z` across; `−Y` below), mips side by side.

use crate::texture::{Cube, Equirect};
use splitsum_shaders::cubemap::CubeLayout;
use splitsum_shaders::glam::{Vec3, Vec4};
use splitsum_shaders::tonemap::{self, Tonemapper};

/// An RGB image in linear radiance.
pub struct Picture {
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
    /// Row-major pixels.
    pub pixels: Vec<Vec3>,
}

impl Picture {
    fn blank(width: u32, height: u32) -> Self {
        Self { width, height, pixels: vec![Vec3::ZERO; (width * height) as usize] }
    }

    /// 8-bit sRGB after `exposure` and `curve`.
    pub fn to_rgb8(&self, exposure: f32, curve: Tonemapper) -> Vec<u8> {
        self.pixels
            .iter()
            .flat_map(|&c| {
                let d = tonemap::display(c, exposure, curve);
                [d.x, d.y, d.z].map(|v| (v * 255.0 + 0.5) as u8)
            })
            .collect()
    }
}

/// The one automatic exposure, of the display and the previews alike: a white Lambert
/// surface shows, on average, at 0.5 before the tone curve, `0.5 / mean(E/π)`. The mean of
/// `E/π` over all normals is the solid-angle-weighted mean of the radiance
/// (`∫ max(0, n·l) dn = π` for every `l`), read from level 0 of `cube`.
pub fn auto_exposure(cube: &Cube) -> f32 {
    let s = cube.layout.size;
    let (mut sum, mut weight) = (0.0f64, 0.0f64);
    for (i, c) in cube.level(0).iter().enumerate() {
        let (x, y) = (i as u32 % s, (i as u32 / s) % s);
        let w = splitsum_shaders::cubemap::texel_solid_angle(x, y, s) as f64;
        sum += w * tonemap::luminance(c.truncate()) as f64;
        weight += w;
    }
    let mean = sum / weight.max(f64::MIN_POSITIVE);
    if mean > 0.0 && mean.is_finite() { (0.5 / mean) as f32 } else { 1.0 }
}

/// Where each face goes in a 4×3 cross, in face order +X, −X, +Y, −Y, +Z, −Z.
const CROSS: [(u32, u32); 6] = [(2, 1), (0, 1), (1, 0), (1, 2), (1, 1), (3, 1)];

/// Level `level` of `cube` as a cross with faces `face` pixels wide (nearest texel).
pub fn cross(cube: &Cube, level: u32, face: u32) -> Picture {
    let mut pic = Picture::blank(4 * face, 3 * face);
    draw_cross(&mut pic, 0, cube.layout, cube.level(level), level, face);
    pic
}

fn draw_cross(pic: &mut Picture, x0: u32, layout: CubeLayout, texels: &[Vec4], level: u32, face: u32) {
    let s = layout.level_size(level);
    for (f, &(cx, cy)) in CROSS.iter().enumerate() {
        for y in 0..face {
            for x in 0..face {
                let tx = x * s / face;
                let ty = y * s / face;
                let t = texels[((f as u32 * s + ty) * s + tx) as usize];
                let px = x0 + cx * face + x;
                let py = cy * face + y;
                pic.pixels[(py * pic.width + px) as usize] = t.truncate();
            }
        }
    }
}

/// Every level of `cube` as crosses side by side, each with faces `face` pixels wide.
pub fn mip_strip(cube: &Cube, face: u32) -> Picture {
    let n = cube.layout.levels;
    let mut pic = Picture::blank(4 * face * n, 3 * face);
    for level in 0..n {
        draw_cross(&mut pic, level * 4 * face, cube.layout, cube.level(level), level, face);
    }
    pic
}

/// `env` scaled down (box filter) to at most `max_width` pixels wide.
pub fn equirect(env: &Equirect, max_width: u32) -> Picture {
    let step = env.width.div_ceil(max_width).max(1);
    let (w, h) = (env.width / step, env.height / step);
    let mut pic = Picture::blank(w, h);
    for y in 0..h {
        for x in 0..w {
            let mut acc = Vec3::ZERO;
            for j in 0..step {
                for i in 0..step {
                    acc += env.texels[((y * step + j) * env.width + x * step + i) as usize].truncate();
                }
            }
            pic.pixels[(y * w + x) as usize] = acc / (step * step) as f32;
        }
    }
    pic
}
