//! A windowed smoke test: the viewer opens a real window on an X server (Xvfb, with
//! lavapipe presenting), and a screenshot of the screen shows the rendered scene.

use splitsum_display::render::{GpuScene, ViewState};
use std::process::{Child, Command};
use std::sync::{Arc, Mutex};

struct Xvfb(Child);

impl Drop for Xvfb {
    fn drop(&mut self) {
        // SIGTERM, so that Xvfb removes its socket and lock file (SIGKILL leaves them).
        // SAFETY: signalling our own child.
        unsafe { libc::kill(self.0.id() as i32, libc::SIGTERM) };
        let _ = self.0.wait();
    }
}

/// Whether display `n` is taken: its lock file names a live process. (A killed server
/// leaves a stale lock and socket behind; Xvfb replaces them.)
fn taken(n: u32) -> bool {
    match std::fs::read_to_string(format!("/tmp/.X{n}-lock")) {
        Ok(pid) => pid.trim().parse::<u32>().is_ok_and(|pid| std::path::Path::new(&format!("/proc/{pid}")).exists()),
        Err(_) => false,
    }
}

fn start_xvfb() -> (Xvfb, String) {
    for n in 90..120 {
        if taken(n) {
            continue;
        }
        // A dead server's leftovers: remove them, so that the socket below is the new one's.
        let _ = std::fs::remove_file(format!("/tmp/.X11-unix/X{n}"));
        let _ = std::fs::remove_file(format!("/tmp/.X{n}-lock"));
        let child = Command::new("Xvfb")
            .args([format!(":{n}").as_str(), "-screen", "0", "1024x640x24", "-nolisten", "tcp"])
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
            .expect("Xvfb (Debian package xvfb; `bash scripts/dev.sh test` installs it)");
        let guard = Xvfb(child);
        for _ in 0..100 {
            if std::path::Path::new(&format!("/tmp/.X11-unix/X{n}")).exists() {
                return (guard, format!(":{n}"));
            }
            std::thread::sleep(std::time::Duration::from_millis(50));
        }
        panic!("Xvfb :{n} did not come up");
    }
    panic!("no free X display number");
}

/// The root window as RGB, from `xwd` (X Window Dump, ZPixmap, 32 bits per pixel).
fn screenshot(display: &str) -> (u32, u32, Vec<[u8; 3]>) {
    let out = Command::new("xwd").args(["-root", "-silent", "-display", display]).output().expect("xwd (Debian package x11-apps)");
    assert!(out.status.success(), "xwd failed");
    let b = out.stdout;
    let u = |i: usize| u32::from_be_bytes(b[4 * i..4 * i + 4].try_into().unwrap());
    let (header, format, width, height, byte_order, bpp, stride) = (u(0) as usize, u(2), u(4), u(5), u(7), u(11), u(12) as usize);
    let (rmask, gmask, bmask, ncolors) = (u(14), u(15), u(16), u(19) as usize);
    assert_eq!((format, bpp), (2, 32), "expected a 32-bit ZPixmap");
    let data = &b[header + 12 * ncolors..];
    let channel = |p: u32, mask: u32| ((p & mask) >> mask.trailing_zeros()) as u8;
    let mut px = Vec::with_capacity((width * height) as usize);
    for y in 0..height as usize {
        for x in 0..width as usize {
            let q: [u8; 4] = data[y * stride + 4 * x..y * stride + 4 * x + 4].try_into().unwrap();
            let p = if byte_order == 0 { u32::from_le_bytes(q) } else { u32::from_be_bytes(q) };
            px.push([channel(p, rmask), channel(p, gmask), channel(p, bmask)]);
        }
    }
    (width, height, px)
}

#[test]
fn the_viewer_window_shows_the_scene() {
    let (_xvfb, display) = start_xvfb();
    // SAFETY: this test binary runs this one test; nothing else reads the environment now.
    unsafe { std::env::set_var("DISPLAY", &display) };
    let baked = support::small_display_bake();
    let (w, h) = (320u32, 200u32);
    let state = ViewState { exposure: baked.auto_exposure(), ..ViewState::default() };

    type Shot = Option<(u32, u32, Vec<[u8; 3]>)>;
    let shot: Arc<Mutex<Shot>> = Arc::default();
    let sink = shot.clone();
    let shot_display = display.clone();
    let options = splitsum_display::view::ViewOptions {
        exit_after: Some(std::time::Duration::from_secs(60)),
        exit_after_frames: Some(3),
        on_presented: Some(Box::new(move |frame| {
            if frame == 3 {
                *sink.lock().unwrap() = Some(screenshot(&shot_display));
            }
        })),
        size: (w, h),
    };
    let gpu = splitsum::backend::Gpu::new().expect("a Vulkan adapter (lavapipe)");
    splitsum_display::view::run(gpu, &baked, None, state.clone(), options).expect("the viewer ran");
    let (sw, _sh, pixels) = shot.lock().unwrap().take().expect("a screenshot was taken");

    // The window (at the origin: Xvfb has no window manager) against the same frame
    // rendered offscreen.
    let gpu = splitsum::backend::Gpu::new().unwrap();
    let scene = GpuScene::new(&gpu, &baked);
    let want = scene.render_offscreen(&gpu, &state.frame(scene.shape, w, h, true), None).unwrap();
    let mut sum = 0.0f64;
    let mut lit = 0usize;
    for y in 0..h {
        for x in 0..w {
            let got = pixels[(y * sw + x) as usize];
            let ref_px = want[(y * w + x) as usize];
            for (k, v) in [ref_px.x, ref_px.y, ref_px.z].into_iter().enumerate() {
                sum += (got[k] as f64 / 255.0 - v as f64).abs();
            }
            lit += (got.iter().map(|&c| c as u32).sum::<u32>() > 60) as usize;
        }
    }
    let mean = sum / (3 * w * h) as f64;
    let png = std::env::temp_dir().join("splitsum-window-screenshot.png");
    let rgb: Vec<u8> = (0..h).flat_map(|y| (0..w).map(move |x| (y * sw + x) as usize)).flat_map(|i| pixels[i]).collect();
    splitsum::files::write_png(&png, w, h, &rgb).unwrap();
    println!("window screenshot ({}): mean |Δ| vs offscreen render {mean:.4}, {:.0} % of pixels lit", png.display(), 100.0 * lit as f64 / (w * h) as f64);
    assert!(lit as f64 > 0.9 * (w * h) as f64, "the window is mostly black");
    // 8-bit quantisation and the swapchain's format conversion: well under 1 %.
    assert!(mean < 0.01, "the window does not show the scene: mean difference {mean}");
}
