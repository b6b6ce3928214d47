//! Hostile input, whole process: headers that promise more than a file holds or than
//! memory allows (EXR, Radiance, glTF), and every kind of failure named by its real cause
//! with one exit-code rule.

use super::*;
use crate::common::{courtyard, runner, scratch, snapshot};
use std::path::{Path, PathBuf};
use std::process::Command;

/// A small RGB OpenEXR (a gradient, f16) written with `compression` and `blocks`.
fn small_exr(path: &Path, compression: exr::prelude::Compression, blocks: exr::prelude::Blocks) {
    use exr::prelude::*;
    let channels = SpecificChannels::rgb(|p: Vec2<usize>| (f16::from_f32(p.x() as f32 * 0.01), f16::from_f32(0.5), f16::from_f32(p.y() as f32 * 0.02)));
    let encoding = Encoding { compression, blocks, line_order: LineOrder::Increasing };
    Image::from_layer(Layer::new((64, 32), LayerAttributes::default(), encoding, channels)).write().to_file(path).unwrap();
}

/// Rewrites the box2i attribute `name` of the first header of the OpenEXR at `path` (the
/// header as written, not as parsed: a hostile header).
fn patch_box(path: &Path, name: &str, b: [i32; 4]) {
    let mut bytes = std::fs::read(path).unwrap();
    let key = format!("{name}\0box2i\0");
    let at = bytes.windows(key.len()).position(|w| w == key.as_bytes()).unwrap() + key.len() + 4;
    for (k, v) in b.iter().enumerate() {
        bytes[at + 4 * k..at + 4 * k + 4].copy_from_slice(&v.to_le_bytes());
    }
    std::fs::write(path, bytes).unwrap();
}

/// Sets the compression byte of the first header of the OpenEXR at `path`.
fn patch_compression(path: &Path, code: u8) {
    let mut bytes = std::fs::read(path).unwrap();
    let key = b"compression\0compression\0";
    let at = bytes.windows(key.len()).position(|w| w == key).unwrap() + key.len() + 4;
    bytes[at] = code;
    std::fs::write(path, bytes).unwrap();
}

