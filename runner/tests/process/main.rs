//! The `runner` binary as a user runs it, in its own process: inputs of 4K–16K, peak
//! memory (measured by the kernel, `getrusage`), interruptions, a full disk and concurrent
//! runs. Large inputs are generated here, never committed.

#[path = "../common/mod.rs"]
mod common;
mod hostile;

use common::{courtyard, runner, scratch};
use equirect::write_equirect;

#[path = "../common/equirect.rs"]
mod equirect;
use std::path::Path;
use std::process::{Command, Output};

fn text(o: &Output) -> String {
    format!("status {:?}\nstdout:\n{}\nstderr:\n{}", o.status, String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr))
}

/// Runs `command` to its end and returns its exit status, its output and its own peak
/// resident memory in bytes, as the kernel counts it (`wait4`'s `ru_maxrss`, this child
/// alone, whatever other tests run beside it).
fn run_measured(mut command: Command, dir: &Path) -> (bool, String, u64) {
    let (out, err) = (dir.join("stdout.txt"), dir.join("stderr.txt"));
    // Reaped by wait4 below, which also gives the peak memory `Child::wait` does not.
    #[allow(clippy::zombie_processes)]
    let child = command.stdout(std::fs::File::create(&out).unwrap()).stderr(std::fs::File::create(&err).unwrap()).spawn().unwrap();
    let mut status = 0;
    let mut usage = std::mem::MaybeUninit::<libc::rusage>::zeroed();
    // SAFETY: waits for our own child; wait4 writes the status and the struct it is given.
    let pid = unsafe { libc::wait4(child.id() as i32, &mut status, 0, usage.as_mut_ptr()) };
    assert_eq!(pid, child.id() as i32);
    // SAFETY: initialised by the successful call.
    let peak = unsafe { usage.assume_init() }.ru_maxrss as u64 * 1024;
    let said = format!("{}{}", std::fs::read_to_string(&out).unwrap(), std::fs::read_to_string(&err).unwrap());
    (libc::WIFEXITED(status) && libc::WEXITSTATUS(status) == 0, said, peak)
}

/// A 16384×8192 HDRI bakes with the defaults in at most 2 GiB (the target of issue 11):
/// the file is reduced as it is decoded to what a 256² source cube resolves.
#[test]
fn a_16k_equirect_bakes_within_2_gib() {
    let d = scratch("16k");
    let env = d.join("16k.exr");
    write_equirect(&env, 16384, 5.0e4);
    let mut c = runner();
    c.args(["bake", env.to_str().unwrap(), "--backend", "cpu", "--out", d.join("out").to_str().unwrap()]);
    let (ok, said, peak) = run_measured(c, &d);
    assert!(ok, "{said}");
    assert!(said.contains("16384×8192 read as 2048×1024"), "{said}");
    assert!(peak <= 2 << 30, "peak RSS {:.0} MiB", peak as f64 / 1048576.0);
    eprintln!("peak RSS {:.0} MiB", peak as f64 / 1048576.0);
    if std::env::var_os("KEEP").is_none() {
        let _ = std::fs::remove_dir_all(&d);
    }
}

/// The RGB values of an EXR written by `runner`.
fn read_rgb(path: &Path) -> Vec<f32> {
    use exr::prelude::*;
    let image = read_first_rgba_layer_from_file(
        path,
        |size, _| (size.width(), vec![0.0f32; 3 * size.width() * size.height()]),
        |(w, px): &mut (usize, Vec<f32>), pos: Vec2<usize>, (r, g, b, _): (f32, f32, f32, f32)| {
            let i = 3 * (pos.y() * *w + pos.x());
            px[i..i + 3].copy_from_slice(&[r, g, b]);
        },
    )
    .unwrap();
    image.layer_data.channel_data.pixels.1
}

