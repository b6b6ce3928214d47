//! The Charlie sheen lobe (`brdf::sheen`) against the independent f64 reference
//! (`splitsum_reference::sheen`), closed forms and its defining properties.

use splitsum_reference::quadrature::integrate;
use splitsum_reference::sheen as reference;
use splitsum_shaders::brdf::sheen;
use splitsum_shaders::glam::Vec2;
use splitsum_shaders::sampling::hammersley;
use std::f64::consts::PI;

const ROUGHNESS: [f32; 5] = [0.07, 0.2, 0.4, 0.7, 1.0];

/// `D`, `Λ` and both visibility terms against the f64 reference over `n·h`, `n·l`, `n·v`
/// from grazing to normal and roughness 0.07–1. Bounds: `D` raises `sin²θ` to `1/(2α)`
/// (up to 102 at r = 0.07) through the shaders' `exp2(y·log2 x)`, which multiplies the
/// f32 rounding of `log2 x` by the exponent: measured 3.3·10⁻⁶, bound 2·10⁻⁵ relative where
/// `D` is above 10⁻²⁰ of its peak (below, its share of any integral is nil); the
/// visibilities' `exp` and powers of the fit, measured 1.9·10⁻⁶, bound 2·10⁻⁵ relative.
#[test]
fn charlie_terms_match_the_f64_reference() {
    let cosines = [0.0f32, 0.01, 0.1, 0.3, 0.5, 0.5001, 0.7, 0.9, 0.99, 1.0];
    let (mut worst_d, mut worst_v) = (0.0f64, 0.0f64);
    for &r in &ROUGHNESS {
        let (a, a64) = (sheen::alpha(r), reference::alpha(r as f64));
        let peak = reference::d_charlie(0.0, a64);
        for &c in &cosines {
            let want = reference::d_charlie(c as f64, a64);
            if want > 1e-20 * peak {
                let got = sheen::d_charlie(c, a) as f64;
                worst_d = worst_d.max((got - want).abs() / want);
                assert!((got - want).abs() <= 2e-5 * want, "D(n·h = {c}, r = {r}) = {got:e}, reference {want:e}");
            }
            let lam = (sheen::lambda_charlie(c, a) as f64, reference::lambda_charlie(c as f64, a64));
            assert!((lam.0 - lam.1).abs() <= 2e-5 * lam.1, "Λ({c}, r = {r}) = {:e}, reference {:e}", lam.0, lam.1);
            for &v in &cosines {
                let pairs = [
                    (sheen::v_charlie(c, v, a) as f64, reference::v_charlie(c as f64, v as f64, a64)),
                    (sheen::v_neubelt(c, v) as f64, reference::v_neubelt(c as f64, v as f64)),
                ];
                for (got, want) in pairs {
                    worst_v = worst_v.max((got - want).abs() / want.max(1e-30));
                    assert!((got - want).abs() <= 2e-5 * want.max(1e-6), "V(n·l = {c}, n·v = {v}, r = {r}) = {got:e}, reference {want:e}");
                }
            }
        }
    }
    println!("sheen against f64: D max relative {worst_d:.2e}, visibilities {worst_v:.2e}");
}

/// The distribution is normalised: `∫ D(h)(n·h) dω = 2π ∫ D cos θ sin θ dθ = 1` (the module
/// header's derivation), for the shaders' f32 `D` integrated in f64 over `θ` by a
/// composite 10-point Gauss–Legendre rule on 4000 pieces (each 4·10⁻⁴ rad, under a
/// hundredth of the narrowest lobe's width, about √α = r = 0.07 rad at r = 0.07).
/// Bound 10⁻⁴: five times `D`'s relative bound above.
#[test]
fn charlie_is_normalised() {
    for &r in &ROUGHNESS {
        let a = sheen::alpha(r);
        let f = |t: f64| 2.0 * PI * sheen::d_charlie(t.cos() as f32, a) as f64 * t.cos() * t.sin();
        let total = integrate(f, 0.0, PI / 2.0, 4000, 10);
        println!("r = {r}: ∫ D (n·h) dω = {total:.6}");
        assert!((total - 1.0).abs() < 1e-4, "r = {r}: {total}");
    }
}

