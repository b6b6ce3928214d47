//! The elementary functions of `splitsum_shaders::math` against f64 `std`.

use splitsum_shaders::math;
use std::f64::consts::TAU;

/// Error in units of the f32 spacing at the reference value (a "ULP of the truth").
fn ulps(got: f32, want: f64) -> f64 {
    let ulp = {
        let w = want.abs() as f32;
        let next = f32::from_bits(w.to_bits() + 1);
        (next - w) as f64
    };
    (got as f64 - want).abs() / ulp
}

#[test]
fn sin_cos_turns_is_accurate_everywhere() {
    let mut worst_abs = 0.0f64;
    let n = 1_000_000;
    for i in 0..=n {
        let t = -3.0 + 6.0 * i as f64 / n as f64;
        let (s, c) = math::sin_cos_turns(t as f32);
        let tf = (t as f32) as f64; // the argument actually evaluated
        let (rs, rc) = (TAU * tf).sin_cos();
        worst_abs = worst_abs.max((s as f64 - rs).abs()).max((c as f64 - rc).abs());
    }
    println!("sin_cos_turns on [-3, 3] turns: max |error| = {worst_abs:.3e}");
    // 1.5 ULP of 1.0: the polynomial's truncation is below 3e-9, the rest is f32 rounding.
    assert!(worst_abs < 1.8e-7, "{worst_abs:e}");
    // Exact at the quarter turns.
    assert_eq!(math::sin_cos_turns(0.0), (0.0, 1.0));
    assert_eq!(math::sin_cos_turns(0.25), (1.0, 0.0));
    assert_eq!(math::sin_cos_turns(0.5), (0.0, -1.0));
    assert_eq!(math::sin_cos_turns(-0.25), (-1.0, 0.0));
}

#[test]
fn atan2_is_accurate_in_every_quadrant() {
    let mut worst = 0.0f64;
    let n = 2000;
    for i in 0..n {
        for j in 0..n {
            let y = -1.0 + 2.0 * (i as f32 + 0.37) / n as f32;
            let x = -1.0 + 2.0 * (j as f32 + 0.61) / n as f32;
            let r = (y as f64).atan2(x as f64);
            worst = worst.max((math::atan2(y, x) as f64 - r).abs());
        }
    }
    println!("atan2: max |error| = {worst:.3e} rad");
    // Cephes atanf: ~2e-7 relative on the reduced argument; π adds one rounding of 2.4e-7.
    assert!(worst < 5e-7, "{worst:e}");
    assert_eq!(math::atan2(0.0, 0.0), 0.0);
    assert_eq!(math::atan2(0.0, 1.0), 0.0);
    assert!((math::atan2(1.0, 0.0) as f64 - std::f64::consts::FRAC_PI_2).abs() < 1e-7);
}

#[test]
fn exp2_and_log2_are_accurate() {
    let mut worst_exp = 0.0f64;
    let mut worst_log = 0.0f64;
    for i in 0..200_000 {
        let x = -140.0 + 267.0 * i as f64 / 200_000.0;
        let xf = x as f32;
        let e = math::exp2(xf);
        let re = (xf as f64).exp2();
        if re >= f32::MIN_POSITIVE as f64 && re <= f32::MAX as f64 {
            worst_exp = worst_exp.max(ulps(e, re));
        }
        let y = (2.0f64).powf(x) as f32;
        if y > 0.0 && y.is_finite() {
            let l = math::log2(y);
            let rl = (y as f64).log2();
            worst_log = worst_log.max((l as f64 - rl).abs() / rl.abs().max(1.0));
        }
    }
    println!("exp2: max {worst_exp:.2} ULP; log2: max relative error {worst_log:.3e}");
    assert!(worst_exp < 4.0, "exp2 {worst_exp} ULP");
    assert!(worst_log < 3e-7, "log2 {worst_log:e}");
    for k in -126..=127 {
        assert_eq!(math::exp2(k as f32), (2.0f64).powi(k) as f32, "exp2({k})");
        assert_eq!(math::log2((2.0f64).powi(k) as f32), k as f32, "log2(2^{k})");
    }
    // Subnormals and the saturating edges.
    assert_eq!(math::log2(f32::from_bits(1)), -149.0);
    assert_eq!(math::log2(0.0), math::LOG2_FLOOR);
    assert_eq!(math::log2(-1.0), math::LOG2_FLOOR);
    assert_eq!(math::log2(f32::NAN), math::LOG2_FLOOR);
    assert_eq!(math::exp2(200.0), math::LARGEST);
    assert_eq!(math::exp2(-200.0), 0.0);
    assert!(math::exp2(-140.0) > 0.0);
}

#[test]
fn compensated_sum_does_not_drift() {
    // 2^24 + 1 additions of 0.1: naive f32 accumulation drifts by 15 %.
    let n = (1u32 << 24) + 1;
    let mut s = math::CompensatedSum::new();
    let mut naive = 0.0f32;
    for _ in 0..n {
        s.add(0.1);
        naive += 0.1;
    }
    let exact = n as f64 * 0.1f32 as f64;
    let err = (s.total() as f64 - exact).abs() / exact;
    println!("2^24+1 × 0.1: compensated relative error {err:.2e}, naive {:.2e}", (naive as f64 - exact).abs() / exact);
    assert!(err < 1e-7, "{err:e}");
}

/// `math::floor` equals the f64 floor of the same value, bit for bit (signed zeros included), over every exponent and the edges.
#[test]
fn floor_is_exact_bit_for_bit() {
    let mut values = vec![
        0.0f32,
        -0.0,
        0.5,
        -0.5,
        1.0,
        -1.0,
        1.5,
        -1.5,
        f32::MIN_POSITIVE,
        -f32::MIN_POSITIVE,
        1e-45,
        -1e-45,
        f32::MAX,
        f32::MIN,
        f32::INFINITY,
        f32::NEG_INFINITY,
    ];
    for k in -3i32..=3 {
        for base in [8_388_608.0f32, 16_777_216.0, 2_147_483_648.0] {
            values.push(base + k as f32);
            values.push(-(base + k as f32));
        }
    }
    // Every exponent and sign, with pseudo-random mantissas.
    let mut state = 0x2545_F491u32;
    for _ in 0..2_000_000 {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        let v = f32::from_bits(state);
        if !v.is_nan() {
            values.push(v);
        }
    }
    for v in values {
        let want = (v as f64).floor() as f32;
        let got = splitsum_shaders::math::floor(v);
        assert_eq!(got.to_bits(), want.to_bits(), "floor({v:e}) = {got:e}, want {want:e}");
    }
    assert!(splitsum_shaders::math::floor(f32::NAN).is_nan());
}
