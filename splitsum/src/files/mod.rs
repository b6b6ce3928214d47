//! Writing outputs safely, and the plain image formats: every file is written to a
//! temporary sibling and renamed into place, so an existing output is never left
//! half-written and a failed run loses nothing already there; output folders are written
//! as a unit ([`OutputDir`]), and what splitsum removes from a folder it replaces is what
//! `manifest` checked, nothing else (`docs/SECURITY.md`).

use crate::error::{Error, Result};
use crate::texture::Lut;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// Checks, before any work, that `path` can be created: it is not a folder, and its folder
/// exists and takes files, or else the nearest folder above it that exists is a writable
/// folder (the missing ones are created when the file is written).
pub fn check_writable(path: &Path) -> Result<()> {
    if path.is_dir() {
        return Err(Error::file(path, "is a folder, not a file"));
    }
    let mut dir = parent_dir(path);
    while !dir.exists() {
        match dir.parent() {
            Some(p) if !p.as_os_str().is_empty() => dir = p.to_path_buf(),
            _ => dir = PathBuf::from("."),
        }
    }
    match std::fs::metadata(&dir) {
        Ok(m) if m.is_dir() => {}
        Ok(_) => return Err(Error::file(path, format!("cannot write here: {} is a file, not a folder", dir.display()))),
        Err(e) => return Err(Error::file_caused(path, format!("cannot write here: folder {}", dir.display()), e)),
    }
    // Probe with a temporary file of a name nobody has (created new, never opened if it
    // exists): permissions and read-only file systems show up now, not after a long bake.
    let (probe, _) = create_new_sibling(&dir.join(".splitsum-probe")).map_err(|e| Error::file_caused(path, "cannot write here", e))?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

/// Reads the regular file `path` as text of at most `max` bytes (a scene, a calibration):
/// a device, a pipe or a larger file is refused before it is read, so no input file can
/// make a reader hold more than `max`.
pub fn read_text(path: &Path, max: u64) -> Result<String> {
    use std::io::Read;
    let file = File::open(path).map_err(|e| Error::file_caused(path, "cannot read", e))?;
    let meta = file.metadata().map_err(|e| Error::file_caused(path, "cannot read", e))?;
    if !meta.is_file() {
        return Err(Error::file(path, "is not a regular file"));
    }
    if meta.len() > max {
        return Err(Error::file(path, format!("is {} bytes; a file of this kind has at most {max}", meta.len())));
    }
    let mut text = String::new();
    file.take(max).read_to_string(&mut text).map_err(|e| Error::file_caused(path, "cannot read", e))?;
    Ok(text)
}

/// The kind of a single-file output: what splitsum writes under a name, and the only kind
/// of existing file it replaces.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum FileKind {
    /// OpenEXR.
    Exr,
    /// PNG.
    Png,
    /// JPEG.
    Jpeg,
}

impl FileKind {
    /// The kind's name, as a message says it.
    pub fn name(self) -> &'static str {
        match self {
            FileKind::Exr => "OpenEXR",
            FileKind::Png => "PNG",
            FileKind::Jpeg => "JPEG",
        }
    }

    /// The file-name extensions of the kind (lower case).
    pub fn extensions(self) -> &'static [&'static str] {
        match self {
            FileKind::Exr => &["exr"],
            FileKind::Png => &["png"],
            FileKind::Jpeg => &["jpg", "jpeg"],
        }
    }

    /// The kind whose signature `head` (a file's first bytes) starts with.
    pub fn of_signature(head: &[u8]) -> Option<FileKind> {
        match head {
            [0x76, 0x2f, 0x31, 0x01, ..] => Some(FileKind::Exr),
            [0x89, b'P', b'N', b'G', ..] => Some(FileKind::Png),
            [0xFF, 0xD8, 0xFF, ..] => Some(FileKind::Jpeg),
            _ => None,
        }
    }

    /// The picture kind `path`'s extension names (PNG or JPEG); `called` is what the caller
    /// calls the path (a flag, a field), for the message.
    pub fn picture(path: &Path, called: &str) -> Result<FileKind> {
        let ext = path.extension().map(|e| e.to_string_lossy().to_lowercase()).unwrap_or_default();
        [FileKind::Png, FileKind::Jpeg]
            .into_iter()
            .find(|k| k.extensions().contains(&ext.as_str()))
            .ok_or_else(|| Error::Invalid(format!("{called} {}: name a .png or .jpg file (the format follows the extension)", path.display())))
    }

    /// The `image` crate's format of a picture kind.
    fn image_format(self) -> image::ImageFormat {
        match self {
            FileKind::Exr => image::ImageFormat::OpenExr,
            FileKind::Png => image::ImageFormat::Png,
            FileKind::Jpeg => image::ImageFormat::Jpeg,
        }
    }
}

