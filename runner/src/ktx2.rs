//! KTX 2.0 writer for float cube maps with mips (Khronos, "KTX File Format Specification",
//! version 2.0, §3–§4), no supercompression.
//!
//! Layout: identifier, header, index, level index, data format descriptor (a basic DFD
//! block built as libktx's `createDFDUnpacked` does for `*_SFLOAT` formats: RGBSDA model,
//! BT.709 primaries, linear transfer, one sample per channel with the FLOAT and SIGNED
//! qualifiers and bounds −1.0…1.0), key/value data (`KTXwriter`, `KTXorientation`), then
//! the levels from the smallest to the largest, each aligned to `lcm(texel size, 4)`.
//! Faces inside a level are in the order +X, −X, +Y, −Y, +Z, −Z, rows top to bottom.
//!
//! **Half-float overflow rule**: `RGBA16F` holds finite values up to 65504. Larger values
//! are clamped to 65504 and counted; nothing becomes infinity. [`Format::Auto`] picks
//! `RGBA16F` unless some value exceeds 65504, then `RGBA32F`.

use crate::error::Result;
use crate::files::write_atomic;
use crate::texture::Cube;
use half::f16;
use std::io::Write;
use std::path::Path;

/// `VK_FORMAT_R16G16B16A16_SFLOAT`.
pub const VK_FORMAT_R16G16B16A16_SFLOAT: u32 = 97;
/// `VK_FORMAT_R32G32B32A32_SFLOAT`.
pub const VK_FORMAT_R32G32B32A32_SFLOAT: u32 = 109;
/// The largest finite half float.
pub const HALF_MAX: f32 = 65504.0;

/// Texel format of a written cube.
#[derive(Copy, Clone, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Format {
    /// RGBA16F, or RGBA32F when a value exceeds the half-float range.
    Auto,
    /// Half floats; values above 65504 are clamped (and counted).
    Rgba16f,
    /// Single floats.
    Rgba32f,
}

/// What writing a cube did to its values.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct Written {
    /// The format used.
    pub vk_format: u32,
    /// Channel values clamped to 65504.
    pub clamped: u64,
    /// The largest value in the cube.
    pub max_value: f32,
}

impl Format {
    /// The format that writing `cube` with `self` uses.
    pub fn resolve(self, cube: &Cube) -> Format {
        match self {
            Format::Auto if max_value(cube) > HALF_MAX => Format::Rgba32f,
            Format::Auto => Format::Rgba16f,
            f => f,
        }
    }
}

fn max_value(cube: &Cube) -> f32 {
    cube.texels.iter().map(|t| t.x.max(t.y).max(t.z).max(t.w)).fold(0.0, f32::max)
}

fn round_up(x: usize, to: usize) -> usize {
    x.div_ceil(to) * to
}

/// The basic data format descriptor of an RGBA float format with `bytes` per channel.
fn dfd(bytes: u32) -> Vec<u32> {
    let samples = 4u32;
    let block_size = 24 + 16 * samples;
    let mut d = vec![
        4 + block_size,           // dfdTotalSize
        0,                        // vendorId = Khronos (0), descriptorType = basic (0)
        2 | (block_size << 16),   // versionNumber = 2 (KDF 1.3), descriptorBlockSize
        1 | (1 << 8) | (1 << 16), // model RGBSDA, primaries BT709, transfer linear, flags straight alpha
        0,                        // texel block dimensions 1×1×1×1
        4 * bytes,                // bytesPlane0
        0,                        // bytesPlane4..7
    ];
    let bits = 8 * bytes;
    for (i, channel) in [0u32, 1, 2, 15].iter().enumerate() {
        let qualifiers = 0x80 | 0x40; // FLOAT | SIGNED
        d.push((i as u32 * bits) | ((bits - 1) << 16) | ((channel | qualifiers) << 24));
        d.push(0); // sample position
        d.push((-1.0f32).to_bits()); // sampleLower
        d.push(1.0f32.to_bits()); // sampleUpper
    }
    d
}

