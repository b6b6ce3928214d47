//! IEEE 754 binary16 ("half") conversion in integer arithmetic, so that the GPU's texture
//! packing and the CPU's agree bit for bit (spirv-std's `PackHalf2x16` exists only on the
//! GPU, and its rounding is implementation-defined).
//!
//! f32 → f16 rounds to nearest, ties to even (IEEE 754-2019 §4.3.1): the 23-bit mantissa
//! keeps its top 10 bits and the 13 dropped bits decide the rounding; below 2⁻¹⁴ the value
//! becomes a subnormal `m·2⁻²⁴` with `m` the mantissa shifted right by `14 − e`. A carry
//! out of the mantissa moves into the exponent, which is the correctly rounded result
//! (up to +∞ past 65504). [`pack_radiance`] clamps first, so radiance never reaches ∞.

use crate::math;
use spirv_std::glam::Vec4;

/// The largest finite half float.
pub const HALF_MAX: f32 = 65504.0;

/// The binary16 bits of `x` (in the low 16 bits), rounded to nearest even.
#[inline]
pub fn f32_to_f16_bits(x: f32) -> u32 {
    let b = x.to_bits();
    let sign = (b >> 16) & 0x8000;
    let exp = ((b >> 23) & 0xff) as i32;
    let man = b & 0x7f_ffff;
    if exp == 0xff {
        // ∞ stays ∞; NaN stays a quiet NaN.
        return sign | 0x7c00 | if man != 0 { 0x200 } else { 0 };
    }
    let e = exp - 127 + 15;
    if e >= 0x1f {
        return sign | 0x7c00;
    }
    if e <= 0 {
        let shift = (14 - e) as u32;
        if shift > 24 {
            return sign;
        }
        let full = man | 0x80_0000;
        let m = full >> shift;
        let rest = full & ((1u32 << shift) - 1);
        let half = 1u32 << (shift - 1);
        let up = rest > half || (rest == half && (m & 1) == 1);
        return sign | (m + up as u32);
    }
    let h = ((e as u32) << 10) | (man >> 13);
    let rest = man & 0x1fff;
    let up = rest > 0x1000 || (rest == 0x1000 && (h & 1) == 1);
    sign | (h + up as u32)
}

/// The f32 value of the binary16 bits in the low 16 bits of `h` (exact: every half is an
/// f32).
#[inline]
pub fn f16_bits_to_f32(h: u32) -> f32 {
    let sign = (h & 0x8000) << 16;
    let exp = (h >> 10) & 0x1f;
    let man = h & 0x3ff;
    if exp == 0 {
        // Zero or subnormal: man·2⁻²⁴, exact in f32.
        let v = man as f32 * (1.0 / 16_777_216.0);
        return if sign != 0 { -v } else { v };
    }
    let bits = if exp == 31 { sign | 0x7f80_0000 | (man << 13) } else { sign | ((exp + 112) << 23) | (man << 13) };
    f32::from_bits(bits)
}

/// The bits of `x ≥ 0` as an unsigned float with a 5-bit exponent (bias 15, as binary16)
/// and `mantissa` bits (6 for the 11-bit, 5 for the 10-bit channels of
/// `R11F_G11F_B10F`; OpenGL 4.6 §2.3.4.3–4), rounded to nearest even. NaN and values
/// `≤ 0` give 0; values past the largest finite one (`65024` with 6 bits, `64512` with 5)
/// give that one, never ∞.
#[inline]
pub fn f32_to_unsigned_small_float(x: f32, mantissa: u32) -> u32 {
    let max_bits = (30u32 << mantissa) | ((1u32 << mantissa) - 1);
    #[allow(clippy::eq_op)]
    if x != x || x <= 0.0 {
        return 0;
    }
    let b = x.to_bits();
    let exp = ((b >> 23) & 0xff) as i32;
    let man = b & 0x7f_ffff;
    let e = exp - 127 + 15;
    if exp == 0xff || e >= 0x1f {
        return max_bits;
    }
    let drop = 23 - mantissa;
    let bits = if e <= 0 {
        // Subnormal: m·2^(−14 − mantissa).
        let shift = drop + (1 - e) as u32;
        if shift > 24 {
            return 0;
        }
        let full = man | 0x80_0000;
        let m = full >> shift;
        let rest = full & ((1u32 << shift) - 1);
        let half = 1u32 << (shift - 1);
        m + (rest > half || (rest == half && (m & 1) == 1)) as u32
    } else {
        let h = ((e as u32) << mantissa) | (man >> drop);
        let rest = man & ((1u32 << drop) - 1);
        let half = 1u32 << (drop - 1);
        h + (rest > half || (rest == half && (h & 1) == 1)) as u32
    };
    if bits > max_bits { max_bits } else { bits }
}

/// The largest value of an 11-bit unsigned float (6-bit mantissa): `2¹⁵·(2 − 2⁻⁶)`.
pub const UFLOAT11_MAX: f32 = 65024.0;