/// Checks, before any work, that a file of `kind` may be written at `path` (`called`: what
/// the caller calls it, a flag or a field): its name has the kind's extension, it is not a
/// folder or a symbolic link, an existing file there is of the same kind (splitsum never
/// replaces a file of another kind), and its folder takes files ([`check_writable`]).
pub fn check_output_file(path: &Path, kind: FileKind, called: &str) -> Result<()> {
    let shown = path.display();
    let ext = path.extension().map(|e| e.to_string_lossy().to_lowercase()).unwrap_or_default();
    if !kind.extensions().contains(&ext.as_str()) && !path.is_dir() {
        return Err(Error::Invalid(format!("{called} {shown}: this file is written as {}; name it .{}", kind.name(), kind.extensions()[0])));
    }
    match std::fs::symlink_metadata(path) {
        Ok(m) if m.file_type().is_symlink() => {
            return Err(Error::Invalid(format!("{called} {shown} is a symbolic link; name the file itself (splitsum replaces a file, never a link)")));
        }
        Ok(m) if m.is_dir() => return Err(Error::Invalid(format!("{called} {shown} is a folder; name a .{} file", kind.extensions()[0]))),
        Ok(m) if !m.is_file() => return Err(Error::Invalid(format!("{called} {shown} exists and is not a regular file; name another file"))),
        Ok(_) => {
            let mut head = [0u8; 8];
            let n = std::fs::File::open(path).and_then(|mut f| std::io::Read::read(&mut f, &mut head)).map_err(|e| Error::file_caused(path, "cannot read the existing file", e))?;
            let found = FileKind::of_signature(&head[..n]);
            if found != Some(kind) {
                let what = found.map_or_else(|| "not".to_string(), |k| format!("an {} file, not", k.name()));
                return Err(Error::Invalid(format!(
                    "{called} {shown} exists and is {what} a {} file; splitsum replaces only a file of the kind it writes: move it away or name another file",
                    kind.name()
                )));
            }
        }
        Err(_) => {}
    }
    check_writable(path)
}

/// Creates a new file beside `base` named `base` plus a suffix no file there has yet (the
/// process id, then a counter), never opening an existing file.
fn create_new_sibling(base: &Path) -> std::io::Result<(PathBuf, File)> {
    let name = base.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    for k in 0..1000u32 {
        let p = parent_dir(base).join(format!("{name}.{}.{k}.tmp", std::process::id()));
        match std::fs::OpenOptions::new().write(true).create_new(true).open(&p) {
            Ok(f) => return Ok((p, f)),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(e),
        }
    }
    Err(std::io::Error::other("no free temporary file name"))
}