fn kv(key: &str, value: &str) -> Vec<u8> {
    let mut entry = Vec::new();
    let len = key.len() + 1 + value.len() + 1;
    entry.extend_from_slice(&(len as u32).to_le_bytes());
    entry.extend_from_slice(key.as_bytes());
    entry.push(0);
    entry.extend_from_slice(value.as_bytes());
    entry.push(0);
    while entry.len() % 4 != 0 {
        entry.push(0);
    }
    entry
}

/// Encodes `cube` as a KTX2 cube map in `format` (see the module's overflow rule).
pub fn encode(cube: &Cube, format: Format) -> (Vec<u8>, Written) {
    let format = format.resolve(cube);
    let (vk_format, bytes) = match format {
        Format::Rgba32f => (VK_FORMAT_R32G32B32A32_SFLOAT, 4u32),
        _ => (VK_FORMAT_R16G16B16A16_SFLOAT, 2u32),
    };
    let mut written = Written { vk_format, clamped: 0, max_value: max_value(cube) };
    let layout = cube.layout;
    let levels = layout.levels as usize;
    let texel_bytes = 4 * bytes as usize;
    let align = if texel_bytes % 4 == 0 { texel_bytes } else { texel_bytes * 4 };

    // Level payloads.
    let mut payloads: Vec<Vec<u8>> = Vec::with_capacity(levels);
    for level in 0..layout.levels {
        let mut p = Vec::new();
        for t in cube.level(level) {
            for v in [t.x, t.y, t.z, t.w] {
                if bytes == 4 {
                    p.extend_from_slice(&v.to_le_bytes());
                } else {
                    let c = if v > HALF_MAX {
                        written.clamped += 1;
                        HALF_MAX
                    } else {
                        v
                    };
                    p.extend_from_slice(&f16::from_f32(c).to_le_bytes());
                }
            }
        }
        payloads.push(p);
    }

    let header_len = 12 + 13 * 4 + 2 * 8;
    let level_index_len = 24 * levels;
    let dfd_words = dfd(bytes);
    let dfd_offset = header_len + level_index_len;
    let dfd_len = dfd_words.len() * 4;
    let mut kvd = kv("KTXorientation", "rd");
    kvd.extend(kv("KTXwriter", concat!("splitsum ", env!("CARGO_PKG_VERSION"))));
    let kvd_offset = dfd_offset + dfd_len;
    let mut data_start = round_up(kvd_offset + kvd.len(), align);

    // Levels are stored smallest first; the level index lists level 0 first.
    let mut offsets = vec![0usize; levels];
    for level in (0..levels).rev() {
        offsets[level] = data_start;
        data_start = round_up(data_start + payloads[level].len(), align);
    }

    let mut out = Vec::new();
    out.extend_from_slice(&[0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A]);
    for w in [vk_format, bytes, layout.size, layout.size, 0, 0, 6, layout.levels, 0] {
        out.extend_from_slice(&w.to_le_bytes());
    }
    for w in [dfd_offset as u32, dfd_len as u32, kvd_offset as u32, kvd.len() as u32] {
        out.extend_from_slice(&w.to_le_bytes());
    }
    out.extend_from_slice(&0u64.to_le_bytes()); // sgdByteOffset
    out.extend_from_slice(&0u64.to_le_bytes()); // sgdByteLength
    for level in 0..levels {
        let len = payloads[level].len() as u64;
        out.extend_from_slice(&(offsets[level] as u64).to_le_bytes());
        out.extend_from_slice(&len.to_le_bytes());
        out.extend_from_slice(&len.to_le_bytes());
    }
    for w in &dfd_words {
        out.extend_from_slice(&w.to_le_bytes());
    }
    out.extend_from_slice(&kvd);
    for level in (0..levels).rev() {
        out.resize(offsets[level], 0);
        out.extend_from_slice(&payloads[level]);
    }
    (out, written)
}

/// Writes `cube` to `path` as KTX2 (atomically).
pub fn write(path: &Path, cube: &Cube, format: Format) -> Result<Written> {
    let (bytes, written) = encode(cube, format);
    write_atomic(path, |w| w.write_all(&bytes))?;
    Ok(written)
}
