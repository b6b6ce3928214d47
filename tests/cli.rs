//! The command line: bad arguments and unwritable paths give clear errors, and nothing
//! already written is lost.

use runner::cli;
use std::path::PathBuf;

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("splitsum-cli-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn err(args: &[&str]) -> String {
    let mut full = vec!["runner"];
    full.extend_from_slice(args);
    format!("{:#}", cli::run(full).expect_err("should fail"))
}

#[test]
fn lut_rejects_bad_sizes_and_counts() {
    let d = scratch("bad");
    let out = d.join("lut.exr");
    let o = out.to_str().unwrap();
    let e = err(&["lut", "--size", "0", "--backend", "cpu", "--out", o]);
    assert!(e.contains("--size") && e.contains("0"), "{e}");
    let e = err(&["lut", "--size", "100000", "--backend", "cpu", "--out", o]);
    assert!(e.contains("--size"), "{e}");
    let e = err(&["lut", "--samples", "0", "--backend", "cpu", "--out", o]);
    assert!(e.contains("--samples"), "{e}");
    let e = err(&["lut", "--size=-3", "--backend", "cpu", "--out", o]);
    assert!(e.contains("--size"), "{e}");
    assert!(!out.exists());
}

/// The shading ladder's rungs are 1, 2, 4, 8 and 16 fetches; anything else is refused by
/// the flag's name before anything is baked.
#[test]
fn render_refuses_a_fetch_count_off_the_ladder() {
    let d = scratch("fetches");
    let out = d.join("frame.png");
    for bad in ["3", "0", "32", "many"] {
        let e = err(&["render", "--backend", "cpu", "--fetches", bad, "--out", out.to_str().unwrap()]);
        assert!(e.contains("--fetches") && e.contains(bad), "{e}");
    }
    assert!(!out.exists());
}

#[test]
fn lut_names_an_unwritable_path() {
    let d = scratch("dir");
    let file = d.join("a-file");
    std::fs::write(&file, "x").unwrap();
    let under = file.join("lut.exr");
    let e = err(&["lut", "--backend", "cpu", "--out", under.to_str().unwrap()]);
    assert!(e.contains(under.to_str().unwrap()) && e.contains("cannot write"), "{e}");
    let e = err(&["lut", "--backend", "cpu", "--out", d.to_str().unwrap()]);
    assert!(e.contains("folder"), "{e}");
}

#[test]
fn a_failed_run_leaves_the_existing_output_alone() {
    let d = scratch("keep");
    let out = d.join("lut.exr");
    std::fs::write(&out, b"previous result").unwrap();
    let _ = err(&["lut", "--samples", "0", "--backend", "cpu", "--out", out.to_str().unwrap()]);
    assert_eq!(std::fs::read(&out).unwrap(), b"previous result");
    // A write that fails half-way leaves the old file and no temporary behind.
    let r = splitsum::files::write_atomic(&out, |w| {
        use std::io::Write;
        w.write_all(b"half")?;
        Err(std::io::Error::other("disk full"))
    });
    // The message names the file; what failed underneath is its source, not repeated in it.
    let e = r.expect_err("must fail");
    let (msg, cause) = (e.to_string(), std::error::Error::source(&e).map(|c| c.to_string()).unwrap_or_default());
    assert!(msg.contains("lut.exr") && !msg.contains("disk full") && cause == "disk full", "{msg}: {cause}");
    assert_eq!(std::fs::read(&out).unwrap(), b"previous result");
    let leftovers: Vec<_> = std::fs::read_dir(&d).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(leftovers.len(), 1, "{leftovers:?}");
}