/// Every read path keeps within 64 MiB + 4 × the file's size + what the same command
/// needs on a small valid input (the bake and render at those settings), on truncated,
/// lying and hostile headers: OpenEXR of every compression (cut short, or claiming
/// 32768×16384 in a 10 KiB file, or 1×1 tiles over that size), Radiance `.hdr`, face
/// folders, glTF/GLB models and cache entries. Each is refused with a message that says
/// what is wrong, and exits 1.
#[test]
fn hostile_headers_stay_within_memory_bounds() {
    use exr::prelude::{Blocks, Compression, Vec2};
    let d = scratch("hostile");
    let bake = |input: &Path| {
        let mut c = runner();
        c.args(["bake", input.to_str().unwrap(), "--backend", "cpu", "--size", "16", "--out", d.join("out").to_str().unwrap()]);
        c
    };
    // What the same command needs on a valid input of the same kind.
    let valid = d.join("valid.exr");
    small_exr(&valid, Compression::ZIP16, Blocks::ScanLines);
    let (ok, said, baseline) = run_measured(bake(&valid), &d);
    assert!(ok, "{said}");
    let mut cases: Vec<(String, PathBuf, &str)> = Vec::new();
    let compressions = [
        Compression::Uncompressed,
        Compression::RLE,
        Compression::ZIP1,
        Compression::ZIP16,
        Compression::PIZ,
        Compression::PXR24,
        Compression::B44,
        Compression::B44A,
        Compression::DWAA(None),
        Compression::DWAB(None),
    ];
    for (k, c) in compressions.into_iter().enumerate() {
        let whole = d.join(format!("c{k}.exr"));
        small_exr(&whole, c, Blocks::ScanLines);
        let bytes = std::fs::read(&whole).unwrap();
        // Cut short after its header.
        let cut = d.join(format!("c{k}-cut.exr"));
        std::fs::write(&cut, &bytes[..bytes.len() * 2 / 3]).unwrap();
        cases.push((format!("{c:?} cut short"), cut, "OpenEXR"));
        // The header claims 32768×16384; the file stays as small as it was.
        let lying = d.join(format!("c{k}-lying.exr"));
        std::fs::write(&lying, &bytes).unwrap();
        patch_box(&lying, "dataWindow", [0, 0, 32767, 16383]);
        patch_box(&lying, "displayWindow", [0, 0, 32767, 16383]);
        cases.push((format!("{c:?} lying about its size"), lying.clone(), "OpenEXR"));
        // The same, padded so that its blocks' offsets fit in the file: the blocks it
        // reads are garbage, and nothing beyond what the file holds is decoded.
        let padded = d.join(format!("c{k}-padded.exr"));
        let mut b = std::fs::read(&lying).unwrap();
        b.resize(b.len() + (300 << 10), 0);
        std::fs::write(&padded, b).unwrap();
        cases.push((format!("{c:?} lying, padded to its block count"), padded, "OpenEXR"));
    }
    // A header claiming every compression code over the same lying size.
    for code in 0..10u8 {
        let p = d.join(format!("code{code}.exr"));
        small_exr(&p, Compression::ZIP16, Blocks::ScanLines);
        patch_box(&p, "dataWindow", [0, 0, 32767, 16383]);
        patch_box(&p, "displayWindow", [0, 0, 32767, 16383]);
        patch_compression(&p, code);
        cases.push((format!("compression code {code}, lying"), p, "OpenEXR"));
    }
    // 1×1 tiles over 32768×16384: 5·10⁸ blocks promised, whose offset table alone would be 4 GiB.
    let tiles = d.join("tiles.exr");
    small_exr(&tiles, Compression::Uncompressed, Blocks::Tiles(Vec2(1, 1)));
    patch_box(&tiles, "dataWindow", [0, 0, 32767, 16383]);
    patch_box(&tiles, "displayWindow", [0, 0, 32767, 16383]);
    cases.push(("1×1 tiles, lying".into(), tiles, "truncated OpenEXR: its header promises 32768×16384 pixels in 536870912 blocks"));
    let inverted = d.join("inverted.exr");
    small_exr(&inverted, Compression::ZIP16, Blocks::ScanLines);
    patch_box(&inverted, "dataWindow", [63, 31, 0, 0]);
    cases.push(("inverted data window".into(), inverted, "data window is inverted"));
    // Radiance: a header promising 32768×16384, then a few bytes of scanline.
    let hdr = d.join("lying.hdr");
    let mut b = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 16384 +X 32768\n".to_vec();
    b.extend(std::iter::repeat_n([2u8, 2, 128, 0], 20000).flatten());
    std::fs::write(&hdr, &b).unwrap();
    cases.push(("hdr lying about its size".into(), hdr, "Radiance HDR"));
    // 1000 valid run-length scanlines of 16384 pixels (the widest run-length coding takes
    // is 32767) under a header promising 8192.
    let hdr = d.join("short.hdr");
    let mut b = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 8192 +X 16384\n".to_vec();
    let mut line = vec![2u8, 2, 64, 0];
    for _ in 0..4 {
        // 129 runs of 127 and one of 1: 16384 values of one channel.
        for _ in 0..129 {
            line.extend_from_slice(&[128 + 127, 100]);
        }
        line.extend_from_slice(&[128 + 1, 100]);
    }
    for _ in 0..1000 {
        b.extend_from_slice(&line);
    }
    std::fs::write(&hdr, &b).unwrap();
    cases.push(("hdr cut short after 1000 valid scanlines".into(), hdr, "the file ends in scanline 1000 of 8192"));
    let no_res = d.join("nores.hdr");
    let mut b = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n".to_vec();
    b.extend((0..4096u32).map(|i| (i * 37 % 251) as u8 | 0x80));
    std::fs::write(&no_res, &b).unwrap();
    cases.push(("hdr without a resolution line".into(), no_res, "no resolution line"));
    // A face folder whose +Y face lies about its size (32768²), beside valid 64² faces.
    let faces = d.join("faces");
    std::fs::create_dir_all(&faces).unwrap();
    for name in ["px", "nx", "py", "ny", "pz", "nz"] {
        let p = faces.join(format!("{name}.exr"));
        use exr::prelude::*;
        let ch = SpecificChannels::rgb(|_: Vec2<usize>| (f16::ONE, f16::ONE, f16::ONE));
        Image::from_channels((64, 64), ch).write().to_file(&p).unwrap();
        if name == "py" {
            patch_box(&p, "dataWindow", [0, 0, 32767, 32767]);
            patch_box(&p, "displayWindow", [0, 0, 32767, 32767]);
        }
    }
    cases.push(("face folder with a lying face".into(), faces, "py.exr"));
    let render = |model: &Path| {
        let mut c = runner();
        let out = d.join("frame.png");
        c.args(["render", "--backend", "cpu", "--size", "16", "--samples", "16", "--width", "32", "--height", "16", "--model", model.to_str().unwrap()]);
        c.args(["--out", out.to_str().unwrap()]);
        c
    };
    let torus = d.join("torus.glb");
    std::fs::write(&torus, std::fs::read(format!("{}/../display/assets/torus.glb", env!("CARGO_MANIFEST_DIR"))).unwrap()).unwrap();
    let (ok, said, model_baseline) = run_measured(render(&torus), &d);
    assert!(ok, "{said}");
    let mut models: Vec<(String, PathBuf, &str)> = Vec::new();
    let glb = std::fs::read(&torus).unwrap();
    let cut = d.join("cut.glb");
    std::fs::write(&cut, &glb[..glb.len() / 2]).unwrap();
    models.push(("GLB cut short".into(), cut, "truncated GLB"));
    let (json, bin) = split_glb(&glb);
    let edit = |name: &str, f: &dyn Fn(&mut serde_json::Value)| {
        let mut j: serde_json::Value = serde_json::from_slice(&json).unwrap();
        f(&mut j);
        let p = d.join(name);
        std::fs::write(&p, join_glb(&serde_json::to_vec(&j).unwrap(), &bin)).unwrap();
        p
    };
    // A second buffer read from an endless device: refused, never read.
    let endless = edit("endless.glb", &|j| j["buffers"].as_array_mut().unwrap().push(serde_json::json!({"uri": "file:///dev/zero", "byteLength": 1u64 << 31})));
    models.push(("a buffer naming /dev/zero".into(), endless, "not a regular file"));
    // A binary chunk claiming 2 GiB.
    let long = edit("long.glb", &|j| j["buffers"][0]["byteLength"] = serde_json::json!(1u64 << 31));
    models.push(("a buffer claiming 2 GiB".into(), long, "byteLength"));
    // An accessor claiming 2³⁰ vertices in a small buffer view.
    let many = edit("many.glb", &|j| j["accessors"][0]["count"] = serde_json::json!(1u64 << 30));
    models.push(("an accessor claiming 2^30 vertices".into(), many, "accessor 0 claims 1073741824 elements"));
    // Images whose PNG header claims 65535² and 8000² (within the texture limit) over the
    // same few compressed bytes.
    for (side, message) in [(65535u32, "larger than the 8192×8192"), (8000, "cannot be decoded")] {
        let mut b = bin.clone();
        let at = b.windows(8).position(|w| w == b"\x89PNG\r\n\x1a\n").expect("a PNG in the sample");
        let ihdr = at + 8 + 8;
        b[ihdr..ihdr + 4].copy_from_slice(&side.to_be_bytes());
        b[ihdr + 4..ihdr + 8].copy_from_slice(&side.to_be_bytes());
        let crc = crc32(&b[ihdr - 4..ihdr + 13]);
        b[ihdr + 13..ihdr + 17].copy_from_slice(&crc.to_be_bytes());
        let p = d.join(format!("png{side}.glb"));
        std::fs::write(&p, join_glb(&json, &b)).unwrap();
        models.push((format!("a PNG claiming {side}²"), p, message));
    }
    for (what, input, message) in &models {
        let len = std::fs::metadata(input).unwrap().len();
        let (ok, said, peak) = run_measured(render(input), &d);
        let bound = (64 << 20) + 4 * len + model_baseline;
        eprintln!("{what}: peak {:.1} MiB (bound {:.1} MiB): {}", peak as f64 / 1048576.0, bound as f64 / 1048576.0, said.lines().last().unwrap_or(""));
        assert!(!ok, "{what}: {said}");
        assert!(said.contains(message), "{what}: expected {message:?} in: {said}");
        assert!(peak <= bound, "{what}: peak {peak} bytes > bound {bound}: {said}");
    }
    // A cache entry whose specular product is a 1 GiB (sparse) file, as its manifest says,
    // but not the bake it claims: its hash is streamed, it is never held, and the scene
    // is baked again within what the first bake took.
    let scene = format!("{}/../scenes/brushed-metal.toml", env!("CARGO_MANIFEST_DIR"));
    let cache = d.join("cache");
    let scene_bake = || {
        let mut c = runner();
        c.args(["bake", "--scene", &scene, "--backend", "cpu", "--cache", cache.to_str().unwrap(), "--out", d.join("scene-out").to_str().unwrap()]);
        c
    };
    let (ok, said, scene_baseline) = run_measured(scene_bake(), &d);
    assert!(ok, "{said}");
    let entry = std::fs::read_dir(&cache).unwrap().map(|e| e.unwrap().path()).find(|p| p.is_dir()).unwrap();
    let big = std::fs::File::create(entry.join("specular.bin")).unwrap();
    big.set_len(1 << 30).unwrap();
    let manifest = entry.join("manifest.json");
    let mut m: serde_json::Value = serde_json::from_slice(&std::fs::read(&manifest).unwrap()).unwrap();
    m["files"]["specular.bin"]["bytes"] = serde_json::json!(1u64 << 30);
    std::fs::write(&manifest, serde_json::to_vec(&m).unwrap()).unwrap();
    let (ok, said, peak) = run_measured(scene_bake(), &d);
    eprintln!(
        "cache entry of 1 GiB: peak {:.1} MiB (first bake {:.1} MiB): {}",
        peak as f64 / 1048576.0,
        scene_baseline as f64 / 1048576.0,
        said.lines().last().unwrap_or("")
    );
    assert!(ok && said.contains("rejected (specular.bin is corrupt (its BLAKE3 hash differs"), "{said}");
    assert!(peak <= (64 << 20) + scene_baseline, "peak {peak}");
    for (what, input, message) in &cases {
        let len = std::fs::metadata(input).map(|m| if m.is_dir() { (6 * 16) << 10 } else { m.len() }).unwrap();
        let (ok, said, peak) = run_measured(bake(input), &d);
        let bound = (64 << 20) + 4 * len + baseline;
        eprintln!("{what}: peak {:.1} MiB (bound {:.1} MiB): {}", peak as f64 / 1048576.0, bound as f64 / 1048576.0, said.lines().last().unwrap_or(""));
        assert!(!ok, "{what}: {said}");
        assert!(said.contains(message), "{what}: expected {message:?} in: {said}");
        assert!(peak <= bound, "{what}: peak {peak} bytes > bound {bound}: {said}");
    }
    let _ = std::fs::remove_dir_all(&d);
}

