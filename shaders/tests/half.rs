//! `splitsum_shaders::half` against the `half` crate (an independent implementation of
//! IEEE 754 binary16), exhaustively where that is cheap.

use half::f16;
use splitsum_shaders::glam::Vec4;
use splitsum_shaders::half::{HALF_MAX, clean_radiance, f16_bits_to_f32, f32_to_f16_bits, pack_radiance};

#[test]
fn every_half_decodes_as_the_half_crate_does() {
    for h in 0..=u16::MAX {
        let want = f16::from_bits(h).to_f32();
        let got = f16_bits_to_f32(h as u32);
        assert!(got.to_bits() == want.to_bits() || (got.is_nan() && want.is_nan()), "{h:#06x}: {got} vs {want}");
    }
}

/// Every f32 whose top 16 bits are each pattern, with low bits that probe the rounding
/// boundaries (exact halves, just below and above ties), against `half`'s
/// round-to-nearest-even conversion: no difference at all is allowed (both are IEEE).
#[test]
fn f32_to_half_rounds_to_nearest_even_like_the_half_crate() {
    let lows = [0u32, 1, 0x0fff, 0x1000, 0x1001, 0x1fff, 0x2000, 0x3000, 0x7fff, 0x8000, 0xffff];
    let mut checked = 0u64;
    for hi in 0..=u16::MAX as u32 {
        for &lo in &lows {
            let x = f32::from_bits(hi << 16 | lo);
            let want = f16::from_f32(x).to_bits() as u32;
            let got = f32_to_f16_bits(x);
            if x.is_nan() {
                assert_eq!(got & 0x7c00, 0x7c00, "{x:?}: NaN stays NaN");
                assert_ne!(got & 0x3ff, 0, "{x:?}: NaN stays NaN");
            } else {
                assert_eq!(got, want, "{x:e} ({:#010x})", x.to_bits());
            }
            checked += 1;
        }
    }
    assert_eq!(checked, 65536 * lows.len() as u64);
}

#[test]
fn radiance_packing_clamps_overflow_and_drops_nan() {
    let unpack = |w: u32| (f16::from_bits(w as u16).to_f32(), f16::from_bits((w >> 16) as u16).to_f32());
    assert_eq!(unpack(pack_radiance(1e6, 65519.0)), (HALF_MAX, HALF_MAX), "a 10⁶ sun stays the largest finite half");
    assert_eq!(unpack(pack_radiance(f32::INFINITY, f32::NAN)), (HALF_MAX, 0.0));
    assert_eq!(unpack(pack_radiance(-1e9, 0.5)), (-HALF_MAX, 0.5));
    assert_eq!(unpack(pack_radiance(1e-8, 6.0e-8)), (0.0, f16::from_f32(6.0e-8).to_f32()), "subnormals round as IEEE says");
}

#[test]
fn cleaning_a_texture_texel_keeps_radiance_finite_and_non_negative() {
    let v = clean_radiance(Vec4::new(f32::NAN, -3.0, f32::INFINITY, 2.5));
    assert_eq!(v, Vec4::new(0.0, 0.0, splitsum_shaders::math::MAX_RADIANCE, 2.5));
}

/// An unsigned small float's value from its bits (OpenGL 4.6 §2.3.4.3–4), written here from
/// the definition: 5-bit exponent, bias 15, `m` mantissa bits, subnormals below 2⁻¹⁴.
fn small_float_value(bits: u32, m: u32) -> f64 {
    let e = (bits >> m) & 31;
    let f = (bits & ((1 << m) - 1)) as f64 / (1u32 << m) as f64;
    if e == 0 { f * 2f64.powi(-14) } else { (1.0 + f) * 2f64.powi(e as i32 - 15) }
}