/// Half vectors drawn by `sample_charlie_tangent` follow the density `D(h)(n·h)`: over 4096
/// Hammersley points, the mean of `cos²θ` is its closed form `2α/(4α + 1)` (the moment of
/// the density, from `E[1 − s²]` with `s` distributed as `s^(2 + 1/α)`), and the mean of
/// `sin θ` is `(2α + 1)/(3α + 1)`, within 10⁻³ (the points' discrepancy at N = 4096, a
/// quasi-random error of order log N / N); every sample is a unit vector above the surface.
#[test]
fn charlie_sampling_follows_its_density() {
    let n = 4096;
    for &r in &ROUGHNESS {
        let a = sheen::alpha(r);
        let (mut cos2, mut sin1) = (0.0f64, 0.0f64);
        for i in 0..n {
            let h = sheen::sample_charlie_tangent(hammersley(i, n), a);
            assert!((h.length() - 1.0).abs() < 1e-5 && h.z >= 0.0, "{h:?}");
            cos2 += (h.z as f64).powi(2);
            sin1 += (h.x as f64).hypot(h.y as f64);
        }
        let (a, n) = (a as f64, n as f64);
        let (want_cos2, want_sin) = (2.0 * a / (4.0 * a + 1.0), (2.0 * a + 1.0) / (3.0 * a + 1.0));
        println!("r = {r}: E[cos²θ] {:.5} (closed form {want_cos2:.5}), E[sin θ] {:.5} ({want_sin:.5})", cos2 / n, sin1 / n);
        assert!((cos2 / n - want_cos2).abs() < 1e-3 && (sin1 / n - want_sin).abs() < 1e-3, "r = {r}");
    }
    // ξ on the edges of the unit square stays finite and unit.
    for xi in [Vec2::ZERO, Vec2::ONE, Vec2::new(0.0, 1.0), Vec2::new(1.0, 0.0)] {
        let h = sheen::sample_charlie_tangent(xi, sheen::alpha(0.0));
        assert!(h.is_finite() && (h.length() - 1.0).abs() < 1e-5, "{xi:?}: {h:?}");
    }
}

/// The reference's directional albedo is converged (tightening its tolerance a
/// tenfold moves it less than 10⁻⁵, a tenth of the tables' 10⁻⁴ target) and physical with the Charlie visibility
/// (between 0 and 1: a layer that reflects no more than it receives).
#[test]
fn sheen_albedo_reference_is_converged() {
    for &r in &[0.07, 0.4, 1.0] {
        for &nv in &[0.05, 0.5, 1.0] {
            let coarse = reference::albedo(nv, r, reference::Visibility::Charlie, 1e-6);
            let fine = reference::albedo(nv, r, reference::Visibility::Charlie, 1e-7);
            println!("E_charlie(n·v = {nv}, r = {r}) = {fine:.6}");
            assert!((coarse - fine).abs() < 1e-5, "{coarse} against {fine}");
            assert!(fine > 0.0 && fine <= 1.0, "{fine}");
        }
    }
}

/// The sheen albedo by quadrature (`sheen::albedo`, the tables' integrand) against the f64
/// reference (over the light direction, adaptive), both visibility terms, n·v from grazing
/// to normal and roughness 0.07–1: within 10⁻⁴ (the target for the tables).
#[test]
fn sheen_albedo_matches_the_f64_reference() {
    let mut worst = (0.0f64, 0.0f32, 0.0f32, "");
    for &r in &ROUGHNESS {
        for &nv in &[0.002f32, 0.01, 0.05, 0.1, 0.25, 0.5, 0.75, 0.9, 1.0] {
            for (vis, rvis, name) in [(sheen::SheenVisibility::Charlie, reference::Visibility::Charlie, "charlie"), (sheen::SheenVisibility::Neubelt, reference::Visibility::Neubelt, "neubelt")] {
                let got = sheen::albedo(nv, r, vis) as f64;
                let want = reference::albedo(nv as f64, r as f64, rvis, 1e-8);
                let err = (got - want).abs();
                if err > worst.0 {
                    worst = (err, nv, r, name);
                }
                assert!(err <= 1e-4, "{name}: E(n·v = {nv}, r = {r}) = {got:.6}, reference {want:.6}");
            }
        }
    }
    println!("sheen albedo against f64: worst {:.2e} at n·v {}, r {} ({})", worst.0, worst.1, worst.2, worst.3);
}

