//! `runner` with no arguments: the embedded environment on the sphere grid.

use super::*;

/// `runner` with no arguments: bake the embedded environment and show the sphere grid in a
/// window, or, where there is no display (or no GPU), render it to `splitsum.png`.
pub(super) fn default_run() -> anyhow::Result<()> {
    let (env, name) = load_environment(None, false)?;
    // The bake's backend by the one rule (`BackendKind::Auto`: the CPU where the best
    // adapter is a software rasteriser); the window, if any, draws on a device either way.
    let backend = match Backend::open(BackendKind::Auto) {
        Ok(b) => b,
        Err(e) => {
            eprintln!("{}\nfalling back to the CPU backend", splitsum::error::chain(&e));
            Backend::Cpu
        }
    };
    let start = Instant::now();
    let baked = splitsum::reading::bake_for_display(&backend, &env, &Settings::display(env.native_face_size()))?;
    println!("baked {name} on {} in {:.2} s", backend.describe(), start.elapsed().as_secs_f64());
    let look = LookArgs {
        diffuse: DiffuseModel::default(),
        specular: SpecularModel::default(),
        fresnel: FresnelForm::default(),
        no_ibl: false,
        no_lights: false,
        exposure: 0.0,
        tonemapper: Tonemapper::default(),
        sky_blur: 0.0,
        yaw: 0.0,
        pitch: 0.0,
        model: None,
        no_model: true,
        no_grid: false,
        shading: Default::default(),
    };
    let state = look.view(baked.auto_exposure());
    let backend = if crate::view::display_available() {
        let gpu = match backend {
            Backend::Gpu(gpu) => Ok(*gpu),
            Backend::Cpu => splitsum::Gpu::new(),
        };
        let options = crate::view::ViewOptions { size: (960, 540), ..Default::default() };
        match gpu.map(|gpu| crate::view::run(gpu, &baked, None, state.clone(), options)) {
            Ok(Ok(())) => return Ok(()),
            Ok(Err(e)) => eprintln!("{}; rendering to a file instead", splitsum::error::chain(&e)),
            Err(e) => eprintln!("{}; rendering to a file instead", splitsum::error::chain(&e)),
        }
        Backend::open(BackendKind::Auto).unwrap_or(Backend::Cpu)
    } else {
        backend
    };
    let (w, h) = (960, 540);
    let out = PathBuf::from("splitsum.png");
    files::check_output_file(&out, files::FileKind::Png, "the picture")?;
    let pixels = crate::render::render(&backend, &baked, &state.frame(baked.shape(), w, h, true), None)?;
    files::write_png(&out, w, h, &crate::render::to_rgb8(&pixels))?;
    let shown = std::fs::canonicalize(&out).unwrap_or(out);
    println!("no display here: rendered the sphere grid ({w}×{h}) to {}", shown.display());
    println!("{}", state.summary());
    Ok(())
}
