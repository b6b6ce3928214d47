//! Radiance `.hdr` files, read scanline by scanline into a [`Reducer`].

use super::*;
use crate::error::{Error, Result};
use crate::texture::Equirect;
use std::path::Path;

/// Every scanline of a Radiance file takes at least 4 bytes: a header that promises more
/// rows than the file can hold is refused.
pub(super) fn check_hdr_length(path: &Path, h: u32, len: u64) -> Result<()> {
    if len < 4 * h as u64 {
        return Err(Error::file(
            path,
            format!("truncated Radiance HDR: its header promises {h} scanlines, which take at least {} bytes, but the file has {len}", 4 * h as u64),
        ));
    }
    Ok(())
}

/// A Radiance `.hdr` file, decoded scanline by scanline into a [`Reducer`] ([`rgbe`]).
pub(super) fn read_hdr(path: &Path, weights: Weights, sanitize: bool, factor: u32) -> Result<(Equirect, InputReport)> {
    read_hdr_from(path, buffered(path)?, file_len(path)?, weights, sanitize, factor)
}

/// [`read_hdr`] from `r`, which holds `len` bytes; `path` names it in errors.
pub(super) fn read_hdr_from(
    path: &Path,
    mut r: impl std::io::BufRead,
    len: u64,
    weights: Weights,
    sanitize: bool,
    factor: u32,
) -> Result<(Equirect, InputReport)> {
    let (w, h) = rgbe::header(path, &mut r)?;
    check_side(path, w, h)?;
    check_hdr_length(path, h, len)?;
    let mut reducer = Reducer::new(w, h, factor, weights, sanitize);
    let mut line = vec![[0u8; 4]; w as usize];
    for y in 0..h {
        rgbe::scanline(&mut r, &mut line).map_err(|e| match e.kind() {
            std::io::ErrorKind::UnexpectedEof => Error::file(path, format!("truncated Radiance HDR: the file ends in scanline {y} of {h}")),
            _ => Error::file_caused(path, format!("malformed Radiance HDR in scanline {y} of {h}"), e),
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
pub(super) mod rgbe {
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
