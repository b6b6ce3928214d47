//! Cube-map conventions, texel solid angles and seamless filtering.

use splitsum_reference as reference;
use splitsum_shaders::cubemap::{self, CubeLayout};
use splitsum_shaders::glam::{Vec2, Vec3, Vec4};

#[test]
fn face_mapping_round_trips_and_follows_the_vulkan_table() {
    // Face centres.
    let centres = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
    for (f, c) in centres.iter().enumerate() {
        let (face, uv) = cubemap::dir_to_face_uv(*c);
        assert_eq!((face, uv), (f as u32, Vec2::splat(0.5)));
    }
    // Orientation: on +X, u grows towards −Z and v towards −Y (OpenGL 4.6 table 8.19).
    let (_, uv) = cubemap::dir_to_face_uv(Vec3::new(1.0, -0.5, -0.5));
    assert_eq!(uv, Vec2::new(0.75, 0.75));
    // Round trip, and agreement with the independent f64 table.
    for f in 0..6 {
        for (x, y) in [(0u32, 0u32), (3, 7), (15, 15), (8, 2)] {
            let d = cubemap::texel_dir(f, x, y, 16);
            let r = reference::texel_dir(f, x, y, 16);
            assert!((d.x as f64 - r[0]).abs() < 1e-6 && (d.y as f64 - r[1]).abs() < 1e-6 && (d.z as f64 - r[2]).abs() < 1e-6);
            let (face, uv) = cubemap::dir_to_face_uv(d);
            assert_eq!(face, f);
            assert!((uv - Vec2::new((x as f32 + 0.5) / 16.0, (y as f32 + 0.5) / 16.0)).abs().max_element() < 1e-6);
        }
    }
    // Ties at edges and corners are decided the same way every time; zero is harmless.
    assert_eq!(cubemap::dir_to_face_uv(Vec3::new(1.0, 1.0, 1.0)).0, 0);
    assert_eq!(cubemap::dir_to_face_uv(Vec3::new(0.0, -1.0, 1.0)).0, 3);
    assert_eq!(cubemap::dir_to_face_uv(Vec3::ZERO), (0, Vec2::splat(0.5)));
}

/// The exact texel solid angles add up to the sphere, and agree texel by texel with
/// Driscoll's corner formula evaluated in f64.
#[test]
fn texel_solid_angles_sum_to_4_pi() {
    for s in [1u32, 2, 4, 64, 1024] {
        let mut sum = 0.0f64;
        let mut worst = 0.0f64;
        for y in 0..s {
            for x in 0..s {
                let o = cubemap::texel_solid_angle(x, y, s) as f64;
                let r = reference::texel_solid_angle(x, y, s);
                worst = worst.max((o - r).abs() / r);
                sum += 6.0 * o;
            }
        }
        let rel = (sum - 4.0 * std::f64::consts::PI).abs() / (4.0 * std::f64::consts::PI);
        println!("s = {s}: Σ Ω = 4π·(1 {rel:+.1e}), worst texel relative error {worst:.1e}");
        // f32: a few ULP per texel (the triple product is exact); the sum is in f64.
        assert!(worst < 1e-6, "s {s}: {worst:e}");
        assert!(rel < 1e-6, "s {s}: {rel:e}");
    }
}

fn noise_cube(size: u32, levels: u32) -> (CubeLayout, Vec<Vec4>) {
    let layout = CubeLayout::new(size, levels);
    let mut state = 0x2545_f491u32;
    let texels = (0..layout.texel_count())
        .map(|_| {
            let mut next = || {
                state ^= state << 13;
                state ^= state >> 17;
                state ^= state << 5;
                (state >> 8) as f32 / (1 << 24) as f32
            };
            Vec4::new(next(), next(), next(), 1.0)
        })
        .collect();
    (layout, texels)
}