#[test]
fn lut_writes_exr_and_png() {
    let d = scratch("ok");
    let out = d.join("t.exr");
    let preview = d.join("t.png");
    cli::run([
        "runner",
        "lut",
        "--size",
        "16",
        "--method",
        "sampled",
        "--samples",
        "64",
        "--backend",
        "cpu",
        "--png",
        preview.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ])
    .expect("bake");
    let png = image::open(d.join("t.png")).expect("png").to_rgb8();
    assert_eq!(png.dimensions(), (16, 16));
    // Reading the EXR back gives two 32-bit channels with the table's conventions: the
    // top-left texel (grazing, smooth) has a small scale and a large bias.
    use exr::prelude::*;
    let img = read().no_deep_data().largest_resolution_level().all_channels().first_valid_layer().all_attributes().from_file(&out).expect("exr");
    let layer = &img.layer_data;
    let names: Vec<String> = layer.channel_data.list.iter().map(|c| c.name.to_string()).collect();
    assert_eq!(names, ["G", "R"]);
    for c in &layer.channel_data.list {
        assert!(matches!(c.sample_data, exr::prelude::FlatSamples::F32(_)));
    }
    let r: Vec<f32> = layer.channel_data.list[1].sample_data.values_as_f32().collect();
    let g: Vec<f32> = layer.channel_data.list[0].sample_data.values_as_f32().collect();
    let want = splitsum_shaders::lut::texel(0, 0, 16, 64);
    assert_eq!((r[0], g[0]), (want.x, want.y));
    assert!(r[0] < g[0]);
}

#[test]
fn missing_gpu_names_the_cpu_backend_and_lavapipe() {
    let e = splitsum::backend::Gpu::matching(wgpu::Backends::all(), Some("no-such-adapter-anywhere")).err().expect("no adapter").to_string();
    assert!(e.contains("on the CPU") && e.contains("mesa-vulkan-drivers") && !e.contains("--"), "the library's own terms: {e}");
}

fn repo(path: &str) -> String {
    format!("{}/../{path}", env!("CARGO_MANIFEST_DIR"))
}

fn ok(args: &[&str]) {
    let mut full = vec!["runner"];
    full.extend_from_slice(args);
    if let Err(e) = cli::run(full) {
        panic!("{args:?} failed: {e:#}");
    }
}

fn names(dir: &std::path::Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    v.sort();
    v
}

/// An output folder is replaced as a unit: a second bake with fewer mips leaves none of
/// the first bake's extra mips, a scene's bake into a full bake's folder leaves none of
/// its files, and the parent holds nothing else afterwards (no staging folder).
#[test]
fn an_output_folder_is_replaced_whole() {
    let d = scratch("unit");
    let out = d.join("out");
    let (o, env) = (out.to_str().unwrap(), repo("splitsum/assets/courtyard.exr"));
    ok(&["bake", &env, "--backend", "cpu", "--size", "32", "--out", o]);
    assert!(out.join("specular_mip1.exr").exists() && out.join("sh9.json").exists());
    ok(&["bake", &env, "--backend", "cpu", "--size", "32", "--mips", "1", "--out", o]);
    let after = names(&out);
    assert!(after.contains(&"specular_mip0.exr".to_string()) && !after.iter().any(|n| n == "specular_mip1.exr"), "{after:?}");
    let cache = d.join("cache");
    ok(&["bake", "--scene", &repo("scenes/brushed-metal.toml"), "--backend", "cpu", "--cache", cache.to_str().unwrap(), "--out", o]);
    assert_eq!(names(&out), [".splitsum-manifest.json", "brdf_lut.exr", "plan.json", "specular.ktx2"]);
    assert_eq!(names(&d), ["cache", "out"]);
}

/// A failed bake creates no folder; `--out` naming a file, or a folder of someone else's
/// files, is refused before any work with a message naming the flag.
#[test]
fn output_folder_mistakes_are_refused_in_the_users_terms() {
    let d = scratch("outerr");
    let missing = d.join("new").join("deeper");
    let e = err(&["bake", "no-such.exr", "--backend", "cpu", "--out", missing.to_str().unwrap()]);
    assert!(e.contains("no-such.exr"), "{e}");
    assert!(!d.join("new").exists(), "a failed bake left {:?}", names(&d));
    let file = d.join("file.txt");
    std::fs::write(&file, "mine").unwrap();
    let e = err(&["bake", &repo("splitsum/assets/courtyard.exr"), "--out", file.to_str().unwrap()]);
    assert!(e.contains("--out") && e.contains("existing file"), "{e}");
    let theirs = d.join("theirs");
    std::fs::create_dir_all(&theirs).unwrap();
    std::fs::write(theirs.join("notes.txt"), "mine").unwrap();
    let e = err(&["bake", &repo("splitsum/assets/courtyard.exr"), "--out", theirs.to_str().unwrap()]);
    assert!(e.contains("--out") && e.contains("notes.txt"), "{e}");
    assert_eq!(std::fs::read_to_string(theirs.join("notes.txt")).unwrap(), "mine");
}

