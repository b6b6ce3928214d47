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

use crate::error::{Error, Result};
use crate::texture::{Cube, Equirect};
use splitsum_shaders::cubemap::CubeLayout;
use splitsum_shaders::glam::Vec4;
use splitsum_shaders::math::MAX_RADIANCE;
use std::path::{Path, PathBuf};

/// Largest image side accepted (a 32768×16384 RGBA f32 equirect is 8 GiB).
pub const MAX_SIDE: u32 = 32768;
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
}

/// Face file names of a cube map folder, in KTX2/Vulkan face order.
pub const FACE_NAMES: [&str; 6] = ["px", "nx", "py", "ny", "pz", "nz"];

/// Reads an environment: a `.hdr`/`.exr` equirect file, or a folder holding six faces
/// `px nx py ny pz nz` (`.hdr` or `.exr`) in Vulkan/KTX2 orientation.
pub fn load(path: &Path, sanitize: bool) -> Result<(Environment, InputReport)> {
    if path.is_dir() {
        let faces = face_paths(path)?;
        return load_faces(&faces, sanitize);
    }
    let (width, height, mut texels) = read_image(path)?;
    check_equirect_shape(path, width, height)?;
    let report = clean(path, &mut texels, sanitize)?;
    Ok((Environment::Equirect(Equirect { width, height, texels }), report))
}

/// The six face files of a cube map folder.
pub fn face_paths(dir: &Path) -> Result<[PathBuf; 6]> {
    let find = |name: &str| -> Result<PathBuf> {
        for ext in ["exr", "hdr"] {
            let p = dir.join(format!("{name}.{ext}"));
            if p.is_file() {
                return Ok(p);
            }
        }
        Err(Error::file(dir, format!("no face `{name}.exr` or `{name}.hdr` (a cube map folder needs px nx py ny pz nz)")))
    };
    Ok([find("px")?, find("nx")?, find("py")?, find("ny")?, find("pz")?, find("nz")?])
}

/// Reads six square, equally sized, power-of-two faces into a one-level cube.
pub fn load_faces(paths: &[PathBuf; 6], sanitize: bool) -> Result<(Environment, InputReport)> {
    let mut size = 0;
    let mut all = Vec::new();
    let mut report = InputReport { sanitized: sanitize, ..Default::default() };
    for p in paths {
        let (w, h, mut t) = read_image(p)?;
        if w != h {
            return Err(Error::file(p, format!("a cube face must be square, this one is {w}×{h}")));
        }
        if !w.is_power_of_two() {
            return Err(Error::file(p, format!("a cube face must be a power of two wide, this one is {w}")));
        }
        if size == 0 {
            size = w;
        } else if w != size {
            return Err(Error::file(p, format!("is {w}×{w} but the first face is {size}×{size}")));
        }
        let r = clean(p, &mut t, sanitize)?;
        report.negative += r.negative;
        report.clamped += r.clamped;
        report.nan += r.nan;
        report.infinite += r.infinite;
        report.max_value = report.max_value.max(r.max_value);
        all.extend(t);
    }
    Ok((Environment::Cube(Cube { layout: CubeLayout::new(size, 1), texels: all }), report))
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

/// Reads an `.hdr` or `.exr` image as RGBA f32 (alpha 1), row 0 at the top.
pub fn read_image(path: &Path) -> Result<(u32, u32, Vec<Vec4>)> {
    let bytes = std::fs::read(path).map_err(|e| Error::file(path, format!("cannot read: {e}")))?;
    if bytes.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
        read_exr(path, &bytes)
    } else if bytes.starts_with(b"#?") {
        read_hdr(path, &bytes)
    } else if bytes.is_empty() {
        Err(Error::file(path, "is empty"))
    } else {
        Err(Error::file(path, "is neither an OpenEXR nor a Radiance HDR file (unknown signature)"))
    }
}

