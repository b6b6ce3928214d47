//! A large synthetic equirect, generated rather than committed: the process tests read it,
//! and `runner/examples/figure_inputs.rs` writes it for the guide's memory figure.

use std::path::Path;

/// A `width`×`width/2` equirect, f16 RGB, written pixel by pixel (never held whole): a dim
/// sky gradient with a small sun of `sun` at 30° elevation.
pub fn write_equirect(path: &Path, width: usize, sun: f32) {
    use exr::prelude::*;
    let h = width / 2;
    let channels = SpecificChannels::rgb(move |p: Vec2<usize>| {
        let (x, y) = (p.x() as f32 / width as f32, p.y() as f32 / h as f32);
        // Texel noise, so that the file compresses no better than a photograph.
        let n = ((p.x() as u32).wrapping_mul(0x9E37_79B9) ^ (p.y() as u32).wrapping_mul(0x85EB_CA6B)).rotate_left(13).wrapping_mul(0xC2B2_AE35);
        let sky = (0.2 + 0.8 * (1.0 - y)) * (0.75 + 0.5 * (n >> 8) as f32 / (1u32 << 24) as f32);
        let (dx, dy) = (x - 0.3, y - 1.0 / 3.0);
        let v = if dx * dx + dy * dy < 1e-5 { sun } else { sky };
        (f16::from_f32(v * 0.6), f16::from_f32(v * 0.8), f16::from_f32(v))
    });
    let layer = Layer::new((width, h), LayerAttributes::default(), Encoding::FAST_LOSSLESS, channels);
    Image::from_layer(layer).write().to_file(path).unwrap();
}

