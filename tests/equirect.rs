//! Equirect conventions and the area-correct resampling to a cube.

use splitsum::Backend;
use splitsum::Product;
use splitsum::texture::Equirect;
use splitsum_shaders::choice::Choice;
use splitsum_shaders::equirect::{self, Facing};
use splitsum_shaders::glam::{Vec2, Vec3, Vec4};
use std::f64::consts::PI;
use support::reference;

#[test]
fn mapping_conventions() {
    let uv = equirect::dir_to_uv(-Vec3::Z);
    assert!((uv - Vec2::new(0.5, 0.5)).abs().max_element() < 1e-7, "{uv}");
    let uv = equirect::dir_to_uv(Vec3::X);
    assert!((uv - Vec2::new(0.75, 0.5)).abs().max_element() < 1e-7, "{uv}");
    assert!(equirect::dir_to_uv(Vec3::Y).y.abs() < 1e-7);
    assert!((equirect::dir_to_uv(-Vec3::Y).y - 1.0).abs() < 1e-7);
    for i in 0..1000 {
        let p = splitsum_shaders::sampling::hammersley(i, 1000) * Vec2::new(1.0, 0.98) + Vec2::new(0.0, 0.01);
        let back = equirect::dir_to_uv(equirect::uv_to_dir(p));
        let du = (back.x - p.x).abs().min(1.0 - (back.x - p.x).abs());
        assert!(du < 1e-6 && (back.y - p.y).abs() < 1e-6, "{p} → {back}");
    }
}

fn env(width: u32, f: impl Fn(u32, u32) -> Vec4) -> Equirect {
    let height = width / 2;
    let texels = (0..height).flat_map(|y| (0..width).map(move |x| (x, y))).map(|(x, y)| f(x, y)).collect();
    Equirect { width, height, texels }
}

/// Solid angle of equirect texel row `y` of an image `height` high and `width` wide.
fn equirect_texel_omega(y: u32, width: u32, height: u32) -> f64 {
    let t0 = PI * y as f64 / height as f64;
    let t1 = PI * (y + 1) as f64 / height as f64;
    2.0 * PI / width as f64 * (t0.cos() - t1.cos())
}

fn cube_power(cube: &splitsum::texture::Cube) -> f64 {
    reference::texels(cube.level(0), cube.layout.size).iter().map(|(_, o, c)| o * c[0]).sum()
}

#[test]
fn constant_environment_gives_the_constant_cube() {
    let c = Vec4::new(2.5, 0.5, 1e4, 1.0);
    let e = env(64, |_, _| c);
    for b in [&Backend::Cpu, support::gpu()] {
        let cube = b.equirect_to_cube(&e, 16, 4, Facing::NegZ).unwrap();
        for t in &cube.texels {
            assert!((*t - c).abs().max_element() <= 1e4 * 1e-6, "{t}");
        }
    }
}

/// A one-texel sun of 34 000 lands in the cube with its power wherever it sits — on the
/// equator, near a pole, across a face edge — instead of being hit or missed.
#[test]
fn a_small_sun_keeps_its_power() {
    let (w, h) = (256u32, 128u32);
    let mut worst = 0.0f64;
    for (sx, sy) in [(10u32, 64u32), (32, 64), (96, 40), (128, 3), (200, 100), (224, 64), (31, 21)] {
        let e = env(w, |x, y| if (x, y) == (sx, sy) { Vec4::new(34_000.0, 0.0, 0.0, 1.0) } else { Vec4::ZERO });
        let want = 34_000.0 * equirect_texel_omega(sy, w, h);
        let n = equirect::supersampling(64, w, 2.0);
        let cube = Backend::Cpu.equirect_to_cube(&e, 64, n, Facing::NegZ).unwrap();
        let got = cube_power(&cube);
        let rel = (got - want).abs() / want;
        worst = worst.max(rel);
        assert!(cube.texels.iter().all(|t| t.is_finite()));
    }
    println!("one-texel sun: largest relative error of its power in the cube: {worst:.3}");
    // Measured: within 1.3 % everywhere, the pole included (point sampling of a bilinear
    // reconstruction found 0 % of the sun near the pole).
    assert!(worst < 0.03, "{worst}");
}