fn read_hdr(path: &Path, bytes: &[u8]) -> Result<(u32, u32, Vec<Vec4>)> {
    use image::ImageDecoder;
    let decoder = image::codecs::hdr::HdrDecoder::new(std::io::Cursor::new(bytes)).map_err(|e| Error::file(path, format!("malformed Radiance HDR: {e}")))?;
    let (w, h) = decoder.dimensions();
    check_side(path, w, h)?;
    let mut buf = vec![0u8; decoder.total_bytes() as usize];
    decoder.read_image(&mut buf).map_err(|e| Error::file(path, format!("truncated or malformed Radiance HDR: {e}")))?;
    let rgb: Vec<f32> = bytemuck::pod_collect_to_vec(&buf);
    Ok((w, h, rgb.chunks_exact(3).map(|c| Vec4::new(c[0], c[1], c[2], 1.0)).collect()))
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

fn read_exr(path: &Path, bytes: &[u8]) -> Result<(u32, u32, Vec<Vec4>)> {
    use exr::prelude::{AnyChannel, FlatSamples, ReadChannels, ReadLayers};
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_buffered(std::io::Cursor::new(bytes))
        .map_err(|e| Error::file(path, format!("truncated or malformed OpenEXR: {e}")))?;
    let layer = &image.layer_data;
    let size = layer.size;
    let (w, h) = (size.width() as u32, size.height() as u32);
    check_side(path, w, h)?;
    let channel = |names: &[&str]| {
        layer.channel_data.list.iter().find(|c| {
            let n = c.name.to_string();
            let base = n.rsplit('.').next().unwrap_or(&n).to_string();
            names.iter().any(|x| base.eq_ignore_ascii_case(x))
        })
    };
    let n = (w * h) as usize;
    let values = |c: &AnyChannel<FlatSamples>| -> Vec<f32> { c.sample_data.values_as_f32().collect() };
    let (r, g, b) = match (channel(&["R", "red"]), channel(&["G", "green"]), channel(&["B", "blue"])) {
        (Some(r), Some(g), Some(b)) => (values(r), values(g), values(b)),
        _ => match channel(&["Y", "L"]) {
            Some(y) => {
                let y = values(y);
                (y.clone(), y.clone(), y)
            }
            None => {
                let names: Vec<String> = layer.channel_data.list.iter().map(|c| c.name.to_string()).collect();
                return Err(Error::file(path, format!("has no R, G, B (or Y) channels, only {names:?}")));
            }
        },
    };
    if r.len() != n || g.len() != n || b.len() != n {
        return Err(Error::file(path, "channels are subsampled, which is not supported"));
    }
    Ok((w, h, (0..n).map(|i| Vec4::new(r[i], g[i], b[i], 1.0)).collect()))
}

/// Counts and fixes negative values, and refuses or sanitises NaN and ∞ (see the module
/// documentation). Alpha is set to 1.
pub fn clean(path: &Path, texels: &mut [Vec4], sanitize: bool) -> Result<InputReport> {
    let mut report = InputReport { sanitized: sanitize, ..Default::default() };
    let mut channel_max = [0.0f32; 3];
    for t in texels.iter() {
        let c = [t.x, t.y, t.z];
        if c.iter().any(|v| v.is_nan()) {
            report.nan += 1;
        } else if c.iter().any(|v| v.is_infinite()) {
            report.infinite += 1;
        }
        for k in 0..3 {
            if c[k].is_finite() {
                channel_max[k] = channel_max[k].max(c[k]);
            }
        }
    }
    if (report.nan > 0 || report.infinite > 0) && !sanitize {
        return Err(Error::file(
            path,
            format!(
                "has {} texels with NaN and {} with an infinite value; pass --sanitize to replace NaN and -inf by 0 and +inf by the channel's largest finite value",
                report.nan, report.infinite
            ),
        ));
    }
    for t in texels.iter_mut() {
        let mut c = [t.x, t.y, t.z];
        let mut negative = false;
        let mut clamped = false;
        for k in 0..3 {
            if c[k].is_nan() || c[k] == f32::NEG_INFINITY {
                c[k] = 0.0;
            } else if c[k] == f32::INFINITY {
                c[k] = channel_max[k];
            } else if c[k] < 0.0 {
                c[k] = 0.0;
                negative = true;
            }
            if c[k] > MAX_RADIANCE {
                c[k] = MAX_RADIANCE;
                clamped = true;
            }
        }
        report.negative += negative as u64;
        report.clamped += clamped as u64;
        *t = Vec4::new(c[0], c[1], c[2], 1.0);
    }
    report.max_value = channel_max.iter().copied().fold(0.0, f32::max);
    Ok(report)
}

/// The environment `runner` shows when given none: Greg Zaal's "courtyard" (CC0, see
/// `assets/environments/LICENSE.md`), embedded in the binary.
pub static EMBEDDED_DEFAULT: &[u8] = include_bytes!("../../assets/environments/courtyard.exr");

/// Decodes [`EMBEDDED_DEFAULT`].
pub fn embedded_default() -> Result<Environment> {
    let path = Path::new("<embedded courtyard.exr>");
    let (width, height, mut texels) = read_exr(path, EMBEDDED_DEFAULT)?;
    clean(path, &mut texels, false)?;
    Ok(Environment::Equirect(Equirect { width, height, texels }))
}

/// The bytes that identify an environment for the bake cache: the file's bytes, a face
/// folder's six files in order, or the embedded default.
pub fn identity_bytes(path: Option<&Path>) -> Result<Vec<u8>> {
    match path {
        None => Ok(EMBEDDED_DEFAULT.to_vec()),
        Some(p) if p.is_dir() => {
            let mut all = Vec::new();
            for f in face_paths(p)? {
                all.extend(std::fs::read(&f).map_err(|e| Error::file(&f, format!("cannot read: {e}")))?);
            }
            Ok(all)
        }
        Some(p) => std::fs::read(p).map_err(|e| Error::file(p, format!("cannot read: {e}"))),
    }
}