/// The GPU backend takes an 8192×4096 HDRI at `--source-size 1024`, whose row pyramid
/// (1 GiB) is far beyond lavapipe's 128 MiB storage binding: the resampling runs on the
/// CPU, says so, and everything else stays on the GPU; the result matches the CPU backend's.
#[test]
fn the_gpu_backend_takes_inputs_beyond_its_binding_limit() {
    let d = scratch("8k");
    let env = d.join("8k.exr");
    write_equirect(&env, 8192, 5.0e4);
    let run = |backend: &str| {
        let out = d.join(backend);
        let o = runner()
            .args(["bake", env.to_str().unwrap(), "--backend", backend, "--source-size", "1024", "--size", "128", "--out", out.to_str().unwrap()])
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", text(&o));
        (out, text(&o))
    };
    let (gpu, said) = run("gpu");
    // Lavapipe (llvmpipe) binds at most 128 MiB; a GPU that binds the whole pyramid needs no fallback.
    if said.contains("llvmpipe") {
        assert!(
            said.contains("resampling the 8192×4096 equirect (its row pyramid) needs a 1024 MiB buffer") && said.contains("running this step on the CPU"),
            "{said}"
        );
    }
    let (cpu, _) = run("cpu");
    for m in 0..4 {
        let name = format!("specular_mip{m}.exr");
        let (a, b) = (read_rgb(&gpu.join(&name)), read_rgb(&cpu.join(&name)));
        assert_eq!(a.len(), b.len());
        // GPU-vs-CPU: the same functions; lavapipe's fused multiply-adds and 2.5-ulp division
        // leave relative differences of about 1e-5 per sum (tests/prefilter.rs bounds them).
        let worst = a.iter().zip(&b).map(|(x, y)| (x - y).abs() / y.abs().max(1e-3)).fold(0.0f32, f32::max);
        assert!(worst < 1e-3, "mip {m}: worst relative difference {worst}");
    }
}

fn listing(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir).map(|r| r.map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect()).unwrap_or_default();
    v.sort();
    v
}

/// The files `bake.json` of `dir` lists, itself included.
fn manifest_files(dir: &Path) -> Vec<String> {
    let json: serde_json::Value = serde_json::from_slice(&std::fs::read(dir.join("bake.json")).unwrap()).unwrap();
    let mut v: Vec<String> = json["files"].as_array().unwrap().iter().map(|f| f["name"].as_str().unwrap().to_string()).collect();
    v.push("bake.json".into());
    v.push(splitsum::files::OUTPUT_MANIFEST.into());
    v.sort();
    v
}

/// SIGINT while reading, baking or writing: the output folder is afterwards the whole old
/// set (byte for byte) or the whole new set (every file its manifest lists, nothing else),
/// and its parent holds no staging folder.
#[test]
fn an_interrupted_bake_leaves_the_old_folder_or_the_whole_new_one() {
    use std::io::BufRead;
    for phase in ["reading", "specular…", "writing the files…"] {
        let d = scratch(&format!("sigint-{}", phase.len()));
        let out = d.join("out");
        let o = runner().args(["bake", &courtyard(), "--backend", "cpu", "--size", "32", "--out", out.to_str().unwrap()]).output().unwrap();
        assert!(o.status.success(), "{}", text(&o));
        let old = listing(&out);
        let old_manifest = std::fs::read(out.join("bake.json")).unwrap();
        let mut child = runner()
            .args(["bake", &courtyard(), "--backend", "cpu", "--size", "512", "--out", out.to_str().unwrap()])
            .stderr(std::process::Stdio::piped())
            .stdout(std::process::Stdio::null())
            .spawn()
            .unwrap();
        let stderr = child.stderr.take().unwrap();
        let mut seen = Vec::new();
        let mut sent = false;
        // Read stderr to its end (the child's last words included), signalling once.
        for line in std::io::BufReader::new(stderr).lines() {
            let line = line.unwrap();
            if !sent && line.starts_with(phase) {
                // SAFETY: signalling our own child.
                unsafe { libc::kill(child.id() as i32, libc::SIGINT) };
                sent = true;
            }
            seen.push(line);
        }
        let status = child.wait().unwrap();
        let now = listing(&out);
        if now == old && std::fs::read(out.join("bake.json")).unwrap() == old_manifest {
            assert_eq!(status.code(), Some(130), "interrupted in {phase}: {seen:?}");
        } else {
            assert_eq!(now, manifest_files(&out), "interrupted in {phase}: a mix of files: {seen:?}");
            assert!(now.iter().any(|n| n == "specular_mip5.exr"), "the new set (512², 7 mips): {now:?}");
        }
        assert_eq!(listing(&d), ["out"], "interrupted in {phase}: leftovers beside the output folder");
    }
}