/// Messages name what the user wrote: a small `--size` bakes (the irradiance and SH9
/// sources follow it unless given), `--samples -1` and `--lut-size 0` name the flag and
/// value, a scene's `samples = 0` names the scene field, and flags beside `--scene` that the
/// scene sets are refused by name, even when equal to their defaults.
#[test]
fn messages_name_the_users_own_input() {
    let d = scratch("msgs");
    let env = repo("splitsum/assets/courtyard.exr");
    ok(&["bake", &env, "--backend", "cpu", "--size", "16", "--out", d.join("small").to_str().unwrap()]);
    let e = err(&["bake", &env, "--samples", "-1"]);
    assert!(e.contains("--samples") && e.contains("-1") && !e.contains("-- -1"), "{e}");
    let e = err(&["bake", &env, "--lut-size", "0"]);
    assert!(e.contains("--lut-size") && e.contains("not 0"), "{e}");
    let scene = d.join("zero.toml");
    std::fs::write(
        &scene,
        format!("environment = {env:?}\n[quality]\nsamples = 0\n[[materials]]\nname = \"m\"\n[[objects]]\nkind = \"sphere-grid\"\nmaterial = \"m\"\n"),
    )
    .unwrap();
    let e = err(&["plan", scene.to_str().unwrap()]);
    assert!(e.contains("[quality] samples") && !e.contains("--samples"), "{e}");
    let e = err(&["render", "--scene", &repo("scenes/brushed-metal.toml"), "--yaw", "20", "--width", "960"]);
    assert!(e.contains("--yaw") && e.contains("--width"), "{e}");
    let e = err(&["bake", "--scene", &repo("scenes/brushed-metal.toml"), "--samples", "64"]);
    assert!(e.contains("--samples"), "{e}");
    let e = err(&["render", "--out", d.join("f.bmp").to_str().unwrap()]);
    assert!(e.contains("--out") && e.contains(".png or .jpg"), "{e}");
}

/// `render --out x.jpg` writes a JPEG, and `lut --out` creates missing folders as `bake` does.
#[test]
fn outputs_follow_their_names() {
    let d = scratch("names");
    let jpg = d.join("frame.jpg");
    ok(&["render", "--backend", "cpu", "--width", "64", "--height", "32", "--size", "16", "--samples", "16", "--no-model", "--out", jpg.to_str().unwrap()]);
    assert_eq!(&std::fs::read(&jpg).unwrap()[..3], &[0xFF, 0xD8, 0xFF], "JPEG signature");
    let deep = d.join("a").join("b").join("lut.exr");
    ok(&["lut", "--backend", "cpu", "--size", "8", "--out", deep.to_str().unwrap()]);
    assert!(deep.exists());
}

/// A bake estimated at over an hour is refused before it starts, with the estimate and the
/// flags that set it, unless `--force`.
#[test]
fn runs_estimated_over_an_hour_are_refused() {
    let env = repo("splitsum/assets/courtyard.exr");
    let e = err(&["bake", &env, "--backend", "cpu", "--size", "2048", "--samples", "1048576", "--sampled-only"]);
    assert!(e.contains("estimated to take") && e.contains("--samples") && e.contains("--force"), "{e}");
    let e = err(&["lut", "--backend", "cpu", "--size", "4096", "--method", "sampled", "--samples", "100000000"]);
    assert!(e.contains("estimated to take") && e.contains("--samples") && e.contains("--force"), "{e}");
}

