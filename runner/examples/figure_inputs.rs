//! The inputs of the guide's generated speed and memory figures (`bash scripts/dev.sh
//! figures` runs this, then `runner bench --processes … --figures`), made here rather than
//! committed:
//!
//! - `figure_inputs hdr IN OUT.hdr WIDTH`: `IN` (any environment splitsum reads) as a
//!   Radiance `.hdr` of `WIDTH`×`WIDTH/2`, box-filtered down by a whole factor, which the
//!   Khronos glTF-IBL-Sampler reads too;
//! - `figure_inputs sky OUT.exr WIDTH`: a synthetic `WIDTH`×`WIDTH/2` sky with a sun of
//!   5·10⁴ and texel noise (so it compresses like a photograph), written row by row.

#[path = "../tests/common/equirect.rs"]
mod equirect;

use splitsum::environment::Environment;
use std::path::Path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let usage = "usage: figure_inputs hdr IN OUT.hdr WIDTH | figure_inputs sky OUT.exr WIDTH";
    match args.iter().map(String::as_str).collect::<Vec<_>>()[..] {
        ["hdr", input, output, width] => {
            let width: u32 = width.parse()?;
            let (Environment::Equirect(e), _) = splitsum::environment::load(Path::new(input), true)? else {
                return Err(format!("{input} is not an equirect").into());
            };
            let f = e.width / width.max(1);
            if f == 0 || e.width % width != 0 || e.height != e.width / 2 {
                return Err(format!("{input} is {}×{}: WIDTH {width} must divide its width, which must be twice its height", e.width, e.height).into());
            }
            let (w, h) = (e.width / f, e.height / f);
            let mut pixels = Vec::with_capacity((w * h) as usize);
            for y in 0..h {
                for x in 0..w {
                    let mut sum = [0.0f32; 3];
                    for dy in 0..f {
                        for dx in 0..f {
                            let t = e.texels[((y * f + dy) * e.width + x * f + dx) as usize];
                            for (s, v) in sum.iter_mut().zip([t.x, t.y, t.z]) {
                                *s += v / (f * f) as f32;
                            }
                        }
                    }
                    pixels.push(image::Rgb(sum));
                }
            }
            let file = std::io::BufWriter::new(std::fs::File::create(output)?);
            image::codecs::hdr::HdrEncoder::new(file).encode(&pixels, w as usize, h as usize)?;
        }
        ["sky", output, width] => equirect::write_equirect(Path::new(output), width.parse()?, 5.0e4),
        _ => return Err(usage.into()),
    }
    Ok(())
}
