//! Reading environments: equirectangular Radiance `.hdr` and OpenEXR `.exr` images (every
//! compression the `exr` crate decodes, DWAB included), or a cube map given as six face
//! images. Every problem is reported with the file it is in.
//!
//! Radiance must be finite and non-negative. Negative values (ringing of lossy EXR
//! compressions such as DWAB) are set to 0 and counted; values above
//! `math::MAX_RADIANCE` (10²⁰, the headroom every sum of the bake is built for) are clamped
//! to it and counted. NaN and ±∞ are refused, with their count, unless sanitising is asked
//! for; then NaN and −∞ become 0 and +∞ becomes the largest finite value of its channel in
//! the image (then clamped like any other).

use crate::adjustment::Adjustment;
use crate::error::{Error, Result};
use crate::texture::{Cube, Equirect};
use serde::Serialize;
use splitsum_shaders::cubemap::{self, CubeLayout};
use splitsum_shaders::equirect;
use splitsum_shaders::glam::Vec4;
use splitsum_shaders::math::MAX_RADIANCE;
use std::path::{Path, PathBuf};

/// Largest image side accepted (a 32768×16384 RGBA f32 equirect is 8 GiB).
pub const MAX_SIDE: u32 = 32768;
/// Largest cube face accepted (faces are reduced as they are decoded, as equirects are).
pub const MAX_FACE: u32 = MAX_SIDE;
/// Smallest equirect accepted.
pub const MIN_WIDTH: u32 = 8;

/// An environment as read: an equirect image or a cube.
#[derive(Clone, Debug)]
pub enum Environment {
    /// Latitude–longitude image.
    Equirect(Equirect),
    /// Six faces (level 0 only, or with mips).
    Cube(Cube),
}

impl Environment {
    /// The environment's own resolution as a cube face size (a quarter of an equirect's
    /// width, as a power of two, at most [`NATIVE_FACE`]).
    pub fn native_face_size(&self) -> u32 {
        self.resolves().min(NATIVE_FACE)
    }

    /// The cube face size the environment resolves: a quarter of an equirect's width (the
    /// next power of two, at least 8), or a cube's own face size.
    pub fn resolves(&self) -> u32 {
        match self {
            Environment::Equirect(e) => (e.width / 4).max(8).next_power_of_two(),
            Environment::Cube(c) => c.layout.size,
        }
    }
}

/// What an environment is, as far as a bake's plan goes.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum InputShape {
    /// An equirect image (as read: after any reduction).
    Equirect {
        /// Width.
        width: u32,
        /// Height.
        height: u32,
    },
    /// A cube of six faces.
    Cube {
        /// Face size.
        size: u32,
    },
    /// Not known (settings checked on their own).
    Unknown,
}

impl InputShape {
    /// The shape of `env`.
    pub fn of(env: &Environment) -> Self {
        match env {
            Environment::Equirect(e) => InputShape::Equirect { width: e.width, height: e.height },
            Environment::Cube(c) => InputShape::Cube { size: c.layout.size },
        }
    }
}

/// What was found and changed while reading.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct InputReport {
    /// Texels with a negative channel, set to 0.
    pub negative: u64,
    /// Texels with a channel above `MAX_RADIANCE`, clamped to it.
    pub clamped: u64,
    /// Texels with a NaN channel.
    pub nan: u64,
    /// Texels with an infinite channel.
    pub infinite: u64,
    /// Whether NaN/∞ were replaced.
    pub sanitized: bool,
    /// The largest finite value of any channel.
    pub max_value: f32,
    /// Width and height of the file (of one face, for a cube), before any reduction.
    pub original: (u32, u32),
    /// The cube face size the environment was read for (see [`load_for`]).
    pub read_for: u32,
}

impl InputReport {
    /// What reading changed, with `env` as read: a reduction, negative texels set to 0,
    /// texels clamped, NaN and ∞ replaced.
    pub fn adjustments(&self, env: &Environment) -> Vec<Adjustment> {
        self.adjustments_for(InputShape::of(env))
    }

