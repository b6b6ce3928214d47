//! The split of a source cube before the sheen prefilter (`splitsum_shaders::bright`: the
//! brightest texels summed exactly, the rest sampled): which level, which threshold, and
//! the residual cube with its mips on the backend. The filter itself is each backend's
//! `Kernels::prefilter`.

use super::kernels::{Kernels, Prefilter};
use crate::error::Result;
use splitsum_shaders::bright;
use splitsum_shaders::cubemap::{self, CubeLayout, FACES};
use splitsum_shaders::glam::Vec4;
use splitsum_shaders::prefilter::Lobe;

/// The most texels of the split level summed exactly, `K` (`bright`'s module header).
/// Measured with the level one coarser than an exact sum's (`split_size`) on the sunny sky
/// of `tests/sheen.rs` (a 5·10⁴ sun): mips 1–5 within 0.46 % at 128 (the same at 256: the
/// sun has fewer bright texels there), within 1.15 % at 64 a level coarser still, and at
/// the exact sum's level 3.7 % at 128 against 0.25 % at 256; the three-sun sky of
/// `sheen_cube_matches_the_exact_integral` agrees (mips 2–5 0.09–1.02 % against 0.11–1.28 %
/// at the exact sum's level with 256). The list's terms are most of the split's cost.
pub const TEXELS: u32 = 128;

/// A source cube split for a prefilter: the residual (no texel brighter than the
/// threshold) with its full mip chain in `layout`, and the excess list (`bright::ENTRY`
/// texels per entry, `entries` of them).
pub struct Split<T> {
    /// The residual cube.
    pub residual: T,
    /// Its layout: the split level's faces, their full chain.
    pub layout: CubeLayout,
    /// The excess list.
    pub list: T,
    /// Entries in the list.
    pub entries: u32,
    /// The list binned by the tiles of the ring's output ([`ring_table`]), where the job
    /// has a ring.
    pub ring: Option<T>,
}

impl<T> Split<T> {
    /// The residual's level that stands for source level `exact_level` (of `src_layout`)
    /// in an exact sum: the one of the same size (0 for a sampled level).
    pub fn level_of(&self, src_layout: CubeLayout, exact_level: u32) -> u32 {
        if exact_level == splitsum_shaders::prefilter::SAMPLED {
            return 0;
        }
        self.layout.level_of_size(src_layout.level_size(exact_level))
    }

    /// The face size a level of faces `size` of `lobe` for `roughness` is traced at
    /// (see [`traced_size`]), on a source of faces `src_size`.
    pub fn traced(&self, lobe: Lobe, roughness: f32, size: u32, src_size: u32) -> Option<u32> {
        traced_size(lobe, roughness, size, src_size, self.layout.size)
    }

    /// Terms of the residual's sum for a level with `samples` samples, or summed exactly
    /// (`exact_level` not `SAMPLED`) over the residual's level `residual_level`.
    pub fn terms(&self, exact_level: u32, residual_level: u32, samples: u32) -> u32 {
        if exact_level == splitsum_shaders::prefilter::SAMPLED { samples } else { FACES * self.layout.level_size(residual_level).pow(2) }
    }
}

/// Face size of the level `job` splits its source (faces of `src_size`) at, if any of
/// its levels splits ([`split_size_of`]).
pub fn split_size(job: &Prefilter<'_>, src_size: u32) -> Option<u32> {
    split_size_of(job.lobe, job.roughness, job.levels, src_size)
}

/// Face size of the level a cube of `lobe` whose mip `m` holds `roughness[m]`, baking
/// `levels`, splits a source of faces `src_size` at, if any level splits
/// (`bright::splits`): the [`band_size`] of the sharpest of them (see [`TEXELS`]). The
/// ring (roughness 0) is traced at this size ([`traced_size`]).
pub fn split_size_of(lobe: Lobe, roughness: &[f32], levels: &[u32], src_size: u32) -> Option<u32> {
    levels.iter().map(|&m| roughness[m as usize]).filter(|&r| bright::splits(lobe, r, src_size)).map(|r| band_size(lobe, r, src_size)).max()
}

