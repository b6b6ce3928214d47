//! KTX 2.0 writer for float cube maps with mips (Khronos, "KTX File Format Specification",
//! version 2.0, §3–§4), and 2D tables; optionally Zstandard-supercompressed.
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
//! `RGBA16F` unless some value exceeds 65504, then `RGBA32F`. `RGB9E5` (opt-in: half the
//! size, but each channel keeps only 9 bits below the brightest of the three, so a
//! saturated colour's dim channels lose most of theirs) clamps at 65408 the same way.

use crate::error::Result;
use crate::files::write_atomic;
pub use crate::texture::Format;
use crate::texture::{Cube, Lut, max_value};
use splitsum_shaders::half::{f32_to_f16_bits, pack_rgb9e5};
use std::io::Write;
use std::path::Path;

/// `VK_FORMAT_R16G16B16A16_SFLOAT`.
pub const VK_FORMAT_R16G16B16A16_SFLOAT: u32 = 97;
/// `VK_FORMAT_R32G32B32A32_SFLOAT`.
pub const VK_FORMAT_R32G32B32A32_SFLOAT: u32 = 109;
/// `VK_FORMAT_E5B9G9R9_UFLOAT_PACK32`.
pub const VK_FORMAT_E5B9G9R9_UFLOAT_PACK32: u32 = 123;
/// `VK_FORMAT_B10G11R11_UFLOAT_PACK32`: the texel of GL's `R11F_G11F_B10F`, which the
/// KTX 1.1 files (`crate::ktx1`) hold.
pub const VK_FORMAT_B10G11R11_UFLOAT_PACK32: u32 = 122;
pub use splitsum_shaders::half::{HALF_MAX, RGB9E5_MAX};


/// What writing a cube did to its values (KTX2, and KTX 1.1 by its Vulkan twin format).
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct Written {
    /// The format used.
    pub vk_format: u32,
    /// Channel values clamped to the format's largest value.
    pub clamped: u64,
    /// The largest value in the cube.
    pub max_value: f32,
}

fn round_up(x: usize, to: usize) -> usize {
    x.div_ceil(to) * to
}

/// The data format descriptor of `format` (`dfdTotalSize`, then the basic block the
/// `ktx2` crate builds from the format's description, as libktx's `createDFDUnpacked`
/// does), and the header's `typeSize`. A supercompressed file's descriptor has
/// `bytesPlane0 = 0` (§3.10.2: its levels are "unsized"), except for the packed
/// shared-exponent `E5B9G9R9`, whose texel size libktx cannot rebuild from its samples (it
/// refuses such a file, "Texture type not supported"); it keeps 4, as Bevy's own
/// `*_rgb9e5_zstd.ktx2` do.
fn dfd(format: ::ktx2::Format, supercompressed: bool) -> (Vec<u8>, u32) {
    let (mut basic, type_size) = ::ktx2::dfd::Basic::from_format(format).expect("float formats have a descriptor");
    if supercompressed && format != ::ktx2::Format::E5B9G9R9_UFLOAT_PACK32 {
        basic.bytes_planes[0] = 0;
    }
    let block = ::ktx2::dfd::Block::Basic(basic).to_vec();
    let mut d = (4 + block.len() as u32).to_le_bytes().to_vec();
    d.extend_from_slice(&block);
    (d, type_size)
}

/// One key/value entry (`keyAndValueByteSize`, `key\0value\0`, padded to 4 bytes): the
/// same in KTX2 (§3.11) and KTX 1.1.
pub(crate) fn kv(key: &str, value: &str) -> Vec<u8> {
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

/// Zstandard supercompression of every level (KTX 2.0 §3.12.2, scheme 2), as Bevy's
/// loader and its own environment maps use; libktx inflates it on load.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Supercompression {
    /// Levels stored as they are.
    None,
    /// Each level one Zstandard frame (`ruzstd`, its fastest level, about zstd's level 1).
    Zstd,
}

/// Encodes `cube` as a KTX2 cube map in `format` (see the module's overflow rule).
pub fn encode(cube: &Cube, format: Format) -> (Vec<u8>, Written) {
    encode_with(cube, format, Supercompression::None)
}

