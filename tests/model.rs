//! glTF models: the bundled sample is current, loads with its transforms and every
//! texture, and the GPU draws it as the CPU reference rasteriser does.

use runner::Backend;
use runner::render::{GpuModel, GpuScene, ViewState};
use splitsum_shaders::glam::{Vec3, Vec4};
use std::path::PathBuf;

fn sample_path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../assets/models/torus.glb")
}

/// `assets/models/torus.glb` is what `support::model::sample_glb` writes (regenerate with
/// `SPLITSUM_WRITE_ASSETS=1 cargo test -p splitsum-tests --test model`).
#[test]
fn committed_sample_model_is_current() {
    let fresh = support::model::sample_glb();
    if std::env::var_os("SPLITSUM_WRITE_ASSETS").is_some() {
        std::fs::write(sample_path(), &fresh).unwrap();
    }
    assert!(std::fs::read(sample_path()).unwrap() == fresh, "assets/models/torus.glb is stale");
}

#[test]
fn loads_with_node_transforms_and_every_texture() {
    let m = runner::model::load(&sample_path()).unwrap();
    assert_eq!(m.primitives.len(), 1);
    let p = &m.primitives[0];
    assert!(p.textures.iter().all(|t| t.is_some()), "all five slots");
    assert_eq!(p.material.textures.x, 0b11111);
    assert_eq!(p.material.emissive.truncate(), Vec3::splat(4.0));
    assert!(p.textures[0].as_ref().unwrap().srgb && !p.textures[2].as_ref().unwrap().srgb);
    // Scale 2 and a 60° turn about x: x keeps its extent 2·1.4; the highest point of the
    // tilted tube is 2·(R sin 60° + r) = 2·(0.866 + 0.4) (64×32 segments: within 0.02).
    let (lo, hi) = m.bounds();
    assert!((hi.x - 2.8).abs() < 1e-3 && (lo.x + 2.8).abs() < 1e-3, "{lo} {hi}");
    let want_y = 2.0 * (60f32.to_radians().sin() + 0.4);
    assert!((hi.y - want_y).abs() < 0.02, "{hi} vs {want_y}");
    for v in &p.vertices {
        assert!((Vec3::from(v.normal).length() - 1.0).abs() < 1e-5);
        assert!((Vec4::from(v.tangent).truncate().length() - 1.0).abs() < 1e-5);
    }
    // Errors name the file.
    let e = runner::model::load(std::path::Path::new("/no/such/model.glb")).unwrap_err().to_string();
    assert!(e.contains("/no/such/model.glb"), "{e}");
}

/// The textured model, GPU (hardware texture sampling with mipmaps) against the CPU
/// reference (software trilinear filtering of the same mip chain, the level from quad UV
/// differences). Coverage, interpolation and shading follow the same rules and code; what
/// differs is texture filtering — the hardware's fixed-point weights and level arithmetic —
/// which shows along the checker's hard edges (measured on lavapipe: mean |Δ| 2.8·10⁻³,
/// 8 % of the model's pixels above 2/255, all on texture edges and silhouettes).
#[test]
fn gpu_draws_the_model_as_the_cpu_reference() {
    let baked = support::small_display_bake();
    let mut model = runner::model::load(&sample_path()).unwrap();
    model.fit(Vec3::new(0.0, 0.0, 1.5), 4.0);
    let Backend::Gpu(gpu) = support::gpu() else { unreachable!() };
    let scene = GpuScene::new(gpu, &baked);
    let gpu_model = GpuModel::new(gpu, &scene, &model);
    let view = ViewState { exposure: baked.auto_exposure(), pitch: 0.35, ..ViewState::default() };
    let (w, h) = (256, 160);
    let frame = view.frame(scene.shape, w, h, true);
    let g = scene.render_offscreen(gpu, &frame, Some(&gpu_model)).unwrap();
    let c = runner::raster::render(&baked, &frame, &model);
    let no_model = runner::render::render_cpu(&baked, &frame);
    let (mut n, mut over, mut sum, mut worst) = (0usize, 0usize, 0.0f64, 0.0f32);
    for i in 0..g.len() {
        // A model pixel in either image (1e-3: well above the spheres' GPU-vs-CPU difference).
        if (c[i] - no_model[i]).abs().max_element() == 0.0 && (g[i] - no_model[i]).abs().max_element() < 1e-3 {
            continue; // not a model pixel in either
        }
        n += 1;
        let d = (g[i] - c[i]).abs().max_element();
        sum += d as f64;
        worst = worst.max(d);
        over += (d > 2.0 / 255.0) as usize;
    }
    let mean = sum / n as f64;
    if let Some(dir) = std::env::var_os("SPLITSUM_DUMP") {
        let dir = PathBuf::from(dir);
        runner::files::write_png(&dir.join("model_gpu.png"), w, h, &runner::render::to_rgb8(&g)).unwrap();
        runner::files::write_png(&dir.join("model_cpu.png"), w, h, &runner::render::to_rgb8(&c)).unwrap();
        let d: Vec<Vec4> = g.iter().zip(&c).map(|(a, b)| Vec4::splat(((*a - *b).abs().max_element() * 10.0).min(1.0))).collect();
        runner::files::write_png(&dir.join("model_diff.png"), w, h, &runner::render::to_rgb8(&d)).unwrap();
    }
    println!("model: {n} pixels; GPU vs CPU mean |Δ| {mean:.2e}, max {worst:.3}, {:.2} % above 2/255", 100.0 * over as f64 / n as f64);
    assert!(n > (w * h) as usize / 10, "the model covers too little of the frame: {n}");
    // The hardware sampler is not the CPU's: lavapipe differs on texture edges (mean
    // 2.8e-3, 8 % of pixels above 2/255); an H100's texture units, with their fixed-point
    // filter weights and own level-of-detail arithmetic, more (5.1e-3, 16 %), also on edges.
    let (mean_bound, over_bound) = (support::gpu_bound(5e-3, 1e-2), support::gpu_bound(0.12, 0.25));
    assert!(mean < mean_bound, "{mean:e}");
    assert!((over as f64) < over_bound * n as f64, "{over} of {n}");
}