    /// [`InputReport::adjustments`] of an environment of `shape` as read.
    pub fn adjustments_for(&self, shape: InputShape) -> Vec<Adjustment> {
        let mut out = Vec::new();
        let (w, h) = self.original;
        match shape {
            InputShape::Equirect { width, height } if width < w => out.push(Adjustment::Reduced { from: (w, h), to: (width, height), source_size: self.read_for }),
            InputShape::Cube { size } if size < w => out.push(Adjustment::FacesReduced { from: w, to: size }),
            _ => {}
        }
        if self.negative > 0 {
            out.push(Adjustment::NegativeTexels { count: self.negative });
        }
        if self.clamped > 0 {
            out.push(Adjustment::ClampedTexels { count: self.clamped, max: MAX_RADIANCE });
        }
        if self.sanitized && (self.nan > 0 || self.infinite > 0) {
            out.push(Adjustment::Sanitized { nan: self.nan, infinite: self.infinite });
        }
        out
    }

    fn add(&mut self, r: &InputReport) {
        self.negative += r.negative;
        self.clamped += r.clamped;
        self.nan += r.nan;
        self.infinite += r.infinite;
        self.max_value = self.max_value.max(r.max_value);
    }
}

/// Face file names of a cube map folder, in KTX2/Vulkan face order.
pub const FACE_NAMES: [&str; 6] = ["px", "nx", "py", "ny", "pz", "nz"];

/// The largest cube face the display and the planner build from an environment (see
/// `Environment::native_face_size`): what [`load`] reads an environment for.
pub const NATIVE_FACE: u32 = 1024;

/// Reads an environment for cubes of faces up to [`NATIVE_FACE`] (see [`load_for`]).
pub fn load(path: &Path, sanitize: bool) -> Result<(Environment, InputReport)> {
    load_for(path, sanitize, NATIVE_FACE)
}

/// Reads an environment: a `.hdr`/`.exr` equirect file, or a folder holding six faces
/// `px nx py ny pz nz` (`.hdr` or `.exr`) in Vulkan/KTX2 orientation, keeping only the
/// resolution a cube of faces `face` wide resolves: an equirect is reduced by
/// `equirect::reduction_factor` (area-weighted, as it is decoded, so a 16384×8192 file is
/// never held whole), and faces wider than `face` are reduced to `face` through the cube's
/// own mip filter. [`InputReport::original`] keeps the size of the file.
pub fn load_for(path: &Path, sanitize: bool, face: u32) -> Result<(Environment, InputReport)> {
    if path.is_dir() {
        let faces = face_paths(path)?;
        let (env, report) = load_faces(&faces, sanitize, face)?;
        return Ok((env, InputReport { read_for: face, ..report }));
    }
    let (width, height) = dimensions(path)?;
    check_equirect_shape(path, width, height)?;
    let factor = equirect::reduction_factor(width, height, face);
    let (image, report) = read_reduced(path, sanitize, factor)?;
    Ok((Environment::Equirect(image), InputReport { read_for: face, ..report }))
}

/// The six face files of a cube map folder.
pub fn face_paths(dir: &Path) -> Result<[PathBuf; 6]> {
    let find = |name: &str| -> Result<PathBuf> {
        let mut found = Vec::new();
        for ext in ["exr", "hdr"] {
            let p = dir.join(format!("{name}.{ext}"));
            match std::fs::metadata(&p) {
                Ok(m) if m.is_file() => found.push(p),
                Ok(m) if m.is_dir() => return Err(Error::file(&p, "is a folder; a cube face must be an .exr or .hdr file")),
                Ok(_) => return Err(Error::file(&p, "is not a regular file; a cube face must be an .exr or .hdr file")),
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                    if std::fs::symlink_metadata(&p).is_ok() {
                        return Err(Error::file(&p, "is a symbolic link to nothing"));
                    }
                }
                Err(e) => return Err(Error::file(&p, format!("cannot read: {e}"))),
            }
        }
        match found.len() {
            1 => Ok(found.remove(0)),
            0 => Err(Error::file(dir, format!("has no face `{name}.exr` or `{name}.hdr` (a cube map folder needs px nx py ny pz nz)"))),
            _ => Err(Error::file(dir, format!("has both `{name}.exr` and `{name}.hdr`; keep one face per direction"))),
        }
    };
    Ok([find("px")?, find("nx")?, find("py")?, find("ny")?, find("pz")?, find("nz")?])
}