/// Encodes `cube` as a KTX2 cube map in `format`, supercompressed by `sc`.
pub fn encode_with(cube: &Cube, format: Format, sc: Supercompression) -> (Vec<u8>, Written) {
    let format = format.resolve(cube);
    let kformat = match format {
        Format::Rgba32f => ::ktx2::Format::R32G32B32A32_SFLOAT,
        Format::Rgb9e5 => ::ktx2::Format::E5B9G9R9_UFLOAT_PACK32,
        _ => ::ktx2::Format::R16G16B16A16_SFLOAT,
    };
    let mut written = Written { vk_format: kformat.value(), clamped: 0, max_value: max_value(cube) };
    let payloads: Vec<Vec<u8>> = (0..cube.layout.levels)
        .map(|level| {
            let mut p = Vec::new();
            for t in cube.level(level) {
                if format == Format::Rgb9e5 {
                    written.clamped += [t.x, t.y, t.z].iter().filter(|&&v| v > RGB9E5_MAX).count() as u64;
                    p.extend_from_slice(&pack_rgb9e5(t.x, t.y, t.z).to_le_bytes());
                    continue;
                }
                for v in [t.x, t.y, t.z, t.w] {
                    if format == Format::Rgba32f {
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
            p
        })
        .collect();
    (container(kformat, cube.layout.size, 6, payloads, sc), written)
}

/// Encodes the BRDF table as a 2D KTX2 `R16G16_SFLOAT` texture: red `A`, green `B`, `x`
/// = n·v, rows top to bottom = roughness from 0 (Bevy's `dfg.ktx2` layout).
pub fn encode_table(lut: &Lut, sc: Supercompression) -> Vec<u8> {
    let mut p = Vec::with_capacity(lut.texels.len() * 4);
    for t in &lut.texels {
        for v in [t.x, t.y] {
            p.extend_from_slice(&(f32_to_f16_bits(v) as u16).to_le_bytes());
        }
    }
    container(::ktx2::Format::R16G16_SFLOAT, lut.size, 1, vec![p], sc)
}

/// The KTX2 file of square `size`² images in `kformat`, `faces` (6: a cube; 1: 2D) per
/// level, `payloads[level]` holding each level's faces in order.
fn container(kformat: ::ktx2::Format, size: u32, faces: u32, payloads: Vec<Vec<u8>>, sc: Supercompression) -> Vec<u8> {
    let levels = payloads.len();
    let (dfd_bytes, type_size) = dfd(kformat, sc != Supercompression::None);
    // Unsupercompressed levels align to lcm(texel size, 4) (§3.9.7); supercompressed ones
    // need none (and their descriptor says "unsized", see `dfd`).
    let texel_bytes = payloads[0].len() / (faces as usize * size as usize * size as usize);
    let raw_lengths: Vec<usize> = payloads.iter().map(Vec::len).collect();
    let (align, stored): (usize, Vec<Vec<u8>>) = match sc {
        Supercompression::None => (if texel_bytes.is_multiple_of(4) { texel_bytes } else { texel_bytes * 4 }, payloads),
        Supercompression::Zstd => {
            (1, payloads.iter().map(|p| ruzstd::encoding::compress_to_vec(p.as_slice(), ruzstd::encoding::CompressionLevel::Fastest)).collect())
        }
    };
    let level_index_len = ::ktx2::LevelIndex::LENGTH * levels;
    let dfd_offset = ::ktx2::Header::LENGTH + level_index_len;
    let mut kvd = kv("KTXorientation", "rd");
    kvd.extend(kv("KTXwriter", concat!("splitsum ", env!("CARGO_PKG_VERSION"))));
    let kvd_offset = dfd_offset + dfd_bytes.len();
    let mut data_start = round_up(kvd_offset + kvd.len(), align);

    // Levels are stored smallest first; the level index lists level 0 first.
    let mut offsets = vec![0usize; levels];
    for level in (0..levels).rev() {
        offsets[level] = data_start;
        data_start = round_up(data_start + stored[level].len(), align);
    }

    let header = ::ktx2::Header {
        format: Some(kformat),
        type_size,
        pixel_width: size,
        pixel_height: size,
        pixel_depth: 0,
        layer_count: 0,
        face_count: faces,
        level_count: levels as u32,
        supercompression_scheme: match sc {
            Supercompression::None => None,
            Supercompression::Zstd => Some(::ktx2::SupercompressionScheme::Zstandard),
        },
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
        let index = ::ktx2::LevelIndex {
            byte_offset: offsets[level] as u64,
            byte_length: stored[level].len() as u64,
            uncompressed_byte_length: raw_lengths[level] as u64,
        };
        out.extend_from_slice(&index.as_bytes());
    }
    out.extend_from_slice(&dfd_bytes);
    out.extend_from_slice(&kvd);
    for level in (0..levels).rev() {
        out.resize(offsets[level], 0);
        out.extend_from_slice(&stored[level]);
    }
    out
}

/// Writes `cube` to `path` as KTX2 (atomically).
pub fn write(path: &Path, cube: &Cube, format: Format) -> Result<Written> {
    let (bytes, written) = encode_with(cube, format, Supercompression::None);
    write_atomic(path, |w| w.write_all(&bytes))?;
    Ok(written)
}
