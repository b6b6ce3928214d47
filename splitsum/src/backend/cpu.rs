//! The CPU backend: the same `splitsum_shaders` functions the kernels call, run natively
//! over every texel with rayon, with a progress bar on work that takes a while.

use super::kernels::{Kernels, Prefilter, chunks};
use super::split::Split;
use crate::error::Result;
use crate::progress::{Bar, bar as progress};
use crate::texture::{Equirect, Sh9};
use rayon::prelude::*;
use splitsum_shaders::brdf::microfacet::Masking;
use splitsum_shaders::cubemap::{self, CubeLayout, FACES};
use splitsum_shaders::equirect::Facing;
use splitsum_shaders::glam::Vec4;
use splitsum_shaders::irradiance;
use splitsum_shaders::kernels::{self, ProbeParams};
use splitsum_shaders::calibrate::{self, Rate};
use splitsum_shaders::math::MeanPartial;
use splitsum_shaders::{bright, equirect, lut, prefilter};

/// The CPU backend (rayon's global thread pool).
#[derive(Copy, Clone, Debug, Default)]
pub struct Cpu;

/// A `size`² table with texel `(x, y)` = `f(x, y)` in `xy`.
fn table(what: &str, size: u32, f: impl Fn(u32, u32) -> Vec4 + Sync) -> Vec<Vec4> {
    let bar = progress(what, size as u64);
    let mut texels = vec![Vec4::ZERO; (size * size) as usize];
    texels.par_chunks_mut(size as usize).enumerate().for_each(|(y, row)| {
        for (x, t) in row.iter_mut().enumerate() {
            *t = f(x as u32, y as u32);
        }
        bar.inc(1);
    });
    texels
}

/// Fills one level (`FACES · size` rows of `size` texels) with `f(face, x, y)`.
fn fill_level(out: &mut [Vec4], size: u32, bar: &Bar, f: impl Fn(u32, u32, u32) -> Vec4 + Sync) {
    out.par_chunks_mut(size as usize).enumerate().for_each(|(row, texels)| {
        let face = row as u32 / size;
        let y = row as u32 % size;
        for (x, t) in texels.iter_mut().enumerate() {
            *t = f(face, x as u32, y);
        }
        bar.inc(1);
    });
}

/// The row pyramid of `env` (`equirect::pyramid_texel`): level 0 the image, each level
/// above half as wide.
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

/// Level `level` of the cube `src` alone, as a one-level cube, followed by its geometry table
/// (`cubemap::level_geometry`, as the GPU backend places it for the irradiance): what an
/// exact sum reads in place of computing two triangles' solid angles per term, with the
/// same values bit for bit. Returns the cube, its layout and where the table starts.
fn level_with_geometry(src: &[Vec4], layout: CubeLayout, level: u32) -> (Vec<Vec4>, CubeLayout, u32) {
    let s = layout.level_size(level);
    let n = FACES * s * s;
    let start = layout.level_offset(level) as usize;
    let input = src[start..start + n as usize].iter().copied().chain(cubemap::level_geometry(s)).collect();
    (input, CubeLayout::new(s, 1), n)
}

impl Cpu {
    /// The `size`² sheen tables, `(Charlie table, sheen albedo, 0, 0)` per texel
    /// (`lut::sheen_texel`): constants, made on the CPU only (`crate::table`).
    pub fn sheen_tables(&self, size: u32) -> Vec<Vec4> {
        table("sheen tables", size, |x, y| lut::sheen_texel(x, y, size).extend(0.0).extend(0.0))
    }
}

impl Kernels for Cpu {
    type Texels = Vec<Vec4>;

    fn finish(&self) -> Result<()> {
        Ok(())
    }

    fn upload(&self, _what: &str, texels: &[Vec4]) -> Result<Vec<Vec4>> {
        Ok(texels.to_vec())
    }

    fn read(&self, texels: &Vec<Vec4>) -> Result<Vec<Vec4>> {
        Ok(texels.clone())
    }

    fn slice(&self, texels: &Vec<Vec4>, start: u32, count: u32) -> Result<Vec<Vec4>> {
        Ok(texels[start as usize..(start + count) as usize].to_vec())
    }