/// Bilinear filtering is continuous across face edges and at cube corners: approaching a
/// seam from its two sides gives the same value, up to the slope over the tiny step.
#[test]
fn bilinear_filtering_is_seamless() {
    let (layout, texels) = noise_cube(8, 1);
    let eps = 1e-4f32;
    let mut worst = 0.0f32;
    // Points on the twelve edges (between two faces) and at the eight corners.
    let mut seams = Vec::new();
    for i in 0..=20 {
        let t = -1.0 + 2.0 * i as f32 / 20.0;
        for (a, b) in [(1.0f32, 1.0f32), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
            seams.push(Vec3::new(a, b, t));
            seams.push(Vec3::new(a, t, b));
            seams.push(Vec3::new(t, a, b));
        }
    }
    for p in seams {
        let p = p.normalize();
        // Step off the seam in every direction perpendicular to it.
        let (t, b) = splitsum_shaders::sampling::orthonormal_basis(p);
        let mut vals = Vec::new();
        for k in 0..16 {
            let (s, c) = (k as f32 * std::f32::consts::TAU / 16.0).sin_cos();
            let d = (p + (t * c + b * s) * eps).normalize();
            vals.push(cubemap::sample_bilinear(&texels, layout, 0, d));
        }
        for v in &vals {
            worst = worst.max((*v - vals[0]).abs().max_element());
        }
    }
    println!("largest jump across seams and corners at a step of {eps:e}: {worst:.2e}");
    // Texel values are in [0, 1] and 8 texels span a face, so a step of 1e-4 moves a
    // continuous bilinear value by at most ~1e-3; a seam would jump by O(0.5).
    assert!(worst < 3e-3, "{worst:e}");
}

#[test]
fn bilinear_at_texel_centres_returns_the_texel() {
    let (layout, texels) = noise_cube(16, 1);
    for f in 0..6 {
        for y in 0..16 {
            for x in 0..16 {
                let v = cubemap::sample_bilinear(&texels, layout, 0, cubemap::texel_dir(f, x, y, 16));
                let t = texels[layout.index(0, f, x, y) as usize];
                assert!((v - t).abs().max_element() < 2e-6, "{f} {x} {y}: {v} vs {t}");
            }
        }
    }
}

#[test]
fn constant_cube_filters_to_the_constant() {
    let layout = CubeLayout::new(16, 5);
    let c = Vec4::new(3.0, 0.25, 7.5, 1.0);
    let texels = vec![c; layout.texel_count() as usize];
    for i in 0..2000 {
        let p = splitsum_shaders::sampling::hammersley(i, 2000);
        let d = splitsum_shaders::equirect::uv_to_dir(p);
        for lod in [0.0, 0.3, 1.0, 2.7, 4.0, 9.0, -3.0] {
            let v = cubemap::sample_lod(&texels, layout, d, lod);
            assert!((v - c).abs().max_element() <= 1e-6 * 7.5, "{d} {lod}: {v}");
        }
    }
}

/// The solid-angle-weighted box filter conserves the sphere's integral of radiance from
/// level to level.
#[test]
fn downsampling_conserves_energy() {
    let (layout, mut texels) = noise_cube(32, 6);
    for level in 0..5 {
        let s = layout.level_size(level + 1);
        for f in 0..6 {
            for y in 0..s {
                for x in 0..s {
                    let v = cubemap::downsample_texel(&texels, layout, level, f, x, y);
                    texels[layout.index(level + 1, f, x, y) as usize] = v;
                }
            }
        }
    }
    let energy = |level: u32| -> f64 {
        let s = layout.level_size(level);
        let start = layout.level_offset(level) as usize;
        reference::texels(&texels[start..start + (6 * s * s) as usize], s).iter().map(|(_, o, c)| o * c[0]).sum()
    };
    let e0 = energy(0);
    for level in 1..6 {
        let rel = (energy(level) - e0).abs() / e0;
        assert!(rel < 1e-5, "level {level}: {rel:e}");
    }
}

/// Each facing is a turn about +Y: it keeps up and length, `cube_direction` undoes
/// `image_direction`, and the image centre (splitsum's −Z) lands where the facing says.
#[test]
fn facings_turn_the_image_centre_about_up() {
    use splitsum_shaders::choice::Choice;
    use splitsum_shaders::equirect::Facing;
    let centre = Vec3::new(0.0, 0.0, -1.0);
    for (f, want) in [(Facing::NegZ, Vec3::NEG_Z), (Facing::PosX, Vec3::X), (Facing::PosZ, Vec3::Z), (Facing::NegX, Vec3::NEG_X)] {
        assert_eq!(f.cube_direction(centre), want, "{}", f.name());
        assert_eq!(f.image_direction(want), centre, "{}", f.name());
        assert_eq!(f.cube_direction(Vec3::Y), Vec3::Y, "up stays up");
        let d = Vec3::new(0.3, -0.5, 0.7);
        assert!((f.image_direction(f.cube_direction(d)) - d).length() < 1e-7);
        // A proper rotation: the triple product of the turned axes is +1.
        let (x, y, z) = (f.cube_direction(Vec3::X), f.cube_direction(Vec3::Y), f.cube_direction(Vec3::Z));
        assert!((x.cross(y).dot(z) - 1.0).abs() < 1e-7, "{} keeps handedness", f.name());
        assert_eq!(Facing::from_u32(f.code()), f);
    }
}