/// A Draco-compressed glTF whose stream is missing says so, naming the extension, instead
/// of the validator's "accessors[n].bufferView: Missing data" (decoding is tested in
/// `tests/model.rs`).
#[test]
fn a_broken_draco_model_names_the_extension() {
    let d = scratch("draco");
    let model = d.join("draco.gltf");
    std::fs::write(&model, r#"{"asset":{"version":"2.0"},"extensionsUsed":["KHR_draco_mesh_compression"],"extensionsRequired":["KHR_draco_mesh_compression"],"accessors":[{"componentType":5126,"count":3,"type":"VEC3"}],"meshes":[{"primitives":[{"attributes":{"POSITION":0},"extensions":{"KHR_draco_mesh_compression":{"bufferView":0,"attributes":{"POSITION":0}}}}]}],"nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}],"scene":0}"#).unwrap();
    let e = format!("{}", splitsum_display::model::load(&model).map(|_| ()).expect_err("refused"));
    assert!(e.contains("KHR_draco_mesh_compression") && !e.contains("Missing data"), "{e}");
}

/// An engine target fixes what its engine reads; a flag that contradicts it is refused by
/// name, before anything is written.
#[test]
fn a_target_refuses_flags_its_engine_cannot_read() {
    let d = scratch("target");
    let env = d.join("sky.hdr");
    std::fs::write(&env, b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 2\n\x80\x80\x80\x81\x80\x80\x80\x81").unwrap();
    let out = d.join("out");
    let o = out.to_str().unwrap();
    let e = err(&["bake", env.to_str().unwrap(), "--target", "khronos", "--mapping", "geometric", "--out", o]);
    assert!(e.contains("--mapping") && e.contains("linear") && e.contains("khronos"), "{e}");
    let e = err(&["bake", env.to_str().unwrap(), "--target", "filament", "--mips", "3", "--out", o]);
    assert!(e.contains("--mips") && e.contains("must be 5"), "{e}");
    let e = err(&["bake", env.to_str().unwrap(), "--target", "filament", "--format", "rgba16f", "--out", o]);
    assert!(e.contains("--format") && e.contains("R11F_G11F_B10F"), "{e}");
    let e = err(&["bake", env.to_str().unwrap(), "--target", "unity", "--out", o]);
    assert!(e.contains("khronos") && e.contains("filament"), "{e}");
    assert!(!out.exists());
}

/// `runner bake A B … --out DIR` bakes each environment into `DIR/NAME` on one device; one
/// that fails is named and the others are still written; two that would share a folder are
/// refused before anything is read or written.
#[test]
fn a_batch_writes_each_environment_and_survives_a_bad_one() {
    let d = scratch("batch");
    let out = d.join("out");
    let o = out.to_str().unwrap();
    let (a, b) = (repo("splitsum/assets/courtyard.exr"), repo("assets/environments/studio.exr"));
    let bad = d.join("broken.hdr");
    std::fs::write(&bad, b"#?RADIANCE\nnot an image\n").unwrap();
    let e = err(&["bake", &a, bad.to_str().unwrap(), &b, "--backend", "cpu", "--size", "16", "--out", o]);
    assert!(e.contains("1 of 3") && e.contains("broken.hdr"), "{e}");
    assert_eq!(names(&out), ["courtyard", "studio"]);
    for (name, src) in [("courtyard", &a), ("studio", &b)] {
        let json = std::fs::read_to_string(out.join(name).join("bake.json")).unwrap();
        assert!(json.contains(src.as_str()), "{name}/bake.json names its environment: {json}");
        assert!(out.join(name).join("specular.ktx2").exists());
    }
    let twin = d.join("twin");
    std::fs::create_dir_all(&twin).unwrap();
    std::fs::copy(&a, twin.join("courtyard.exr")).unwrap();
    let o2 = d.join("out2");
    let e = err(&["bake", &a, twin.join("courtyard.exr").to_str().unwrap(), "--backend", "cpu", "--out", o2.to_str().unwrap()]);
    assert!(e.contains("ENV") && e.contains("both"), "{e}");
    assert!(!o2.exists(), "nothing is written when two outputs collide");
}

/// `--budget` chooses the sample count and the irradiance source itself: beside either
/// flag, or not a positive number, it is refused by name before anything is written.
#[test]
fn a_budget_is_refused_beside_what_it_chooses() {
    let d = scratch("budget");
    let out = d.join("out");
    let (o, env) = (out.to_str().unwrap(), repo("splitsum/assets/courtyard.exr"));
    let e = err(&["bake", &env, "--backend", "cpu", "--budget", "0.5", "--samples", "64", "--out", o]);
    assert!(e.contains("--budget") && e.contains("--samples"), "{e}");
    let e = err(&["bake", &env, "--backend", "cpu", "--budget", "0", "--out", o]);
    assert!(e.contains("--budget") && e.contains("positive"), "{e}");
    assert!(!out.exists());
}
