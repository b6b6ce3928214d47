//! The CPU backend: the same `splitsum_shaders` functions the kernels call, run natively
//! over every texel with rayon, with a progress bar on work that takes a while.

use crate::progress::bar as progress;
use crate::texture::{Cube, Equirect, Lut};
use indicatif::ProgressBar;
use rayon::prelude::*;
use splitsum_shaders::cubemap::{self, CubeLayout, FACES};
use splitsum_shaders::glam::{Vec2, Vec4};
use splitsum_shaders::irradiance::{self, SH9};
use splitsum_shaders::{equirect, lut, prefilter};

/// A `size`×`size` table, `f(x, y)` per texel, one rayon task per row.
fn table(what: &str, size: u32, f: impl Fn(u32, u32) -> Vec2 + Sync) -> Lut {
    let bar = progress(what, size as u64);
    let mut texels = vec![Vec2::ZERO; (size * size) as usize];
    texels.par_chunks_mut(size as usize).enumerate().for_each(|(y, row)| {
        for (x, t) in row.iter_mut().enumerate() {
            *t = f(x as u32, y as u32);
        }
        bar.inc(1);
    });
    bar.finish_and_clear();
    Lut { size, texels }
}

/// The BRDF table from `samples` Hammersley points per texel.
pub fn brdf_lut(size: u32, samples: u32) -> Lut {
    table("brdf lut", size, |x, y| lut::texel(x, y, size, samples))
}

/// The BRDF table by quadrature.
pub fn brdf_table(size: u32, masking: splitsum_shaders::brdf::microfacet::Masking) -> Lut {
    table("brdf table", size, |x, y| lut::texel_quadrature(x, y, size, masking))
}

/// Fills the rows of one cube level, `f(face, x, y)` per texel, in parallel.
fn fill_level(out: &mut [Vec4], size: u32, bar: &ProgressBar, f: impl Fn(u32, u32, u32) -> Vec4 + Sync) {
    out.par_chunks_mut(size as usize).enumerate().for_each(|(row, texels)| {
        let face = row as u32 / size;
        let y = row as u32 % size;
        for (x, t) in texels.iter_mut().enumerate() {
            *t = f(face, x as u32, y);
        }
        bar.inc(1);
    });
}

/// The row pyramid of `env` (see `equirect::pyramid_texel`).
pub fn equirect_pyramid(env: &Equirect) -> Vec<Vec4> {
    let (w, h) = (env.width, env.height);
    let mut pyramid = env.texels.clone();
    pyramid.resize(equirect::pyramid_len(w, h) as usize, Vec4::ZERO);
    for level in 1..equirect::pyramid_levels(w) {
        let start = equirect::pyramid_offset(level, w, h) as usize;
        let lw = (w >> level) as usize;
        let (above, below) = pyramid.split_at_mut(start);
        let src: &[Vec4] = above;
        below[..lw * h as usize].par_chunks_mut(lw).enumerate().for_each(|(y, row)| {
            for (x, t) in row.iter_mut().enumerate() {
                *t = equirect::pyramid_texel(src, w, h, level, x as u32, y as u32);
            }
        });
    }
    pyramid
}

/// Level 0 of a cube of face size `size` (with room for its full mip chain) resampled from
/// `env` with `supersample`² points per texel.
pub fn equirect_to_cube(env: &Equirect, size: u32, supersample: u32) -> Cube {
    let layout = CubeLayout::new(size, CubeLayout::full_chain(size));
    let mut texels = vec![Vec4::ZERO; layout.texel_count() as usize];
    let pyramid = equirect_pyramid(env);
    let levels = equirect::pyramid_levels(env.width);
    let bar = progress("equirect", (FACES * size) as u64);
    let level0 = &mut texels[..(FACES * size * size) as usize];
    fill_level(level0, size, &bar, |face, x, y| equirect::cube_texel(&pyramid, env.width, env.height, levels, face, x, y, size, supersample));
    bar.finish_and_clear();
    Cube { layout, texels }
}

/// Levels 1.. of `cube` from level 0, by the solid-angle-weighted box filter.
pub fn build_mips(cube: &mut Cube) {
    let layout = cube.layout;
    for level in 0..layout.levels - 1 {
        let start = layout.level_offset(level + 1) as usize;
        let (above, below) = cube.texels.split_at_mut(start);
        let s = layout.level_size(level + 1);
        let dst = &mut below[..(FACES * s * s) as usize];
        let src: &[Vec4] = above;
        dst.par_chunks_mut(s as usize).enumerate().for_each(|(row, texels)| {
            let face = row as u32 / s;
            let y = row as u32 % s;
            for (x, t) in texels.iter_mut().enumerate() {
                *t = cubemap::downsample_texel(src, layout, level, face, x as u32, y);
            }
        });
    }
}

/// Levels `levels` of the prefiltered specular cube (the others stay zero).
/// The prefiltered cube: level `m` (of `levels`) for `roughness[m]` from `samples[m]` GGX
/// samples, or summed exactly over source level `exact[m]` (unless `prefilter::SAMPLED`).
pub fn prefilter(src: &Cube, out: CubeLayout, roughness: &[f32], levels: &[u32], samples: &[u32], exact: &[u32], lod_bias: f32) -> Cube {
    let mut texels = vec![Vec4::ZERO; out.texel_count() as usize];
    let rows: u64 = levels.iter().map(|&m| (FACES * out.level_size(m)) as u64).sum();
    let bar = progress("specular", rows);
    for &m in levels {
        let s = out.level_size(m);
        let start = out.level_offset(m) as usize;
        let level = &mut texels[start..start + (FACES * s * s) as usize];
        let (r, n, e) = (roughness[m as usize], samples[m as usize], exact[m as usize]);
        fill_level(level, s, &bar, |face, x, y| prefilter::prefilter_texel(&src.texels, src.layout, face, x, y, s, r, n, lod_bias, e));
    }
    bar.finish_and_clear();
    Cube { layout: out, texels }
}

/// The irradiance cube (`E/π`) of face size `size`, summed over level `level` of `src`.
pub fn irradiance(src: &Cube, level: u32, size: u32) -> Cube {
    let layout = CubeLayout::new(size, 1);
    let mut texels = vec![Vec4::ZERO; layout.texel_count() as usize];
    let bar = progress("irradiance", (FACES * size) as u64);
    fill_level(&mut texels, size, &bar, |face, x, y| irradiance::convolve_dir(&src.texels, src.layout, level, cubemap::texel_dir(face, x, y, size)));
    bar.finish_and_clear();
    Cube { layout, texels }
}

/// The per-row SH9 partial sums of level `level` of `src` (see `irradiance::sh9_row`).
pub fn sh9_rows(src: &Cube, level: u32) -> Vec<[Vec4; SH9 + 1]> {
    let s = src.layout.level_size(level);
    (0..FACES * s).into_par_iter().map(|row| irradiance::sh9_row(&src.texels, src.layout, level, row / s, row % s)).collect()
}
