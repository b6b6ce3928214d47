//! Hammersley points, the orthonormal frame and GGX sampling, against their definitions
//! and the analytic GGX distribution.

use splitsum_shaders::glam::{Vec2, Vec3};
use splitsum_shaders::sampling;

/// Φ₂ by its definition: Σ bₖ 2^−(k+1) over the bits of i, in f64.
fn radical_inverse_f64(mut i: u32) -> f64 {
    let mut f = 0.5;
    let mut r = 0.0;
    while i > 0 {
        if i & 1 == 1 {
            r += f;
        }
        f *= 0.5;
        i >>= 1;
    }
    r
}

#[test]
fn radical_inverse_is_the_correctly_rounded_definition() {
    assert_eq!(sampling::radical_inverse(0), 0.0);
    assert_eq!(sampling::radical_inverse(1), 0.5);
    assert_eq!(sampling::radical_inverse(2), 0.25);
    assert_eq!(sampling::radical_inverse(3), 0.75);
    let mut i = 0u32;
    for _ in 0..200_000 {
        let want = (radical_inverse_f64(i) as f32).min(sampling::ONE_MINUS_EPSILON);
        assert_eq!(sampling::radical_inverse(i), want, "i = {i}");
        i = i.wrapping_mul(2_654_435_761).wrapping_add(12345);
    }
    assert!(sampling::radical_inverse(u32::MAX) < 1.0);
}

#[test]
fn hammersley_has_no_wrap_beyond_2_pow_24() {
    let n = (1u32 << 24) + 1;
    // The last point stays inside the unit square, and the first coordinate is monotone.
    let last = sampling::hammersley(n - 1, n);
    assert!(last.x < 1.0 && last.y < 1.0, "{last}");
    let mut prev = -1.0f32;
    for i in (n - 4096)..n {
        let p = sampling::hammersley(i, n);
        assert!(p.x >= prev);
        prev = p.x;
    }
    // Points 2^24 apart are told apart by their first coordinate.
    let a = sampling::hammersley(3, n);
    let b = sampling::hammersley(3 + (1 << 24), n);
    assert!(a != b, "{a} {b}");
    // Small indices keep exact quotients: i/n for n ≤ 2^24 is correctly rounded.
    for (i, m) in [(1u32, 3u32), (5, 7), (1 << 23, 1 << 24), (16_777_215, 16_777_216)] {
        assert_eq!(sampling::hammersley(i, m).x, (i as f64 / m as f64) as f32);
    }
}

