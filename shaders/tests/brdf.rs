//! Reflectance models against closed forms and their defining properties.

use splitsum_reference::quadrature::adaptive;
use splitsum_shaders::brdf::{diffuse, fresnel, microfacet, phong};
use splitsum_shaders::glam::Vec3;
use std::f64::consts::PI;

/// GGX is a normalised distribution of microfacet normals: its projected area integrates
/// to one, ∫ D(h)(n·h) dω_h = 2π ∫ D(cos θ) cos θ sin θ dθ = 1 (Walter et al. 2007, eq. 4).
/// The scalar form is exact down to α ≈ 10⁻²; below, the peak is narrower than the f32
/// spacing of cos θ near 1 and only the vector form (|n×h|² for 1 − (n·h)²) holds.
#[test]
fn ggx_d_integrates_to_one_over_projected_area() {
    for &alpha in &[1.0f32, 0.5, 0.1, 0.02, 4e-4, 1e-5] {
        let scalar = |theta: f64| {
            let c = theta.cos();
            microfacet::d_ggx(c as f32, alpha) as f64 * c * theta.sin() * 2.0 * PI
        };
        let vector = |theta: f64| {
            let h = Vec3::new(theta.sin() as f32, 0.0, theta.cos() as f32);
            microfacet::d_ggx_vec(Vec3::Z, h, alpha) as f64 * theta.cos() * theta.sin() * 2.0 * PI
        };
        // Breakpoints at α·10ᵏ so that the adaptive rule finds the peak at once; the
        // tolerance stays above the f32 rounding noise of the integrand.
        let mut edges = vec![0.0];
        let mut e = alpha as f64;
        while e < PI / 2.0 {
            edges.push(e);
            e *= 10.0;
        }
        edges.push(PI / 2.0);
        let over = |f: &dyn Fn(f64) -> f64| edges.windows(2).map(|w| adaptive(&f, w[0], w[1], 1e-8)).sum::<f64>();
        let total_vec = over(&vector);
        println!("alpha {alpha}: ∫ D (n·h) dω = {total_vec:.7}");
        // f32 evaluation of D: a few ULP relative, and the f32 rounding of h.
        assert!((total_vec - 1.0).abs() < 1e-5, "alpha {alpha}: {total_vec}");
        if alpha >= 0.02 {
            let total = over(&scalar);
            assert!((total - 1.0).abs() < 1e-5, "alpha {alpha}: {total}");
        }
    }
}

#[test]
fn ggx_d_is_finite_at_the_peak_for_tiny_widths() {
    for &alpha in &[1e-4f32, 1e-8, 1e-14, 1e-19] {
        let d = microfacet::d_ggx(1.0, alpha);
        assert!(d.is_finite() && d > 0.0, "alpha {alpha}: {d}");
        // At the peak D = 1/(π α²).
        let want = 1.0 / (PI * alpha as f64 * alpha as f64);
        assert!(((d as f64) - want).abs() / want < 1e-6, "alpha {alpha}: {d} vs {want}");
    }
}

/// Schlick's G₁ is 1 at normal incidence and 0 at grazing; G is symmetric in v and l.
#[test]
fn smith_schlick_g_limits_and_symmetry() {
    for &r in &[0.0f32, 0.3, 1.0] {
        for k in [microfacet::k_direct(r), microfacet::k_ibl(r)] {
            assert!((microfacet::g1_schlick(1.0, k) - 1.0).abs() < 1e-7);
            if k > 0.0 {
                assert_eq!(microfacet::g1_schlick(0.0, k), 0.0);
            }
            assert_eq!(microfacet::g_smith_schlick(0.3, 0.8, k), microfacet::g_smith_schlick(0.8, 0.3, k));
        }
    }
    assert_eq!(microfacet::k_direct(1.0), 0.5); // (1+1)²/8
    assert_eq!(microfacet::k_ibl(1.0), 0.5); // 1²/2
    assert_eq!(microfacet::k_direct(0.0), 0.125);
    // The visibility form is G/(4 n·l n·v) and stays finite at grazing angles.
    let k = microfacet::k_direct(0.5);
    let vis = microfacet::vis_smith_schlick(0.3, 0.6, k);
    let g = microfacet::g_smith_schlick(0.3, 0.6, k);
    assert!((vis - g / (4.0 * 0.3 * 0.6)).abs() < 1e-6);
    assert!(microfacet::vis_smith_schlick(0.0, 0.0, k).is_finite());
}

