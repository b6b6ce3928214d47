//! The image-based shading options and the roughness mapping against closed forms: energy
//! under a white furnace, the limits of the dominant direction, filtered sampling of a
//! constant sky, the exact Smith visibility against its textbook form, and the geometric
//! mapping's round trip.

use splitsum_reference as reference;
use splitsum_shaders::brdf::microfacet;
use splitsum_shaders::cubemap::CubeLayout;
use splitsum_shaders::glam::{Vec2, Vec3, Vec4};
use splitsum_shaders::lut;
use splitsum_shaders::prefilter::RoughnessMapping;
use splitsum_shaders::shade::{self, IblSample, Material, ShadeOptions};

fn metal(base: f32, roughness: f32) -> Material {
    Material { base_color: Vec3::splat(base), metallic: 1.0, roughness, occlusion: 1.0, emissive: Vec3::ZERO, sheen_color: Vec3::ZERO, sheen_roughness: 0.0 }
}

/// A white furnace (prefiltered radiance and `E/π` both 1) seen by a white metal (`F₀ = 1`):
/// with multiple scattering the metal reflects exactly 1 (Kulla & Conty 2017: a white
/// microfacet surface loses no energy); single scattering reflects only `A + B`, which at
/// roughness 1 loses about 40–55 % at grazing to normal views (Kulla & Conty, fig. 2). The
/// bound on the compensated case is f32 rounding of a few operations.
#[test]
fn multiple_scattering_conserves_a_white_metals_energy() {
    let furnace = |brdf: Vec2| IblSample { prefiltered: Vec3::ONE, irradiance: Vec3::ONE, brdf };
    let n = Vec3::Z;
    let ms = ShadeOptions { flags: ShadeOptions::IBL | ShadeOptions::MULTISCATTER, ..ShadeOptions::DEFAULT };
    let ss = ShadeOptions { flags: ShadeOptions::IBL, ..ShadeOptions::DEFAULT };
    for &r in &[0.0f32, 0.25, 0.5, 0.75, 1.0] {
        for &nv in &[0.05f32, 0.3, 0.7, 1.0] {
            let v = Vec3::new((1.0 - nv * nv).sqrt(), 0.0, nv);
            let table = lut::integrate_brdf_quadrature(nv, r, microfacet::Masking::SmithCorrelated);
            let with = shade::ibl(ms, &metal(1.0, r), n, v, furnace(table));
            let without = shade::ibl(ss, &metal(1.0, r), n, v, furnace(table));
            assert!((with - Vec3::ONE).abs().max_element() < 1e-5, "r {r}, n·v {nv}: {with:?}");
            assert!((without.x - (table.x + table.y)).abs() < 1e-6, "r {r}, n·v {nv}: {without:?} vs {table:?}");
        }
    }
    // At roughness 1 (α = 1, D = 1/π) and normal incidence only half vectors within 45° of
    // the normal reflect above the horizon: they carry exactly half of the distribution's
    // projected mass (sin²45°), and the masking term keeps less than all of that. Measured
    // 0.307: single scattering loses about 70 % here.
    let e = lut::integrate_brdf_quadrature(1.0, 1.0, microfacet::Masking::SmithCorrelated);
    println!("white GGX metal, r = 1, n·v = 1: single-scattering albedo {:.3}", e.x + e.y);
    assert!((0.25..0.5).contains(&(e.x + e.y)), "{e:?}");
    // A coloured metal gains less than a white one: F_ms scales with F_avg.
    let table = lut::integrate_brdf_quadrature(0.5, 1.0, microfacet::Masking::SmithCorrelated);
    let gold = shade::ibl(ms, &metal(0.5, 1.0), n, Vec3::new(0.75f32.sqrt(), 0.0, 0.5), furnace(table));
    let gold_ss = shade::ibl(ss, &metal(0.5, 1.0), n, Vec3::new(0.75f32.sqrt(), 0.0, 0.5), furnace(table));
    assert!(gold.x > gold_ss.x && gold.x - gold_ss.x < 1.0 - (table.x + table.y), "{gold:?} {gold_ss:?}");
}

/// The dominant direction is the mirror direction for a mirror, the normal at roughness 1
/// (`s = 0`), a unit vector between the two otherwise, and leans further towards the normal
/// as roughness grows (Lagarde & de Rousiers 2014, §4.9.3).
#[test]
fn dominant_direction_limits() {
    let n = Vec3::Z;
    let r = Vec3::new(0.8, 0.0, 0.6);
    assert!((shade::dominant_direction(n, r, 0.0) - r).length() < 1e-6);
    assert!((shade::dominant_direction(n, r, 1.0) - n).length() < 1e-6);
    let mut last = r.dot(n);
    for k in 1..10 {
        let d = shade::dominant_direction(n, r, k as f32 / 10.0);
        assert!((d.length() - 1.0).abs() < 1e-6 && d.y == 0.0);
        assert!(d.dot(n) >= last, "roughness {}: {d:?}", k as f32 / 10.0);
        last = d.dot(n);
    }
}

