//! glTF models: the bundled sample is current, loads with its transforms and every
//! texture, and the GPU draws it as the CPU reference rasteriser does.

use splitsum::Backend;
use splitsum_display::render::{GpuModel, GpuScene, ViewState};
use splitsum_shaders::glam::{Vec3, Vec4};
use std::path::PathBuf;

fn sample_path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../display/assets/torus.glb")
}

/// `display/assets/torus.glb` is what `support::model::sample_glb` writes (regenerate with
/// `SPLITSUM_WRITE_ASSETS=1 cargo test -p splitsum-tests --test model`).
#[test]
fn committed_sample_model_is_current() {
    let fresh = support::model::sample_glb();
    if std::env::var_os("SPLITSUM_WRITE_ASSETS").is_some() {
        std::fs::write(sample_path(), &fresh).unwrap();
    }
    assert!(std::fs::read(sample_path()).unwrap() == fresh, "display/assets/torus.glb is stale");
}

#[test]
fn loads_with_node_transforms_and_every_texture() {
    let m = splitsum_display::model::load(&sample_path()).unwrap();
    assert_eq!(m.primitives.len(), 1);
    let p = &m.primitives[0];
    assert!(p.textures[..5].iter().all(|t| t.is_some()), "all five metallic–roughness slots");
    assert!(p.textures[5..].iter().all(|t| t.is_none()), "no sheen textures (the model has no KHR_materials_sheen)");
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
    let e = splitsum_display::model::load(std::path::Path::new("/no/such/model.glb")).unwrap_err().to_string();
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
    let mut model = splitsum_display::model::load(&sample_path()).unwrap();
    model.fit(Vec3::new(0.0, 0.0, 1.5), 4.0);
    let Backend::Gpu(gpu) = support::gpu() else { unreachable!() };
    let scene = GpuScene::new(gpu, &baked);
    let gpu_model = GpuModel::new(gpu, &scene, &model);
    let view = ViewState { exposure: baked.auto_exposure(), pitch: 0.35, ..ViewState::default() };
    let (w, h) = (256, 160);
    let frame = view.frame(scene.shape, w, h, true);
    let g = scene.render_offscreen(gpu, &frame, Some(&gpu_model)).unwrap();
    let c = splitsum_display::raster::render(&baked, &frame, &model);
    let no_model = splitsum_display::render::render_cpu(&baked, &frame);
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
        splitsum::files::write_png(&dir.join("model_gpu.png"), w, h, &splitsum_display::render::to_rgb8(&g)).unwrap();
        splitsum::files::write_png(&dir.join("model_cpu.png"), w, h, &splitsum_display::render::to_rgb8(&c)).unwrap();
        let d: Vec<Vec4> = g.iter().zip(&c).map(|(a, b)| Vec4::splat(((*a - *b).abs().max_element() * 10.0).min(1.0))).collect();
        splitsum::files::write_png(&dir.join("model_diff.png"), w, h, &splitsum_display::render::to_rgb8(&d)).unwrap();
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

/// A Draco-compressed glTF decodes to the geometry it was compressed from. The torus's
/// positions, normals and UVs are read with the `gltf` crate, compressed with
/// `draco-core`'s encoder (EdgeBreaker at speed 0, which reorders vertices and faces, and
/// sequential at speed 10), written as a `KHR_draco_mesh_compression` GLB and loaded; each
/// loaded triangle is matched to the original triangle with the nearest centroid.
#[test]
fn draco_compressed_models_decode_to_their_geometry() {
    let (doc, buffers, _) = gltf::import_slice(splitsum_display::model::EMBEDDED_SAMPLE).unwrap();
    // The Draco GLB's node has no transform: compare in the mesh's own space.
    let node = doc.nodes().find(|n| n.mesh().is_some()).unwrap();
    let prim = node.mesh().unwrap().primitives().next().unwrap();
    let r = prim.reader(|b| Some(&buffers[b.index()].0[..]));
    let positions: Vec<[f32; 3]> = r.read_positions().unwrap().collect();
    let normals: Vec<[f32; 3]> = r.read_normals().unwrap().collect();
    let uvs: Vec<[f32; 2]> = r.read_tex_coords(0).unwrap().into_f32().collect();
    let indices: Vec<u32> = r.read_indices().unwrap().into_u32().collect();
    let extent = {
        let lo = positions.iter().fold(Vec3::splat(f32::MAX), |a, p| a.min(Vec3::from(*p)));
        let hi = positions.iter().fold(Vec3::splat(f32::MIN), |a, p| a.max(Vec3::from(*p)));
        (hi - lo).max_element()
    };
    let centroid = |t: &[Vec3]| (t[0] + t[1] + t[2]) / 3.0;
    let want: Vec<(Vec3, Vec3, [f32; 2])> = indices
        .chunks_exact(3)
        .map(|t| {
            let p: Vec<Vec3> = t.iter().map(|&i| Vec3::from(positions[i as usize])).collect();
            let nrm = t.iter().map(|&i| Vec3::from(normals[i as usize])).sum::<Vec3>().normalize();
            let uv = t.iter().fold([0.0f32; 2], |a, &i| [a[0] + uvs[i as usize][0] / 3.0, a[1] + uvs[i as usize][1] / 3.0]);
            (centroid(&p), nrm, uv)
        })
        .collect();
    for speed in [0, 10] {
        let glb = support::model::draco_torus_glb(speed);
        let dir = std::env::temp_dir().join(format!("splitsum-draco-{}-{speed}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("torus-draco.glb");
        std::fs::write(&path, glb).unwrap();
        let model = splitsum_display::model::load(&path).unwrap_or_else(|e| panic!("speed {speed}: {e}"));
        let p = &model.primitives[0];
        assert_eq!(p.indices.len(), indices.len(), "speed {speed}: triangles");
        let (mut worst_pos, mut worst_nrm, mut worst_uv) = (0.0f32, 0.0f32, 0.0f32);
        for t in p.indices.chunks_exact(3) {
            let v: Vec<_> = t.iter().map(|&i| p.vertices[i as usize]).collect();
            let c = centroid(&v.iter().map(|x| Vec3::from(x.position)).collect::<Vec<_>>());
            let nrm = v.iter().map(|x| Vec3::from(x.normal)).sum::<Vec3>().normalize();
            let uv = v.iter().fold([0.0f32; 2], |a, x| [a[0] + x.uv[0] / 3.0, a[1] + x.uv[1] / 3.0]);
            let nearest = want.iter().min_by(|a, b| (a.0 - c).length_squared().total_cmp(&(b.0 - c).length_squared())).unwrap();
            worst_pos = worst_pos.max((nearest.0 - c).length() / extent);
            worst_nrm = worst_nrm.max(1.0 - nearest.1.dot(nrm));
            worst_uv = worst_uv.max((nearest.2[0] - uv[0]).abs().max((nearest.2[1] - uv[1]).abs()));
        }
        eprintln!("speed {speed}: position {worst_pos:.2e} of the extent, normal 1-cos {worst_nrm:.2e}, uv {worst_uv:.2e}");
        // Quantisation bounds: 14-bit positions, half a step 2^-15 = 3e-5 of the extent per
        // axis (measured 4.3e-5 for a centroid, three axes); 12-bit UVs, half a step of
        // their range (measured 3.6e-4); 10-bit octahedral normals, about 2e-3 rad
        // (1 − cos measured 2.4e-6).
        assert!(worst_pos < 1e-4 && worst_uv < 5e-4 && worst_nrm < 1e-4, "speed {speed}");
    }
}

/// The glTF crate unwraps an embedded image's MIME type while importing even a validated
/// file (gltf 1.4.1, `image.rs`); a file without one is a clear error, not a panic. Found
/// by `fuzz::gltf_models` in a fresh-clone CI run.
#[test]
fn an_embedded_image_without_a_mime_type_is_an_error_not_a_panic() {
    let glb = support::model::sample_glb();
    let json_len = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    let mut json: serde_json::Value = serde_json::from_slice(&glb[20..20 + json_len]).unwrap();
    let bin_start = 20 + json_len + 8;
    let bin = &glb[bin_start..];
    json["images"][0].as_object_mut().unwrap().remove("mimeType");
    let dir = std::env::temp_dir().join(format!("splitsum-mime-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("no-mime.glb");
    std::fs::write(&path, support::model::glb(&json, bin)).unwrap();
    let e = splitsum_display::model::load(&path).expect_err("refused").to_string();
    assert!(e.contains("no-mime.glb") && e.contains("malformed glTF"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}
