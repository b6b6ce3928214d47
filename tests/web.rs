//! The web page (`web/`, built by `bash scripts/web.sh`) as a user meets it, in headless
//! Chromium's WebGPU (SwiftShader) through `tests/webgpu/page.mjs` (puppeteer-core): a
//! generated sunny sky dropped on it is baked and drawn, and the grid it shows and the
//! folder of each target it downloads are checked against the native command line's. Needs what
//! `bash scripts/dev.sh webgpu` builds and installs (it runs this test, and so does
//! `dev.sh test`); ignored otherwise.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// A 256×128 sky: a blue gradient above the horizon, brown ground below, and a sun of
/// 2·10⁴ (12 texels) above the horizon, as Radiance RGBE.
fn sunny_sky(path: &Path) {
    let (w, h) = (256u32, 128u32);
    let pixels: Vec<image::Rgb<f32>> = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as i32, (i / w) as i32);
            if (x - 90).pow(2) + (y - 40).pow(2) < 4 {
                image::Rgb([20000.0, 19000.0, 17000.0])
            } else if y < h as i32 / 2 {
                let up = 1.0 - y as f32 / (h as f32 / 2.0);
                image::Rgb([0.4 + 0.2 * up, 0.6 + 0.2 * up, 1.2])
            } else {
                image::Rgb([0.3, 0.25, 0.2])
            }
        })
        .collect();
    image::codecs::hdr::HdrEncoder::new(std::fs::File::create(path).unwrap()).encode(&pixels, w as usize, h as usize).unwrap();
}

/// Every file under `dir`, by its `/`-separated name inside it.
fn folder(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut walk = vec![dir.to_path_buf()];
    while let Some(d) = walk.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk.push(p);
            } else {
                out.insert(p.strip_prefix(dir).unwrap().to_string_lossy().replace('\\', "/"), std::fs::read(&p).unwrap());
            }
        }
    }
    out
}

/// `bake.json` without what names the run rather than the bake: the timings, the backend
/// and the environment's name (the command line writes the path it was given).
fn bake_json(bytes: &[u8]) -> serde_json::Value {
    let mut v: serde_json::Value = serde_json::from_slice(bytes).unwrap();
    for key in ["timings", "backend", "environment"] {
        v.as_object_mut().unwrap().remove(key);
    }
    v
}

#[test]
#[ignore = "needs Chromium and the page's build: bash scripts/dev.sh webgpu"]
fn the_web_page_shows_and_downloads_what_the_command_line_makes() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../target/web-test");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let sky = dir.join("sky.hdr");
    sunny_sky(&sky);
    let cpu = dir.join("cpu.png");
    let args =
        ["runner", "render", sky.to_str().unwrap(), "--backend", "cpu", "--no-model", "--width", "640", "--height", "360", "--out", cpu.to_str().unwrap()];
    runner::cli::run(args.map(String::from)).unwrap();
    let want = image::open(&cpu).unwrap().to_rgb8();
    let script = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("webgpu/page.mjs");
    // On the browser's WebGPU, and as a browser without it (the CPU backend in wasm).
    let runs = [("page", None), ("page-cpu", Some("--no-webgpu"))];
    for (name, flag) in runs {
        let page = dir.join(name);
        let status = std::process::Command::new("node").arg(&script).arg(&sky).arg(&page).args(flag).status().expect("node");
        assert!(status.success(), "node {}", script.display());
        if let Ok(message) = std::fs::read_to_string(page.join("error.txt")) {
            panic!("the page failed ({name}): {message}");
        }
        eprintln!("the page in headless Chromium ({name}): {}", std::fs::read_to_string(page.join("page.json")).unwrap());
        // The grid: the page's canvas against the CPU reference renderer's frame of the
        // same bake settings and view. Tolerance 2/255 mean: on WebGPU the page bakes and
        // shades on the GPU (f32 in another order, the GPU's own transcendentals) and its
        // canvas rounds to 8 bits as `to_rgb8` does; a wrong exposure, view or mip moves
        // the mean by far more.
        let shown = image::open(page.join("grid.png")).unwrap().to_rgb8();
        assert_eq!(shown.dimensions(), want.dimensions());
        let diffs: Vec<f64> = shown.as_raw().iter().zip(want.as_raw()).map(|(a, b)| (*a as f64 - *b as f64).abs()).collect();
        let mean = diffs.iter().sum::<f64>() / diffs.len() as f64;
        let worst = diffs.iter().copied().fold(0.0, f64::max);
        eprintln!("{name}: grid against runner render --backend cpu: mean |Δ| {mean:.3}/255, largest {worst}/255");
        assert!(mean <= 2.0, "{name}: mean |Δ| {mean:.3}/255");
    }

    // Each target's download against `runner bake --target T` (the CPU backend, as the
    // page's downloads): every file byte for byte; bake.json but for what names the run.
    for target in ["splitsum", "khronos", "bevy", "filament"] {
        let cli = dir.join("cli").join(target).join("sky");
        let args = ["runner", "bake", sky.to_str().unwrap(), "--backend", "cpu", "--target", target, "--out", cli.to_str().unwrap()];
        runner::cli::run(args.map(String::from)).unwrap();
        let mut want = folder(&cli);
        want.remove(splitsum::files::OUTPUT_MANIFEST);
        for (name, _) in runs {
            let mut zip = zip::ZipArchive::new(std::io::Cursor::new(std::fs::read(dir.join(name).join(format!("{target}.zip"))).unwrap())).unwrap();
            let mut got = BTreeMap::new();
            for k in 0..zip.len() {
                let mut f = zip.by_index(k).unwrap();
                let full = f.name().unwrap().to_string();
                let file = full.strip_prefix("sky/").unwrap_or_else(|| panic!("{full} is outside the folder sky/")).to_string();
                let mut bytes = Vec::new();
                std::io::Read::read_to_end(&mut f, &mut bytes).unwrap();
                got.insert(file, bytes);
            }
            assert_eq!(got.keys().collect::<Vec<_>>(), want.keys().collect::<Vec<_>>(), "{name}: the {target} zip's files");
            for (file, bytes) in &got {
                if file == "bake.json" {
                    assert_eq!(bake_json(bytes), bake_json(&want[file]), "{name}: {target} bake.json");
                } else {
                    assert!(*bytes == want[file], "{name}: {target} {file} differs from the command line's");
                }
            }
            eprintln!("{name}: the {target} download, {} files, identical to runner bake --target {target}", got.len());
        }
    }
}