/// The sheen prefilter's light samples (`sheen::charlie_light_sample`) invert the
/// survival function of their density in closed form, `S(u) = (1 − u)^b (1 + b·u)`,
/// `b = 1 + 1/(2α)`, evaluated in f64: `|S(u) − ξ|` within 10⁻⁵ (a hundredth of a stratum
/// of 1024 samples; f32 Newton steps on `y`, measured up to 6·10⁻⁶) for ξ from 2⁻²⁴ to 1 − 2⁻²⁴ and α from 10⁻¹² (sheen roughness 0) to
/// 1; every direction above the horizon and of unit length; the returned density equals
/// the closed form `b(b + 1)/(2π) · u (1 − u)^(b−1)` (f64) within 10⁻⁴ relative; and the
/// stratified samples' mean `n·l` is the Beta(2, b) mean `2/(b + 2)` within 10⁻³ relative.
#[test]
fn charlie_light_samples_invert_their_distribution() {
    for &r in &[1e-6f32, 1e-3, 0.05, 0.143, 0.3, 0.5, 0.75, 1.0] {
        let alpha = sheen::alpha(r);
        let b = 1.0 + 0.5 / alpha as f64;
        let mut worst = 0.0f64;
        let n = 4096;
        let mut mean = 0.0f64;
        for i in 0..n {
            let xi_y = (i as f32 + 0.5) / n as f32;
            for xi in [xi_y, 2f32.powi(-24), 1.0 - 2f32.powi(-24)] {
                let s = sheen::charlie_light_sample(Vec2::new(0.37, xi), alpha);
                let u = s.z as f64;
                assert!(u > 0.0 && u <= 1.0, "r {r}, ξ {xi}: n·l {u}");
                assert!((s.truncate().length() - 1.0).abs() < 1e-6, "r {r}, ξ {xi}: |l| = {}", s.truncate().length());
                // Survival and density in f64, through ln(1 − u) (ln_1p) for huge b.
                let log1mu = (-u).ln_1p();
                let surv = (b * log1mu).exp() * (1.0 + b * u);
                let dens = b * (b + 1.0) / (2.0 * PI) * u * ((b - 1.0) * log1mu).exp();
                // The slope of S is the density in u, 2π·pdf: a rounding δu of u moves S by
                // 2π·pdf·δu.
                let slack = 1e-5 + 2.0 * PI * dens * u * 2.0 * f32::EPSILON as f64;
                let e = (surv - xi as f64).abs();
                assert!(e <= slack, "r {r}, ξ {xi}: S(u = {u:e}) = {surv}, {e:e} from ξ (slack {slack:e})");
                worst = worst.max(e);
                assert!(((s.w as f64) - dens).abs() <= 1e-4 * dens, "r {r}, ξ {xi}: pdf {} against {dens}", s.w);
                if xi == xi_y {
                    mean += u / n as f64;
                }
            }
        }
        let want = 2.0 / (b + 2.0);
        println!("r {r}: |S(u) − ξ| ≤ {worst:.1e}; mean n·l {mean:.4e} against {want:.4e}");
        assert!((mean - want).abs() <= 1e-3 * want, "r {r}: mean n·l {mean} against {want}");
    }
}