/// Every Fresnel form gives F₀ at normal incidence and tends to 1 at grazing incidence.
#[test]
fn fresnel_at_normal_and_grazing_incidence() {
    let f0 = Vec3::new(0.04, 0.5, 0.95);
    assert_eq!(fresnel::schlick3(f0, 1.0), f0);
    assert_eq!(fresnel::schlick3(f0, 0.0), Vec3::ONE);
    assert_eq!(fresnel::schlick(0.04, 1.0), 0.04);
    // The spherical-Gaussian fit is not exact at the ends: at cos θ = 1 its weight is
    // 2^(−5.55473 − 6.98316) = 1.68·10⁻⁴ instead of 0 (Karis 2013).
    let sg = fresnel::spherical_gaussian3(f0, 1.0);
    let w = 2f64.powf(-5.55473 - 6.98316);
    for (got, f) in [(sg.x, 0.04), (sg.y, 0.5), (sg.z, 0.95)] {
        assert!((got as f64 - (f + (1.0 - f) * w)).abs() < 1e-7);
    }
    assert_eq!(fresnel::spherical_gaussian3(f0, 0.0), Vec3::ONE);
    // It tracks Schlick to within 0.5 % of (1 − F₀) everywhere (measured: 3.8·10⁻³ near cos θ = 0.03).
    let worst = (0..=1000)
        .map(|i| {
            let c = i as f32 / 1000.0;
            (fresnel::spherical_gaussian_weight(c) - fresnel::schlick_weight(c)).abs()
        })
        .fold(0.0f32, f32::max);
    println!("spherical-Gaussian vs Schlick weight: max |Δ| = {worst:.2e}");
    assert!(worst < 5e-3, "{worst}");
    // With roughness, grazing reflectance stops at max(1 − r, F₀).
    let fr = fresnel::schlick_roughness3(f0, 0.0, 0.8);
    assert!((fr - Vec3::new(0.2, 0.5, 0.95)).abs().max_element() < 1e-6, "{fr}");
    assert_eq!(fresnel::schlick_roughness3(f0, 1.0, 0.8), f0);
}

/// Directional albedo ∫ f_d (n·l) dω_l by quadrature over the hemisphere.
fn albedo(f: impl Fn(Vec3) -> f32) -> f64 {
    let outer = |theta: f64| {
        let inner = |phi: f64| {
            let l = Vec3::new((theta.sin() * phi.cos()) as f32, (theta.sin() * phi.sin()) as f32, theta.cos() as f32);
            f(l) as f64 * theta.cos() * theta.sin()
        };
        adaptive(&inner, 0.0, 2.0 * PI, 1e-7)
    };
    adaptive(&outer, 0.0, PI / 2.0, 1e-7)
}

#[test]
fn lambert_reflects_its_albedo() {
    let rho = Vec3::new(0.2, 0.5, 0.9);
    let a = albedo(|_| diffuse::lambert(rho).y);
    assert!((a - 0.5).abs() < 1e-6, "{a}");
}

#[test]
fn oren_nayar_at_zero_roughness_is_lambert() {
    let rho = Vec3::new(0.2, 0.5, 0.9);
    let v = Vec3::new(0.6, 0.0, 0.8);
    for l in [Vec3::Z, Vec3::new(0.0, 0.6, 0.8), Vec3::new(-0.8, 0.0, 0.6)] {
        assert_eq!(diffuse::oren_nayar(rho, 0.0, l.z, v.z, l.dot(v)), diffuse::lambert(rho));
    }
    // Rough surfaces back-scatter: lit and seen from the same grazing direction (70°),
    // they are brighter than Lambert.
    let g = Vec3::new(0.939_692_6, 0.0, 0.342_020_1);
    let back = diffuse::oren_nayar(rho, 0.5, g.z, g.z, 1.0);
    assert!(back.y > diffuse::lambert(rho).y, "{back}");
    // And never reflect more than their albedo at normal view.
    let a = albedo(|l| diffuse::oren_nayar(Vec3::ONE, 1.0, l.z, 1.0, l.z).x);
    assert!(a <= 1.0, "{a}");
}

/// Reciprocity, f(l, v) = f(v, l), for every model.
#[test]
fn every_brdf_is_reciprocal() {
    let l = Vec3::new(0.3, -0.2, 0.932_737_9);
    let v = Vec3::new(-0.5, 0.4, 0.768_114_6);
    let h = (l + v).normalize();
    let rho = Vec3::new(0.3, 0.6, 0.9);
    let swap_eq = |a: Vec3, b: Vec3| assert!((a - b).abs().max_element() <= 1e-7 * a.abs().max_element().max(1.0), "{a} vs {b}");
    swap_eq(diffuse::oren_nayar(rho, 0.4, l.z, v.z, l.dot(v)), diffuse::oren_nayar(rho, 0.4, v.z, l.z, v.dot(l)));
    swap_eq(diffuse::fresnel_weighted(rho, Vec3::splat(0.04), l.z, v.z), diffuse::fresnel_weighted(rho, Vec3::splat(0.04), v.z, l.z));
    let k = microfacet::k_direct(0.4);
    let ct = |a: Vec3, b: Vec3| microfacet::d_ggx(h.z, 0.16) * microfacet::vis_smith_schlick(a.z, b.z, k) * fresnel::schlick(0.04, a.dot(h));
    assert!((ct(l, v) - ct(v, l)).abs() < 1e-7);
    let n = phong::blinn_exponent(0.16);
    let reflect = |d: Vec3| Vec3::Z * (2.0 * d.z) - d;
    assert!((phong::phong(reflect(v).dot(l), n / 4.0) - phong::phong(reflect(l).dot(v), n / 4.0)).abs() < 1e-6);
    assert_eq!(phong::blinn_phong(h.z, n), phong::blinn_phong(h.z, n));
}
