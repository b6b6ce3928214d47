//! KTX 2.0 writer for float cube maps with mips (Khronos, "KTX File Format Specification",
//! version 2.0, §3–§4), no supercompression.
//!
//! Layout: identifier, header, index, level index (the `ktx2` crate's `Header` and
//! `LevelIndex`), data format descriptor (the `ktx2` crate's basic DFD block for the
//! format: RGBSDA model, BT.709 primaries, linear transfer, one FLOAT | SIGNED sample per
//! channel), key/value data (`KTXwriter`, `KTXorientation`), then the levels from the
//! smallest to the largest, each aligned to `lcm(texel size, 4)`.
//! Faces inside a level are in the order +X, −X, +Y, −Y, +Z, −Z, rows top to bottom.
//!
//! **Half-float overflow rule**: `RGBA16F` holds finite values up to 65504. Larger values
//! are clamped to 65504 and counted; nothing becomes infinity. [`Format::Auto`] picks
//! `RGBA16F` unless some value exceeds 65504, then `RGBA32F`.

use crate::error::Result;
use crate::files::write_atomic;
use crate::texture::Cube;
use splitsum_shaders::half::f32_to_f16_bits;
use std::io::Write;
use std::path::Path;

/// `VK_FORMAT_R16G16B16A16_SFLOAT`.
pub const VK_FORMAT_R16G16B16A16_SFLOAT: u32 = 97;
/// `VK_FORMAT_R32G32B32A32_SFLOAT`.
pub const VK_FORMAT_R32G32B32A32_SFLOAT: u32 = 109;
pub use splitsum_shaders::half::HALF_MAX;

/// Texel format of a written cube.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Format {
    /// RGBA16F, or RGBA32F when a value exceeds the half-float range.
    Auto,
    /// Half floats; values above 65504 are clamped (and counted).
    Rgba16f,
    /// Single floats.
    Rgba32f,
}

splitsum_shaders::choice!(Format: Auto => "auto", Rgba16f => "rgba16f", Rgba32f => "rgba32f");

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

/// The data format descriptor of `format` (`dfdTotalSize`, then the basic block the
/// `ktx2` crate builds from the format's description, as libktx's `createDFDUnpacked`
/// does), and the header's `typeSize`.
fn dfd(format: ::ktx2::Format) -> (Vec<u8>, u32) {
    let (basic, type_size) = ::ktx2::dfd::Basic::from_format(format).expect("RGBA float formats have a descriptor");
    let block = ::ktx2::dfd::Block::Basic(basic).to_vec();
    let mut d = (4 + block.len() as u32).to_le_bytes().to_vec();
    d.extend_from_slice(&block);
    (d, type_size)
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
    let (kformat, bytes) = match format {
        Format::Rgba32f => (::ktx2::Format::R32G32B32A32_SFLOAT, 4u32),
        _ => (::ktx2::Format::R16G16B16A16_SFLOAT, 2u32),
    };
    let vk_format = kformat.value();
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
                    p.extend_from_slice(&(f32_to_f16_bits(c) as u16).to_le_bytes());
                }
            }
        }
        payloads.push(p);
    }

    let level_index_len = ::ktx2::LevelIndex::LENGTH * levels;
    let (dfd_bytes, type_size) = dfd(kformat);
    let dfd_offset = ::ktx2::Header::LENGTH + level_index_len;
    let mut kvd = kv("KTXorientation", "rd");
    kvd.extend(kv("KTXwriter", concat!("splitsum ", env!("CARGO_PKG_VERSION"))));
    let kvd_offset = dfd_offset + dfd_bytes.len();
    let mut data_start = round_up(kvd_offset + kvd.len(), align);

    // Levels are stored smallest first; the level index lists level 0 first.
    let mut offsets = vec![0usize; levels];
    for level in (0..levels).rev() {
        offsets[level] = data_start;
        data_start = round_up(data_start + payloads[level].len(), align);
    }

    let header = ::ktx2::Header {
        format: Some(kformat),
        type_size,
        pixel_width: layout.size,
        pixel_height: layout.size,
        pixel_depth: 0,
        layer_count: 0,
        face_count: 6,
        level_count: layout.levels,
        supercompression_scheme: None,
        index: ::ktx2::Index {
            dfd_byte_offset: dfd_offset as u32,
            dfd_byte_length: dfd_bytes.len() as u32,
            kvd_byte_offset: kvd_offset as u32,
            kvd_byte_length: kvd.len() as u32,
            sgd_byte_offset: 0,
            sgd_byte_length: 0,
        },
    };
    let mut out = header.as_bytes().to_vec();
    for level in 0..levels {
        let len = payloads[level].len() as u64;
        out.extend_from_slice(&::ktx2::LevelIndex { byte_offset: offsets[level] as u64, byte_length: len, uncompressed_byte_length: len }.as_bytes());
    }
    out.extend_from_slice(&dfd_bytes);
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