    fn equirect_to_cube(&self, env: &Equirect, size: u32, supersample: u32, facing: Facing) -> Result<Vec<Vec4>> {
        let layout = CubeLayout::new(size, CubeLayout::full_chain(size));
        let mut texels = vec![Vec4::ZERO; layout.texel_count() as usize];
        let pyramid = equirect_pyramid(env);
        let levels = equirect::pyramid_levels(env.width);
        let bar = progress("equirect", (FACES * size) as u64);
        let level0 = &mut texels[..(FACES * size * size) as usize];
        fill_level(level0, size, &bar, |face, x, y| equirect::cube_texel(&pyramid, env.width, env.height, levels, facing, face, x, y, size, supersample));
            self.build_mips(&mut texels, layout)?;
        Ok(texels)
    }

    fn build_mips(&self, cube: &mut Vec<Vec4>, layout: CubeLayout) -> Result<()> {
        for level in 0..layout.levels - 1 {
            let start = layout.level_offset(level + 1) as usize;
            let (above, below) = cube.split_at_mut(start);
            let s = layout.level_size(level + 1);
            let dst = &mut below[..(FACES * s * s) as usize];
            let src: &[Vec4] = above;
            // The weights are the same on every face: made once per level.
            let src_size = layout.level_size(level);
            let weights: Vec<Vec4> = (0..s * s).map(|i| cubemap::downsample_weights(i % s, i / s, src_size)).collect();
            dst.par_chunks_mut(s as usize).enumerate().for_each(|(row, texels)| {
                let face = row as u32 / s;
                let y = row as u32 % s;
                for (x, t) in texels.iter_mut().enumerate() {
                    *t = cubemap::downsample_with(src, layout, level, face, x as u32, y, weights[(y * s) as usize + x]);
                }
            });
        }
        Ok(())
    }

    fn prefilter(&self, src: &Vec<Vec4>, src_layout: CubeLayout, job: &Prefilter<'_>, split: Option<&Split<Vec<Vec4>>>) -> Result<Vec<Vec4>> {
        let out = job.layout;
        let mut texels = vec![Vec4::ZERO; out.texel_count() as usize];
        let rows: u64 = job.levels.iter().map(|&m| (FACES * out.level_size(m)) as u64).sum();
        let bar = progress(job.what, rows);
        for &m in job.levels {
            let s = out.level_size(m);
            let start = out.level_offset(m) as usize;
            let level = &mut texels[start..start + (FACES * s * s) as usize];
            let (r, n, e) = (job.roughness[m as usize], job.samples[m as usize], job.exact[m as usize]);
            if let Some(split) = split.filter(|_| super::split::uses_split(job.lobe, r, src_layout.size)) {
                // The residual sampled (its samples made once for the level) or summed over
                // its level of the exact sum's size, then the excess: at each texel, or the
                // residual traced at the split level's size and read from it with the
                // excess's terms (the ring's chords, or the density).
                let table: Vec<Vec4> =
                    if e == prefilter::SAMPLED { prefilter::lobe_samples(job.lobe, n, r, split.layout.size, job.lod_bias).collect() } else { Vec::new() };
                let residual_level = split.level_of(src_layout, e);
                let terms = split.terms(e, residual_level, n);
                let alpha = job.lobe.alpha(r);
                let exact = if e == prefilter::SAMPLED { None } else { Some(level_with_geometry(&split.residual, split.layout, residual_level)) };
                let residual = |d| {
                    MeanPartial::default().then_chunked(terms, |start, c, p| match &exact {
                        None => prefilter::accumulate_samples(job.lobe, &split.residual, split.layout, d, &table, start, c, p),
                        Some((input, one, geometry)) => prefilter::exact_accumulate(job.lobe, input, *one, 0, *geometry, d, r, start, c, p),
                    })
                };
                if let Some(ts) = split.traced(job.lobe, r, s, src_layout.size) {
                    let mut buf = vec![Vec4::ZERO; (FACES * ts * ts) as usize];
                    fill_level(&mut buf, ts, &Bar::hidden(), |face, x, y| residual(cubemap::texel_dir(face, x, y, ts)).resolve());
                    // The ring reads its tile's entries (`split::ring_table`), any other
                    // level the whole list.
                    let ring = r <= 0.0;
                    let tail = if ring { split.ring.as_ref().expect("a job with a ring has its table") } else { &split.list };
                    let start = FACES * ts * ts;
                    if ring {
                        buf.extend_from_slice(tail);
                    } else {
                        // The entries, then the level's density table (`bright`).
                        buf.extend_from_slice(&tail[..(bright::ENTRY * split.entries) as usize]);
                        buf.extend(bright::density_table(alpha));
                    }
                    fill_level(level, s, &bar, |face, x, y| {
                        let (list, count) = if ring {
                            let h = buf[(start + bright::ring_tile(face, x, y, s)) as usize];
                            (start + h.x.to_bits(), h.y.to_bits())
                        } else {
                            (start, split.entries)
                        };
                        bright::traced_texel(&buf, ts, list, count, cubemap::texel_dir(face, x, y, s), alpha, ring)
                    });
                } else {
                    // The level's density table, then the list (`bright::list_start`).
                    let list: Vec<Vec4> = bright::density_table(alpha).chain(split.list.iter().copied()).collect();
                    fill_level(level, s, &bar, |face, x, y| {
                        let d = cubemap::texel_dir(face, x, y, s);
                        residual(d).then_chunked(split.entries, |start, c, p| bright::accumulate(&list, d, alpha, start, c, p)).resolve()
                    });
                }
            } else if e == prefilter::SAMPLED && !job.lobe.is_mirror(r) && job.lobe.alpha(r) > 0.0 {
                // The samples depend on no texel: made once for the level.
                let table: Vec<Vec4> = prefilter::lobe_samples(job.lobe, n, r, src_layout.size, job.lod_bias).collect();
                fill_level(level, s, &bar, |face, x, y| prefilter::prefilter_dir_samples(job.lobe, src, src_layout, cubemap::texel_dir(face, x, y, s), &table));
            } else if e != prefilter::SAMPLED && !job.lobe.is_mirror(r) {
                // An exact sum reads its level's geometry from a table made once.
                let (input, one, geometry) = level_with_geometry(src, src_layout, e);
                fill_level(level, s, &bar, |face, x, y| prefilter::exact_dir(job.lobe, &input, one, 0, geometry, cubemap::texel_dir(face, x, y, s), r));
            } else {
                fill_level(level, s, &bar, |face, x, y| prefilter::prefilter_texel(job.lobe, src, src_layout, face, x, y, s, r, n, job.lod_bias, e));
            }
        }
            Ok(texels)
    }

