//! OpenEXR files: the header read and checked before any pixel is decoded, then the
//! pixels streamed into a [`Reducer`] (every compression the `exr` crate decodes).

use super::*;
use crate::error::{Error, Result};
use crate::texture::Equirect;
use std::path::Path;

/// The channels an environment is read from: `R`, `G`, `B` (matched by the last part of
/// their names, so `diffuse.R` counts), or a luminance `Y` (or `L`) read as grey.
enum ExrChannels {
    Rgb([exr::meta::attribute::Text; 3]),
    Grey(exr::meta::attribute::Text),
}

/// What splitsum needs of an OpenEXR header.
pub(super) struct ExrHeader {
    pub(super) size: (u32, u32),
    channels: ExrChannels,
}

/// The data window `(x_min, y_min, x_max, y_max)` of the first header, read from its bytes:
/// the `exr` crate swaps an inverted window's corners without a word, which would read
/// another image than the file describes. `None` where the header cannot be walked (the
/// `exr` crate then says why).
fn exr_raw_data_window(r: &mut impl std::io::BufRead) -> Option<[i32; 4]> {
    use std::io::Read;
    let mut head = [0u8; 8];
    r.read_exact(&mut head).ok()?;
    let text = |r: &mut dyn std::io::BufRead| -> Option<Vec<u8>> {
        let mut v = Vec::new();
        std::io::BufRead::read_until(&mut r.take(256), 0, &mut v).ok()?;
        (v.pop() == Some(0)).then_some(v)
    };
    loop {
        let name = text(r)?;
        if name.is_empty() {
            return None;
        }
        let _type = text(r)?;
        let mut size = [0u8; 4];
        r.read_exact(&mut size).ok()?;
        let size = i32::from_le_bytes(size);
        if name == b"dataWindow" && size == 16 {
            let mut v = [0u8; 16];
            r.read_exact(&mut v).ok()?;
            return Some(std::array::from_fn(|k| i32::from_le_bytes(v[4 * k..4 * k + 4].try_into().expect("4 bytes"))));
        }
        if size < 0 || std::io::copy(&mut r.take(size as u64), &mut std::io::sink()).ok()? != size as u64 {
            return None;
        }
    }
}

/// The first OpenEXR header of `reader` (a file of `len` bytes) that holds an image
/// splitsum reads, checked before anything is allocated for its pixels: a flat (not deep)
/// image with R, G, B or Y channels at full resolution, a data window that is not inverted,
/// and no more blocks than the file can hold (each takes at least 16 bytes: its entry in
/// the offset table and its own header).
pub(super) fn exr_header<R: std::io::BufRead + std::io::Seek>(path: &Path, reader: &mut R, len: u64) -> Result<ExrHeader> {
    let malformed = |why: String| Error::file(path, format!("malformed OpenEXR: {why}"));
    if let Some([x0, y0, x1, y1]) = exr_raw_data_window(reader)
        && (x1 < x0 || y1 < y0)
    {
        return Err(malformed(format!("its data window is inverted (from ({x0}, {y0}) to ({x1}, {y1}))")));
    }
    reader.seek(std::io::SeekFrom::Start(0)).map_err(|e| Error::file_caused(path, "cannot read", e))?;
    let meta = exr::meta::MetaData::read_from_buffered(reader, false).map_err(|e| exr_error(path, e))?;
    let header = meta.headers.iter().find(|h| !h.deep && exr_channels(h).is_some()).ok_or_else(|| {
        let names: Vec<String> = meta.headers.iter().flat_map(|h| h.channels.list.iter().map(|c| c.name.to_string())).collect();
        if meta.headers.iter().all(|h| h.deep) {
            malformed("only deep data, which is not an image".into())
        } else {
            Error::file(path, format!("has no R, G, B (or Y) channels, only {names:?}"))
        }
    })?;
    let size = header.layer_size;
    let (w, h) = (size.width().min(u32::MAX as usize) as u32, size.height().min(u32::MAX as usize) as u32);
    check_side(path, w, h)?;
    if header.channels.list.iter().any(|c| c.sampling != exr::math::Vec2(1, 1)) {
        return Err(Error::file(path, "has subsampled channels, which are not supported"));
    }
    let chunks: u64 = meta.headers.iter().map(|h| h.chunk_count as u64).sum();
    if chunks.saturating_mul(16) > len {
        return Err(Error::file(
            path,
            format!(
                "truncated OpenEXR: its header promises {w}×{h} pixels in {chunks} blocks, which take at least {} bytes, but the file has {len}",
                chunks * 16
            ),
        ));
    }
    Ok(ExrHeader { size: (w, h), channels: exr_channels(header).expect("found above") })
}