/// The largest value of a 10-bit unsigned float (5-bit mantissa, the blue of
/// `R11F_G11F_B10F`): `2¹⁵·(2 − 2⁻⁵)`.
pub const UFLOAT10_MAX: f32 = 64512.0;

/// An RGB value packed as `R11F_G11F_B10F` (`GL_UNSIGNED_INT_10F_11F_11F_REV`: red in
/// bits 0–10, green 11–21, blue 22–31), each channel by [`f32_to_unsigned_small_float`]:
/// negative and NaN channels become 0, channels past the format's range its largest value.
#[inline]
pub fn pack_r11g11b10f(r: f32, g: f32, b: f32) -> u32 {
    f32_to_unsigned_small_float(r, 6) | (f32_to_unsigned_small_float(g, 6) << 11) | (f32_to_unsigned_small_float(b, 5) << 22)
}

/// The largest value of `RGB9_E5`: `(2⁹ − 1)/2⁹ · 2¹⁶`.
pub const RGB9E5_MAX: f32 = 65408.0;

/// `2ᵏ` for `−126 ≤ k ≤ 127`, exactly, from its bits.
#[inline]
fn pow2(k: i32) -> f32 {
    f32::from_bits(((k + 127) as u32) << 23)
}

/// An RGB value packed as `RGB9_E5` (`E5B9G9R9_UFLOAT_PACK32`: red in bits 0–8, green
/// 9–17, blue 18–26, the shared exponent in 27–31), by the encoding of
/// `EXT_texture_shared_exponent` (§"Shared exponent encoding"; OpenGL 4.6 §8.5.2): each
/// channel clamped to `[0, RGB9E5_MAX]` (NaN to 0), the exponent `max(−16,
/// ⌊log₂ max⌋) + 16` (raised by one where the largest mantissa rounds up to 2⁹), each
/// mantissa `⌊c / 2^(e − 24) + ½⌋`. `⌊log₂⌋` is read from the f32 exponent bits and the
/// powers of two are built from bits, so both backends agree bit for bit.
#[inline]
pub fn pack_rgb9e5(r: f32, g: f32, b: f32) -> u32 {
    #[allow(clippy::eq_op)]
    let c = |x: f32| {
        if x != x || x <= 0.0 {
            0.0
        } else if x > RGB9E5_MAX {
            RGB9E5_MAX
        } else {
            x
        }
    };
    let (r, g, b) = (c(r), c(g), c(b));
    let m = if r > g { r } else { g };
    let m = if m > b { m } else { b };
    // ⌊log₂ m⌋ for normal m; zero and subnormals are below 2⁻¹⁶ and take the floor −16.
    let floor_log2 = ((m.to_bits() >> 23) & 0xff) as i32 - 127;
    let mut e = if floor_log2 < -16 { -16 } else { floor_log2 } + 16;
    let maxm = math::floor(m * pow2(24 - e) + 0.5) as u32;
    if maxm == 512 {
        e += 1;
    }
    let scale = pow2(24 - e);
    let q = |x: f32| math::floor(x * scale + 0.5) as u32;
    q(r) | (q(g) << 9) | (q(b) << 18) | ((e as u32) << 27)
}

/// Two radiance values packed as halves (`a` in the low 16 bits): NaN becomes 0 and
/// magnitudes beyond [`HALF_MAX`] become ±`HALF_MAX`, so a sun of 10⁶ stays the brightest
/// finite value rather than ∞.
#[inline]
pub fn pack_radiance(a: f32, b: f32) -> u32 {
    #[allow(clippy::eq_op)]
    let c = |x: f32| if x != x { 0.0 } else { crate::math::clamp(x, -HALF_MAX, HALF_MAX) };
    f32_to_f16_bits(c(a)) | (f32_to_f16_bits(c(b)) << 16)
}

/// Texel `x` of the copied texture row starting at word `row` of `words`: four halves
/// (two words) or four f32 (four words) per texel, RGBA.
#[inline]
pub fn copied_texel(words: &[u32], row: usize, x: usize, half: bool) -> Vec4 {
    if half {
        let (a, b) = (words[row + 2 * x], words[row + 2 * x + 1]);
        Vec4::new(f16_bits_to_f32(a & 0xffff), f16_bits_to_f32(a >> 16), f16_bits_to_f32(b & 0xffff), f16_bits_to_f32(b >> 16))
    } else {
        let w = row + 4 * x;
        Vec4::new(f32::from_bits(words[w]), f32::from_bits(words[w + 1]), f32::from_bits(words[w + 2]), f32::from_bits(words[w + 3]))
    }
}

/// A texel read from a caller's texture, made what the bake takes: NaN and negative
/// values become 0, values above `math::MAX_RADIANCE` (and +∞) become it.
#[inline]
pub fn clean_radiance(v: Vec4) -> Vec4 {
    let c = |x: f32| if x > 0.0 { if x < crate::math::MAX_RADIANCE { x } else { crate::math::MAX_RADIANCE } } else { 0.0 };
    Vec4::new(c(v.x), c(v.y), c(v.z), c(v.w))
}