/// The lift above the horizon against its closed form in f64 trigonometry: a read direction
/// lower than `θ = 2·atan(HORIZON_LIFT·α)` above the horizon comes back at exactly that
/// elevation, at the same azimuth; one higher comes back unchanged; the result is a unit
/// vector. Tolerance 2e-6: f32 rounding of unit vectors.
#[test]
fn the_read_is_lifted_to_the_lobes_half_angle_above_the_horizon() {
    let n = Vec3::new(0.36, -0.48, 0.8);
    let (t, b) = splitsum_shaders::sampling::orthonormal_basis(n);
    for &r in &[0.05f32, 0.2, 0.5, 0.8, 1.0] {
        let alpha = (r as f64) * (r as f64);
        let theta = 2.0 * (shade::HORIZON_LIFT as f64 * alpha).atan();
        for &elevation in &[0.0f64, 0.05, 0.2, 0.5, 1.0, 1.5] {
            let azimuth = 0.7f64;
            let d = (t * azimuth.cos() as f32 + b * azimuth.sin() as f32) * elevation.cos() as f32 + n * elevation.sin() as f32;
            let got = shade::above_horizon(n, d, r);
            assert!((got.length() - 1.0).abs() < 2e-6, "r {r}, elevation {elevation}: {got:?}");
            let want = elevation.max(theta.min(std::f64::consts::FRAC_PI_2));
            assert!((got.dot(n) as f64 - want.sin()).abs() < 2e-6, "r {r}, elevation {elevation}: sin {} for {}", got.dot(n), want.sin());
            if elevation >= theta {
                assert!((got - d).length() < 2e-6, "r {r}: a direction above was moved");
            } else if want < std::f64::consts::FRAC_PI_2 - 1e-3 {
                let flat = got - n * got.dot(n);
                let got_azimuth = (flat.dot(b) as f64).atan2(flat.dot(t) as f64);
                assert!((got_azimuth - azimuth).abs() < 1e-5, "r {r}: azimuth {got_azimuth}");
            }
        }
    }
}

/// Filtered sampling at shading time of a constant sky returns the constant (its weights
/// sum to one), for every roughness below mip 1.
#[test]
fn filtered_sampling_of_a_constant_sky_is_the_constant() {
    let layout = CubeLayout::new(32, 4);
    let cube = vec![Vec4::new(2.5, 0.5, 1e4, 1.0); layout.texel_count() as usize];
    for &r in &[0.01f32, 0.05, 0.1, 0.15] {
        for d in [Vec3::X, Vec3::new(1.0, 1.0, 1.0), Vec3::new(-0.3, 0.9, 0.1)] {
            let got = shade::filtered_lookup(&cube, layout, d, r);
            assert!((got.truncate() - Vec3::new(2.5, 0.5, 1e4)).abs().max_element() <= 1e4 * 2e-6, "r {r}: {got:?}");
        }
    }
}

/// The exact Smith visibility against Heitz's textbook form with tangents, in f64
/// (`splitsum_reference::Smith::Correlated`): `V = G₂ / (4 (n·l)(n·v))`.
#[test]
fn correlated_smith_visibility_matches_the_textbook_form() {
    let mut worst = 0.0f64;
    for &alpha in &[0.01f32, 0.1, 0.5, 1.0] {
        for &nv in &[0.01f32, 0.2, 0.7, 1.0] {
            for &nl in &[0.05f32, 0.5, 0.99] {
                let got = microfacet::vis_smith_correlated(nv, nl, alpha) as f64;
                let want = reference::Smith::Correlated.g(nv as f64, nl as f64, alpha as f64) / (4.0 * nv as f64 * nl as f64);
                worst = worst.max((got - want).abs() / want);
            }
        }
    }
    println!("height-correlated Smith V: max relative error {worst:.2e}");
    assert!(worst < 1e-5, "{worst:e}");
}

/// The geometric mapping: mip 0 the mirror, the last mip roughness 1, α geometric in
/// between from α₁ = 2^(−M), and `lod` the exact inverse of `roughness` on every mip.
#[test]
fn geometric_mapping_round_trips() {
    let g = RoughnessMapping::Geometric;
    for mips in 2..=10u32 {
        assert_eq!(g.roughness(0, mips), 0.0);
        assert!((g.roughness(mips - 1, mips) - 1.0).abs() < 1e-6);
        let a1 = g.roughness(1, mips).powi(2);
        if mips > 2 {
            assert!((a1 - 2f32.powi(-(mips as i32))).abs() < 1e-6 * a1, "M {mips}: α₁ {a1}");
        }
        for m in 0..mips {
            let lod = g.lod(g.roughness(m, mips), mips);
            assert!((lod - m as f32).abs() < 1e-4, "M {mips}, mip {m}: lod {lod}");
        }
        // Monotonic between mips.
        let mut last = -1.0;
        for k in 0..=100 {
            let lod = g.lod(k as f32 / 100.0, mips);
            assert!(lod >= last);
            last = lod;
        }
    }
}

/// The Filament mapping is cmgen's `lodToPerceptualRoughness` (`r = 1 − √(1 − t)`, written
/// here as cmgen writes it: `(√(a² + 4b·t) − a)/(2b)` with `a = 2, b = −1`), and `lod` is
/// Filament's `perceptualRoughnessToLod`, `(M − 1)·r·(2 − r)`: the inverse on every mip.
#[test]
fn filament_mapping_is_cmgens_and_filaments_lod_inverts_it() {
    let f = RoughnessMapping::Filament;
    for mips in 2..=9u32 {
        for m in 0..mips {
            let t = m as f64 / (mips - 1) as f64;
            let cmgen = if t != 0.0 { ((4.0 - 4.0 * t).sqrt() - 2.0) / -2.0 } else { 0.0 };
            let r = f.roughness(m, mips);
            assert!((r as f64 - cmgen).abs() < 1e-6, "M {mips}, mip {m}: {r} vs cmgen {cmgen}");
            let lod = (mips - 1) as f64 * r as f64 * (2.0 - r as f64);
            assert!((f.lod(r, mips) as f64 - lod).abs() < 1e-5 && (lod - m as f64).abs() < 1e-4, "M {mips}, mip {m}: lod {lod}");
        }
    }
}
