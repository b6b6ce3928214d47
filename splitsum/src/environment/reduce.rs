//! Large images reduced while they are decoded ([`Reducer`]): pixels arriving in any order
//! are cleaned (the rules of [the module above](super)) and folded into blocks of
//! `factor × factor` texels, weighted by their solid angle ([`Weights`]), so memory stays
//! bounded by the reduced image.

use super::*;
use crate::error::{Error, Result};
use crate::texture::Equirect;
use splitsum_shaders::cubemap;
use splitsum_shaders::equirect;
use splitsum_shaders::glam::Vec4;
use splitsum_shaders::math::MAX_RADIANCE;
use std::path::Path;

/// How the input texels that one output texel covers are weighted.
#[derive(Copy, Clone, Debug)]
pub(super) enum Weights {
    /// By the solid angle of their equirect row (`equirect::row_solid_angle`).
    EquirectRows,
    /// By their solid angle on a cube face (`cubemap::texel_solid_angle`).
    CubeFace,
}

/// An image received pixel by pixel, in any order (an EXR's blocks may arrive out of
/// order), cleaned as it comes (the module documentation's rules) and reduced by `factor`
/// in both axes: each output texel is the mean of the `factor²` input texels it covers,
/// weighted by their solid angle ([`Weights`]) and summed in f64. Only the output rows
/// still being filled hold sums, so memory is the output image plus a few rows, whatever
/// the input's size or however much of it a file really holds. At factor 1 nothing is
/// summed and no weight plays a part: texels are only cleaned.
pub(super) struct Reducer {
    width: u32,
    height: u32,
    factor: u32,
    weights: Weights,
    sanitize: bool,
    out: Vec<Vec4>,
    /// f64 sums (r, g, b, weight) of the output rows being filled.
    pending: Vec<Option<Box<[f64]>>>,
    /// Input texels received per output row.
    arrived: Vec<u32>,
    /// Solid angle of each input row (equirects reduced by more than 1 only).
    row_weight: Vec<f64>,
    /// Per output texel, the weight of its inputs that were +∞ in each channel (made only
    /// when a +∞ arrives): replaced by the channel's largest finite value when the image
    /// is complete.
    infinite: Vec<[f64; 3]>,
    /// Texels with a +∞ channel and no other clamped value, by which channels are +∞ (bit
    /// k): counted as clamped at the end if such a channel's largest value is.
    infinite_masks: [u64; 8],
    channel_max: [f32; 3],
    report: InputReport,
}

impl Reducer {
    pub(super) fn new(width: u32, height: u32, factor: u32, weights: Weights, sanitize: bool) -> Self {
        let factor = if width.is_multiple_of(factor) && height.is_multiple_of(factor) { factor.max(1) } else { 1 };
        let (ow, oh) = (width / factor, height / factor);
        let rows = factor > 1 && matches!(weights, Weights::EquirectRows);
        let row_weight = if rows { (0..height).map(|y| equirect::row_solid_angle(y, height) as f64).collect() } else { Vec::new() };
        Self {
            width,
            height,
            factor,
            weights,
            sanitize,
            out: vec![Vec4::ZERO; ow as usize * oh as usize],
            pending: (0..oh).map(|_| None).collect(),
            arrived: vec![0; oh as usize],
            row_weight,
            infinite: Vec::new(),
            infinite_masks: [0; 8],
            channel_max: [0.0; 3],
            report: InputReport { sanitized: sanitize, original: (width, height), ..Default::default() },
        }
    }

    /// The weight of input texel `(x, y)`.
    fn weight(&self, x: u32, y: u32) -> f64 {
        match self.weights {
            _ if self.factor == 1 => 1.0,
            Weights::EquirectRows => self.row_weight[y as usize],
            Weights::CubeFace => cubemap::texel_solid_angle(x, y, self.width) as f64,
        }
    }

    /// The total weight of output texel `(ox, oy)`'s inputs.
    fn block_weight(&self, ox: usize, oy: usize) -> f64 {
        let f = self.factor as usize;
        match self.weights {
            _ if f == 1 => 1.0,
            Weights::EquirectRows => self.row_weight[oy * f..(oy + 1) * f].iter().sum::<f64>() * f as f64,
            Weights::CubeFace => (0..f * f).map(|k| self.weight((ox * f + k % f) as u32, (oy * f + k / f) as u32)).sum(),
        }
    }

