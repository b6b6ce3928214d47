//! Writing outputs safely, and the plain image formats: every file is written to a
//! temporary sibling and renamed into place, so an existing output is never left
//! half-written and a failed run loses nothing already there.

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
        Err(e) => return Err(Error::file(path, format!("cannot write here: folder {}: {e}", dir.display()))),
    }
    // Probe with a temporary file: permissions and read-only file systems show up now,
    // not after a long bake.
    let probe = dir.join(format!(".splitsum-probe.{}.tmp", std::process::id()));
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
        // Every change to a folder's entries happens under the interrupt lock: an interrupt
        // that removes a staging folder holds it until the process exits, so nothing is
        // created or renamed in it behind the removal (which would leave it behind).
        let file = {
            let _interrupt = PENDING.lock().unwrap_or_else(|e| e.into_inner());
            std::fs::create_dir_all(parent_dir(path))?;
            File::create(&tmp)?
        };
        let mut w = BufWriter::new(file);
        write(&mut w)?;
        w.flush()?;
        w.into_inner().map_err(|e| e.into_error())?.sync_all()?;
        let _interrupt = PENDING.lock().unwrap_or_else(|e| e.into_inner());
        std::fs::rename(&tmp, path)
    })();
    result.map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        Error::file(path, format!("could not write: {e}"))
    })
}

/// Creates the folder `dir` and its parents, under the interrupt lock (see
/// [`remove_staging_on_interrupt`]): a folder about to be removed by an interrupt is not
/// made again.
pub fn create_folder(dir: &Path) -> Result<()> {
    let _interrupt = PENDING.lock().unwrap_or_else(|e| e.into_inner());
    std::fs::create_dir_all(dir).map_err(|e| Error::file(dir, format!("cannot create the output folder: {e}")))
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
    write_rgb8(path, width, height, rgb, image::ImageFormat::Png)
}

/// The 8-bit format the name of `path` asks for: PNG or JPEG. `called` is what the caller
/// calls the path (a flag, a field), for the message.
pub fn picture_format(path: &Path, called: &str) -> Result<image::ImageFormat> {
    match image::ImageFormat::from_path(path) {
        Ok(f @ (image::ImageFormat::Png | image::ImageFormat::Jpeg)) => Ok(f),
        _ => Err(Error::Invalid(format!("{called} {}: name a .png or .jpg file (the format follows the extension)", path.display()))),
    }
}

/// Writes an 8-bit RGB image from row-major `rgb` in `format` (PNG, or JPEG at quality 95).
pub fn write_rgb8(path: &Path, width: u32, height: u32, rgb: &[u8], format: image::ImageFormat) -> Result<()> {
    let img = image::RgbImage::from_raw(width, height, rgb.to_vec()).ok_or_else(|| Error::file(path, "image buffer has the wrong size"))?;
    write_atomic(path, |w| {
        let mut buf = std::io::Cursor::new(Vec::new());
        if format == image::ImageFormat::Jpeg {
            image::codecs::jpeg::JpegEncoder::new_with_quality(&mut buf, 95).encode_image(&img).map_err(std::io::Error::other)?;
        } else {
            img.write_to(&mut buf, format).map_err(std::io::Error::other)?;
        }
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

/// Names of the manifests splitsum writes into an output folder: a folder holding one of
/// them is a previous output, which a new run may replace whole.
pub const MANIFESTS: [&str; 3] = ["bake.json", "plan.json", "report.md"];

/// Staging folders not yet committed, and the folders created for them: removed if the
/// process is interrupted (SIGINT, SIGTERM, SIGHUP), under this lock, which a commit holds
/// while it swaps folders.
static PENDING: std::sync::Mutex<Vec<(PathBuf, Vec<PathBuf>)>> = std::sync::Mutex::new(Vec::new());

/// Makes SIGINT, SIGTERM and SIGHUP remove every uncommitted staging folder (and the
/// folders made for it) and exit with 130. A process-wide signal handler: the command line
/// installs it; an application with its own handling leaves it out (its interrupted runs
/// may then leave a hidden `.NAME.splitsum-PID` folder beside the output).
pub fn remove_staging_on_interrupt() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        // ctrlc runs this on its own thread, so it may take locks and touch files.
        let _ = ctrlc::set_handler(|| {
            let pending = PENDING.lock().unwrap_or_else(|e| e.into_inner());
            for (staging, created) in pending.iter() {
                let _ = std::fs::remove_dir_all(staging);
                for d in created.iter().rev() {
                    let _ = std::fs::remove_dir(d);
                }
            }
            eprintln!("interrupted: the output folder is as it was");
            std::process::exit(130);
        });
    });
}

/// An output folder written as a unit: every file goes into a hidden staging folder beside
/// it, and [`OutputDir::commit`] swaps the staging folder and the old folder in one
/// `renameat2(RENAME_EXCHANGE)` (Linux; elsewhere two renames), then removes the old one. A
/// reader sees the whole old set of files or the whole new set, never a mix; a failure
/// before the commit leaves the old folder as it was, no staging folder and no folder this
/// run created, and so does an interruption once [`remove_staging_on_interrupt`] is on.
pub struct OutputDir {
    target: PathBuf,
    staging: PathBuf,
    created: Vec<PathBuf>,
    committed: bool,
}