/// Reads six square, equally sized, power-of-two faces into a one-level cube, each reduced
/// to `face` wide (if wider) as it is decoded: every output texel is the solid-angle
/// weighted mean (`cubemap::texel_solid_angle`) of the input texels it covers, summed in
/// f64, which is what the cube's own 2×2 mip filter (`cubemap::downsample_texel`) gives
/// applied level after level, rounded once. A face is never held whole.
pub fn load_faces(paths: &[PathBuf; 6], sanitize: bool, face: u32) -> Result<(Environment, InputReport)> {
    let mut size = 0;
    for p in paths {
        let (w, h) = dimensions(p)?;
        if w != h {
            return Err(Error::file(p, format!("a cube face must be square, this one is {w}×{h}")));
        }
        if w > MAX_FACE {
            return Err(Error::file(p, format!("a cube face may be at most {MAX_FACE}², this one is {w}²")));
        }
        if !w.is_power_of_two() {
            return Err(Error::file(p, format!("a cube face must be a power of two wide, this one is {w}")));
        }
        if size == 0 {
            size = w;
        } else if w != size {
            return Err(Error::file(p, format!("is {w}×{w} but the first face is {size}×{size}")));
        }
    }
    let out = size.min(face.max(1));
    let mut all = Vec::with_capacity(6 * (out as usize).pow(2));
    let mut report = InputReport { sanitized: sanitize, ..Default::default() };
    for p in paths {
        let (img, r) = read_with(p, Weights::CubeFace, sanitize, size / out)?;
        report.add(&r);
        all.extend(img.texels);
    }
    report.original = (size, size);
    Ok((Environment::Cube(Cube { layout: CubeLayout::new(out, 1), texels: all }), report))
}

fn check_equirect_shape(path: &Path, width: u32, height: u32) -> Result<()> {
    if width > MAX_SIDE || height > MAX_SIDE {
        return Err(Error::file(path, format!("{width}×{height} is larger than the {MAX_SIDE} texels per side accepted")));
    }
    if width < MIN_WIDTH {
        return Err(Error::file(path, format!("{width}×{height} is too small for an environment (at least {MIN_WIDTH}×{})", MIN_WIDTH / 2)));
    }
    if width != 2 * height {
        return Err(Error::file(path, format!("an equirectangular environment is twice as wide as high, this one is {width}×{height}")));
    }
    Ok(())
}

/// What kind of image a file holds, by its signature.
enum Kind {
    Exr,
    Hdr,
}

fn kind(path: &Path) -> Result<Kind> {
    use std::io::Read;
    let mut head = [0u8; 4];
    let mut f = std::fs::File::open(path).map_err(|e| Error::file(path, format!("cannot read: {e}")))?;
    let n = f.read(&mut head).map_err(|e| Error::file(path, format!("cannot read: {e}")))?;
    match &head[..n] {
        [0x76, 0x2f, 0x31, 0x01] => Ok(Kind::Exr),
        [b'#', b'?', ..] => Ok(Kind::Hdr),
        [] => Err(Error::file(path, "is empty")),
        _ => Err(Error::file(path, "is neither an OpenEXR nor a Radiance HDR file (unknown signature)")),
    }
}

fn file_len(path: &Path) -> Result<u64> {
    std::fs::metadata(path).map(|m| m.len()).map_err(|e| Error::file(path, format!("cannot read: {e}")))
}

/// Width and height of an `.hdr` or `.exr` image, from its header alone, checked against
/// the file's size: a header that promises more blocks or scanlines than the file can hold
/// is refused here, before anything is allocated for them.
pub fn dimensions(path: &Path) -> Result<(u32, u32)> {
    match kind(path)? {
        Kind::Exr => Ok(exr_header(path, &mut buffered(path)?, file_len(path)?)?.size),
        Kind::Hdr => {
            let (w, h) = rgbe::header(path, &mut buffered(path)?)?;
            check_side(path, w, h)?;
            check_hdr_length(path, h, file_len(path)?)?;
            Ok((w, h))
        }
    }
}

fn buffered(path: &Path) -> Result<std::io::BufReader<std::fs::File>> {
    Ok(std::io::BufReader::new(std::fs::File::open(path).map_err(|e| Error::file(path, format!("cannot read: {e}")))?))
}

/// Reads an `.hdr` or `.exr` equirect as RGBA f32 (alpha 1), row 0 at the top, reduced by
/// `factor` (area-weighted, as it is decoded) and cleaned ([`clean`]'s rules).
pub fn read_reduced(path: &Path, sanitize: bool, factor: u32) -> Result<(Equirect, InputReport)> {
    read_with(path, Weights::EquirectRows, sanitize, factor)
}

