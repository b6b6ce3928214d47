//! Writing outputs safely, and the plain image formats: every file is written to a
//! temporary sibling and renamed into place, so an existing output is never left
//! half-written and a failed run loses nothing already there.

use crate::error::{Error, Result};
use crate::texture::Lut;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// Checks, before any work, that `path` can be created: its folder exists and is a folder.
pub fn check_writable(path: &Path) -> Result<()> {
    let dir = parent_dir(path);
    match std::fs::metadata(&dir) {
        Ok(m) if m.is_dir() => {}
        Ok(_) => return Err(Error::file(path, format!("{} is not a folder", dir.display()))),
        Err(e) => return Err(Error::file(path, format!("cannot write here: folder {}: {e}", dir.display()))),
    }
    if path.is_dir() {
        return Err(Error::file(path, "is a folder, not a file"));
    }
    // Probe with a temporary file: permissions and read-only file systems show up now,
    // not after a long bake.
    let probe = temp_path(path);
    File::create(&probe).map_err(|e| Error::file(path, format!("cannot write here: {e}")))?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

fn parent_dir(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

fn temp_path(path: &Path) -> PathBuf {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    parent_dir(path).join(format!(".{name}.{}.tmp", std::process::id()))
}

/// Writes `path` through `write` into a temporary sibling, then renames it into place.
pub fn write_atomic(path: &Path, write: impl FnOnce(&mut BufWriter<File>) -> std::io::Result<()>) -> Result<()> {
    let tmp = temp_path(path);
    let result = (|| {
        let mut w = BufWriter::new(File::create(&tmp)?);
        write(&mut w)?;
        w.flush()?;
        w.into_inner().map_err(|e| e.into_error())?.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    result.map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        Error::file(path, format!("could not write: {e}"))
    })
}

/// Writes the BRDF table as a two-channel (R = scale, G = bias) 32-bit float OpenEXR.
pub fn write_lut_exr(path: &Path, lut: &Lut) -> Result<()> {
    use exr::prelude::*;
    let size = lut.size as usize;
    let pixels = SpecificChannels::build().with_channel("R").with_channel("G").with_pixel_fn(|pos: Vec2<usize>| {
        let t = lut.texels[pos.y() * size + pos.x()];
        (t.x, t.y)
    });
    let image = Image::from_channels((size, size), pixels);
    let mut buf = std::io::Cursor::new(Vec::new());
    image.write().to_buffered(&mut buf).map_err(|e| crate::error::Error::file(path, format!("could not encode: {e}")))?;
    write_atomic(path, |w| w.write_all(buf.get_ref()))
}

/// Writes an 8-bit RGB PNG from row-major `rgb` (values already in [0, 255]).
pub fn write_png(path: &Path, width: u32, height: u32, rgb: &[u8]) -> Result<()> {
    let img = image::RgbImage::from_raw(width, height, rgb.to_vec()).ok_or_else(|| Error::file(path, "image buffer has the wrong size"))?;
    write_atomic(path, |w| {
        let mut buf = std::io::Cursor::new(Vec::new());
        img.write_to(&mut buf, image::ImageFormat::Png).map_err(std::io::Error::other)?;
        w.write_all(buf.get_ref())
    })
}

/// The BRDF table as an 8-bit preview: R = scale, G = bias, values in [0, 1] stored
/// linearly (it is data, not colour).
pub fn lut_preview(lut: &Lut) -> Vec<u8> {
    lut.texels.iter().flat_map(|t| [to_u8(t.x), to_u8(t.y), 0]).collect()
}

fn to_u8(v: f32) -> u8 {
    (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
}

/// Writes RGB float pixels (alpha dropped) as a 32-bit float OpenEXR with a comment.
pub fn write_rgb_exr(path: &Path, width: u32, height: u32, pixels: &[splitsum_shaders::glam::Vec4], comment: &str) -> Result<()> {
    use exr::prelude::*;
    let w = width as usize;
    let mut attributes = LayerAttributes::named("rgb");
    attributes.comments = Some(Text::from(comment));
    attributes.software_name = Some(Text::from("splitsum"));
    let layer = Layer::new(
        (w, height as usize),
        attributes,
        Encoding::SMALL_LOSSLESS,
        SpecificChannels::rgb(|pos: Vec2<usize>| {
            let t = pixels[pos.y() * w + pos.x()];
            (t.x, t.y, t.z)
        }),
    );
    let image = Image::from_layer(layer);
    let mut buf = std::io::Cursor::new(Vec::new());
    image.write().to_buffered(&mut buf).map_err(|e| crate::error::Error::file(path, format!("could not encode: {e}")))?;
    write_atomic(path, |w| w.write_all(buf.get_ref()))
}

/// Writes level `level` of `cube` as a vertical strip of its six faces (+X, −X, +Y, −Y,
/// +Z, −Z from the top, each in Vulkan/KTX2 orientation) to an OpenEXR file.
pub fn write_cube_level_exr(path: &Path, cube: &crate::texture::Cube, level: u32, what: &str) -> Result<()> {
    let s = cube.layout.level_size(level);
    write_rgb_exr(
        path,
        s,
        6 * s,
        cube.level(level),
        &format!("{what}; mip {level} of a cube map, faces +X -X +Y -Y +Z -Z from the top, Vulkan/KTX2 orientation"),
    )
}
