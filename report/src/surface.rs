//! What the error looks like on a surface: a grid of spheres (metal and dielectric rows,
//! roughness across) shaded by splitsum from its default bake, beside the same spheres
//! shaded by the exact reflectance integral (`splitsum_reference::Environment::shade`,
//! exact height-correlated Smith, f64, no split), and the relative luminance error between
//! them in false colour on a log scale (0.1 % to 100 %).
//!
//! Orthographic view along −z (`v = +z` everywhere), so the rim of each sphere is its
//! grazing view: the split sum's own error shows there.

use crate::measurement::{arr, rel};
use rayon::prelude::*;
use splitsum::Product;
use splitsum::reading::BakedEnvironment;
use splitsum_reference as reference;
use splitsum_shaders::glam::Vec3;
use splitsum_shaders::shade::{self, Material, ShadeOptions};

/// Roughness of the columns.
pub const ROUGHNESS: [f32; 6] = [0.1, 0.25, 0.4, 0.55, 0.7, 1.0];
/// Sphere radius in cells (one shading point each); each cell is drawn `CELL`² pixels.
const RADIUS: u32 = 10;
const CELL: u32 = 4;
/// The error scale's ends: `10^LOG_LO` to `10^LOG_HI`.
const LOG_LO: f64 = -3.0;
const LOG_HI: f64 = 0.0;

/// The three pictures, RGB8, and the error of the points shaded.
pub struct ErrorMap {
    /// Width of each picture.
    pub width: u32,
    /// Height of each picture.
    pub height: u32,
    /// splitsum's shading (tone mapped).
    pub splitsum: Vec<u8>,
    /// The exact integral (the same tone mapping).
    pub exact: Vec<u8>,
    /// The relative luminance error, false colour ([`false_colour`]).
    pub error: Vec<u8>,
    /// Mean and largest relative error over every point.
    pub mean: f64,
    /// Largest relative error.
    pub max: f64,
}

/// A perceptually ordered false colour for `t` in 0..1 (viridis, five stops, linear between).
pub fn false_colour(t: f64) -> [u8; 3] {
    const STOPS: [[f64; 3]; 5] = [[68.0, 1.0, 84.0], [59.0, 82.0, 139.0], [33.0, 145.0, 140.0], [94.0, 201.0, 98.0], [253.0, 231.0, 37.0]];
    let x = t.clamp(0.0, 1.0) * 4.0;
    let i = (x.floor() as usize).min(3);
    let f = x - i as f64;
    std::array::from_fn(|c| (STOPS[i][c] + f * (STOPS[i + 1][c] - STOPS[i][c])).round() as u8)
}

/// Where a relative error `e` sits on the scale (0 at 0.1 %, 1 at 100 % and above).
pub fn scale_position(e: f64) -> f64 {
    ((e.max(1e-12).log10() - LOG_LO) / (LOG_HI - LOG_LO)).clamp(0.0, 1.0)
}

/// The scale's ticks: (position, label).
pub fn scale_ticks() -> Vec<(f64, String)> {
    ["0.1 %", "1 %", "10 %", "100 %"].iter().enumerate().map(|(k, l)| (k as f64 / 3.0, l.to_string())).collect()
}

fn srgb(x: f64) -> u8 {
    let x = x.clamp(0.0, 1.0);
    let y = if x <= 0.003_130_8 { 12.92 * x } else { 1.055 * x.powf(1.0 / 2.4) - 0.055 };
    (y * 255.0).round() as u8
}

/// The sphere grid of `baked` against the exact integral over `env`.
pub fn error_map(baked: &BakedEnvironment, env: &reference::Environment) -> ErrorMap {
    let d = 2 * RADIUS;
    let (cols, rows) = (ROUGHNESS.len() as u32, 2u32);
    let (cw, ch) = (cols * d, rows * d);
    // Every cell inside a sphere: (cell x, cell y, material, n).
    let mut points = Vec::new();
    for row in 0..rows {
        for (col, &r) in ROUGHNESS.iter().enumerate() {
            let material = Material {
                base_color: Vec3::new(0.9, 0.6, 0.3),
                metallic: 1.0 - row as f32,
                roughness: r,
                occlusion: 1.0,
                emissive: Vec3::ZERO,
                sheen_color: Vec3::ZERO,
                sheen_roughness: 0.0,
            };
            for y in 0..d {
                for x in 0..d {
                    let (px, py) = ((x as f32 + 0.5) / RADIUS as f32 - 1.0, 1.0 - (y as f32 + 0.5) / RADIUS as f32);
                    let z2 = 1.0 - px * px - py * py;
                    if z2 > 0.0 {
                        points.push((col as u32 * d + x, row * d + y, material, Vec3::new(px, py, z2.sqrt())));
                    }
                }
            }
        }
    }
    let v = Vec3::Z;
    let opts = ShadeOptions::DEFAULT;
    let opts = ShadeOptions { flags: (opts.flags & !ShadeOptions::DIRECT) | ShadeOptions::IBL, ..opts };
    let shape = baked.shape();
    let specular = baked.specular_buffer();
    let shaded: Vec<(Vec3, [f64; 3])> = points
        .par_iter()
        .map(|(_, _, m, n)| {
            let s = shade::ibl_sample(
                shape,
                &specular,
                &baked.cube(Product::Irradiance).texels,
                &baked.table(Product::BrdfTable).texels,
                opts,
                m,
                *n,
                v,
            );
            let got = shade::ibl(opts, m, *n, v, s);
            let want = env.shade(arr(*n), arr(v), arr(m.base_color), m.metallic as f64, m.roughness as f64, reference::Smith::Correlated);
            (got, want)
        })
        .collect();
    // One exposure for both: the exact picture's mean luminance to 0.18.
    let mean_lum = shaded.iter().map(|(_, w)| reference::luminance(*w)).sum::<f64>() / shaded.len().max(1) as f64;
    let exposure = 0.18 / mean_lum.max(1e-12);
    let tone = |c: [f64; 3]| -> [u8; 3] { std::array::from_fn(|k| srgb(c[k] * exposure / (1.0 + c[k] * exposure))) };
    let (w, h) = (cw * CELL, ch * CELL);
    let background = [255u8, 255, 255];
    let mut pictures = [vec![0u8; (w * h * 3) as usize], vec![0u8; (w * h * 3) as usize], vec![0u8; (w * h * 3) as usize]];
    for p in &mut pictures {
        for px in p.chunks_exact_mut(3) {
            px.copy_from_slice(&background);
        }
    }
    let mut errors = Vec::with_capacity(points.len());
    for ((cx, cy, _, _), (got, want)) in points.iter().zip(&shaded) {
        let e = rel(*got, *want);
        errors.push(e);
        let colours = [tone(arr(*got)), tone(*want), false_colour(scale_position(e))];
        for (picture, c) in pictures.iter_mut().zip(colours) {
            for y in cy * CELL..(cy + 1) * CELL {
                for x in cx * CELL..(cx + 1) * CELL {
                    let i = ((y * w + x) * 3) as usize;
                    picture[i..i + 3].copy_from_slice(&c);
                }
            }
        }
    }
    let [splitsum, exact, error] = pictures;
    let mean = errors.iter().sum::<f64>() / errors.len().max(1) as f64;
    let max = errors.iter().copied().fold(0.0, f64::max);
    ErrorMap { width: w, height: h, splitsum, exact, error, mean, max }
}