/// The channels of `header` splitsum reads (see [`ExrChannels`]).
fn exr_channels(header: &exr::meta::header::Header) -> Option<ExrChannels> {
    let find = |names: &[&str]| {
        header.channels.list.iter().find(|c| {
            let n = c.name.to_string();
            let base = n.rsplit('.').next().unwrap_or(&n).to_string();
            names.iter().any(|x| base.eq_ignore_ascii_case(x))
        })
    };
    match (find(&["R", "red"]), find(&["G", "green"]), find(&["B", "blue"])) {
        (Some(r), Some(g), Some(b)) => Some(ExrChannels::Rgb([r.name.clone(), g.name.clone(), b.name.clone()])),
        _ => find(&["Y", "L"]).map(|y| ExrChannels::Grey(y.name.clone())),
    }
}

/// An `exr` crate error in the user's terms.
fn exr_error(path: &Path, e: exr::error::Error) -> Error {
    match e {
        exr::error::Error::Io(io) if io.kind() == std::io::ErrorKind::UnexpectedEof => {
            Error::file(path, "truncated OpenEXR: the file ends before its last block")
        }
        exr::error::Error::Io(io) => Error::file(path, format!("cannot read: {io}")),
        exr::error::Error::NotSupported(what) => Error::file(path, format!("an OpenEXR feature the exr crate does not read: {what}")),
        // The offset table points past the end: the file was cut short.
        exr::error::Error::Invalid(what) if what.contains("missing bytes") => {
            Error::file(path, format!("truncated OpenEXR: a block lies past the end of the file ({what})"))
        }
        exr::error::Error::Invalid(what) => Error::file(path, format!("malformed OpenEXR: {what}")),
        exr::error::Error::Aborted => Error::file(path, "reading the OpenEXR was aborted"),
    }
}

/// An OpenEXR file's R, G, B (or Y) channels, streamed block by block into a [`Reducer`]:
/// whatever the file, only the reduced image and a few rows of sums are held.
pub(super) fn read_exr<R: std::io::BufRead + std::io::Seek>(
    path: &Path,
    mut reader: R,
    len: u64,
    weights: Weights,
    sanitize: bool,
    factor: u32,
) -> Result<(Equirect, InputReport)> {
    use exr::prelude::{ReadChannels, ReadLayers, ReadSpecificChannel};
    let header = exr_header(path, &mut reader, len)?;
    reader.seek(std::io::SeekFrom::Start(0)).map_err(|e| Error::file_caused(path, "cannot read", e))?;
    let (w, h) = header.size;
    let new = |size: exr::math::Vec2<usize>| (size.width() == w as usize && size.height() == h as usize).then(|| Reducer::new(w, h, factor, weights, sanitize));
    let pixels = match header.channels {
        ExrChannels::Rgb([r, g, b]) => exr::prelude::read()
            .no_deep_data()
            .largest_resolution_level()
            .specific_channels()
            .required(r)
            .required(g)
            .required(b)
            .collect_pixels(
                |size: exr::math::Vec2<usize>, _: &_| new(size),
                |red: &mut Option<Reducer>, pos: exr::math::Vec2<usize>, (r, g, b): (f32, f32, f32)| {
                    if let Some(red) = red {
                        red.push(pos.x() as u32, pos.y() as u32, [r, g, b]);
                    }
                },
            )
            .first_valid_layer()
            .all_attributes()
            .from_buffered(reader)
            .map(|image| image.layer_data.channel_data.pixels),
        ExrChannels::Grey(y) => exr::prelude::read()
            .no_deep_data()
            .largest_resolution_level()
            .specific_channels()
            .required(y)
            .collect_pixels(
                |size: exr::math::Vec2<usize>, _: &_| new(size),
                |red: &mut Option<Reducer>, pos: exr::math::Vec2<usize>, (y,): (f32,)| {
                    if let Some(red) = red {
                        red.push(pos.x() as u32, pos.y() as u32, [y, y, y]);
                    }
                },
            )
            .first_valid_layer()
            .all_attributes()
            .from_buffered(reader)
            .map(|image| image.layer_data.channel_data.pixels),
    };
    match pixels.map_err(|e| exr_error(path, e))? {
        Some(reducer) => reducer.finish(path),
        None => Err(Error::file(path, "malformed OpenEXR: its layers disagree about the image's size")),
    }
}
