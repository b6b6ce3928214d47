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

#[test]
fn lut_names_an_unwritable_path() {
    let e = err(&["lut", "--backend", "cpu", "--out", "/no/such/folder/lut.exr"]);
    assert!(e.contains("/no/such/folder/lut.exr") && e.contains("cannot write"), "{e}");
    let d = scratch("dir");
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
    let r = runner::files::write_atomic(&out, |w| {
        use std::io::Write;
        w.write_all(b"half")?;
        Err(std::io::Error::other("disk full"))
    });
    let msg = r.expect_err("must fail").to_string();
    assert!(msg.contains("lut.exr") && msg.contains("disk full"), "{msg}");
    assert_eq!(std::fs::read(&out).unwrap(), b"previous result");
    let leftovers: Vec<_> = std::fs::read_dir(&d).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(leftovers.len(), 1, "{leftovers:?}");
}

#[test]
fn lut_writes_exr_and_png() {
    let d = scratch("ok");
    let out = d.join("t.exr");
    cli::run(["runner", "lut", "--size", "16", "--method", "sampled", "--samples", "64", "--backend", "cpu", "--png", "--out", out.to_str().unwrap()])
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
    let e = runner::gpu::Gpu::matching(Some("no-such-adapter-anywhere")).err().expect("no adapter").to_string();
    assert!(e.contains("--backend cpu") && e.contains("mesa-vulkan-drivers"), "{e}");
}