/// `mirrored_x_texel` is the texel whose centre is the mirror `(−x, y, z)` of the given
/// texel's centre, on every face, and an involution.
#[test]
fn mirrored_x_texel_mirrors_the_texel_centre() {
    for s in [1u32, 2, 5, 8] {
        for face in 0..6 {
            for y in 0..s {
                for x in 0..s {
                    let d = reference::texel_dir(face, x, y, s);
                    let (f, mx, my) = cubemap::mirrored_x_texel(face, x, y, s);
                    let m = reference::texel_dir(f, mx, my, s);
                    assert!((m[0] + d[0]).abs() < 1e-12 && (m[1] - d[1]).abs() < 1e-12 && (m[2] - d[2]).abs() < 1e-12, "face {face} ({x}, {y}) of {s}");
                    assert_eq!(cubemap::mirrored_x_texel(f, mx, my, s), (face, x, y));
                }
            }
        }
    }
}

/// The log-luminance blend between two mips against its closed form: with level 0 a
/// constant grey `a` and level 1 a constant grey `b`, the lookup at `lod = t` is
/// `a^(1−t)·b^t` (the linear blend is `(1−t)·a + t·b`); a constant cube comes back as it is;
/// a black level gives black, not NaN.
#[test]
fn log_luminance_mip_blend_is_geometric_between_levels() {
    let layout = CubeLayout::new(4, 2);
    let (a, b) = (8.0f32, 0.5f32);
    let mut texels = vec![Vec4::ZERO; layout.texel_count() as usize];
    for (i, t) in texels.iter_mut().enumerate() {
        let level0 = (i as u32) < layout.level_offset(1);
        *t = Vec4::new(1.0, 1.0, 1.0, 1.0) * if level0 { a } else { b };
        t.w = 1.0;
    }
    let d = Vec3::new(0.3, -0.5, 0.8).normalize();
    for t in [0.0f32, 0.25, 0.5, 0.9, 1.0] {
        let got = cubemap::sample_lod_log(&texels, layout, d, t);
        let want = a.powf(1.0 - t) * b.powf(t);
        assert!((got.x / want - 1.0).abs() < 2e-6 && (got.y - got.x).abs() < 1e-5 && got.w == 1.0, "t = {t}: {got} against {want}");
    }
    let constant = vec![Vec4::new(0.2, 0.4, 0.8, 1.0); layout.texel_count() as usize];
    let got = cubemap::sample_lod_log(&constant, layout, d, 0.6);
    assert!((got - Vec4::new(0.2, 0.4, 0.8, 1.0)).abs().max_element() < 1e-6, "{got}");
    let mut black = texels.clone();
    for t in black.iter_mut().skip(layout.level_offset(1) as usize) {
        *t = Vec4::new(0.0, 0.0, 0.0, 1.0);
    }
    let got = cubemap::sample_lod_log(&black, layout, d, 0.5);
    assert!(got.is_finite() && got.truncate().max_element() < 1e-3, "{got}");
}

/// The tabulated edge wrap (`cubemap::edge_texel`) is the geometric one: for every face,
/// every edge, every texel along it and every level size from 1 to 1024, the texel one
/// step across the edge is the texel whose square holds the direction through that step's
/// centre on the extended face plane (`texel_of_dir(face_uv_to_cube(face, uv))`, in the
/// same f32 arithmetic the seamless lookup used before the table).
#[test]
fn the_tabulated_edge_wrap_is_the_geometric_one() {
    let mut s = 1u32;
    while s <= 1024 {
        let layout = CubeLayout::new(s, 1);
        for face in 0..6 {
            for edge in 0..4u32 {
                for t in 0..s {
                    let (x, y) = match edge {
                        0 => (-1, t as i32),
                        1 => (s as i32, t as i32),
                        2 => (t as i32, -1),
                        _ => (t as i32, s as i32),
                    };
                    let sf = s as f32;
                    let uv = Vec2::new((x as f32 + 0.5) / sf, (y as f32 + 0.5) / sf);
                    let want = cubemap::texel_of_dir(layout, 0, cubemap::face_uv_to_cube(face, uv));
                    let (f, ex, ey) = cubemap::edge_texel(face, edge, t, s);
                    assert_eq!(layout.index(0, f, ex, ey), want, "size {s}, face {face}, edge {edge}, t {t}");
                }
            }
        }
        s *= 2;
    }
}
