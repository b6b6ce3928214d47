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
use splitsum_shaders::cubemap::{self, CubeLayout};
use splitsum_shaders::equirect;
use splitsum_shaders::glam::Vec4;
use splitsum_shaders::math::MAX_RADIANCE;
use std::path::{Path, PathBuf};

/// Largest image side accepted (a 32768×16384 RGBA f32 equirect is 8 GiB).
pub const MAX_SIDE: u32 = 32768;
/// Largest cube face accepted (a face is read whole before it is reduced: 1 GiB at 8192²).
pub const MAX_FACE: u32 = 8192;
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
        match self {
            Environment::Equirect(e) => (e.width / 4).max(8).next_power_of_two().min(NATIVE_FACE),
            Environment::Cube(c) => c.layout.size.min(NATIVE_FACE),
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
}

impl InputReport {
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
        return load_faces(&faces, sanitize, face);
    }
    let (width, height) = dimensions(path)?;
    check_equirect_shape(path, width, height)?;
    let factor = equirect::reduction_factor(width, height, face);
    let (image, report) = read_reduced(path, sanitize, factor)?;
    Ok((Environment::Equirect(image), report))
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

/// Reads six square, equally sized, power-of-two faces into a one-level cube, each reduced
/// to `face` wide (if wider) by the cube's solid-angle-weighted 2×2 filter
/// (`cubemap::downsample_texel`, the same arithmetic as the source cube's mips), one face
/// at a time.
pub fn load_faces(paths: &[PathBuf; 6], sanitize: bool, face: u32) -> Result<(Environment, InputReport)> {
    let mut size = 0;
    let mut all = Vec::new();
    let mut report = InputReport { sanitized: sanitize, ..Default::default() };
    for p in paths {
        let (w, h) = dimensions(p)?;
        if w != h {
            return Err(Error::file(p, format!("a cube face must be square, this one is {w}×{h}")));
        }
        if w > MAX_FACE {
            return Err(Error::file(
                p,
                format!(
                    "a cube face may be at most {MAX_FACE}² (each face is read whole, {} MiB at that size), this one is {w}²",
                    (MAX_FACE as u64).pow(2) * 16 >> 20
                ),
            ));
        }
        if !w.is_power_of_two() {
            return Err(Error::file(p, format!("a cube face must be a power of two wide, this one is {w}")));
        }
        if size == 0 {
            size = w;
        } else if w != size {
            return Err(Error::file(p, format!("is {w}×{w} but the first face is {size}×{size}")));
        }
        let (img, r) = read_reduced(p, sanitize, 1)?;
        report.add(&r);
        let mut texels = img.texels;
        let mut s = w;
        while s > face.max(1) {
            let layout = CubeLayout::new(s, 1);
            let h = s / 2;
            texels = (0..h * h).map(|i| cubemap::downsample_texel(&texels, layout, 0, 0, i % h, i / h)).collect();
            s = h;
        }
        all.extend(texels);
    }
    report.original = (size, size);
    let size = size.min(face.max(1));
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

/// Width and height of an `.hdr` or `.exr` image, from its header alone.
pub fn dimensions(path: &Path) -> Result<(u32, u32)> {
    let (w, h) = match kind(path)? {
        Kind::Exr => {
            let meta = exr::meta::MetaData::read_from_file(path, false).map_err(|e| Error::file(path, format!("truncated or malformed OpenEXR: {e}")))?;
            let header = meta.headers.first().ok_or_else(|| Error::file(path, "malformed OpenEXR: no header"))?;
            let size = header.layer_size;
            (size.width().min(u32::MAX as usize) as u32, size.height().min(u32::MAX as usize) as u32)
        }
        Kind::Hdr => rgbe::header(path, &mut buffered(path)?)?,
    };
    check_side(path, w, h)?;
    Ok((w, h))
}

fn buffered(path: &Path) -> Result<std::io::BufReader<std::fs::File>> {
    Ok(std::io::BufReader::new(std::fs::File::open(path).map_err(|e| Error::file(path, format!("cannot read: {e}")))?))
}

/// Reads an `.hdr` or `.exr` image as RGBA f32 (alpha 1), row 0 at the top, reduced by
/// `factor` as an equirect (`Reducer`) and cleaned ([`clean`]'s rules).
pub fn read_reduced(path: &Path, sanitize: bool, factor: u32) -> Result<(Equirect, InputReport)> {
    match kind(path)? {
        Kind::Exr => read_exr(path, buffered(path)?, sanitize, factor),
        Kind::Hdr => read_hdr(path, sanitize, factor),
    }
}

/// A Radiance `.hdr` file, decoded scanline by scanline into a [`Reducer`] ([`rgbe`]).
fn read_hdr(path: &Path, sanitize: bool, factor: u32) -> Result<(Equirect, InputReport)> {
    let mut r = buffered(path)?;
    let (w, h) = rgbe::header(path, &mut r)?;
    check_side(path, w, h)?;
    // Every scanline takes at least 4 bytes: refuse a header that promises more rows than
    // the file can hold before allocating for them.
    let len = std::fs::metadata(path).map(|m| m.len()).unwrap_or(0);
    if len < 4 * h as u64 {
        return Err(Error::file(path, format!("truncated Radiance HDR: {len} bytes cannot hold {h} scanlines")));
    }
    let mut reducer = Reducer::new(w, h, factor, sanitize);
    let mut line = vec![[0u8; 4]; w as usize];
    for y in 0..h {
        rgbe::scanline(&mut r, &mut line).map_err(|e| Error::file(path, format!("truncated or malformed Radiance HDR (row {y}): {e}")))?;
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

    /// Reads the header and the resolution line: `(width, height)`.
    pub fn header(path: &Path, r: &mut impl BufRead) -> Result<(u32, u32)> {
        let bad = |why: String| Error::file(path, format!("malformed Radiance HDR: {why}"));
        let mut line = String::new();
        let mut first = true;
        loop {
            line.clear();
            let n = r.by_ref().take(4096).read_line(&mut line).map_err(|e| bad(e.to_string()))?;
            if n == 0 {
                return Err(bad("the header never ends (no empty line)".into()));
            }
            let l = line.trim_end_matches(['\n', '\r']);
            if first && !l.starts_with("#?") {
                return Err(bad("no #? signature".into()));
            }
            first = false;
            if let Some(format) = l.strip_prefix("FORMAT=") {
                if format.trim() != "32-bit_rle_rgbe" {
                    return Err(bad(format!("FORMAT={format} is not supported (only 32-bit_rle_rgbe)")));
                }
            }
            if l.is_empty() {
                break;
            }
        }
        line.clear();
        r.by_ref().take(256).read_line(&mut line).map_err(|e| bad(e.to_string()))?;
        let f: Vec<&str> = line.split_whitespace().collect();
        match f.as_slice() {
            ["-Y", h, "+X", w] => match (h.parse::<u32>(), w.parse::<u32>()) {
                (Ok(h), Ok(w)) => Ok((w, h)),
                _ => Err(bad(format!("unreadable resolution line {:?}", line.trim_end()))),
            },
            _ => Err(bad(format!("resolution line {:?}: only the standard orientation -Y H +X W is supported", line.trim_end()))),
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

/// An OpenEXR file's R, G, B channels, streamed block by block into a [`Reducer`]; files
/// without plain `R`, `G`, `B` channels (luminance `Y`, or layer-prefixed names) are read
/// whole ([`read_exr_channels`]).
fn read_exr(path: &Path, reader: impl std::io::Read + std::io::Seek, sanitize: bool, factor: u32) -> Result<(Equirect, InputReport)> {
    use exr::prelude::{ReadChannels, ReadLayers, ReadSpecificChannel};
    let streamed = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .specific_channels()
        .required("R")
        .required("G")
        .required("B")
        .collect_pixels(
            |size: exr::math::Vec2<usize>, _: &_| {
                let (w, h) = (size.width() as u32, size.height() as u32);
                (w > 0 && h > 0 && w <= MAX_SIDE && h <= MAX_SIDE).then(|| Reducer::new(w, h, factor, sanitize))
            },
            |r: &mut Option<Reducer>, pos: exr::math::Vec2<usize>, (red, green, blue): (f32, f32, f32)| {
                if let Some(r) = r {
                    r.push(pos.x() as u32, pos.y() as u32, [red, green, blue]);
                }
            },
        )
        .first_valid_layer()
        .all_attributes()
        .from_buffered(reader);
    match streamed {
        Ok(image) => match image.layer_data.channel_data.pixels {
            Some(reducer) => reducer.finish(path),
            None => {
                let size = image.layer_data.size;
                check_side(path, size.width().min(u32::MAX as usize) as u32, size.height().min(u32::MAX as usize) as u32)?;
                Err(Error::file(path, "malformed OpenEXR: no pixels"))
            }
        },
        Err(exr::error::Error::Invalid(_)) | Err(exr::error::Error::NotSupported(_)) => read_exr_channels(path, sanitize, factor),
        Err(e) => Err(Error::file(path, format!("truncated or malformed OpenEXR: {e}"))),
    }
}

/// An OpenEXR file read whole, every channel, then R, G, B (matched by the last part of
/// their names) or Y.
fn read_exr_channels(path: &Path, sanitize: bool, factor: u32) -> Result<(Equirect, InputReport)> {
    exr_channels(path, buffered(path)?, sanitize, factor)
}

fn exr_channels(path: &Path, reader: impl std::io::Read + std::io::Seek, sanitize: bool, factor: u32) -> Result<(Equirect, InputReport)> {
    use exr::prelude::{AnyChannel, FlatSamples, ReadChannels, ReadLayers};
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_buffered(reader)
        .map_err(|e| Error::file(path, format!("truncated or malformed OpenEXR: {e}")))?;
    let layer = &image.layer_data;
    let size = layer.size;
    let (w, h) = (size.width().min(u32::MAX as usize) as u32, size.height().min(u32::MAX as usize) as u32);
    check_side(path, w, h)?;
    let channel = |names: &[&str]| {
        layer.channel_data.list.iter().find(|c| {
            let n = c.name.to_string();
            let base = n.rsplit('.').next().unwrap_or(&n).to_string();
            names.iter().any(|x| base.eq_ignore_ascii_case(x))
        })
    };
    let n = (w as usize) * (h as usize);
    let at = |c: &AnyChannel<FlatSamples>, i: usize| -> f32 { c.sample_data.value_by_flat_index(i).to_f32() };
    let (r, g, b) = match (channel(&["R", "red"]), channel(&["G", "green"]), channel(&["B", "blue"])) {
        (Some(r), Some(g), Some(b)) => (r, g, b),
        _ => match channel(&["Y", "L"]) {
            Some(y) => (y, y, y),
            None => {
                let names: Vec<String> = layer.channel_data.list.iter().map(|c| c.name.to_string()).collect();
                return Err(Error::file(path, format!("has no R, G, B (or Y) channels, only {names:?}")));
            }
        },
    };
    if [r, g, b].iter().any(|c| c.sample_data.len() != n) {
        return Err(Error::file(path, "channels are subsampled, which is not supported"));
    }
    let mut reducer = Reducer::new(w, h, factor, sanitize);
    for i in 0..n {
        reducer.push((i % w as usize) as u32, (i / w as usize) as u32, [at(r, i), at(g, i), at(b, i)]);
    }
    reducer.finish(path)
}

/// Counts and fixes negative values, and refuses or sanitises NaN and ∞ (see the module
/// documentation), in place. Alpha is set to 1.
pub fn clean(path: &Path, texels: &mut [Vec4], sanitize: bool) -> Result<InputReport> {
    let mut reducer = Reducer::new(texels.len() as u32, 1, 1, sanitize);
    for (i, t) in texels.iter().enumerate() {
        reducer.push(i as u32, 0, [t.x, t.y, t.z]);
    }
    let (image, report) = reducer.finish(path)?;
    texels.copy_from_slice(&image.texels);
    Ok(report)
}

/// An equirect image received pixel by pixel, in any order (an EXR's blocks may arrive
/// out of order), cleaned as it comes (the module documentation's rules) and reduced by
/// `factor` in both axes: each output texel is the solid-angle-weighted mean
/// (`equirect::row_solid_angle`) of the `factor²` input texels it covers, summed in f64.
/// Only the output rows still being filled hold f64 sums, so memory is the output image
/// plus a few rows, whatever the input's size. At factor 1 nothing is summed and no weight
/// plays a part: texels are only cleaned (a plain list of texels, a cube face).
struct Reducer {
    width: u32,
    height: u32,
    factor: u32,
    sanitize: bool,
    out: Vec<Vec4>,
    /// f64 sums (r, g, b) of the output rows being filled.
    pending: Vec<Option<Box<[f64]>>>,
    /// Input texels received per output row.
    arrived: Vec<u32>,
    /// Solid angle of each input row (empty at factor 1, where nothing is summed).
    row_weight: Vec<f64>,
    /// (output texel, channels that are +∞ (bit k), weight, already counted as clamped) of
    /// each input with a +∞ channel: replaced by the channel's largest finite value when the
    /// image is complete (and counted as clamped if that value is).
    infinite: Vec<(u32, u8, f64, bool)>,
    channel_max: [f32; 3],
    report: InputReport,
}

impl Reducer {
    fn new(width: u32, height: u32, factor: u32, sanitize: bool) -> Self {
        let factor = if width % factor == 0 && height % factor == 0 { factor.max(1) } else { 1 };
        let (ow, oh) = (width / factor, height / factor);
        let row_weight = if factor > 1 { (0..height).map(|y| equirect::row_solid_angle(y, height) as f64).collect() } else { Vec::new() };
        Self {
            width,
            height,
            factor,
            sanitize,
            out: vec![Vec4::ZERO; ow as usize * oh as usize],
            pending: (0..oh).map(|_| None).collect(),
            arrived: vec![0; oh as usize],
            row_weight,
            infinite: Vec::new(),
            channel_max: [0.0; 3],
            report: InputReport { sanitized: sanitize, original: (width, height), ..Default::default() },
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
        let w = if f == 1 { 1.0 } else { self.row_weight[y as usize] };
        let mask = (infinite[0] as u8) | (infinite[1] as u8) << 1 | (infinite[2] as u8) << 2;
        if mask != 0 {
            self.infinite.push(((oy * ow + ox) as u32, mask, w, clamped));
        }
        if f == 1 {
            self.out[oy * ow + ox] = Vec4::new(c[0], c[1], c[2], 1.0);
        } else {
            let row = self.pending[oy].get_or_insert_with(|| vec![0.0; 3 * ow].into_boxed_slice());
            for k in 0..3 {
                row[3 * ox + k] += c[k] as f64 * w;
            }
        }
        self.arrived[oy] += 1;
        if f > 1 && self.arrived[oy] == f * self.width {
            self.resolve_row(oy);
        }
    }

    /// The total weight of one output texel of row `oy`.
    fn texel_weight(&self, oy: usize) -> f64 {
        let f = self.factor as usize;
        self.row_weight[oy * f..(oy + 1) * f].iter().sum::<f64>() * f as f64
    }

    fn resolve_row(&mut self, oy: usize) {
        let ow = (self.width / self.factor) as usize;
        let total = self.texel_weight(oy);
        if let Some(row) = self.pending[oy].take() {
            for ox in 0..ow {
                let m = |k: usize| (row[3 * ox + k] / total) as f32;
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
                // Texels never received (a truncated block) count as black.
                self.resolve_row(oy);
            }
        }
        let f = self.factor as usize;
        for &(texel, mask, w, counted) in &self.infinite {
            let oy = texel as usize / ow as usize;
            let share = if f == 1 { 1.0 } else { w / self.texel_weight(oy) };
            let mut clamped = false;
            for k in (0..3).filter(|k| mask & (1 << k) != 0) {
                clamped |= self.channel_max[k] > MAX_RADIANCE;
                let max = self.channel_max[k].min(MAX_RADIANCE);
                let t = &mut self.out[texel as usize];
                t[k] = (t[k] as f64 + max as f64 * share) as f32;
            }
            self.report.clamped += (clamped && !counted) as u64;
        }
        self.report.max_value = self.channel_max.iter().copied().fold(0.0, f32::max);
        Ok((Equirect { width: ow, height: oh, texels: self.out }, self.report))
    }
}

/// The environment `runner` shows when given none: Greg Zaal's "courtyard" (CC0, see
/// `assets/environments/LICENSE.md`), embedded in the binary.
pub static EMBEDDED_DEFAULT: &[u8] = include_bytes!("../../assets/environments/courtyard.exr");

/// Decodes [`EMBEDDED_DEFAULT`].
pub fn embedded_default() -> Result<Environment> {
    let path = Path::new("<embedded courtyard.exr>");
    let (image, _) = exr_channels(path, std::io::Cursor::new(EMBEDDED_DEFAULT), false, 1)?;
    Ok(Environment::Equirect(image))
}

/// What identifies an environment for the bake cache: the BLAKE3 hash of the file's bytes,
/// of a face folder's six files in order, or of the embedded default, read in a stream.
pub fn identity(path: Option<&Path>) -> Result<[u8; 32]> {
    let mut h = blake3::Hasher::new();
    match path {
        None => {
            h.update(EMBEDDED_DEFAULT);
        }
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