fn unit_vectors() -> Vec<Vec3> {
    let mut v = vec![Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
    // Directions next to the poles, where naive frames divide by ~0.
    for e in [1e-7f32, 1e-4, 1e-2] {
        for s in [1.0f32, -1.0] {
            v.push(Vec3::new(e, 0.0, s).normalize());
            v.push(Vec3::new(0.0, e, s).normalize());
            v.push(Vec3::new(e, -e, s).normalize());
        }
    }
    for i in 0..1000 {
        let p = sampling::hammersley(i, 1000);
        let z = 1.0 - 2.0 * p.x;
        let r = (1.0 - z * z).max(0.0).sqrt();
        let (s, c) = (std::f32::consts::TAU * p.y).sin_cos();
        v.push(Vec3::new(r * c, r * s, z));
    }
    v
}

#[test]
fn orthonormal_basis_is_finite_and_orthonormal_at_the_poles() {
    for n in unit_vectors() {
        let (t, b) = sampling::orthonormal_basis(n);
        assert!(t.is_finite() && b.is_finite(), "{n}");
        // 1e-6: a few roundings of O(1) products.
        assert!((t.length() - 1.0).abs() < 1e-6 && (b.length() - 1.0).abs() < 1e-6, "{n}: {t} {b}");
        assert!(t.dot(n).abs() < 1e-6 && b.dot(n).abs() < 1e-6 && t.dot(b).abs() < 1e-6, "{n}: {t} {b}");
        assert!((t.cross(b) - n).length() < 2e-6, "not right-handed at {n}");
    }
}

/// The GGX half-vector density D(h)(n·h) has the closed-form CDF
/// P(θ_h ≤ θ) = tan²θ / (α² + tan²θ) (Walter et al. 2007, from eq. 33); 2¹⁶ Hammersley
/// samples must match it in Kolmogorov–Smirnov distance, and φ must be uniform.
#[test]
fn ggx_samples_follow_the_analytic_distribution() {
    let n = 1u32 << 16;
    for &alpha in &[1.0f32, 0.5, 0.1, 0.01] {
        let mut tan2: Vec<f64> = Vec::with_capacity(n as usize);
        let mut phis: Vec<f64> = Vec::with_capacity(n as usize);
        for i in 0..n {
            let h = sampling::sample_ggx_tangent(sampling::hammersley(i, n), alpha);
            assert!((h.length() - 1.0).abs() < 1e-6);
            // tan²θ from the tangential components: 1 − cos²θ would cancel near the pole.
            let (x, y, z) = (h.x as f64, h.y as f64, h.z as f64);
            tan2.push((x * x + y * y) / (z * z));
            phis.push((h.y as f64).atan2(h.x as f64).rem_euclid(std::f64::consts::TAU));
        }
        tan2.sort_by(|a, b| a.partial_cmp(b).unwrap());
        phis.sort_by(|a, b| a.partial_cmp(b).unwrap());
        let a2 = (alpha as f64) * (alpha as f64);
        let ks_theta = ks(&tan2, |t| t / (a2 + t));
        let ks_phi = ks(&phis, |p| p / std::f64::consts::TAU);
        println!("alpha {alpha}: KS distance θ {ks_theta:.2e}, φ {ks_phi:.2e}");
        // Low-discrepancy points sit within ~log(N)/N of the CDF: 10⁻⁴ at N = 2¹⁶ leaves
        // a margin of 4 over what is measured.
        assert!(ks_theta < 1e-4 && ks_phi < 1e-4, "alpha {alpha}: {ks_theta:e} {ks_phi:e}");
    }
}

fn ks(sorted: &[f64], cdf: impl Fn(f64) -> f64) -> f64 {
    let n = sorted.len() as f64;
    sorted
        .iter()
        .enumerate()
        .map(|(i, &x)| {
            let f = cdf(x);
            (f - i as f64 / n).abs().max((f - (i + 1) as f64 / n).abs())
        })
        .fold(0.0, f64::max)
}

#[test]
fn ggx_sampling_is_finite_at_extreme_roughness_and_poles() {
    for &alpha in &[0.0f32, 1e-14, 1e-8, 1e-4, 1.0] {
        for n in unit_vectors() {
            for i in [0u32, 1, 7, 1023] {
                let h = sampling::sample_ggx(sampling::hammersley(i, 1024), alpha, n);
                assert!(h.is_finite(), "alpha {alpha} n {n}");
                assert!((h.length() - 1.0).abs() < 1e-5, "alpha {alpha} n {n}: {h}");
                if alpha == 0.0 {
                    assert!((h - n).length() < 1e-6, "a mirror's half vector is the normal");
                }
            }
        }
    }
    // The last Hammersley point (u → 1) at α = 1 gives a grazing but finite half vector.
    let h = sampling::sample_ggx_tangent(Vec2::new(0.3, sampling::ONE_MINUS_EPSILON), 1.0);
    assert!(h.is_finite() && h.z >= 0.0);
}

#[test]
fn normalize_never_returns_nan() {
    let f = Vec3::Z;
    assert_eq!(sampling::normalize_or(Vec3::ZERO, f), f);
    assert_eq!(sampling::normalize_or(Vec3::splat(1e-30), f), f);
    assert_eq!(sampling::normalize_or(Vec3::new(f32::INFINITY, 0.0, 0.0), f), f);
    assert_eq!(sampling::normalize_or(Vec3::new(f32::NAN, 0.0, 0.0), f), f);
    assert!((sampling::normalize_or(Vec3::new(3.0, 4.0, 0.0), f) - Vec3::new(0.6, 0.8, 0.0)).length() < 1e-7);
}
