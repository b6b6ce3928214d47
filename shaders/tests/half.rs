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