/// A full disk (a 2 MiB tmpfs, in a private mount namespace) fails the second, larger bake
/// with the system's own words, and leaves the first bake's folder as it was and nothing
/// else.
#[test]
fn a_full_disk_leaves_the_old_folder_as_it_was() {
    let d = scratch("full");
    let script = format!(
        "set -u; mount -t tmpfs -o size=2m tmpfs {d} || exit 99; \
         {r} bake {env} --backend cpu --size 16 --out {d}/out >/dev/null 2>&1 || exit 98; \
         ls -A {d}/out > {d}/before.txt; md5sum {d}/out/bake.json > {d}/sum.txt; \
         {r} bake {env} --backend cpu --size 256 --out {d}/out; echo rc=$?; \
         echo parent:; ls -A {d}; echo out:; ls -A {d}/out | diff - {d}/before.txt && echo same-files; md5sum -c --quiet {d}/sum.txt && echo same-manifest",
        d = d.display(),
        r = env!("CARGO_BIN_EXE_runner"),
        env = courtyard()
    );
    let o = Command::new("unshare").args(["--user", "--map-root-user", "--mount", "sh", "-c", &script]).output().expect("unshare (util-linux)");
    let t = text(&o);
    assert!(o.status.code() != Some(99) && o.status.code() != Some(98), "could not set up the tmpfs: {t}");
    assert!(t.contains("No space left on device") && !t.contains("rc=0"), "{t}");
    assert!(t.contains("parent:\nbefore.txt\nout\nsum.txt\nout:"), "leftovers beside the output folder: {t}");
    assert!(t.contains("same-files") && t.contains("same-manifest"), "{t}");
}

/// Two `bake --scene` runs of one scene on one cache at once: one bakes, the other waits
/// for it and takes its entry.
#[test]
fn concurrent_scene_bakes_bake_once() {
    let d = scratch("concurrent");
    let scene = format!("{}/../scenes/brushed-metal.toml", env!("CARGO_MANIFEST_DIR"));
    let spawn = |name: &str| {
        runner()
            .args(["bake", "--scene", &scene, "--backend", "cpu", "--cache", d.join("cache").to_str().unwrap(), "--out", d.join(name).to_str().unwrap()])
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap()
    };
    let (a, b) = (spawn("a"), spawn("b"));
    let (a, b) = (a.wait_with_output().unwrap(), b.wait_with_output().unwrap());
    let (ta, tb) = (text(&a), text(&b));
    assert!(a.status.success() && b.status.success(), "{ta}\n{tb}");
    let baked = [&ta, &tb].iter().filter(|t| t.contains("\nbaked ")).count();
    let hits = [&ta, &tb].iter().filter(|t| t.contains("cache hit")).count();
    assert_eq!((baked, hits), (1, 1), "{ta}\n{tb}");
}