#[test]
fn gpu_matches_cpu_on_a_real_environment() {
    let (envr, _) = splitsum::environment::load(std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../assets/environments/city.exr")), false).unwrap();
    let splitsum::environment::Environment::Equirect(e) = envr else { panic!() };
    let n = equirect::supersampling(64, e.width, 2.0);
    let reference = Backend::Cpu.equirect_to_cube(&e, 64, n, Facing::NegZ).unwrap();
    // Every facing of the engine targets, on both backends.
    for facing in [Facing::NegZ, Facing::PosX, Facing::PosZ, Facing::NegX] {
        let g = support::gpu().equirect_to_cube(&e, 64, n, facing).unwrap();
        let c = Backend::Cpu.equirect_to_cube(&e, 64, n, facing).unwrap();
        let mut worst = 0.0f32;
        for (a, b) in g.texels.iter().zip(&c.texels) {
            worst = worst.max(((*a - *b).abs() / b.abs().max(Vec4::splat(1e-3))).max_element());
        }
        println!("city.exr → 64² cube with mips, facing {}, gpu vs cpu: max relative difference {worst:.2e}", facing.name());
        // lavapipe 3.4e-7; an H100 5.8e-5 (its division, square root and fused multiply–adds;
        // see `support::gpu_bound`).
        let bound = support::gpu_bound(1e-5, 2e-4) as f32;
        assert!(worst < bound, "{worst:e} (bound {bound:e})");
        // A quarter or half turn about +Y maps the texel grid onto itself: each texel of
        // the turned cube is the texel of the unturned one at the turned direction, up to
        // the rounding of the directions of its supersampling points (measured 1.3e-5).
        let mut worst = 0.0f32;
        for face in 0..6 {
            for y in 0..64 {
                for x in 0..64 {
                    let d = facing.image_direction(splitsum_shaders::cubemap::texel_dir(face, x, y, 64));
                    let k = splitsum_shaders::cubemap::texel_of_dir(reference.layout, 0, d) as usize;
                    let (a, b) = (c.texels[reference.layout.index(0, face, x, y) as usize], reference.texels[k]);
                    worst = worst.max(((a - b).abs() / b.abs().max(Vec4::splat(1e-3))).max_element());
                }
            }
        }
        println!("facing {}: largest difference from the turned splitsum cube {worst:.2e}", facing.name());
        assert!(worst < 1e-4, "facing {}: {worst:e}", facing.name());
    }
}

/// A `width`×`width/2` test sky: texel noise over a gradient, and a small sun of `sun`.
fn noisy_sky(x: u32, y: u32, width: u32, sun: f32) -> f32 {
    let (u, v) = (x as f32 / width as f32, 2.0 * y as f32 / width as f32);
    let n = (x.wrapping_mul(0x9E37_79B9) ^ y.wrapping_mul(0x85EB_CA6B)).rotate_left(13).wrapping_mul(0xC2B2_AE35);
    let sky = (0.2 + 0.8 * (1.0 - v)) * (0.75 + 0.5 * (n >> 8) as f32 / (1u32 << 24) as f32);
    let (du, dv) = (u - 0.3, v - 1.0 / 3.0);
    if du * du + dv * dv < 2e-5 { sun } else { sky }
}

/// Reading a large equirect for a small cube reduces it as it is decoded (to what the cube
/// resolves): the power of the reduced image equals the file's, summed independently in
/// f64 from the generating function, and the baked products differ from those of the
/// unreduced image by less than their own sampling error.
#[test]
fn reading_for_a_cube_reduces_the_image_and_keeps_its_power() {
    let width = 4096u32;
    let sun = 2.0e4;
    let dir = std::env::temp_dir().join(format!("splitsum-reduce-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("sky.exr");
    {
        use exr::prelude::*;
        let ch = SpecificChannels::rgb(|p: Vec2<usize>| {
            let v = noisy_sky(p.x() as u32, p.y() as u32, width, sun);
            (v, 0.5 * v, 0.25 * v)
        });
        Image::from_channels((width as usize, width as usize / 2), ch).write().to_file(&path).unwrap();
    }
    let height = width / 2;
    let power: f64 = (0..height).map(|y| (0..width).map(|x| noisy_sky(x, y, width, sun) as f64).sum::<f64>() * equirect_texel_omega(y, width, height)).sum();

    let (reduced, report) = splitsum::environment::load_for(&path, false, 256).unwrap();
    let (full, _) = splitsum::environment::load_for(&path, false, 4096).unwrap();
    let splitsum::environment::Environment::Equirect(r) = &reduced else { panic!() };
    assert_eq!((r.width, r.height, report.original), (2048, 1024, (4096, 2048)));
    let reduced_power: f64 = (0..r.height)
        .map(|y| (0..r.width).map(|x| r.texels[(y * r.width + x) as usize].x as f64).sum::<f64>() * equirect_texel_omega(y, r.width, r.height))
        .sum();
    // f32 texels (7 significant digits) and f32 row weights: 1e-5 relative.
    assert!((reduced_power / power - 1.0).abs() < 1e-5, "power {reduced_power} vs {power}");

    let settings = splitsum::settings::Settings::default();
    let products = splitsum::Products::of(&[Product::Specular, Product::Irradiance]);
    let a = splitsum::bake::bake(&Backend::Cpu, &reduced, &settings, products).unwrap();
    let b = splitsum::bake::bake(&Backend::Cpu, &full, &settings, products).unwrap();
    // Both source cubes hold the file's power, the sun's included: the resampling keeps a
    // one-texel sun's power within 1.3 % (a_small_sun_keeps_its_power); over this 60-texel
    // sun and the sky, measured 1.5e-4 apart.
    let (pa, pb) = (cube_power(a.cube(Product::SourceCube).unwrap()), cube_power(b.cube(Product::SourceCube).unwrap()));
    assert!((pa / power - 1.0).abs() < 1e-3 && (pb / power - 1.0).abs() < 1e-3, "source power {pa} (reduced), {pb} (full) vs {power}");
    let (sa, sb) = (a.cube(Product::Specular).cloned().unwrap(), b.cube(Product::Specular).cloned().unwrap());
    for m in 0..sa.layout.levels {
        let max = support::max_relative(sa.level(m), sb.level(m), 0.05);
        let mean = mean_relative(sa.level(m), sb.level(m));
        eprintln!("mip {m}: max {max:.2e} mean {mean:.2e}");
        if m == 0 {
            // The mirror mip is the source cube itself: each texel averages the ±25 % texel
            // noise over a footprint that the reduction shifts (measured 1.1 %).
            assert!(mean < 0.02, "mip 0: mean relative difference {mean}");
        } else {
            // Filtered mips: measured 1.4e-4 to 3.6e-4 mean and at most 2.7e-2 (at the sun's
            // rim), against 5–10 % that the bake's sampling adds to the shaded colour.
            assert!(mean < 1e-3 && max < 0.05, "mip {m}: mean {mean}, max {max}");
        }
    }
    let d = mean_relative(&a.cube(Product::Irradiance).cloned().unwrap().texels, &b.cube(Product::Irradiance).cloned().unwrap().texels);
    assert!(d < 1e-3, "irradiance: mean relative difference {d}");
    let _ = std::fs::remove_dir_all(&dir);
}

fn mean_relative(a: &[Vec4], b: &[Vec4]) -> f64 {
    a.iter().zip(b).map(|(x, y)| ((x.x - y.x).abs() / y.x.abs().max(1e-3)) as f64).sum::<f64>() / a.len() as f64
}

/// A step whose largest buffer is more than the device binds runs on the CPU, the others
/// on the device (`splitsum::placement`, decided before the bake; the GPU executor has no
/// fallback of its own). The row pyramid of a 4096×2048 equirect is 256 MiB, over the
/// 128 MiB lavapipe binds: its source cube is the CPU's, bit for bit, and the products the
/// device makes from it hold the GPU-vs-CPU bound of the prefilter (`prefilter.rs`).
#[test]
fn a_step_larger_than_the_device_binds_runs_on_the_cpu() {
    use splitsum::placement::{Place, place};
    let w = 4096u32; // env(w, …) is w × w/2
    let env = splitsum::Environment::Equirect(env(w, |x, y| Vec4::new(1.0 + (x % 97) as f32 / 97.0, 0.5 + (y % 31) as f32 / 31.0, 2.0, 1.0)));
    let settings = splitsum::Settings { size: 32, source_size: Some(64), irradiance_size: 8, lut_size: 16, ..Default::default() };
    let job = settings.resolve(splitsum::InputShape::of(&env), splitsum::Products::DISPLAY).unwrap();
    let splitsum::Backend::Gpu(g) = support::gpu() else { unreachable!("opened as a GPU") };
    let on_host = matches!(place(Product::SourceCube, &job, Some(g.max_binding())), Place::Host { .. });
    assert_eq!(place(Product::Specular, &job, Some(g.max_binding())), Place::Device, "the 32² cube's sums fit");
    let gpu = splitsum::bake::bake_job(support::gpu(), &env, &job).unwrap();
    let cpu = splitsum::bake::bake_job(&Backend::Cpu, &env, &job).unwrap();
    let (gs, cs) = (gpu.cube(Product::SourceCube).unwrap(), cpu.cube(Product::SourceCube).unwrap());
    if on_host {
        assert!(gs.texels == cs.texels, "the source cube placed on the host is the CPU's");
    } else {
        println!("this device binds {} MiB: the source cube ran on it", g.max_binding() >> 20);
    }
    let rel = support::max_relative(&gpu.cube(Product::Specular).unwrap().texels, &cpu.cube(Product::Specular).unwrap().texels, 1e-3);
    println!("4096×2048 → 64² source (on the {}), 32² specular on the device: gpu vs cpu max relative {rel:.2e}", if on_host { "CPU" } else { "device" });
    let bound = support::gpu_bound(1e-5, 5e-5) as f32;
    assert!(rel < bound, "{rel:e} (bound {bound:e})");
}
