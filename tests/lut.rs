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
    let c = splitsum::Backend::Cpu.brdf_lut(size, samples).expect("cpu bake");
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

/// The texels the quadrature table is checked at: every texel of a 32² table, and from a
/// 256² table the first, second and last two rows and columns in full (the grazing and
/// mirror-like edges, where integrands end abruptly) plus a 16² lattice inside.
fn quadrature_probes() -> Vec<(f32, f32)> {
    let mut pts: Vec<(f32, f32)> = (0..32 * 32).map(|i| lut::texel_coords(i % 32, i / 32, 32)).map(|c| (c.x, c.y)).collect();
    for k in 0..256u32 {
        for edge in [0u32, 1, 254, 255] {
            for (x, y) in [(k, edge), (edge, k)] {
                let c = lut::texel_coords(x, y, 256);
                pts.push((c.x, c.y));
            }
        }
    }
    for y in (8..256).step_by(16) {
        for x in (8..256).step_by(16) {
            let c = lut::texel_coords(x, y, 256);
            pts.push((c.x, c.y));
        }
    }
    pts
}

/// The deterministic quadrature is within 10⁻⁵ of the adaptive f64 Gauss–Kronrod reference
/// (tolerance 10⁻⁹, converged to about 10⁻⁷) at every probe, for both masking models. The
/// bound is the target; measured worst: see the printed line (f64 prototypes of the
/// rule reached 6·10⁻⁶; f32 rounding of some 550 terms adds about 10⁻⁶).
#[test]
fn quadrature_table_is_within_1e5_of_the_reference() {
    use rayon::prelude::*;
    use splitsum_shaders::brdf::microfacet::Masking;
    let pts = quadrature_probes();
    for (masking, smith) in [(Masking::SmithSchlick, reference::Smith::Schlick), (Masking::SmithCorrelated, reference::Smith::Correlated)] {
        let (worst, at) = pts
            .par_iter()
            .map(|&(nv, r)| {
                let got = lut::integrate_brdf_quadrature(nv, r, masking);
                let (ra, rb) = reference::brdf_lut_with(nv as f64, r as f64, 1e-9, smith);
                ((got.x as f64 - ra).abs().max((got.y as f64 - rb).abs()), (nv, r))
            })
            .reduce(|| (0.0, (0.0, 0.0)), |a, b| if b.0 > a.0 { b } else { a });
        println!("brdf table by quadrature ({masking:?}): max |error| {worst:.3e} over {} texels, worst at (n·v, r) = {at:?}", pts.len());
        assert!(worst <= 1e-5, "{masking:?}: {worst:e} at {at:?}");
    }
}

/// The quadrature table on the GPU equals the CPU's to the rounding of the two compilers
/// (the same bound as the sampled table: far below half-float resolution).
#[test]
fn quadrature_table_gpu_matches_cpu() {
    use splitsum_shaders::brdf::microfacet::Masking;
    for masking in [Masking::SmithSchlick, Masking::SmithCorrelated] {
        let g = gpu().brdf_table(64, masking).expect("gpu bake");
        let c = splitsum::Backend::Cpu.brdf_table(64, masking).expect("cpu bake");
        let (abs, ulp) = max_diffs(g.texels.iter().flat_map(|t| [t.x, t.y]), c.texels.iter().flat_map(|t| [t.x, t.y]));
        println!("brdf table 64² by quadrature ({masking:?}), gpu vs cpu: max |Δ| = {abs:.3e}, max {ulp} ULP");
        // Hardware may round division and sqrt to 3 ULP and fuse multiply–adds (Vulkan allows
        // it): some 30 operations per term and 550 terms give a few 10⁻⁶, still half the error target.
        assert!(abs as f64 <= support::gpu_bound(1.5e-6, 5e-6), "{masking:?}: gpu and cpu differ by {abs:e}");
    }
}