/// `bench` reports the process's peak memory as the kernel counts it.
#[test]
fn bench_reports_peak_memory() {
    let o = runner().args(["bench", &courtyard(), "--backends", "cpu", "--size", "32"]).output().unwrap();
    assert!(o.status.success(), "{}", text(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    let mib: f64 = out
        .lines()
        .find_map(|l| l.strip_prefix("peak memory of this process (VmHWM, all backends so far): "))
        .and_then(|v| v.trim_end_matches(" MiB").parse().ok())
        .unwrap_or_else(|| panic!("no peak memory line: {out}"));
    // The embedded-size HDRI, decoded (8 MiB as RGBA f32) and baked at 32²: more than the
    // image, far less than a gigabyte.
    assert!((8.0..1024.0).contains(&mib), "{mib} MiB");
}

/// `runner bench --processes`: whole-process bakes with the bench's quality flags (and only
/// those) paired with another command, their figures written with their provenance; a
/// figures file runner bench did not write is refused by name and left as it was. The
/// other side sleeps 0.3 s, so its median is at least that (the kernel's clock), and the
/// sleeping shell's peak memory is far below the bake's.
#[test]
fn bench_pairs_whole_processes_and_writes_its_figures() {
    let d = scratch("bench-processes");
    let figures = d.join("speed.md");
    let o = runner()
        .args(["bench", &courtyard(), "--backends", "cpu", "--size", "16", "--samples", "8", "--processes", "2", "--versus", "sleep 0.3"])
        .arg("--figures")
        .arg(&figures)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o));
    let md = std::fs::read_to_string(&figures).unwrap();
    assert!(md.starts_with("<!-- Generated by runner bench: runner bench "), "{md}");
    let row = |prefix: &str| -> Vec<String> {
        md.lines().find(|l| l.starts_with(prefix)).unwrap_or_else(|| panic!("no row {prefix}: {md}")).split('|').map(|c| c.trim().to_string()).collect()
    };
    // The child bake got --size 16 and --samples 8 and nothing of the bench's own flags.
    let bake = row("| `runner bake courtyard.exr --size 16 --samples 8 --backend cpu`");
    let other = row("| `sleep 0.3`");
    let seconds = |c: &str| c.trim_end_matches(" s").parse::<f64>().unwrap();
    let mib = |c: &str| c.trim_end_matches(" MiB").parse::<f64>().unwrap();
    assert!(seconds(&other[2]) >= 0.3, "{md}");
    assert!(mib(&bake[3]) > mib(&other[3]), "{md}");
    let ratio: f64 = bake[4].trim_matches('*').parse().unwrap();
    assert!(ratio > 0.0 && ratio.is_finite(), "{md}");
    assert!(md.contains("2 timed runs of each side after a warm-up") && md.contains(", commit "), "{md}");
    // Run again, the file is replaced; a user's file is not.
    let mine = d.join("mine.md");
    std::fs::write(&mine, "my notes\n").unwrap();
    let o = runner().args(["bench", &courtyard(), "--backends", "cpu", "--size", "16", "--processes", "1", "--figures"]).arg(&mine).output().unwrap();
    assert!(!o.status.success() && text(&o).contains("--figures") && text(&o).contains("was not written by runner bench"), "{}", text(&o));
    assert_eq!(std::fs::read_to_string(&mine).unwrap(), "my notes\n");
    let _ = std::fs::remove_dir_all(&d);
}

/// A folder of six 2048² faces (which the seed's GPU backend could not bind) bakes on the
/// GPU, read through the cube's mip filter down to the 256² source, and matches the CPU.
#[test]
fn large_face_folders_bake_on_the_gpu() {
    use exr::prelude::*;
    let d = scratch("faces");
    let faces = d.join("faces");
    std::fs::create_dir_all(&faces).unwrap();
    for (k, name) in ["px", "nx", "py", "ny", "pz", "nz"].iter().enumerate() {
        let ch = SpecificChannels::rgb(move |p: Vec2<usize>| {
            let v = 0.2 + 0.1 * k as f32 + if (p.x() / 64 + p.y() / 64).is_multiple_of(2) { 0.5 } else { 0.0 };
            (f16::from_f32(v), f16::from_f32(0.5 * v), f16::from_f32(0.25 * v))
        });
        Image::from_channels((2048, 2048), ch).write().to_file(faces.join(format!("{name}.exr"))).unwrap();
    }
    let run = |backend: &str| {
        let out = d.join(backend);
        let o = runner().args(["bake", faces.to_str().unwrap(), "--backend", backend, "--out", out.to_str().unwrap()]).output().unwrap();
        assert!(o.status.success(), "{}", text(&o));
        assert!(text(&o).contains("faces of 2048² read as 256²"), "{}", text(&o));
        out
    };
    let (gpu, cpu) = (run("gpu"), run("cpu"));
    for name in ["specular_mip0.exr", "specular_mip3.exr", "irradiance.exr"] {
        let (a, b) = (read_rgb(&gpu.join(name)), read_rgb(&cpu.join(name)));
        // The same functions on both backends (see the 8K test): 1e-3 relative.
        let worst = a.iter().zip(&b).map(|(x, y)| (x - y).abs() / y.abs().max(1e-3)).fold(0.0f32, f32::max);
        assert!(worst < 1e-3, "{name}: worst relative difference {worst}");
    }
}