/// The JSON and binary chunks of a GLB.
fn split_glb(glb: &[u8]) -> (Vec<u8>, Vec<u8>) {
    let u32_at = |i: usize| u32::from_le_bytes(glb[i..i + 4].try_into().unwrap()) as usize;
    let json_len = u32_at(12);
    let json = glb[20..20 + json_len].to_vec();
    let bin_at = 20 + json_len;
    let bin_len = u32_at(bin_at);
    (json, glb[bin_at + 8..bin_at + 8 + bin_len].to_vec())
}

/// A GLB of a JSON chunk (padded with spaces) and a binary chunk (padded with zeros).
fn join_glb(json: &[u8], bin: &[u8]) -> Vec<u8> {
    let pad = |v: &[u8], with: u8| {
        let mut v = v.to_vec();
        while !v.len().is_multiple_of(4) {
            v.push(with);
        }
        v
    };
    let (j, b) = (pad(json, b' '), pad(bin, 0));
    let mut out = Vec::new();
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&((12 + 8 + j.len() + 8 + b.len()) as u32).to_le_bytes());
    out.extend_from_slice(&(j.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&j);
    out.extend_from_slice(&(b.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&b);
    out
}

/// CRC-32 (ISO-HDLC, as PNG chunks carry it), bit by bit.
fn crc32(bytes: &[u8]) -> u32 {
    let mut c = !0u32;
    for &b in bytes {
        c ^= b as u32;
        for _ in 0..8 {
            c = if c & 1 != 0 { 0xEDB8_8320 ^ (c >> 1) } else { c >> 1 };
        }
    }
    !c
}

/// Runs `runner args…` to its end: (exit code, stdout and stderr).
fn run_code(args: &[&str]) -> (i32, String) {
    let o = runner().args(args).output().unwrap();
    (o.status.code().unwrap_or(-1), format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr)))
}