impl OutputDir {
    /// Starts writing the folder `target`; `called` is what the caller calls it (a flag, a
    /// field), for messages. Refuses a path
    /// that is a file, and a folder holding files that no splitsum run wrote (it would be
    /// replaced whole).
    pub fn begin(target: &Path, called: &str) -> Result<Self> {
        let shown = target.display();
        match std::fs::metadata(target) {
            Ok(m) if !m.is_dir() => return Err(Error::Invalid(format!("{called} {shown} is an existing file; give a folder (it is created if missing)"))),
            Ok(_) => {
                let entries: Vec<String> = std::fs::read_dir(target)
                    .map_err(|e| Error::file(target, format!("cannot read the output folder: {e}")))?
                    .filter_map(|e| e.ok().map(|e| e.file_name().to_string_lossy().into_owned()))
                    .collect();
                if !entries.is_empty() && !entries.iter().any(|e| MANIFESTS.contains(&e.as_str())) {
                    let mut some = entries.clone();
                    some.sort();
                    some.truncate(3);
                    return Err(Error::Invalid(format!(
                        "{called} {shown} holds files splitsum did not write ({}{}); the output folder is replaced as a whole, so give a new or empty folder",
                        some.join(", "),
                        if entries.len() > 3 { ", …" } else { "" }
                    )));
                }
            }
            Err(_) => {}
        }
        let name = target.file_name().filter(|n| *n != "." && *n != "..").ok_or_else(|| {
            Error::Invalid(format!("{called} {shown} names no folder (the output folder is replaced as a whole; give one such as {called} out)"))
        })?;
        let parent = parent_dir(target);
        // The folders above the output that this run creates (removed again on failure).
        let mut created = Vec::new();
        let mut up = parent.clone();
        while !up.exists() {
            created.push(up.clone());
            match up.parent() {
                Some(p) if !p.as_os_str().is_empty() => up = p.to_path_buf(),
                _ => break,
            }
        }
        created.reverse();
        let staging = parent.join(format!(".{}.splitsum-{}", name.to_string_lossy(), std::process::id()));
        {
            let mut pending = PENDING.lock().unwrap_or_else(|e| e.into_inner());
            let made = std::fs::create_dir_all(&parent).and_then(|_| {
                let _ = std::fs::remove_dir_all(&staging);
                std::fs::create_dir(&staging)
            });
            if let Err(e) = made {
                for d in created.iter().rev() {
                    let _ = std::fs::remove_dir(d);
                }
                return Err(Error::file(target, format!("cannot create the output folder: {e}")));
            }
            pending.push((staging.clone(), created.clone()));
        }
        Ok(Self { target: target.to_path_buf(), staging, created, committed: false })
    }

    /// The folder to write into (the staging folder).
    pub fn path(&self) -> &Path {
        &self.staging
    }

    /// The folder the files end up in.
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// Makes the staged files the output folder, replacing the old one whole.
    pub fn commit(mut self) -> Result<()> {
        let mut pending = PENDING.lock().unwrap_or_else(|e| e.into_inner());
        sync_dir(&self.staging);
        let swapped = if self.target.exists() { exchange(&self.staging, &self.target) } else { std::fs::rename(&self.staging, &self.target) };
        swapped.map_err(|e| Error::file(&self.target, format!("could not replace the output folder: {e}")))?;
        sync_dir(&parent_dir(&self.target));
        // The staging path now holds the old set (or nothing): still removed if interrupted.
        if let Some(entry) = pending.iter_mut().find(|(s, _)| *s == self.staging) {
            entry.1.clear();
        }
        drop(pending);
        self.committed = true;
        let _ = std::fs::remove_dir_all(&self.staging);
        PENDING.lock().unwrap_or_else(|e| e.into_inner()).retain(|(s, _)| *s != self.staging);
        Ok(())
    }
}

impl Drop for OutputDir {
    fn drop(&mut self) {
        if self.committed {
            return;
        }
        let mut pending = PENDING.lock().unwrap_or_else(|e| e.into_inner());
        let _ = std::fs::remove_dir_all(&self.staging);
        for d in self.created.iter().rev() {
            let _ = std::fs::remove_dir(d);
        }
        pending.retain(|(s, _)| *s != self.staging);
    }
}

fn sync_dir(dir: &Path) {
    if let Ok(f) = File::open(dir) {
        let _ = f.sync_all();
    }
}

/// Swaps the folders `a` and `b` atomically.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn exchange(a: &Path, b: &Path) -> std::io::Result<()> {
    use std::os::unix::ffi::OsStrExt;
    let c = |p: &Path| std::ffi::CString::new(p.as_os_str().as_bytes()).map_err(std::io::Error::other);
    let (ca, cb) = (c(a)?, c(b)?);
    // SAFETY: two valid NUL-terminated paths, relative to the current directory.
    let r = unsafe { libc::renameat2(libc::AT_FDCWD, ca.as_ptr(), libc::AT_FDCWD, cb.as_ptr(), libc::RENAME_EXCHANGE) };
    if r == 0 { Ok(()) } else { Err(std::io::Error::last_os_error()) }
}

/// Swaps the folders `a` and `b` with two renames (no atomic exchange on this system: for
/// a moment `b` does not exist, but it never holds a mix).
#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
fn exchange(a: &Path, b: &Path) -> std::io::Result<()> {
    let aside = a.with_extension("old");
    std::fs::rename(b, &aside)?;
    std::fs::rename(a, b)?;
    std::fs::rename(&aside, a)
}