/// A `width`×`width/2` Radiance HDR, flat RGBE scanlines written row by row: the same sky
/// as [`write_equirect`].
fn write_hdr(path: &Path, width: usize) {
    use std::io::Write;
    let h = width / 2;
    let mut f = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    write!(f, "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y {h} +X {width}\n").unwrap();
    let mut row = vec![0u8; 4 * width];
    for y in 0..h {
        for x in 0..width {
            let n = ((x as u32).wrapping_mul(0x9E37_79B9) ^ (y as u32).wrapping_mul(0x85EB_CA6B)).rotate_left(13).wrapping_mul(0xC2B2_AE35);
            // Mantissas 64..255 at exponent 128: values 0.25..1 (flat, not run-length coded).
            row[4 * x..4 * x + 4].copy_from_slice(&[64 + (n >> 26) as u8 * 3, 100, 64 + (y * 191 / h) as u8, 128]);
        }
        f.write_all(&row).unwrap();
    }
}

/// A 16384×8192 Radiance HDR bakes with the defaults in at most 2 GiB.
#[test]
fn a_16k_hdr_bakes_within_2_gib() {
    let d = scratch("16k-hdr");
    let env = d.join("16k.hdr");
    write_hdr(&env, 16384);
    let mut c = runner();
    c.args(["bake", env.to_str().unwrap(), "--backend", "cpu", "--out", d.join("out").to_str().unwrap()]);
    let (ok, said, peak) = run_measured(c, &d);
    assert!(ok, "{said}");
    assert!(said.contains("16384×8192 read as 2048×1024"), "{said}");
    eprintln!("peak RSS {:.0} MiB", peak as f64 / 1048576.0);
    assert!(peak <= 2 << 30, "peak RSS {:.0} MiB", peak as f64 / 1048576.0);
    let _ = std::fs::remove_dir_all(&d);
}

/// Off a terminal, every step of a bake says so on stderr as it starts, with its estimate
/// and how far it may be off where it has one (on a terminal, indicatif spinners and bars
/// show the same), after a calibration of this device's rates; the timings beside the
/// estimates at the end. The table, embedded and only uploaded, has none; an estimate under
/// 0.1 s is not shown, so the prefilter is given 1024 samples at mip 1 (about 1.5 s of work
/// here): at the default 64 its estimate sat at 0.1 s, and a CI run under load, whose
/// calibration happened to read fast rates, showed none.
#[test]
fn each_step_reports_its_start_and_estimate() {
    let d = scratch("steps");
    let o = runner()
        .args(["bake", &courtyard(), "--backend", "cpu", "--size", "128", "--samples", "1024", "--out", d.join("out").to_str().unwrap()])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o));
    let err = String::from_utf8_lossy(&o.stderr);
    for step in ["reading ", "calibrating ", "source cube…", "specular… (estimate ", "irradiance…", "brdf lut…", "writing the files…"] {
        assert!(err.lines().any(|l| l.starts_with(step)), "no line starting {step:?}:\n{err}");
    }
    assert!(err.lines().any(|l| l.starts_with("specular… (estimate ") && l.contains(" ±") && l.ends_with(" %)")), "{err}");
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.lines().any(|l| l.trim_start().starts_with("specular") && l.contains("(estimated ")), "{out}");
}