/// Reads an `.hdr` or `.exr` image reduced by `factor`, its texels weighted by `weights`.
fn read_with(path: &Path, weights: Weights, sanitize: bool, factor: u32) -> Result<(Equirect, InputReport)> {
    match kind(path)? {
        Kind::Exr => read_exr(path, buffered(path)?, file_len(path)?, weights, sanitize, factor),
        Kind::Hdr => read_hdr(path, weights, sanitize, factor),
    }
}

/// Every scanline of a Radiance file takes at least 4 bytes: a header that promises more
/// rows than the file can hold is refused.
fn check_hdr_length(path: &Path, h: u32, len: u64) -> Result<()> {
    if len < 4 * h as u64 {
        return Err(Error::file(path, format!("truncated Radiance HDR: its header promises {h} scanlines, which take at least {} bytes, but the file has {len}", 4 * h as u64)));
    }
    Ok(())
}

/// A Radiance `.hdr` file, decoded scanline by scanline into a [`Reducer`] ([`rgbe`]).
fn read_hdr(path: &Path, weights: Weights, sanitize: bool, factor: u32) -> Result<(Equirect, InputReport)> {
    let mut r = buffered(path)?;
    let (w, h) = rgbe::header(path, &mut r)?;
    check_side(path, w, h)?;
    check_hdr_length(path, h, file_len(path)?)?;
    let mut reducer = Reducer::new(w, h, factor, weights, sanitize);
    let mut line = vec![[0u8; 4]; w as usize];
    for y in 0..h {
        rgbe::scanline(&mut r, &mut line).map_err(|e| match e.kind() {
            std::io::ErrorKind::UnexpectedEof => Error::file(path, format!("truncated Radiance HDR: the file ends in scanline {y} of {h}")),
            _ => Error::file(path, format!("malformed Radiance HDR in scanline {y} of {h}: {e}")),
        })?;
        for (x, p) in line.iter().enumerate() {
            reducer.push(x as u32, y, rgbe::to_f32(*p));
        }
    }
    reducer.finish(path)
}

/// Radiance RGBE (Ward, "Real Pixels", Graphics Gems II, 1991; the format of `.hdr`
/// files), read one scanline at a time, so a 16384×8192 file needs 64 KiB rather than the
/// 1.5 GiB the `image` crate's whole-image decoder allocates (it has no row interface).
/// The same rules as `image`'s decoder: a header up to an empty line, the standard
/// orientation `-Y H +X W`, and per scanline either the adaptive run-length coding (a
/// `2 2 hi lo` marker, then each component in runs) or flat/old-RLE pixels (`1 1 1 n`
/// repeats the previous pixel). Values convert as `image` does: `c·2^(e−136)`.
mod rgbe {
    use crate::error::{Error, Result};
    use std::io::{BufRead, Read};
    use std::path::Path;

    /// Reads the header and the resolution line: `(width, height)`. Lines are read as bytes
    /// (at most 4 KiB each), so pixel data where a line was expected is reported as such.
    pub fn header(path: &Path, r: &mut impl BufRead) -> Result<(u32, u32)> {
        let bad = |why: String| Error::file(path, format!("malformed Radiance HDR: {why}"));
        let mut line = Vec::new();
        let read_line = |line: &mut Vec<u8>, r: &mut dyn BufRead| -> Result<usize> {
            line.clear();
            let n = r.take(4096).read_until(b'\n', line).map_err(|e| bad(e.to_string()))?;
            while line.last().is_some_and(|b| *b == b'\n' || *b == b'\r') {
                line.pop();
            }
            Ok(n)
        };
        let text = |l: &[u8]| l.iter().all(|b| b.is_ascii_graphic() || *b == b' ' || *b == b'\t');
        let mut first = true;
        loop {
            if read_line(&mut line, r)? == 0 {
                return Err(bad("the header never ends (no empty line before the resolution line)".into()));
            }
            if first && !line.starts_with(b"#?") {
                return Err(bad("no #? signature".into()));
            }
            first = false;
            if line.is_empty() {
                break;
            }
            if !text(&line) {
                return Err(bad("the header never ends: binary data before the empty line that closes it".into()));
            }
            if let Some(format) = line.strip_prefix(b"FORMAT=") {
                let format = String::from_utf8_lossy(format);
                if format.trim() != "32-bit_rle_rgbe" {
                    return Err(bad(format!("FORMAT={format} is not supported (only 32-bit_rle_rgbe)")));
                }
            }
        }
        let n = read_line(&mut line, r)?;
        if n == 0 {
            return Err(bad("no resolution line after the header (expected `-Y height +X width`)".into()));
        }
        if !text(&line) {
            return Err(bad("no resolution line after the header: pixel data follows it where `-Y height +X width` belongs".into()));
        }
        let shown = String::from_utf8_lossy(&line).into_owned();
        let f: Vec<&str> = shown.split_whitespace().collect();
        match f.as_slice() {
            ["-Y", h, "+X", w] => match (h.parse::<u32>(), w.parse::<u32>()) {
                (Ok(h), Ok(w)) => Ok((w, h)),
                _ => Err(bad(format!("unreadable resolution line {shown:?} (expected `-Y height +X width`)"))),
            },
            [a, _, b, _] if ["+Y", "-Y", "+X", "-X"].contains(a) && ["+Y", "-Y", "+X", "-X"].contains(b) => {
                Err(bad(format!("resolution line {shown:?}: only the standard orientation -Y height +X width is supported")))
            }
            _ => Err(bad(format!("no resolution line after the header: found {shown:?} where `-Y height +X width` belongs"))),
        }
    }