/// The ring's tiles (`bright::ring_tile_reached`, `splitsum::backend::split::ring_table`)
/// lose no chord: for entries of every solid angle a 16²–256² split level holds, in
/// directions spread over the sphere and on face edges and corners, every tile holding a
/// texel centre whose `(n·l)² < Ω/π` (the chord's support, in f64 from the reference's own
/// face mapping) is reached. And the tiles pay: a 256² ring's tiles reach under a tenth of
/// the entries of a 64² split level on average.
#[test]
fn ring_tiles_keep_every_chord() {
    use splitsum_shaders::bright::{ring_tile, ring_tile_reached, ring_tiles};
    use splitsum_shaders::glam::Vec4;
    let mut dirs: Vec<[f64; 3]> = (0..96)
        .map(|i| {
            let p = hammersley(i, 96);
            let (z, phi) = (1.0 - 2.0 * p.x as f64, 2.0 * PI * p.y as f64);
            let r = (1.0 - z * z).max(0.0).sqrt();
            [r * phi.cos(), r * phi.sin(), z]
        })
        .collect();
    // Face edges and corners.
    let s = 1.0 / 2f64.sqrt();
    let t = 1.0 / 3f64.sqrt();
    dirs.extend([[s, s, 0.0], [0.0, -s, s], [-s, 0.0, -s], [t, t, t], [-t, t, -t], [t, -t, -t]]);
    for size in [8u32, 64, 256] {
        let tiles = ring_tiles(size);
        let mut reached = 0u64;
        let mut tested = 0u64;
        for split in [16u32, 64, 256] {
            // A texel's solid angle at the face centre of a `split`² level, and ten times it.
            for omega in [4.0 / (split * split) as f64, 40.0 / (split * split) as f64] {
                for d in &dirs {
                    let g = Vec4::new(d[0] as f32, d[1] as f32, d[2] as f32, omega as f32);
                    let mut must = vec![false; (6 * tiles * tiles) as usize];
                    for face in 0..6 {
                        for y in 0..size {
                            for x in 0..size {
                                let n = splitsum_reference::texel_dir(face, x, y, size);
                                let u = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
                                if u * u < omega / PI {
                                    must[ring_tile(face, x, y, size) as usize] = true;
                                }
                            }
                        }
                    }
                    for face in 0..6 {
                        for ty in 0..tiles {
                            for tx in 0..tiles {
                                let got = ring_tile_reached(face, tx, ty, size, g);
                                let want = must[((face * tiles + ty) * tiles + tx) as usize];
                                assert!(got || !want, "{size}²: tile ({face}, {tx}, {ty}) misses an entry along {d:?} of Ω {omega:e}");
                                if split == 64 && size == 256 {
                                    reached += got as u64;
                                    tested += 1;
                                }
                            }
                        }
                    }
                }
            }
        }
        if size == 256 {
            let share = reached as f64 / tested as f64;
            println!("256² ring, 64² split level: a tile reaches {:.1} % of the entries", 100.0 * share);
            assert!(share < 0.1, "{share}");
        }
    }
}