/// The coarsest face size that resolves the band of `lobe` for `roughness` on a source of
/// faces `src_size`: one level coarser than its exact sum's
/// (`prefilter::exact_source_size`), a texel a quarter of the band's width.
pub fn band_size(lobe: Lobe, roughness: f32, src_size: u32) -> u32 {
    (splitsum_shaders::prefilter::exact_source_size(lobe, roughness, src_size) / 2).max(1)
}

/// The face size a level of faces `size` of `lobe` for `roughness` is traced at, when its
/// source (faces `src_size`) splits at faces `split_size`: the ring (sheen roughness 0) at
/// the split level's; a split level at its [`band_size`] where that is coarser than the
/// level, the residual's mean then read bilinearly and the excess summed at every texel
/// (`bright::traced_texel`); `None` for a level computed at its own size.
pub fn traced_size(lobe: Lobe, roughness: f32, size: u32, src_size: u32, split_size: u32) -> Option<u32> {
    if is_ring(lobe, roughness) {
        return Some(split_size);
    }
    let band = band_size(lobe, roughness, src_size).min(split_size);
    (bright::splits(lobe, roughness, src_size) && size > band).then_some(band)
}

/// Whether a level of `lobe` for `roughness` is filtered from a split source (faces of
/// `src_size`): a level that splits (`bright::splits`), or the ring.
pub fn uses_split(lobe: Lobe, roughness: f32, src_size: u32) -> bool {
    is_ring(lobe, roughness) || bright::splits(lobe, roughness, src_size)
}

/// Whether a level of `lobe` for `roughness` is the sheen ring (sheen roughness 0).
pub fn is_ring(lobe: Lobe, roughness: f32) -> bool {
    lobe == Lobe::Charlie && roughness <= 0.0
}

/// The threshold luminance of `level`: that of its `(TEXELS + 1)`-th brightest texel (of
/// the finite ones), so that at most `TEXELS` are brighter; 0 for a level of no more.
pub fn threshold(level: &[Vec4]) -> f32 {
    let k = TEXELS as usize;
    let mut lum: Vec<f32> = level.iter().map(|c| splitsum_shaders::tonemap::luminance(c.truncate())).filter(|l| l.is_finite()).collect();
    if lum.len() <= k {
        return 0.0;
    }
    let (_, t, _) = lum.select_nth_unstable_by(k, |a, b| b.total_cmp(a));
    *t
}

/// `level` (faces of `size`, `FACES·size²` texels) split at [`threshold`]: the residual
/// level and the excess list. Each entry lies at the centroid of the excess within its
/// texel, read from the finer level `fine` (faces of `fine_size`, a multiple of `size`):
/// the direction of `Σ max(lum − T, 0)·Ω·l` over the texels it covers, where any is above
/// the threshold `T`, else the texel's centre. A sun narrower than a texel of the split
/// level then lights the ring and the bands where it is, not where its texel's centre is
/// (the sunny sky of `tests/sheen.rs`: its ring from 1.89 to 0.48 %, every mip 0.07–0.48 %;
/// on a 128² source, split at 32², the ring from 8.45 to 2.20 %; under a sun of 10⁶, the
/// ring from 4.51 to 0.87 %).
pub fn split_level(level: &[Vec4], size: u32, fine: &[Vec4], fine_size: u32) -> (Vec<Vec4>, Vec<Vec4>) {
    let t = threshold(level);
    let k = (fine_size / size).max(1);
    let centroid = |i: u32| -> Vec4 {
        let g = cubemap::texel_geometry(i, size);
        let (face, y, x) = (i / (size * size), i / size % size, i % size);
        let mut sum = splitsum_shaders::glam::Vec3::ZERO;
        for fy in y * k..(y + 1) * k {
            for fx in x * k..(x + 1) * k {
                let j = (face * fine_size + fy) * fine_size + fx;
                let Some(c) = fine.get(j as usize) else { continue };
                let excess = splitsum_shaders::tonemap::luminance(c.truncate()) - t;
                if excess > 0.0 && excess.is_finite() {
                    let f = cubemap::texel_geometry(j, fine_size);
                    sum += f.truncate() * (excess * f.w);
                }
            }
        }
        let d = sum.normalize_or_zero();
        if d == splitsum_shaders::glam::Vec3::ZERO { g } else { d.extend(g.w) }
    };
    let mut list = Vec::new();
    let residual = level
        .iter()
        .enumerate()
        .map(|(i, &c)| {
            let (keep, excess) = bright::split_texel(c, t);
            if excess != Vec4::ZERO {
                list.push(centroid(i as u32));
                list.push(excess);
            }
            keep
        })
        .collect();
    (residual, list)
}

