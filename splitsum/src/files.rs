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
    // Probe with a temporary file of a name nobody has (created new, never opened if it
    // exists): permissions and read-only file systems show up now, not after a long bake.
    let (probe, _) = create_new_sibling(&dir.join(".splitsum-probe")).map_err(|e| Error::file(path, format!("cannot write here: {e}")))?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

/// Reads the regular file `path` as text of at most `max` bytes (a scene, a calibration):
/// a device, a pipe or a larger file is refused before it is read, so no input file can
/// make a reader hold more than `max`.
pub fn read_text(path: &Path, max: u64) -> Result<String> {
    use std::io::Read;
    let file = File::open(path).map_err(|e| Error::file(path, format!("cannot read: {e}")))?;
    let meta = file.metadata().map_err(|e| Error::file(path, format!("cannot read: {e}")))?;
    if !meta.is_file() {
        return Err(Error::file(path, "is not a regular file"));
    }
    if meta.len() > max {
        return Err(Error::file(path, format!("is {} bytes; a file of this kind has at most {max}", meta.len())));
    }
    let mut text = String::new();
    file.take(max).read_to_string(&mut text).map_err(|e| Error::file(path, format!("cannot read: {e}")))?;
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
            let n = std::fs::File::open(path).and_then(|mut f| std::io::Read::read(&mut f, &mut head)).map_err(|e| Error::file(path, format!("cannot read the existing file: {e}")))?;
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
    write_rgb8(path, width, height, rgb, FileKind::Png)
}

