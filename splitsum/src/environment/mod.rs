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
use splitsum_shaders::cubemap::CubeLayout;
use splitsum_shaders::equirect;
use splitsum_shaders::glam::Vec4;
use splitsum_shaders::math::MAX_RADIANCE;
use std::path::{Path, PathBuf};

mod openexr;
mod radiance;
mod reduce;
use openexr::{exr_header, read_exr};
use radiance::{check_hdr_length, read_hdr, read_hdr_from, rgbe};
use reduce::{Reducer, Weights};

/// Largest image side accepted (a 32768×16384 RGBA f32 equirect is 8 GiB).
pub const MAX_SIDE: u32 = 32768;
/// Largest cube face accepted (faces are reduced as they are decoded, as equirects are).
pub const MAX_FACE: u32 = MAX_SIDE;
/// Smallest equirect accepted.
pub(crate) const MIN_WIDTH: u32 = 8;

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
    /// width, as a power of two, at most 1024).
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
    /// The cube face size the environment was read for.
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
            InputShape::Equirect { width, height } if width < w => {
                out.push(Adjustment::Reduced { from: (w, h), to: (width, height), source_size: self.read_for })
            }
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

internal! {
    /// The largest cube face the display and the planner build from an environment (see
    /// `Environment::native_face_size`): what [`load`] reads an environment for.
    pub const NATIVE_FACE: u32 = 1024;
}

/// Reads an environment for cubes of faces up to 1024 wide.
pub fn load(path: &Path, sanitize: bool) -> Result<(Environment, InputReport)> {
    load_for(path, sanitize, NATIVE_FACE)
}

internal! {
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
}

/// Reads an equirect `.hdr` or `.exr` file held in memory (`bytes`, a file called `name`:
/// dropped on a web page) as [`load`] reads one from disk: the same checks, reduced to the
/// resolution a 1024-wide cube face resolves as it is decoded.
pub fn read_bytes(name: &str, bytes: &[u8], sanitize: bool) -> Result<(Environment, InputReport)> {
    let path = Path::new(name);
    let len = bytes.len() as u64;
    let kind = match bytes {
        [0x76, 0x2f, 0x31, 0x01, ..] => Kind::Exr,
        [b'#', b'?', ..] => Kind::Hdr,
        [] => return Err(Error::file(path, "is empty")),
        _ => return Err(Error::file(path, "is neither an OpenEXR nor a Radiance HDR file (unknown signature)")),
    };
    let (width, height) = match kind {
        Kind::Exr => exr_header(path, &mut std::io::Cursor::new(bytes), len)?.size,
        Kind::Hdr => rgbe::header(path, &mut std::io::Cursor::new(bytes))?,
    };
    check_equirect_shape(path, width, height)?;
    let factor = equirect::reduction_factor(width, height, NATIVE_FACE);
    let (image, report) = match kind {
        Kind::Exr => read_exr(path, std::io::Cursor::new(bytes), len, Weights::EquirectRows, sanitize, factor)?,
        Kind::Hdr => read_hdr_from(path, std::io::Cursor::new(bytes), len, Weights::EquirectRows, sanitize, factor)?,
    };
    Ok((Environment::Equirect(image), InputReport { read_for: NATIVE_FACE, ..report }))
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
                Err(e) => return Err(Error::file_caused(&p, "cannot read", e)),
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
    let mut f = std::fs::File::open(path).map_err(|e| Error::file_caused(path, "cannot read", e))?;
    let n = f.read(&mut head).map_err(|e| Error::file_caused(path, "cannot read", e))?;
    match &head[..n] {
        [0x76, 0x2f, 0x31, 0x01] => Ok(Kind::Exr),
        [b'#', b'?', ..] => Ok(Kind::Hdr),
        [] => Err(Error::file(path, "is empty")),
        _ => Err(Error::file(path, "is neither an OpenEXR nor a Radiance HDR file (unknown signature)")),
    }
}

fn file_len(path: &Path) -> Result<u64> {
    std::fs::metadata(path).map(|m| m.len()).map_err(|e| Error::file_caused(path, "cannot read", e))
}

internal! {
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
}

fn buffered(path: &Path) -> Result<std::io::BufReader<std::fs::File>> {
    Ok(std::io::BufReader::new(std::fs::File::open(path).map_err(|e| Error::file_caused(path, "cannot read", e))?))
}

internal! {
    /// Reads an `.hdr` or `.exr` equirect as RGBA f32 (alpha 1), row 0 at the top, reduced by
    /// `factor` (area-weighted, as it is decoded) and cleaned ([`clean`]'s rules).
    pub fn read_reduced(path: &Path, sanitize: bool, factor: u32) -> Result<(Equirect, InputReport)> {
        read_with(path, Weights::EquirectRows, sanitize, factor)
    }
}

/// Reads an `.hdr` or `.exr` image reduced by `factor`, its texels weighted by `weights`.
fn read_with(path: &Path, weights: Weights, sanitize: bool, factor: u32) -> Result<(Equirect, InputReport)> {
    match kind(path)? {
        Kind::Exr => read_exr(path, buffered(path)?, file_len(path)?, weights, sanitize, factor),
        Kind::Hdr => read_hdr(path, weights, sanitize, factor),
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

internal! {
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
}

/// The environment `runner` shows when given none: Greg Zaal's "courtyard" (CC0, see
/// `assets/LICENSE.md`), embedded in the binary with the `embedded-environment` feature.
#[cfg(feature = "embedded-environment")]
pub static EMBEDDED_DEFAULT: &[u8] = include_bytes!("../../assets/courtyard.exr");

/// Decodes [`EMBEDDED_DEFAULT`].
#[cfg(feature = "embedded-environment")]
pub fn embedded_default() -> Result<Environment> {
    let path = Path::new("<embedded courtyard.exr>");
    let (image, _) = read_exr(path, std::io::Cursor::new(EMBEDDED_DEFAULT), EMBEDDED_DEFAULT.len() as u64, Weights::EquirectRows, false, 1)?;
    Ok(Environment::Equirect(image))
}

internal! {
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
                    let file = std::fs::File::open(&f).map_err(|e| Error::file_caused(&f, "cannot read", e))?;
                    h.update_reader(file).map_err(|e| Error::file_caused(&f, "cannot read", e))?;
                }
            }
        }
        Ok(*h.finalize().as_bytes())
    }
}
