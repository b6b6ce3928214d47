//! `runner render`: one frame offscreen, on the GPU or the CPU reference renderer.

use super::*;

#[derive(Args)]
pub(super) struct RenderArgs {
    /// The environment (equirect .hdr/.exr or a six-face folder) [default: the embedded courtyard].
    env: Option<PathBuf>,
    #[command(flatten)]
    scene: SceneArgs,
    /// Output image: .png, or .jpg (JPEG, quality 95).
    #[arg(long, default_value = "frame.png")]
    out: PathBuf,
    /// Width in pixels.
    #[arg(long, default_value_t = 960)]
    width: u32,
    /// Height in pixels.
    #[arg(long, default_value_t = 540)]
    height: u32,
    /// Bake and render on the GPU, or on the CPU (the reference renderer); auto: the GPU,
    /// or the CPU where the best adapter is a software rasteriser such as lavapipe.
    #[arg(long, value_parser = choice::<BackendKind>(), default_value = "auto")]
    backend: BackendKind,
    #[command(flatten)]
    look: LookArgs,
    #[command(flatten)]
    bake: DisplayBakeArgs,
}

pub(super) fn render(args: RenderArgs, given: &[String]) -> anyhow::Result<()> {
    let format = files::FileKind::picture(&args.out, "--out")?;
    files::check_output_file(&args.out, format, "--out")?;
    if let Some(scene_path) = &args.scene.scene {
        if args.env.is_some() {
            return Err(Usage::new("give either ENV or --scene, not both (the scene names its environment)").into());
        }
        refuse_beside_scene(given, &SCENE_FLAGS)?;
        let backend = Backend::open(args.backend)?;
        let (scene, sb) = args.scene.bake(scene_path, &backend)?;
        let view = scene.view(sb.env.auto_exposure());
        let model = scene.model()?;
        let (w, h) = (scene.output.width, scene.output.height);
        let start = Instant::now();
        let pixels = {
            let _step = crate::progress::step(&format!("rendering {w}×{h}"), None);
            crate::render::render(&backend, &sb.env, &view.frame(sb.env.shape(), w, h, true), model.as_ref())?
        };
        files::write_rgb8(&args.out, w, h, &crate::render::to_rgb8(&pixels), format)?;
        println!("rendered {w}×{h} in {:.3} s: {}", start.elapsed().as_secs_f64(), view.summary());
        println!("wrote {}", args.out.display());
        return Ok(());
    }
    crate::render::check_size(args.width, args.height)?;
    // The model first: a model that cannot be read costs no bake.
    let model = args.look.load_model()?;
    let (env, name) = load_environment(args.env.as_deref(), args.bake.sanitize)?;
    let backend = Backend::open(args.backend)?;
    let (baked, bake_secs) = args.bake.bake(&env, &backend, args.scene.force)?;
    let view = args.look.view(baked.auto_exposure());
    let start = Instant::now();
    let frame = view.frame(baked.shape(), args.width, args.height, true);
    let pixels = {
        let _step = crate::progress::step(&format!("rendering {}×{}", args.width, args.height), None);
        crate::render::render(&backend, &baked, &frame, model.as_ref())?
    };
    let render_secs = start.elapsed().as_secs_f64();
    files::write_rgb8(&args.out, args.width, args.height, &crate::render::to_rgb8(&pixels), format)?;
    println!("{name} on {}: bake {bake_secs:.2} s, render {render_secs:.3} s", backend.describe());
    println!("{}", view.summary());
    println!("wrote {}", args.out.display());
    Ok(())
}