/// The cases a new user met (issue 19), each with the message that names the real problem
/// and the one exit-code rule: 2 for a request refused as written, 1 for work that failed.
/// A folder of the user's files is never replaced, by any command; a bake whose settings
/// change what was asked says so and records it in `bake.json`; a successful GPU run
/// without `XDG_RUNTIME_DIR` prints no error line.
#[test]
fn each_case_names_the_real_problem_with_one_exit_code_rule() {
    let d = scratch("cases");
    let dir = |name: &str| d.join(name).to_str().unwrap().to_string();
    let env = courtyard();
    // A project folder of the user's, with a file named like a splitsum output.
    let proj = d.join("proj");
    std::fs::create_dir_all(proj.join("figs")).unwrap();
    std::fs::write(proj.join("thesis.tex"), "\\documentclass{article}").unwrap();
    std::fs::write(proj.join("figs/plot.pdf"), "%PDF").unwrap();
    std::fs::write(proj.join("plan.json"), "{}").unwrap();
    let before = snapshot(&proj);
    let scene = format!("{}/../scenes/brushed-metal.toml", env!("CARGO_MANIFEST_DIR"));
    let cache = dir("cache");
    for args in [
        vec!["bake", &env, "--backend", "cpu", "--size", "16", "--out"],
        vec!["bake", &env, "--backend", "cpu", "--size", "16", "--target", "khronos", "--out"],
        vec!["bake", "--scene", &scene, "--backend", "cpu", "--cache", &cache, "--out"],
        vec!["report", "--quick", "--backends", "cpu", "--out"],
    ] {
        let mut args = args.clone();
        let p = dir("proj");
        args.push(&p);
        let (code, said) = run_code(&args);
        assert_eq!(code, 2, "{args:?}: {said}");
        assert!(said.contains("--out") && said.contains("holds figs, a folder splitsum did not write"), "{args:?}: {said}");
        assert_eq!(snapshot(&proj), before, "{args:?} touched the user's folder");
    }
    // A splitsum output to which the user added a file, or whose file the user changed.
    let out = dir("out");
    assert_eq!(run_code(&["bake", &env, "--backend", "cpu", "--size", "16", "--out", &out]).0, 0);
    std::fs::write(d.join("out/notes.txt"), "mine").unwrap();
    let (code, said) = run_code(&["bake", &env, "--backend", "cpu", "--size", "16", "--out", &out]);
    assert!(code == 2 && said.contains("holds notes.txt, which splitsum did not write"), "{said}");
    std::fs::remove_file(d.join("out/notes.txt")).unwrap();
    std::fs::write(d.join("out/bake.json"), "{\"edited\": true}").unwrap();
    let (code, said) = run_code(&["bake", &env, "--backend", "cpu", "--size", "16", "--out", &out]);
    assert!(code == 2 && said.contains("holds bake.json, which has changed since splitsum wrote it"), "{said}");
    assert_eq!(std::fs::read_to_string(d.join("out/bake.json")).unwrap(), "{\"edited\": true}");
    // Folders that are no output folder: the root, a system folder (refused at its first
    // entry, unread below), one that cannot be listed (issue 31).
    let (code, said) = run_code(&["bake", &env, "--backend", "cpu", "--size", "16", "--out", "/"]);
    assert!(code == 2 && said.contains("--out / is the root of the file system"), "{said}");
    let start = std::time::Instant::now();
    let (code, said) = run_code(&["bake", &env, "--backend", "cpu", "--size", "16", "--out", "/usr"]);
    assert!(code == 2 && said.contains("--out /usr holds ") && said.contains("(the folder has no .splitsum-manifest.json)"), "{said}");
    println!("--out /usr refused in {:.3} s (the whole process)", start.elapsed().as_secs_f64());
    let locked = d.join("locked");
    std::fs::create_dir_all(locked.join("inside")).unwrap();
    std::fs::set_permissions(&locked, std::os::unix::fs::PermissionsExt::from_mode(0o000)).unwrap();
    // Root reads any folder: run as nobody there (setpriv, util-linux), where it exists.
    // SAFETY: getuid has no preconditions.
    let root = unsafe { libc::getuid() } == 0;
    let args = ["bake", &env, "--backend", "cpu", "--size", "16", "--out", locked.to_str().unwrap()];
    let as_user = if root {
        Command::new("setpriv").args(["--reuid=65534", "--regid=65534", "--clear-groups", env!("CARGO_BIN_EXE_runner")]).args(args).output().ok()
    } else {
        runner().args(args).output().ok()
    };
    // Skipped where nobody may run the binary (a checkout under a private home folder).
    if let Some(o) = as_user.filter(|o| !matches!(o.status.code(), Some(126 | 127)) && !String::from_utf8_lossy(&o.stderr).contains("failed to execute")) {
        let said = format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
        assert!(o.status.code() == Some(2) && said.contains("cannot be read (permission denied)"), "{said}");
    }
    std::fs::set_permissions(&locked, std::os::unix::fs::PermissionsExt::from_mode(0o755)).unwrap();
    assert!(locked.join("inside").is_dir());
    // Single files: never another kind, never under the wrong extension.
    let (code, said) = run_code(&["lut", "--backend", "cpu", "--size", "8", "--out", &dir("t.png")]);
    assert!(code == 2 && said.contains("--out") && said.contains("name it .exr"), "{said}");
    std::fs::write(d.join("mine.exr"), "not an EXR").unwrap();
    let (code, said) = run_code(&["lut", "--backend", "cpu", "--size", "8", "--out", &dir("mine.exr")]);
    assert!(code == 2 && said.contains("exists and is not a OpenEXR file"), "{said}");
    assert_eq!(std::fs::read(d.join("mine.exr")).unwrap(), b"not an EXR");
    let (code, said) = run_code(&["lut", "--backend", "cpu", "--size", "8", "--png", &dir("preview.png"), "--out", &dir("t.exr")]);
    assert!(code == 0 && said.matches("wrote").count() == 2 && said.contains("t.exr") && said.contains("preview.png"), "{said}");
    // A PNG beside the table that the user never named is never touched (issue 31).
    std::fs::write(d.join("u.png"), b"\x89PNG mine").unwrap();
    let (code, said) = run_code(&["lut", "--backend", "cpu", "--size", "8", "--out", &dir("u.exr")]);
    assert!(code == 0 && !said.contains("u.png"), "{said}");
    assert_eq!(std::fs::read(d.join("u.png")).unwrap(), b"\x89PNG mine");
    // Nothing silent: a flag the path ignores is refused, a cap or an upsampling is stated.
    let (code, said) = run_code(&["lut", "--backend", "cpu", "--size", "8", "--samples", "64", "--out", &dir("u.exr")]);
    assert!(code == 2 && said.contains("--samples") && said.contains("--method sampled"), "{said}");
    let (code, said) = run_code(&["bake", &env, "--backend", "cpu", "--size", "16", "--lut-samples", "64", "--out", &dir("x")]);
    assert!(code == 2 && said.contains("--lut-samples has no effect here"), "{said}");
    let (code, said) = run_code(&["bake", &env, "--backend", "cpu", "--size", "16", "--target", "filament", "--lut-size", "64", "--out", &dir("x")]);
    assert!(code == 2 && said.contains("--lut-size has no effect here: the filament target makes no BRDF table"), "{said}");
    let (code, said) = run_code(&["bake", &env, "--samples", "4294967295", "--out", &dir("x")]);
    assert!(code == 2 && said.contains("--samples must be from 1 to 1048576"), "{said}");
    let small = d.join("small.exr");
    write_equirect(&small, 512, 10.0);
    let adjustments = |out: &str| -> Vec<String> {
        let json: serde_json::Value = serde_json::from_slice(&std::fs::read(Path::new(out).join("bake.json")).unwrap()).unwrap();
        json["adjustments"].as_array().unwrap().iter().map(|a| a["kind"].as_str().unwrap().to_string()).collect()
    };
    let up = dir("upsampled");
    let (code, said) = run_code(&["bake", small.to_str().unwrap(), "--backend", "cpu", "--out", &up]);
    assert_eq!(code, 0, "{said}");
    assert!(said.contains("512×256 resolves about 128² per cube face; the 256² source cube (--source-size) interpolates it 2×"), "{said}");
    assert_eq!(adjustments(&up), ["upsampled"]);
    // 2²⁰ samples at mip 1 of 2² faces, doubling: mip 2 would take 2²¹ (mip 3, r = 1, is summed exactly).
    let capped = dir("capped");
    let (code, said) = run_code(&[
        "bake",
        small.to_str().unwrap(),
        "--backend",
        "cpu",
        "--size",
        "4",
        "--source-size",
        "8",
        "--mips",
        "3",
        "--sampled-only",
        "--samples",
        "1048576",
        "--force",
        "--out",
        &capped,
    ]);
    assert_eq!(code, 0, "{said}");
    assert!(said.contains("mip 2 takes 1048576 GGX samples per texel, not the 2097152 that --samples × --sample-growth^1 asks for"), "{said}");
    assert_eq!(adjustments(&capped), ["reduced", "samples_capped"]);
    // Messages that point the right way.
    let faces = d.join("faces");
    std::fs::create_dir_all(faces.join("py.exr")).unwrap();
    for name in ["px", "nx", "ny", "pz", "nz"] {
        use exr::prelude::*;
        let ch = SpecificChannels::rgb(|_: Vec2<usize>| (f16::ONE, f16::ONE, f16::ONE));
        Image::from_channels((8, 8), ch).write().to_file(faces.join(format!("{name}.exr"))).unwrap();
    }
    let (code, said) = run_code(&["bake", faces.to_str().unwrap(), "--backend", "cpu", "--out", &dir("x")]);
    assert!(code == 1 && said.contains("py.exr: is a folder"), "{said}");
    std::fs::remove_dir(faces.join("py.exr")).unwrap();
    std::os::unix::fs::symlink(d.join("nowhere.exr"), faces.join("py.exr")).unwrap();
    let (code, said) = run_code(&["bake", faces.to_str().unwrap(), "--backend", "cpu", "--out", &dir("x")]);
    assert!(code == 1 && said.contains("py.exr: is a symbolic link to nothing"), "{said}");
    // A scene or calibration that is a device is refused before it is read (it would never end).
    let (code, said) = run_code(&["plan", "/dev/zero"]);
    assert!(code == 1 && said.contains("/dev/zero: is not a regular file"), "{said}");
    let (code, said) = run_code(&["plan", &scene, "--calibration", "/dev/zero"]);
    assert!(code == 1 && said.contains("/dev/zero: is not a regular file"), "{said}");
    // Usage mistakes exit 2 whether clap or splitsum's validation catches them.
    assert_eq!(run_code(&["bake", &env, "--samples", "0"]).0, 2);
    assert_eq!(run_code(&["bake", &env, "--size", "0"]).0, 2);
    assert_eq!(run_code(&["bake", "no-such.exr", "--out", &dir("x")]).0, 1);
    // A successful GPU run without XDG_RUNTIME_DIR prints no error line.
    let o = Command::new(env!("CARGO_BIN_EXE_runner"))
        .args(["lut", "--size", "8", "--out", &dir("gpu.exr")])
        .env_remove("XDG_RUNTIME_DIR")
        .env_remove("NODEVICE_SELECT")
        .output()
        .unwrap();
    assert!(o.status.success() && !String::from_utf8_lossy(&o.stderr).contains("error"), "{}", text(&o));
    assert!(!d.join("x").exists(), "a refused run left its output");
}