/// `R11F_G11F_B10F` packing: every finite code of both widths round-trips, every midpoint
/// between neighbours rounds to the even one and a hair either side to the nearer, and
/// NaN, negatives, overflow and ∞ give 0, 0, the largest value and the largest value.
#[test]
fn unsigned_small_floats_round_to_nearest_even_and_never_overflow() {
    use splitsum_shaders::half::{UFLOAT10_MAX, UFLOAT11_MAX, f32_to_unsigned_small_float as enc, pack_r11g11b10f};
    for m in [6u32, 5] {
        let max_code = (30u32 << m) | ((1 << m) - 1);
        for c in 0..max_code {
            let (a, b) = (small_float_value(c, m), small_float_value(c + 1, m));
            assert_eq!(enc(a as f32, m), c, "code {c} of the {m}-bit mantissa round-trips");
            let mid = 0.5 * (a + b);
            assert_eq!(enc(mid as f32, m), if c % 2 == 0 { c } else { c + 1 }, "tie between {c} and {}", c + 1);
            assert_eq!(enc((mid * (1.0 - 1e-6)) as f32, m), c);
            assert_eq!(enc((mid * (1.0 + 1e-6)) as f32, m), c + 1);
        }
        assert_eq!(enc(small_float_value(max_code, m) as f32, m), max_code);
        for v in [1e6f32, f32::INFINITY, f32::MAX] {
            assert_eq!(enc(v, m), max_code, "{v} clamps to the largest value");
        }
        for v in [-1.0f32, f32::NEG_INFINITY, f32::NAN, 0.0, -0.0] {
            assert_eq!(enc(v, m), 0, "{v} gives 0");
        }
    }
    assert_eq!(small_float_value((30 << 6) | 63, 6), UFLOAT11_MAX as f64);
    assert_eq!(small_float_value((30 << 5) | 31, 5), UFLOAT10_MAX as f64);
    // 1.0: exponent 15, mantissa 0 in each channel; red in bits 0–10, blue in 22–31.
    assert_eq!(pack_r11g11b10f(1.0, 0.0, 0.0), 15 << 6);
    assert_eq!(pack_r11g11b10f(0.0, 1.0, 0.0), (15 << 6) << 11);
    assert_eq!(pack_r11g11b10f(0.0, 0.0, 1.0), (15 << 5) << 22);
}

/// `RGB9_E5` written here from `EXT_texture_shared_exponent` in f64 (with `log2`, `powi`),
/// independently of the packer's bit tricks.
fn rgb9e5_spec(c: [f32; 3]) -> u32 {
    let max = 511.0 / 512.0 * 65536.0;
    let c = c.map(|x| if x.is_nan() { 0.0 } else { (x as f64).clamp(0.0, max) });
    let m = c[0].max(c[1]).max(c[2]);
    let mut e = (if m > 0.0 { m.log2().floor() } else { -16.0 }).max(-16.0) as i32 + 16;
    if (m / 2f64.powi(e - 24) + 0.5).floor() == 512.0 {
        e += 1;
    }
    let q = |x: f64| (x / 2f64.powi(e - 24) + 0.5).floor() as u32;
    q(c[0]) | (q(c[1]) << 9) | (q(c[2]) << 18) | ((e as u32) << 27)
}

/// `pack_rgb9e5` equals the extension's encoding on colours from 2⁻²⁴ to past the
/// maximum, at mantissa boundaries (where the shared exponent steps up) and on NaN, ∞ and
/// negatives; and decoding gives each channel within half a step of its exponent.
#[test]
fn rgb9e5_packs_as_the_shared_exponent_extension_says() {
    use splitsum_shaders::half::{RGB9E5_MAX, pack_rgb9e5};
    let mut values = vec![0.0f32, 1.0, 0.5, 65408.0, 65500.0, 1e9, f32::INFINITY, -3.0, f32::NAN, 511.5 / 512.0, 1.0 - 1.0 / 1024.0, 1.0 - 1.0 / 2048.0];
    let mut x = 1.7e-8f32;
    while x < 1e6 {
        values.push(x);
        x *= 1.37;
    }
    for &r in &values {
        for &g in &[0.0f32, 0.001, 0.75, r * 0.5, r] {
            for &b in &[0.0f32, 3.0, r * 0.01] {
                let got = pack_rgb9e5(r, g, b);
                assert_eq!(got, rgb9e5_spec([r, g, b]), "({r}, {g}, {b})");
                let e = (got >> 27) as i32;
                for (k, c) in [r, g, b].into_iter().enumerate() {
                    let m = (got >> (9 * k)) & 511;
                    let back = m as f64 * 2f64.powi(e - 24);
                    let want = if c.is_nan() { 0.0 } else { (c as f64).clamp(0.0, RGB9E5_MAX as f64) };
                    assert!((back - want).abs() <= 0.5 * 2f64.powi(e - 24) * (1.0 + 1e-9), "({r}, {g}, {b}) channel {k}: {back} for {want}");
                }
            }
        }
    }
}