/// Writes an 8-bit RGB image from row-major `rgb` as `kind` (PNG, or JPEG at quality 95).
pub fn write_rgb8(path: &Path, width: u32, height: u32, rgb: &[u8], kind: FileKind) -> Result<()> {
    let img = image::RgbImage::from_raw(width, height, rgb.to_vec()).ok_or_else(|| Error::file(path, "image buffer has the wrong size"))?;
    write_atomic(path, |w| {
        let mut buf = std::io::Cursor::new(Vec::new());
        if kind == FileKind::Jpeg {
            image::codecs::jpeg::JpegEncoder::new_with_quality(&mut buf, 95).encode_image(&img).map_err(std::io::Error::other)?;
        } else {
            img.write_to(&mut buf, kind.image_format()).map_err(std::io::Error::other)?;
        }
        w.write_all(buf.get_ref())
    })
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

/// The manifest in every output folder splitsum writes as a unit ([`OutputDir`]): every
/// entry it wrote there, files with their size and BLAKE3 hash. A folder may be replaced
/// only when everything in it is listed there, unchanged ([`check_replaceable`]).
pub const OUTPUT_MANIFEST: &str = ".splitsum-manifest.json";

/// Format of [`OUTPUT_MANIFEST`].
const MANIFEST_FORMAT: &str = "splitsum-output-1";

/// The largest manifest read (a folder of 10⁵ entries); a larger file is not one of ours.
const MAX_MANIFEST_BYTES: u64 = 16 << 20;

#[derive(serde::Serialize, serde::Deserialize)]
struct OutputManifest {
    format: String,
    /// Every entry below the folder, `/`-separated, in sorted order.
    entries: Vec<ManifestEntry>,
}

#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
struct ManifestEntry {
    path: String,
    /// `None` for a folder.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    file: Option<FileStamp>,
}

#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
struct FileStamp {
    bytes: u64,
    blake3: String,
}

/// An entry found below a folder: its `/`-separated path and what it is.
enum Found {
    Folder(String),
    File(String, u64),
    /// A symbolic link, device, socket…: never something splitsum writes.
    Other(String),
}

/// Every entry below `dir` except the root's manifest, in sorted order, without following
/// symbolic links.
fn walk(dir: &Path) -> std::io::Result<Vec<Found>> {
    fn visit(dir: &Path, prefix: &str, out: &mut Vec<Found>) -> std::io::Result<()> {
        let mut entries: Vec<_> = std::fs::read_dir(dir)?.collect::<std::io::Result<_>>()?;
        entries.sort_by_key(|e| e.file_name());
        for e in entries {
            let name = e.file_name().to_string_lossy().into_owned();
            if prefix.is_empty() && name == OUTPUT_MANIFEST {
                continue;
            }
            let rel = format!("{prefix}{name}");
            let t = e.file_type()?;
            if t.is_dir() {
                out.push(Found::Folder(rel.clone()));
                visit(&e.path(), &format!("{rel}/"), out)?;
            } else if t.is_file() {
                out.push(Found::File(rel, e.metadata()?.len()));
            } else {
                out.push(Found::Other(rel));
            }
        }
        Ok(())
    }
    let mut out = Vec::new();
    visit(dir, "", &mut out)?;
    Ok(out)
}

fn hash_file(path: &Path) -> std::io::Result<String> {
    let mut h = blake3::Hasher::new();
    h.update_reader(File::open(path)?)?;
    Ok(h.finalize().to_hex().to_string())
}

/// The manifest of everything below `dir` (all of it written by this run).
fn manifest_of(dir: &Path) -> std::io::Result<OutputManifest> {
    let mut entries = Vec::new();
    for f in walk(dir)? {
        entries.push(match f {
            Found::Folder(path) => ManifestEntry { path, file: None },
            Found::File(path, bytes) => {
                let blake3 = hash_file(&dir.join(&path))?;
                ManifestEntry { path, file: Some(FileStamp { bytes, blake3 }) }
            }
            Found::Other(path) => return Err(std::io::Error::other(format!("{path} is neither a file nor a folder"))),
        });
    }
    Ok(OutputManifest { format: MANIFEST_FORMAT.into(), entries })
}

/// The manifest `dir` holds, if it holds a readable one of splitsum's.
fn read_manifest(dir: &Path) -> Option<OutputManifest> {
    let path = dir.join(OUTPUT_MANIFEST);
    let m = std::fs::symlink_metadata(&path).ok()?;
    if !m.is_file() || m.len() > MAX_MANIFEST_BYTES {
        return None;
    }
    let manifest: OutputManifest = serde_json::from_slice(&std::fs::read(&path).ok()?).ok()?;
    (manifest.format == MANIFEST_FORMAT).then_some(manifest)
}

/// Checks that the existing folder `dir` may be replaced whole: every entry below it is
/// listed in its [`OUTPUT_MANIFEST`] and every file there is as splitsum wrote it (size
/// and BLAKE3 hash). Otherwise the error names the first entry splitsum did not write, or
/// the first it wrote that has changed since; `called` is what the caller calls the folder
/// (a flag, a field). An empty folder may be replaced.
pub fn check_replaceable(dir: &Path, called: &str) -> Result<()> {
    let shown = dir.display();
    let found = walk(dir).map_err(|e| Error::file(dir, format!("cannot read the output folder: {e}")))?;
    if found.is_empty() {
        return Ok(());
    }
    let manifest = read_manifest(dir);
    let listed = |path: &str| manifest.as_ref().and_then(|m| m.entries.iter().find(|e| e.path == path));
    let refuse = |entry: &str, why: &str| {
        Err(Error::Invalid(format!(
            "{called} {shown} holds {entry}, {why}; splitsum replaces an output folder only when everything in it is what splitsum wrote there (listed, unchanged, in its {OUTPUT_MANIFEST}): move {entry} away, or give a new or empty folder"
        )))
    };
    for f in &found {
        match f {
            Found::Other(path) => return refuse(path, "which is neither a file nor a folder splitsum wrote"),
            Found::Folder(path) => match listed(path) {
                Some(ManifestEntry { file: None, .. }) => {}
                _ => return refuse(path, "a folder splitsum did not write"),
            },
            Found::File(path, bytes) => match listed(path).and_then(|e| e.file.as_ref()) {
                None => return refuse(path, "which splitsum did not write"),
                Some(stamp) => {
                    let same = stamp.bytes == *bytes && hash_file(&dir.join(path)).is_ok_and(|h| h == stamp.blake3);
                    if !same {
                        return refuse(path, "which has changed since splitsum wrote it");
                    }
                }
            },
        }
    }
    Ok(())
}

/// Removes, from the folder `dir` that [`check_replaceable`] passed, what its manifest
/// lists (files, then folders from the deepest), the manifest and `dir` itself; an entry
/// that is not listed (one that appeared since the check) stays, with the folders above
/// it. Returns whether `dir` is gone.
fn remove_written(dir: &Path) -> bool {
    if let Some(m) = read_manifest(dir) {
        for e in m.entries.iter().filter(|e| e.file.is_some()) {
            let p = dir.join(&e.path);
            if std::fs::symlink_metadata(&p).is_ok_and(|m| m.is_file()) {
                let _ = std::fs::remove_file(p);
            }
        }
        for e in m.entries.iter().rev().filter(|e| e.file.is_none()) {
            let _ = std::fs::remove_dir(dir.join(&e.path));
        }
        let _ = std::fs::remove_file(dir.join(OUTPUT_MANIFEST));
    }
    std::fs::remove_dir(dir).is_ok()
}

/// Staging folders not yet committed, and the folders created for them: removed if the
/// process is interrupted (SIGINT, SIGTERM, SIGHUP), under this lock, which a commit holds
/// while it swaps folders and removes the old one.
static PENDING: std::sync::Mutex<Vec<(PathBuf, Vec<PathBuf>)>> = std::sync::Mutex::new(Vec::new());

/// Makes SIGINT, SIGTERM and SIGHUP remove every uncommitted staging folder (and the
/// folders made for it) and exit with 130. A process-wide signal handler: the command line
/// installs it; an application with its own handling leaves it out (its interrupted runs
/// may then leave a hidden `.NAME.splitsum-PID` folder beside the output).
pub fn remove_staging_on_interrupt() {
    #[cfg(not(target_arch = "wasm32"))]
    static ONCE: std::sync::Once = std::sync::Once::new();
    #[cfg(not(target_arch = "wasm32"))]
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
/// it, and [`OutputDir::commit`] lists them in the folder's [`OUTPUT_MANIFEST`], swaps the
/// staging folder and the old folder in one `renameat2(RENAME_EXCHANGE)` (Linux; elsewhere
/// two renames), then removes what the old folder's manifest lists. A reader sees the
/// whole old set of files or the whole new set, never a mix; a failure before the commit
/// leaves the old folder as it was, no staging folder and no folder this run created, and
/// so does an interruption once [`remove_staging_on_interrupt`] is on. A folder holding
/// anything splitsum did not write is never replaced ([`check_replaceable`]).
pub struct OutputDir {
    target: PathBuf,
    called: String,
    staging: PathBuf,
    created: Vec<PathBuf>,
    committed: bool,
}

impl OutputDir {
    /// Starts writing the folder `target`; `called` is what the caller calls it (a flag, a
    /// field), for messages. Refuses a path that is a file or a symbolic link, and a folder
    /// holding anything splitsum did not write there ([`check_replaceable`]): it would be
    /// replaced whole.
    pub fn begin(target: &Path, called: &str) -> Result<Self> {
        let shown = target.display();
        match std::fs::symlink_metadata(target) {
            Ok(m) if m.file_type().is_symlink() => {
                return Err(Error::Invalid(format!("{called} {shown} is a symbolic link; give the folder itself (the output folder is replaced as a whole)")));
            }
            Ok(m) if !m.is_dir() => return Err(Error::Invalid(format!("{called} {shown} is an existing file; give a folder (it is created if missing)"))),
            Ok(_) => check_replaceable(target, called)?,
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
            let made = std::fs::create_dir_all(&parent).and_then(|_| std::fs::create_dir(&staging));
            if let Err(e) = made {
                for d in created.iter().rev() {
                    let _ = std::fs::remove_dir(d);
                }
                let why = if e.kind() == std::io::ErrorKind::AlreadyExists {
                    format!("{} is in the way (a staging folder of another run with this process id?); remove it", staging.display())
                } else {
                    e.to_string()
                };
                return Err(Error::file(target, format!("cannot create the output folder: {why}")));
            }
            pending.push((staging.clone(), created.clone()));
        }
        Ok(Self { target: target.to_path_buf(), called: called.to_string(), staging, created, committed: false })
    }

    /// The folder to write into (the staging folder).
    pub fn path(&self) -> &Path {
        &self.staging
    }

    /// The folder the files end up in.
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// Makes the staged files the output folder, replacing the old one whole: the staged
    /// entries are listed in the manifest, the old folder is checked again (it may have
    /// changed while the run worked), the two are swapped, and what the old manifest lists
    /// is removed. Should an entry have appeared in the old folder between the check and the
    /// swap, that folder is kept beside the new one and a note says where.
    pub fn commit(mut self) -> Result<()> {
        let manifest = manifest_of(&self.staging).map_err(|e| Error::file(&self.target, format!("cannot list the output files: {e}")))?;
        let json = serde_json::to_vec_pretty(&manifest).expect("serialisable");
        write_atomic(&self.staging.join(OUTPUT_MANIFEST), |w| w.write_all(&json))?;
        let pending = PENDING.lock().unwrap_or_else(|e| e.into_inner());
        let existed = match std::fs::symlink_metadata(&self.target) {
            Ok(m) if m.is_dir() && !m.file_type().is_symlink() => {
                check_replaceable(&self.target, &self.called)?;
                true
            }
            Ok(_) => return Err(Error::Invalid(format!("{} {} is no longer a folder; nothing was replaced", self.called, self.target.display()))),
            Err(_) => false,
        };
        sync_dir(&self.staging);
        let swapped = if existed { exchange(&self.staging, &self.target) } else { std::fs::rename(&self.staging, &self.target) };
        swapped.map_err(|e| Error::file(&self.target, format!("could not replace the output folder: {e}")))?;
        sync_dir(&parent_dir(&self.target));
        self.committed = true;
        // The staging path now holds the old set (or nothing).
        if existed && !remove_written(&self.staging) {
            let kept = self.staging.with_file_name(format!(
                "{}.kept",
                self.staging.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default()
            ));
            let at = if std::fs::rename(&self.staging, &kept).is_ok() { kept } else { self.staging.clone() };
            crate::progress::note(&format!(
                "note: entries appeared in {} {} while this run worked: the old folder, with them, is kept at {}",
                self.called,
                self.target.display(),
                at.display()
            ));
        }
        drop(pending);
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
#[allow(dead_code)]
fn exchange(a: &Path, b: &Path) -> std::io::Result<()> {
    let aside = a.with_extension("old");
    std::fs::rename(b, &aside)?;
    std::fs::rename(a, b)?;
    std::fs::rename(&aside, a)
}