    fn irradiance(&self, src: &Vec<Vec4>, src_layout: CubeLayout, level: u32, size: u32) -> Result<Vec<Vec4>> {
        let layout = CubeLayout::new(size, 1);
        let mut texels = vec![Vec4::ZERO; layout.texel_count() as usize];
        let bar = progress("irradiance", (FACES * size) as u64);
        let (input, one, geometry) = level_with_geometry(src, src_layout, level);
        fill_level(&mut texels, size, &bar, |face, x, y| irradiance::convolve_dir(&input, one, 0, geometry, cubemap::texel_dir(face, x, y, size)));
            Ok(texels)
    }

    fn sh9(&self, src: &Vec<Vec4>, src_layout: CubeLayout, level: u32) -> Result<Sh9> {
        let s = src_layout.level_size(level);
        let rows: Vec<_> = (0..FACES * s).into_par_iter().map(|row| irradiance::sh9_row(src, src_layout, level, row / s, row % s)).collect();
        Ok(Sh9::from_rows(&rows))
    }

    fn brdf_lut(&self, size: u32, samples: u32) -> Result<Vec<Vec4>> {
        Ok(table("brdf lut", size, |x, y| lut::texel(x, y, size, samples).extend(0.0).extend(0.0)))
    }

    fn brdf_table(&self, size: u32, masking: Masking) -> Result<Vec<Vec4>> {
        Ok(table("brdf table", size, |x, y| lut::texel_quadrature(x, y, size, masking).extend(0.0).extend(0.0)))
    }

    fn calibrate(&self, src: &Vec<Vec4>, src_layout: CubeLayout, rate: Rate, size: u32, count: u32) -> Result<Vec<Vec4>> {
        let mut texels = vec![Vec4::ZERO; (FACES * size * size) as usize];
        fill_level(&mut texels, size, &Bar::hidden(), |face, x, y| calibrate::texel(src, src_layout, rate, face, x, y, size, count));
        Ok(texels)
    }

    fn probe_raw(&self, p: ProbeParams, texels: &[Vec4], probes: &[Vec4], terms: u32) -> Result<Vec<Vec4>> {
        let mut out = vec![Vec4::ZERO; 3 * probes.len()];
        for (i, &q) in probes.iter().enumerate() {
            for (start, chunk) in chunks(terms) {
                kernels::probe_chunk(&ProbeParams { start, chunk, ..p }, texels, q, &mut out, i);
            }
        }
        Ok(out)
    }
}