fn parent_dir(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// Writes `path` through `write` into a new temporary sibling, then renames it into place.
pub fn write_atomic(path: &Path, write: impl FnOnce(&mut BufWriter<File>) -> std::io::Result<()>) -> Result<()> {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let mut tmp = None;
    let result = (|| {
        // Every change to a folder's entries happens under the interrupt lock: an interrupt
        // that removes a staging folder holds it until the process exits, so nothing is
        // created or renamed in it behind the removal (which would leave it behind).
        let file = {
            let _interrupt = PENDING.lock().unwrap_or_else(|e| e.into_inner());
            std::fs::create_dir_all(parent_dir(path))?;
            let (p, f) = create_new_sibling(&parent_dir(path).join(format!(".{name}")))?;
            tmp = Some(p);
            f
        };
        let mut w = BufWriter::new(file);
        write(&mut w)?;
        w.flush()?;
        w.into_inner().map_err(|e| e.into_error())?.sync_all()?;
        let _interrupt = PENDING.lock().unwrap_or_else(|e| e.into_inner());
        std::fs::rename(tmp.as_ref().expect("created"), path)
    })();
    result.map_err(|e| {
        if let Some(t) = &tmp {
            let _ = std::fs::remove_file(t);
        }
        Error::file_caused(path, "could not write", e)
    })
}

/// Creates the folder `dir` and its parents, under the interrupt lock (see
/// [`remove_staging_on_interrupt`]): a folder about to be removed by an interrupt is not
/// made again.
pub fn create_folder(dir: &Path) -> Result<()> {
    let _interrupt = PENDING.lock().unwrap_or_else(|e| e.into_inner());
    std::fs::create_dir_all(dir).map_err(|e| Error::file_caused(dir, "cannot create the output folder", e))
}

/// The BRDF table as a two-channel (R = scale, G = bias) 32-bit float OpenEXR; `name`
/// names it in an error.
pub fn encode_lut_exr(name: &Path, lut: &Lut) -> Result<Vec<u8>> {
    use exr::prelude::*;
    let size = lut.size as usize;
    let pixels = SpecificChannels::build().with_channel("R").with_channel("G").with_pixel_fn(|pos: Vec2<usize>| {
        let t = lut.texels[pos.y() * size + pos.x()];
        (t.x, t.y)
    });
    // Its blocks written in order: the `exr` crate's default encoding leaves the order
    // unspecified and writes blocks as its threads finish compressing them, so the same
    // table made a different file in one of two runs of the same bake.
    let encoding = Encoding { line_order: LineOrder::Increasing, ..Encoding::FAST_LOSSLESS };
    let image = Image::from_encoded_channels((size, size), encoding, pixels);
    let mut buf = std::io::Cursor::new(Vec::new());
    image.write().to_buffered(&mut buf).map_err(|e| crate::error::Error::file_caused(name, "could not encode", e))?;
    Ok(buf.into_inner())
}

/// Writes the BRDF table as [`encode_lut_exr`] does.
pub fn write_lut_exr(path: &Path, lut: &Lut) -> Result<()> {
    let bytes = encode_lut_exr(path, lut)?;
    write_atomic(path, |w| w.write_all(&bytes))
}

/// Writes an 8-bit RGB PNG from row-major `rgb` (values already in [0, 255]).
pub fn write_png(path: &Path, width: u32, height: u32, rgb: &[u8]) -> Result<()> {
    write_rgb8(path, width, height, rgb, FileKind::Png)
}

/// Writes an 8-bit RGB image from row-major `rgb` as `kind` (PNG, or JPEG at quality 95).
pub fn write_rgb8(path: &Path, width: u32, height: u32, rgb: &[u8], kind: FileKind) -> Result<()> {
    let bytes = encode_rgb8(path, width, height, rgb, kind)?;
    write_atomic(path, |w| w.write_all(&bytes))
}

/// An 8-bit RGB image from row-major `rgb` encoded as `kind` (PNG, or JPEG at quality 95);
/// `name` names it in an error.
pub fn encode_rgb8(name: &Path, width: u32, height: u32, rgb: &[u8], kind: FileKind) -> Result<Vec<u8>> {
    let img = image::RgbImage::from_raw(width, height, rgb.to_vec()).ok_or_else(|| Error::file(name, "image buffer has the wrong size"))?;
    let mut buf = std::io::Cursor::new(Vec::new());
    let encoded = if kind == FileKind::Jpeg {
        image::codecs::jpeg::JpegEncoder::new_with_quality(&mut buf, 95).encode_image(&img)
    } else {
        img.write_to(&mut buf, kind.image_format())
    };
    encoded.map_err(|e| Error::file_caused(name, "could not encode", std::io::Error::other(e)))?;
    Ok(buf.into_inner())
}

/// The BRDF table as an 8-bit preview: R = scale, G = bias, values in [0, 1] stored
/// linearly (it is data, not colour).
pub fn lut_preview(lut: &Lut) -> Vec<u8> {
    lut.texels.iter().flat_map(|t| [to_u8(t.x), to_u8(t.y), 0]).collect()
}

/// One channel of a table (`channel(texel)`) as 8-bit RGB with the value in every channel
/// (whichever channel a loader reads), values above 1 clamped to 1.
pub fn table_channel_png(lut: &Lut, channel: impl Fn(splitsum_shaders::glam::Vec2) -> f32) -> Vec<u8> {
    lut.texels.iter().flat_map(|t| [to_u8(channel(*t)); 3]).collect()
}

fn to_u8(v: f32) -> u8 {
    (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
}

/// Writes RGB float pixels (alpha dropped) as a 32-bit float OpenEXR with a comment.
pub fn write_rgb_exr(path: &Path, width: u32, height: u32, pixels: &[splitsum_shaders::glam::Vec4], comment: &str) -> Result<()> {
    let bytes = encode_rgb_exr(path, width, height, pixels, comment)?;
    write_atomic(path, |w| w.write_all(&bytes))
}

/// RGB float pixels (alpha dropped) as a 32-bit float OpenEXR with a comment; `name` names
/// it in an error.
pub fn encode_rgb_exr(name: &Path, width: u32, height: u32, pixels: &[splitsum_shaders::glam::Vec4], comment: &str) -> Result<Vec<u8>> {
    use exr::prelude::*;
    let w = width as usize;
    let mut attributes = LayerAttributes::named("rgb");
    attributes.comments = Some(Text::from(comment));
    attributes.software_name = Some(Text::from("splitsum"));
    let layer = Layer::new(
        (w, height as usize),
        attributes,
        // Scan lines written in order (its line order is `Increasing`).
        Encoding::SMALL_LOSSLESS,
        SpecificChannels::rgb(|pos: Vec2<usize>| {
            let t = pixels[pos.y() * w + pos.x()];
            (t.x, t.y, t.z)
        }),
    );
    let image = Image::from_layer(layer);
    let mut buf = std::io::Cursor::new(Vec::new());
    image.write().to_buffered(&mut buf).map_err(|e| crate::error::Error::file_caused(name, "could not encode", e))?;
    Ok(buf.into_inner())
}

/// Level `level` of `cube` as a vertical strip of its six faces (+X, −X, +Y, −Y, +Z, −Z
/// from the top, each in Vulkan/KTX2 orientation), encoded as OpenEXR.
pub fn encode_cube_level_exr(name: &Path, cube: &crate::texture::Cube, level: u32, what: &str) -> Result<Vec<u8>> {
    let s = cube.layout.level_size(level);
    encode_rgb_exr(
        name,
        s,
        6 * s,
        cube.level(level),
        &format!("{what}; mip {level} of a cube map, faces +X -X +Y -Y +Z -Z from the top, Vulkan/KTX2 orientation"),
    )
}

mod folder;
mod manifest;
mod sink;

pub use folder::{OutputDir, remove_staging_on_interrupt};
pub use manifest::{OUTPUT_MANIFEST, Verified, check_replaceable};
pub use sink::{Files, Folder, Memory, Sink};

/// Staging folders not yet committed, and the folders created for them: removed if the
/// process is interrupted (SIGINT, SIGTERM, SIGHUP), under this lock, which a commit holds
/// while it swaps folders and removes the old one.
static PENDING: std::sync::Mutex<Vec<(PathBuf, Vec<PathBuf>)>> = std::sync::Mutex::new(Vec::new());

#[cfg(test)]
mod tests {
    use splitsum_shaders::glam::Vec2;

    /// The same table makes the same bytes every time: blocks top to bottom.
    #[test]
    fn a_table_exr_is_the_same_bytes_every_time() {
        let dir = std::env::temp_dir().join(format!("splitsum-exr-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let size = 256u32;
        let lut = crate::texture::Lut { size, texels: (0..size * size).map(|i| Vec2::new((i % 97) as f32 * 0.37, (i as f32).sin())).collect() };
        let write = |k: u32| {
            let path = dir.join(format!("{k}.exr"));
            super::write_lut_exr(&path, &lut).unwrap();
            std::fs::read(&path).unwrap()
        };
        let first = write(0);
        for k in 1..8 {
            assert!(write(k) == first, "write {k} differs from the first");
        }
        let meta = exr::meta::MetaData::read_from_buffered(std::io::Cursor::new(&first), false).unwrap();
        assert_eq!(meta.headers[0].line_order, exr::prelude::LineOrder::Increasing);
        std::fs::remove_dir_all(&dir).ok();
    }
}