/// The cost model's expected chords per ring tile (`bright::ring_tile_expected`: each
/// entry reaches a tile with chance `min(sin(β + γ), 1)`, since `c·l` is uniform on
/// [−1, 1] for `l` uniform on the sphere) against a count: 20 000 entries in Hammersley
/// directions, each tested by the ring's own `ring_tile_reached`, over the tiles of two
/// faces (a side and a pole, every tile of 8² and 64² rings, every fourth column of 256²),
/// for the mean solid angle of a 64² and a 16² split level. The sum over the tiles is held
/// within 1 % (a quasi-random point set's error on a band is about 1/N of its count, far
/// inside that), each tile within 5 % or 3 entries.
#[test]
fn ring_tile_expected_counts_entries_spread_over_the_sphere() {
    use splitsum_shaders::bright::{ring_tile_expected, ring_tile_reached, ring_tiles};
    use splitsum_shaders::glam::Vec4;
    let n = 20_000u32;
    let dirs: Vec<[f32; 3]> = (0..n)
        .map(|i| {
            let p = hammersley(i, n);
            let (z, phi) = (1.0 - 2.0 * p.x as f64, 2.0 * PI * p.y as f64);
            let r = (1.0 - z * z).max(0.0).sqrt();
            [(r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32]
        })
        .collect();
    for size in [8u32, 64, 256] {
        for split in [16u32, 64] {
            let omega = (4.0 * PI / (6.0 * (split * split) as f64)) as f32;
            let tiles = ring_tiles(size);
            // One face of each: the others are its rotations.
            let (mut counted, mut expected) = (0.0f64, 0.0f64);
            for face in [0u32, 4] {
                for ty in 0..tiles {
                    for tx in (0..tiles).step_by((tiles as usize / 8).max(1)) {
                        let got = dirs.iter().filter(|d| ring_tile_reached(face, tx, ty, size, Vec4::new(d[0], d[1], d[2], omega))).count() as f64;
                        let want = ring_tile_expected(face, tx, ty, size, n, omega) as f64;
                        assert!((got - want).abs() <= (0.05 * want).max(3.0), "{size}² ring, {split}² split, tile ({face}, {tx}, {ty}): {got} entries reach it, {want:.1} expected");
                        counted += got;
                        expected += want;
                    }
                }
            }
            println!("{size}² ring, {split}² split: {counted} entries reach the tiles tested, {expected:.1} expected");
            assert!((counted / expected - 1.0).abs() < 0.01, "{size}² ring, {split}² split: {counted} against {expected}");
        }
    }
}

/// The sheen excess list's density as a traced level reads it (`bright::excess_density`:
/// a table interpolated linearly up to `u` = 63/64 where `1/(2α) ≤ 32`, computed elsewhere)
/// against the f64 density `b(b+1)/(2π)·u(1 − u)^(b−1)`, `b = 1 + 1/(2α)`, at 2·10⁵ values
/// of `u = n·l` and the edges. Bound, relative to the density's peak: the interpolation's
/// `h²/8·max|pdf''|` over the tabulated range (computed here from the f64 second
/// derivative; 1.1·10⁻⁵ at most, at sheen roughness 0.125), plus the f32 density's own
/// error, 2·10⁻⁵ of its value (its power, as `charlie_terms_match_the_f64_reference`
/// bounds `D`'s). Below the horizon, and for NaN, exactly 0.
#[test]
fn tabulated_sheen_density_is_within_its_interpolation_bound() {
    use splitsum_shaders::bright::{DENSITY_ENTRIES, DENSITY_STEPS, density_table, excess_density, tabulates};
    use splitsum_shaders::glam::Vec4;
    for r in [0.1f32, 0.124, 0.125, 0.15, 0.2, 0.3, 0.4, 0.6, 0.8, 1.0] {
        let alpha = sheen::alpha(r);
        let k = 0.5 / alpha as f64;
        let b = 1.0 + k;
        let c = b * (b + 1.0) / (2.0 * PI);
        let pdf = |u: f64| if u > 0.0 { c * u * (1.0 - u).max(0.0).powf(k) } else { 0.0 };
        let d2 = |u: f64| c * (-2.0 * k * (1.0 - u).powf(k - 1.0) + u * k * (k - 1.0) * (1.0 - u).powf(k - 2.0));
        let grid = 200_000;
        let peak = (0..=grid).map(|i| pdf(i as f64 / grid as f64)).fold(0.0, f64::max);
        let table: Vec<Vec4> = density_table(alpha).collect();
        assert_eq!(table.len() as u32, if tabulates(alpha) { DENSITY_ENTRIES } else { 0 }, "roughness {r}");
        let h = 1.0 / DENSITY_STEPS as f64;
        let interpolation = if tabulates(alpha) { (0..=grid).map(|i| 63.0 / 64.0 * i as f64 / grid as f64).map(|u| d2(u).abs()).fold(0.0, f64::max) * h * h / 8.0 / peak } else { 0.0 };
        assert!(interpolation < 1.1e-5, "roughness {r}: {interpolation:e}");
        let mut worst = 0.0f64;
        let us = (0..grid).map(|i| (i as f64 + 0.37) / grid as f64).chain([0.0, 1e-30, 63.0 / 64.0, 63.0 / 64.0 + 1e-7, 1.0 - 1e-7, 1.0]);
        for u in us {
            let got = excess_density(&table, 0, u as f32, alpha) as f64;
            let want = pdf(u as f32 as f64);
            let err = (got - want).abs() / peak;
            assert!(err <= interpolation + 2e-5 * want / peak + 1e-9, "roughness {r}, u {u}: {got:e} against {want:e} ({err:e} of the peak)");
            worst = worst.max(err);
        }
        println!("sheen roughness {r}: tabulated {}, worst {worst:.2e} of the peak (bound {interpolation:.2e} + the f32 density's)", tabulates(alpha));
        for u in [-1.0f32, -0.0, f32::NAN, f32::NEG_INFINITY] {
            assert_eq!(excess_density(&table, 0, u, alpha), 0.0, "roughness {r}, u {u}");
        }
    }
}