    pub(super) fn push(&mut self, x: u32, y: u32, rgb: [f32; 3]) {
        if x >= self.width || y >= self.height {
            return;
        }
        let f = self.factor;
        let ow = (self.width / f) as usize;
        let (ox, oy) = ((x / f) as usize, (y / f) as usize);
        let mut c = rgb;
        let mut infinite = [false; 3];
        if c.iter().any(|v| v.is_nan()) {
            self.report.nan += 1;
        } else if c.iter().any(|v| v.is_infinite()) {
            self.report.infinite += 1;
        }
        let (mut negative, mut clamped) = (false, false);
        for k in 0..3 {
            if c[k].is_finite() {
                self.channel_max[k] = self.channel_max[k].max(c[k]);
            }
            if c[k].is_nan() || c[k] == f32::NEG_INFINITY {
                c[k] = 0.0;
            } else if c[k] == f32::INFINITY {
                c[k] = 0.0;
                infinite[k] = true;
            } else if c[k] < 0.0 {
                c[k] = 0.0;
                negative = true;
            }
            if c[k] > MAX_RADIANCE {
                c[k] = MAX_RADIANCE;
                clamped = true;
            }
        }
        self.report.negative += negative as u64;
        self.report.clamped += clamped as u64;
        let w = self.weight(x, y);
        let mask = (infinite[0] as usize) | (infinite[1] as usize) << 1 | (infinite[2] as usize) << 2;
        if mask != 0 {
            if self.infinite.is_empty() {
                self.infinite = vec![[0.0; 3]; self.out.len()];
            }
            for k in (0..3).filter(|k| infinite[*k]) {
                self.infinite[oy * ow + ox][k] += w;
            }
            if !clamped {
                self.infinite_masks[mask] += 1;
            }
        }
        if f == 1 {
            self.out[oy * ow + ox] = Vec4::new(c[0], c[1], c[2], 1.0);
        } else {
            let row = self.pending[oy].get_or_insert_with(|| vec![0.0; 4 * ow].into_boxed_slice());
            for k in 0..3 {
                row[4 * ox + k] += c[k] as f64 * w;
            }
            row[4 * ox + 3] += w;
        }
        self.arrived[oy] += 1;
        if f > 1 && self.arrived[oy] == f * self.width {
            self.resolve_row(oy);
        }
    }

    fn resolve_row(&mut self, oy: usize) {
        let ow = (self.width / self.factor) as usize;
        if let Some(row) = self.pending[oy].take() {
            for ox in 0..ow {
                let w = row[4 * ox + 3];
                let m = |k: usize| if w > 0.0 { (row[4 * ox + k] / w) as f32 } else { 0.0 };
                self.out[oy * ow + ox] = Vec4::new(m(0), m(1), m(2), 1.0);
            }
        }
    }

    pub(super) fn finish(mut self, path: &Path) -> Result<(Equirect, InputReport)> {
        if (self.report.nan > 0 || self.report.infinite > 0) && !self.sanitize {
            return Err(Error::NonFinite { path: path.to_path_buf(), nan: self.report.nan, infinite: self.report.infinite });
        }
        let (ow, oh) = (self.width / self.factor, self.height / self.factor);
        for oy in 0..oh as usize {
            if self.pending[oy].is_some() {
                // Rows of a file that held fewer texels than its header promised.
                self.resolve_row(oy);
            }
        }
        let infinite = std::mem::take(&mut self.infinite);
        for (texel, weights) in infinite.iter().enumerate().filter(|(_, w)| w.iter().any(|&v| v > 0.0)) {
            let (ox, oy) = (texel % ow as usize, texel / ow as usize);
            let total = self.block_weight(ox, oy);
            for k in 0..3 {
                let max = self.channel_max[k].min(MAX_RADIANCE);
                let t = &mut self.out[texel];
                t[k] = (t[k] as f64 + max as f64 * weights[k] / total) as f32;
            }
        }
        for (mask, &count) in self.infinite_masks.iter().enumerate() {
            if (0..3).any(|k| mask & (1 << k) != 0 && self.channel_max[k] > MAX_RADIANCE) {
                self.report.clamped += count;
            }
        }
        self.report.max_value = self.channel_max.iter().copied().fold(0.0, f32::max);
        Ok((Equirect { width: ow, height: oh, texels: self.out }, self.report))
    }
}
