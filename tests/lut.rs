//! The split-sum BRDF table: GPU against CPU, both against an f64 quadrature, and the
//! extreme corners of its domain.

use splitsum_shaders::lut;
use support::{gpu, max_diffs, reference};

/// GPU (wgpu, lavapipe in CI) and CPU run the same function; they differ only where the
/// two compilers round differently (contraction into FMA, operation order), so the bound
/// is set far below half-float resolution (2⁻¹¹ ≈ 4.9·10⁻⁴ relative).
#[test]
fn gpu_matches_cpu() {
    let (size, samples) = (128, 256);
    let g = gpu().brdf_lut(size, samples).expect("gpu bake");
    let c = runner::Backend::Cpu.brdf_lut(size, samples).expect("cpu bake");
    let (abs, ulp) = max_diffs(g.texels.iter().flat_map(|t| [t.x, t.y]), c.texels.iter().flat_map(|t| [t.x, t.y]));
    println!("brdf lut {size}² × {samples} samples, gpu vs cpu: max |Δ| = {abs:.3e}, max {ulp} ULP");
    assert!(abs <= 1.5e-6, "gpu and cpu differ by {abs:e}");
}

/// Texel centres of a 256² table, extreme rows and columns included.
fn probe_texels() -> Vec<(u32, u32)> {
    let picks = [0u32, 1, 32, 128, 254, 255];
    picks.iter().flat_map(|&y| picks.iter().map(move |&x| (x, y))).collect()
}

fn max_error_against_reference(samples: u32) -> f64 {
    let mut worst = 0.0f64;
    for (x, y) in probe_texels() {
        let c = lut::texel_coords(x, y, 256);
        let got = lut::integrate_brdf(c.x, c.y, samples);
        let (ra, rb) = reference::brdf_lut(c.x as f64, c.y as f64, 1e-8);
        let err = (got.x as f64 - ra).abs().max((got.y as f64 - rb).abs());
        worst = worst.max(err);
    }
    worst
}

/// The quadrature reference is converged: tightening its tolerance a hundredfold moves it
/// far less than the errors measured against it.
#[test]
fn reference_is_converged() {
    let mut worst = 0.0f64;
    for (x, y) in probe_texels() {
        let c = lut::texel_coords(x, y, 256);
        let fine = reference::brdf_lut(c.x as f64, c.y as f64, 1e-8);
        let coarse = reference::brdf_lut(c.x as f64, c.y as f64, 1e-6);
        worst = worst.max((fine.0 - coarse.0).abs()).max((fine.1 - coarse.1).abs());
    }
    println!("reference self-difference (tolerance 1e-8 vs 1e-6): {worst:.3e}");
    assert!(worst < 1e-5, "reference not converged: {worst:e}");
}

/// Hammersley sampling converges on the reference. The worst texel is the grazing column
/// at low roughness (n·v = 0.002, r = 0.127), where the integrand ends abruptly at the
/// horizon and the error falls only as about N^−0.6: measured 6.3·10⁻³ at 1024 points
/// and 1.4·10⁻⁴ at 2²⁰; elsewhere it is 10⁻⁴–10⁻³ and 10⁻⁵ respectively. The bounds
/// leave a factor of about 1.5 over those measurements.
#[test]
fn matches_quadrature_reference() {
    let e1k = max_error_against_reference(1024);
    let e1m = max_error_against_reference(1 << 20);
    println!("max |error| vs f64 quadrature at 36 texel centres: 1024 samples {e1k:.3e}, 2^20 samples {e1m:.3e}");
    assert!(e1k < 1e-2, "1024 samples: {e1k:e}");
    assert!(e1m < 2e-4, "2^20 samples: {e1m:e}");
}

/// At the corners of the domain every value is finite, non-negative, and scale + bias
/// (the directional albedo with F₀ = 1) stays at most 1.
#[test]
fn extreme_inputs_stay_finite_and_bounded() {
    for &nv in &[0.0f32, 1e-7, 1e-3, 1.0] {
        for &r in &[0.0f32, 1e-7, 1e-4, 0.02, 1.0] {
            for &n in &[1u32, 2, 1024] {
                let v = lut::integrate_brdf(nv, r, n);
                assert!(v.x.is_finite() && v.y.is_finite(), "nv={nv} r={r} n={n}: {v}");
                assert!(v.x >= 0.0 && v.y >= 0.0, "nv={nv} r={r} n={n}: {v}");
                // 1e-6: rounding of the sum; the integrand itself is bounded by 1.
                assert!(v.x + v.y <= 1.0 + 1e-6, "nv={nv} r={r} n={n}: {v}");
            }
        }
    }
    // A mirror reflects everything: scale + bias = 1 with Fresnel alone splitting it.
    let m = lut::integrate_brdf(0.5, 0.0, 16);
    let fc = (1.0f32 - 0.5).powi(5);
    assert!((m.x - (1.0 - fc)).abs() < 1e-6 && (m.y - fc).abs() < 1e-6, "{m}");
}

/// 2²⁴ + 1 samples: beyond exact f32 integers, with no wrap and no drift of the sum.
#[test]
fn huge_sample_count() {
    let n = (1u32 << 24) + 1;
    let v = lut::integrate_brdf(0.5, 0.5, n);
    let (ra, rb) = reference::brdf_lut(0.5, 0.5, 1e-8);
    println!("2^24+1 samples at (0.5, 0.5): {v} vs reference ({ra:.7}, {rb:.7})");
    assert!((v.x as f64 - ra).abs() < 1e-5 && (v.y as f64 - rb).abs() < 1e-5);
}