/// The excess list `list` (`entries` entries) binned by the tiles of a `size`-wide ring
/// output (`bright::ring_tile`): a header per tile, the index of its first entry from the
/// table's start and their count as the bits of `x` and `y`, then each tile's entries, those
/// whose chords reach it (`bright::ring_tile_reached`), in the list's order. A sun's chords
/// reach the tiles along one great circle; each texel of the ring reads only its tile's.
pub fn ring_table(list: &[Vec4], entries: u32, size: u32) -> Vec<Vec4> {
    use rayon::prelude::*;
    let t = bright::ring_tiles(size);
    let tiles = FACES * t * t;
    let reached: Vec<Vec<u32>> = (0..tiles)
        .into_par_iter()
        .map(|i| {
            let (face, ty, tx) = (i / (t * t), i / t % t, i % t);
            let cone = bright::ring_tile_cone(face, tx, ty, size);
            (0..entries).filter(|&j| bright::ring_cone_reached(cone, list[(bright::ENTRY * j) as usize])).collect()
        })
        .collect();
    let mut table = Vec::with_capacity(tiles as usize + reached.iter().map(|r| r.len() * bright::ENTRY as usize).sum::<usize>());
    let mut first = tiles;
    for r in &reached {
        table.push(Vec4::new(f32::from_bits(first), f32::from_bits(r.len() as u32), 0.0, 0.0));
        first += bright::ENTRY * r.len() as u32;
    }
    for j in reached.iter().flatten() {
        let at = (bright::ENTRY * j) as usize;
        table.extend_from_slice(&list[at..at + bright::ENTRY as usize]);
    }
    table
}

/// The prefiltered cube of `job` from `src` on `k`: the source split first where a level
/// of `job` splits ([`split_size`]; its level read back, split, and the residual's mips
/// built on `k`).
pub fn prefilter<K: Kernels>(k: &K, src: &K::Texels, src_layout: CubeLayout, job: &Prefilter<'_>) -> Result<K::Texels> {
    let split = match split_size(job, src_layout.size) {
        Some(t) => {
            let level = src_layout.level_of_size(t);
            let t = src_layout.level_size(level);
            let n = FACES * t * t;
            let texels = k.read(&k.slice(src, src_layout.level_offset(level), n)?)?;
            let fine = if level == 0 { texels.clone() } else { k.read(&k.slice(src, 0, FACES * src_layout.size * src_layout.size)?)? };
            let (mut residual, list) = split_level(&texels, t, &fine, src_layout.size);
            let layout = CubeLayout::new(t, CubeLayout::full_chain(t));
            residual.resize(layout.texel_count() as usize, Vec4::ZERO);
            let mut residual = k.upload("sheen residual", &residual)?;
            k.build_mips(&mut residual, layout)?;
            let entries = list.len() as u32 / bright::ENTRY;
            let ring = match job.levels.iter().find(|&&m| is_ring(job.lobe, job.roughness[m as usize])) {
                Some(&m) => Some(k.upload("sheen ring excess", &ring_table(&list, entries, job.layout.level_size(m)))?),
                None => None,
            };
            // A buffer is never empty: an unused entry stands in for none.
            let list = if list.is_empty() { vec![Vec4::ZERO; bright::ENTRY as usize] } else { list };
            Some(Split { residual, layout, list: k.upload("sheen excess", &list)?, entries, ring })
        }
        None => None,
    };
    k.prefilter(src, src_layout, job, split.as_ref())
}