    fn byte(r: &mut impl Read) -> std::io::Result<u8> {
        let mut b = [0u8];
        r.read_exact(&mut b)?;
        Ok(b[0])
    }

    /// Decodes one scanline of `line.len()` pixels.
    pub fn scanline(r: &mut impl Read, line: &mut [[u8; 4]]) -> std::io::Result<()> {
        let width = line.len();
        let mut first = [0u8; 4];
        r.read_exact(&mut first)?;
        let invalid = |why: &str| std::io::Error::new(std::io::ErrorKind::InvalidData, why.to_string());
        if first[0] == 2 && first[1] == 2 && first[2] < 128 {
            for c in 0..4 {
                let mut x = 0;
                while x < width {
                    let n = byte(r)? as usize;
                    if n > 128 {
                        let run = n - 128;
                        if x + run > width {
                            return Err(invalid("a run passes the end of the scanline"));
                        }
                        let v = byte(r)?;
                        line[x..x + run].iter_mut().for_each(|p| p[c] = v);
                        x += run;
                    } else {
                        if n == 0 || x + n > width {
                            return Err(invalid("a literal passes the end of the scanline or is empty"));
                        }
                        for p in &mut line[x..x + n] {
                            p[c] = byte(r)?;
                        }
                        x += n;
                    }
                }
            }
            return Ok(());
        }
        // Flat pixels, where `1 1 1 n` repeats the previous pixel n times (n shifted by 8
        // bits for each marker in a row).
        if first[..3] == [1, 1, 1] {
            return Err(invalid("a scanline starts with a repeat marker"));
        }
        line[0] = first;
        let (mut x, mut shift) = (1, 0u32);
        while x < width {
            let mut p = [0u8; 4];
            r.read_exact(&mut p)?;
            if p[..3] == [1, 1, 1] {
                let run = (p[3] as usize).checked_shl(shift).unwrap_or(usize::MAX);
                if run > width - x {
                    return Err(invalid("a repeat passes the end of the scanline"));
                }
                let prev = line[x - 1];
                line[x..x + run].iter_mut().for_each(|q| *q = prev);
                x += run;
                shift += 8;
            } else {
                line[x] = p;
                x += 1;
                shift = 0;
            }
        }
        Ok(())
    }

    /// An RGBE pixel as linear RGB, exactly as the `image` crate converts it:
    /// `2^(e−128)/256` built from the bits (subnormal for `e = 1`), 0 for `e = 0`.
    pub fn to_f32(p: [u8; 4]) -> [f32; 3] {
        let e = p[3] as u32;
        let exp = f32::from_bits(if e > 1 { (e - 1) << 23 } else { e << 22 }) * 0.00390625;
        [exp * p[0] as f32, exp * p[1] as f32, exp * p[2] as f32]
    }
}

fn check_side(path: &Path, w: u32, h: u32) -> Result<()> {
    if w == 0 || h == 0 {
        return Err(Error::file(path, "has no pixels"));
    }
    if w > MAX_SIDE || h > MAX_SIDE {
        return Err(Error::file(path, format!("{w}×{h} is larger than the {MAX_SIDE} texels per side accepted")));
    }
    Ok(())
}