/// Extremes: n·v of 0 and 1, roughness 0 and 1, and values just inside: finite, in
/// [0, 1], `A + B ≤ 1`; a mirror (roughness 0) is exactly `(1 − F_c, F_c)` at `v·h = n·v`.
#[test]
fn quadrature_table_extremes_are_finite_and_bounded() {
    use splitsum_shaders::brdf::microfacet::Masking;
    for masking in [Masking::SmithSchlick, Masking::SmithCorrelated] {
        for &nv in &[0.0f32, 1e-7, 1e-4, 1e-3, 0.5, 1.0 - 1e-7, 1.0] {
            for &r in &[0.0f32, 1e-7, 1e-4, 0.02, 0.5, 1.0] {
                let t = lut::integrate_brdf_quadrature(nv, r, masking);
                assert!(t.x.is_finite() && t.y.is_finite() && t.x >= 0.0 && t.y >= 0.0 && t.x + t.y <= 1.0, "{masking:?} ({nv}, {r}): {t:?}");
            }
        }
        let t = lut::integrate_brdf_quadrature(0.5, 0.0, masking);
        let fc = 0.5f32.powi(5);
        assert!((t.x - (1.0 - fc)).abs() < 1e-7 && (t.y - fc).abs() < 1e-7, "mirror: {t:?}");
    }
}

/// Every texel of a 256² table against the reference (slow: about a minute per model on
/// two cores; run with `--ignored` for the closing figures).
#[test]
#[ignore]
fn quadrature_table_every_texel_of_256() {
    use rayon::prelude::*;
    use splitsum_shaders::brdf::microfacet::Masking;
    for (masking, smith) in [(Masking::SmithSchlick, reference::Smith::Schlick), (Masking::SmithCorrelated, reference::Smith::Correlated)] {
        let (worst, at) = (0..256 * 256u32)
            .into_par_iter()
            .map(|i| {
                let c = lut::texel_coords(i % 256, i / 256, 256);
                let got = lut::integrate_brdf_quadrature(c.x, c.y, masking);
                let (ra, rb) = reference::brdf_lut_with(c.x as f64, c.y as f64, 1e-9, smith);
                ((got.x as f64 - ra).abs().max((got.y as f64 - rb).abs()), (i % 256, i / 256))
            })
            .reduce(|| (0.0, (0, 0)), |a, b| if b.0 > a.0 { b } else { a });
        println!("every texel of 256² ({masking:?}): max |error| {worst:.3e} at texel {at:?}");
        assert!(worst <= 1e-5);
    }
}

/// The table the library embeds (`splitsum::table`, the defaults' table, which every bake
/// at the defaults uploads instead of integrating) is a fresh CPU computation bit for bit,
/// and it is the table the default settings resolve to. Its accuracy against the f64
/// reference is the quadrature tests' above (same function).
#[test]
fn embedded_table_is_a_fresh_computation_bit_for_bit() {
    use splitsum::table::{self, TableKey};
    let fresh = table::compute(TableKey::EMBEDDED).expect("fresh table");
    let embedded = table::embedded();
    assert_eq!(embedded.len(), fresh.len(), "embedded table has {} texels, a fresh one {}", embedded.len(), fresh.len());
    let differ = embedded.iter().zip(&fresh).filter(|(e, f)| e.x.to_bits() != f.x.to_bits() || e.y.to_bits() != f.y.to_bits()).count();
    assert_eq!(differ, 0, "{differ} texels of the embedded table differ from a fresh computation: run `bash scripts/dev.sh table`");
    let job = splitsum::Settings::default().resolve(splitsum::InputShape::Unknown, splitsum::Products::ALL).expect("defaults");
    assert_eq!(TableKey::of(&job), TableKey::EMBEDDED, "the defaults no longer read the embedded table");
    assert!(
        std::sync::Arc::ptr_eq(&table::texels(TableKey::EMBEDDED).unwrap(), &table::texels(TableKey::EMBEDDED).unwrap()),
        "the table is decoded once per process"
    );
}
