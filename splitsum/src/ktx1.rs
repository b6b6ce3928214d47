//! KTX 1.1 cube maps as Filament loads them (Khronos, "KTX File Format Specification"
//! 1.1; Filament `libs/ktxreader/src/Ktx1Reader.cpp`): cmgen's `_ibl.ktx` and
//! `_skybox.ktx`.
//!
//! Layout: the 12-byte identifier, thirteen `u32` header fields, key/value pairs (each
//! `keyAndValueByteSize`, `key\0value\0`, padded to 4 bytes), then per level its
//! `imageSize` (one face, for a cube) and the six faces +X, −X, +Y, −Y, +Z, −Z, rows top to
//! bottom. Texels are `R11F_G11F_B10F` (`half::pack_r11g11b10f`: 4 bytes, no padding).
//!
//! The header carries what cmgen writes: `glType` and `glInternalFormat`
//! `GL_R11F_G11F_B10F`, `glTypeSize` 1, `glFormat` and `glBaseInternalFormat` `GL_RGB`.
//! Filament's `toPixelDataType` maps only that `glType` (not the standard
//! `GL_UNSIGNED_INT_10F_11F_11F_REV`) to `UINT_10F_11F_11F_REV`.
//!
//! **Overflow rule**: the format's largest value is 65024 (`half::UFLOAT11_MAX`; blue
//! 64512, `half::UFLOAT10_MAX`); larger values are written as that value and counted (in
//! `ktx2::Written`, as `VK_FORMAT_B10G11R11_UFLOAT_PACK32`, the same texel), negative
//! values as 0.

use crate::ktx2::{VK_FORMAT_B10G11R11_UFLOAT_PACK32, Written};
use crate::texture::Cube;
use splitsum_shaders::half::{UFLOAT10_MAX, UFLOAT11_MAX, pack_r11g11b10f};

/// The KTX 1.1 identifier.
pub const IDENTIFIER: [u8; 12] = [0xAB, 0x4B, 0x54, 0x58, 0x20, 0x31, 0x31, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A];
/// `GL_R11F_G11F_B10F`.
pub const GL_R11F_G11F_B10F: u32 = 0x8C3A;
/// `GL_RGB`.
pub const GL_RGB: u32 = 0x1907;

/// Encodes `cube` (every level) as a KTX 1.1 `R11F_G11F_B10F` cube map with `metadata`
/// key/value pairs.
pub fn encode(cube: &Cube, metadata: &[(&str, &str)]) -> (Vec<u8>, Written) {
    let layout = cube.layout;
    let mut written = Written { vk_format: VK_FORMAT_B10G11R11_UFLOAT_PACK32, clamped: 0, max_value: 0.0 };
    let kvd: Vec<u8> = metadata.iter().flat_map(|(key, value)| crate::ktx2::kv(key, value)).collect();
    let header = [0x0403_0201, GL_R11F_G11F_B10F, 1, GL_RGB, GL_R11F_G11F_B10F, GL_RGB, layout.size, layout.size, 0, 0, 6, layout.levels, kvd.len() as u32];
    let mut out = IDENTIFIER.to_vec();
    for v in header {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out.extend_from_slice(&kvd);
    for level in 0..layout.levels {
        let s = layout.level_size(level);
        out.extend_from_slice(&(4 * s * s).to_le_bytes());
        for t in cube.level(level) {
            for (v, max) in [(t.x, UFLOAT11_MAX), (t.y, UFLOAT11_MAX), (t.z, UFLOAT10_MAX)] {
                written.max_value = written.max_value.max(v);
                written.clamped += (v > max) as u64;
            }
            out.extend_from_slice(&pack_r11g11b10f(t.x, t.y, t.z).to_le_bytes());
        }
    }
    (out, written)
}