/// The channels an environment is read from: `R`, `G`, `B` (matched by the last part of
/// their names, so `diffuse.R` counts), or a luminance `Y` (or `L`) read as grey.
enum ExrChannels {
    Rgb([exr::meta::attribute::Text; 3]),
    Grey(exr::meta::attribute::Text),
}

/// What splitsum needs of an OpenEXR header.
struct ExrHeader {
    size: (u32, u32),
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
fn exr_header<R: std::io::BufRead + std::io::Seek>(path: &Path, reader: &mut R, len: u64) -> Result<ExrHeader> {
    let malformed = |why: String| Error::file(path, format!("malformed OpenEXR: {why}"));
    if let Some([x0, y0, x1, y1]) = exr_raw_data_window(reader)
        && (x1 < x0 || y1 < y0) {
            return Err(malformed(format!("its data window is inverted (from ({x0}, {y0}) to ({x1}, {y1}))")));
        }
    reader.seek(std::io::SeekFrom::Start(0)).map_err(|e| Error::file(path, format!("cannot read: {e}")))?;
    let meta = exr::meta::MetaData::read_from_buffered(reader, false).map_err(|e| exr_error(path, e))?;
    let header = meta.headers.iter().find(|h| !h.deep && exr_channels(h).is_some()).ok_or_else(|| {
        let names: Vec<String> = meta.headers.iter().flat_map(|h| h.channels.list.iter().map(|c| c.name.to_string())).collect();
        if meta.headers.iter().all(|h| h.deep) { malformed("only deep data, which is not an image".into()) } else { Error::file(path, format!("has no R, G, B (or Y) channels, only {names:?}")) }
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
            format!("truncated OpenEXR: its header promises {w}×{h} pixels in {chunks} blocks, which take at least {} bytes, but the file has {len}", chunks * 16),
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
        exr::error::Error::Io(io) if io.kind() == std::io::ErrorKind::UnexpectedEof => Error::file(path, "truncated OpenEXR: the file ends before its last block"),
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
fn read_exr<R: std::io::BufRead + std::io::Seek>(
    path: &Path,
    mut reader: R,
    len: u64,
    weights: Weights,
    sanitize: bool,
    factor: u32,
) -> Result<(Equirect, InputReport)> {
    use exr::prelude::{ReadChannels, ReadLayers, ReadSpecificChannel};
    let header = exr_header(path, &mut reader, len)?;
    reader.seek(std::io::SeekFrom::Start(0)).map_err(|e| Error::file(path, format!("cannot read: {e}")))?;
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

/// Counts and fixes negative values, and refuses or sanitises NaN and ∞ (see the module
/// documentation), in place. Alpha is set to 1.
pub fn clean(path: &Path, texels: &mut [Vec4], sanitize: bool) -> Result<InputReport> {
    let mut reducer = Reducer::new(texels.len() as u32, 1, 1, Weights::EquirectRows, sanitize);
    for (i, t) in texels.iter().enumerate() {
        reducer.push(i as u32, 0, [t.x, t.y, t.z]);
    }
    let (image, report) = reducer.finish(path)?;
    texels.copy_from_slice(&image.texels);
    Ok(report)
}

/// How the input texels that one output texel covers are weighted.
#[derive(Copy, Clone, Debug)]
enum Weights {
    /// By the solid angle of their equirect row (`equirect::row_solid_angle`).
    EquirectRows,
    /// By their solid angle on a cube face (`cubemap::texel_solid_angle`).
    CubeFace,
}

/// An image received pixel by pixel, in any order (an EXR's blocks may arrive out of
/// order), cleaned as it comes (the module documentation's rules) and reduced by `factor`
/// in both axes: each output texel is the mean of the `factor²` input texels it covers,
/// weighted by their solid angle ([`Weights`]) and summed in f64. Only the output rows
/// still being filled hold sums, so memory is the output image plus a few rows, whatever
/// the input's size or however much of it a file really holds. At factor 1 nothing is
/// summed and no weight plays a part: texels are only cleaned.
struct Reducer {
    width: u32,
    height: u32,
    factor: u32,
    weights: Weights,
    sanitize: bool,
    out: Vec<Vec4>,
    /// f64 sums (r, g, b, weight) of the output rows being filled.
    pending: Vec<Option<Box<[f64]>>>,
    /// Input texels received per output row.
    arrived: Vec<u32>,
    /// Solid angle of each input row (equirects reduced by more than 1 only).
    row_weight: Vec<f64>,
    /// Per output texel, the weight of its inputs that were +∞ in each channel (made only
    /// when a +∞ arrives): replaced by the channel's largest finite value when the image
    /// is complete.
    infinite: Vec<[f64; 3]>,
    /// Texels with a +∞ channel and no other clamped value, by which channels are +∞ (bit
    /// k): counted as clamped at the end if such a channel's largest value is.
    infinite_masks: [u64; 8],
    channel_max: [f32; 3],
    report: InputReport,
}

impl Reducer {
    fn new(width: u32, height: u32, factor: u32, weights: Weights, sanitize: bool) -> Self {
        let factor = if width.is_multiple_of(factor) && height.is_multiple_of(factor) { factor.max(1) } else { 1 };
        let (ow, oh) = (width / factor, height / factor);
        let rows = factor > 1 && matches!(weights, Weights::EquirectRows);
        let row_weight = if rows { (0..height).map(|y| equirect::row_solid_angle(y, height) as f64).collect() } else { Vec::new() };
        Self {
            width,
            height,
            factor,
            weights,
            sanitize,
            out: vec![Vec4::ZERO; ow as usize * oh as usize],
            pending: (0..oh).map(|_| None).collect(),
            arrived: vec![0; oh as usize],
            row_weight,
            infinite: Vec::new(),
            infinite_masks: [0; 8],
            channel_max: [0.0; 3],
            report: InputReport { sanitized: sanitize, original: (width, height), ..Default::default() },
        }
    }

    /// The weight of input texel `(x, y)`.
    fn weight(&self, x: u32, y: u32) -> f64 {
        match self.weights {
            _ if self.factor == 1 => 1.0,
            Weights::EquirectRows => self.row_weight[y as usize],
            Weights::CubeFace => cubemap::texel_solid_angle(x, y, self.width) as f64,
        }
    }

    /// The total weight of output texel `(ox, oy)`'s inputs.
    fn block_weight(&self, ox: usize, oy: usize) -> f64 {
        let f = self.factor as usize;
        match self.weights {
            _ if f == 1 => 1.0,
            Weights::EquirectRows => self.row_weight[oy * f..(oy + 1) * f].iter().sum::<f64>() * f as f64,
            Weights::CubeFace => (0..f * f).map(|k| self.weight((ox * f + k % f) as u32, (oy * f + k / f) as u32)).sum(),
        }
    }

    fn push(&mut self, x: u32, y: u32, rgb: [f32; 3]) {
        if x >= self.width || y >= self.height {
            return;
        }
        let f = self.factor;
        let ow = (self.width / f) as usize;
        let (ox, oy) = ((x / f) as usize, (y / f) as usize);
        let mut c = rgb;
        let mut infinite = [false; 3];
        if c.iter().any(|v| v.is_nan()) {
            self.report.nan += 1;
        } else if c.iter().any(|v| v.is_infinite()) {
            self.report.infinite += 1;
        }
        let (mut negative, mut clamped) = (false, false);
        for k in 0..3 {
            if c[k].is_finite() {
                self.channel_max[k] = self.channel_max[k].max(c[k]);
            }
            if c[k].is_nan() || c[k] == f32::NEG_INFINITY {
                c[k] = 0.0;
            } else if c[k] == f32::INFINITY {
                c[k] = 0.0;
                infinite[k] = true;
            } else if c[k] < 0.0 {
                c[k] = 0.0;
                negative = true;
            }
            if c[k] > MAX_RADIANCE {
                c[k] = MAX_RADIANCE;
                clamped = true;
            }
        }
        self.report.negative += negative as u64;
        self.report.clamped += clamped as u64;
        let w = self.weight(x, y);
        let mask = (infinite[0] as usize) | (infinite[1] as usize) << 1 | (infinite[2] as usize) << 2;
        if mask != 0 {
            if self.infinite.is_empty() {
                self.infinite = vec![[0.0; 3]; self.out.len()];
            }
            for k in (0..3).filter(|k| infinite[*k]) {
                self.infinite[oy * ow + ox][k] += w;
            }
            if !clamped {
                self.infinite_masks[mask] += 1;
            }
        }
        if f == 1 {
            self.out[oy * ow + ox] = Vec4::new(c[0], c[1], c[2], 1.0);
        } else {
            let row = self.pending[oy].get_or_insert_with(|| vec![0.0; 4 * ow].into_boxed_slice());
            for k in 0..3 {
                row[4 * ox + k] += c[k] as f64 * w;
            }
            row[4 * ox + 3] += w;
        }
        self.arrived[oy] += 1;
        if f > 1 && self.arrived[oy] == f * self.width {
            self.resolve_row(oy);
        }
    }

    fn resolve_row(&mut self, oy: usize) {
        let ow = (self.width / self.factor) as usize;
        if let Some(row) = self.pending[oy].take() {
            for ox in 0..ow {
                let w = row[4 * ox + 3];
                let m = |k: usize| if w > 0.0 { (row[4 * ox + k] / w) as f32 } else { 0.0 };
                self.out[oy * ow + ox] = Vec4::new(m(0), m(1), m(2), 1.0);
            }
        }
    }

    fn finish(mut self, path: &Path) -> Result<(Equirect, InputReport)> {
        if (self.report.nan > 0 || self.report.infinite > 0) && !self.sanitize {
            return Err(Error::NonFinite { path: path.to_path_buf(), nan: self.report.nan, infinite: self.report.infinite });
        }
        let (ow, oh) = (self.width / self.factor, self.height / self.factor);
        for oy in 0..oh as usize {
            if self.pending[oy].is_some() {
                // Rows of a file that held fewer texels than its header promised.
                self.resolve_row(oy);
            }
        }
        let infinite = std::mem::take(&mut self.infinite);
        for (texel, weights) in infinite.iter().enumerate().filter(|(_, w)| w.iter().any(|&v| v > 0.0)) {
            let (ox, oy) = (texel % ow as usize, texel / ow as usize);
            let total = self.block_weight(ox, oy);
            for k in 0..3 {
                let max = self.channel_max[k].min(MAX_RADIANCE);
                let t = &mut self.out[texel];
                t[k] = (t[k] as f64 + max as f64 * weights[k] / total) as f32;
            }
        }
        for (mask, &count) in self.infinite_masks.iter().enumerate() {
            if (0..3).any(|k| mask & (1 << k) != 0 && self.channel_max[k] > MAX_RADIANCE) {
                self.report.clamped += count;
            }
        }
        self.report.max_value = self.channel_max.iter().copied().fold(0.0, f32::max);
        Ok((Equirect { width: ow, height: oh, texels: self.out }, self.report))
    }
}

/// The environment `runner` shows when given none: Greg Zaal's "courtyard" (CC0, see
/// `assets/LICENSE.md`), embedded in the binary with the `embedded-environment` feature.
#[cfg(feature = "embedded-environment")]
pub static EMBEDDED_DEFAULT: &[u8] = include_bytes!("../assets/courtyard.exr");

/// Decodes [`EMBEDDED_DEFAULT`].
#[cfg(feature = "embedded-environment")]
pub fn embedded_default() -> Result<Environment> {
    let path = Path::new("<embedded courtyard.exr>");
    let (image, _) = read_exr(path, std::io::Cursor::new(EMBEDDED_DEFAULT), EMBEDDED_DEFAULT.len() as u64, Weights::EquirectRows, false, 1)?;
    Ok(Environment::Equirect(image))
}

/// What identifies an environment for the bake cache: the BLAKE3 hash of the file's bytes,
/// of a face folder's six files in order, or of the embedded default, read in a stream.
pub fn identity(path: Option<&Path>) -> Result<[u8; 32]> {
    let mut h = blake3::Hasher::new();
    match path {
        #[cfg(feature = "embedded-environment")]
        None => {
            h.update(EMBEDDED_DEFAULT);
        }
        #[cfg(not(feature = "embedded-environment"))]
        None => return Err(Error::Invalid("no environment given, and splitsum was built without the embedded default (feature embedded-environment)".into())),
        Some(p) => {
            let files = if p.is_dir() { face_paths(p)?.to_vec() } else { vec![p.to_path_buf()] };
            for f in files {
                let file = std::fs::File::open(&f).map_err(|e| Error::file(&f, format!("cannot read: {e}")))?;
                h.update_reader(file).map_err(|e| Error::file(&f, format!("cannot read: {e}")))?;
            }
        }
    }
    Ok(*h.finalize().as_bytes())
}
