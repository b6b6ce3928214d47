//! The CPU backend: the same `splitsum_shaders` functions the kernels call, run natively
//! over every texel with rayon, with a progress bar on work that takes a while.

use crate::texture::Lut;
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use splitsum_shaders::lut;
use splitsum_shaders::glam::Vec2;

/// A progress bar of `len` steps named `what`; hidden when stderr is not a terminal.
pub fn progress(what: &str, len: u64) -> ProgressBar {
    let bar = ProgressBar::new(len);
    bar.set_style(
        ProgressStyle::with_template("{prefix:>12} [{bar:30}] {pos}/{len} {elapsed_precise} (eta {eta})")
            .expect("valid template")
            .progress_chars("=> "),
    );
    bar.set_prefix(what.to_string());
    bar
}

/// The BRDF table, one rayon task per row.
pub fn brdf_lut(size: u32, samples: u32) -> Lut {
    let bar = progress("brdf lut", size as u64);
    let mut texels = vec![Vec2::ZERO; (size * size) as usize];
    texels.par_chunks_mut(size as usize).enumerate().for_each(|(y, row)| {
        for (x, t) in row.iter_mut().enumerate() {
            *t = lut::texel(x as u32, y as u32, size, samples);
        }
        bar.inc(1);
    });
    bar.finish_and_clear();
    Lut { size, texels }
}
