//! `runner view`: the interactive viewer.

use super::*;

#[derive(Args)]
pub(super) struct ViewArgs {
    /// The environment (equirect .hdr/.exr or a six-face folder) [default: the embedded courtyard].
    env: Option<PathBuf>,
    #[command(flatten)]
    scene: SceneArgs,
    /// Window width.
    #[arg(long, default_value_t = 960)]
    width: u32,
    /// Window height.
    #[arg(long, default_value_t = 540)]
    height: u32,
    /// Close the window after this many seconds.
    #[arg(long)]
    exit_after: Option<f64>,
    #[command(flatten)]
    look: LookArgs,
    #[command(flatten)]
    bake: DisplayBakeArgs,
}

pub(super) fn view(args: ViewArgs, given: &[String]) -> anyhow::Result<()> {
    if args.scene.scene.is_some() {
        if args.env.is_some() {
            return Err(Usage::new("give either ENV or --scene, not both (the scene names its environment)").into());
        }
        refuse_beside_scene(given, &["--force", "--cache", "--calibration", "--exit-after"])?;
    }
    if !crate::view::display_available() {
        anyhow::bail!("no display (neither DISPLAY nor WAYLAND_DISPLAY is set); `runner render --out frame.png` renders without one");
    }
    if let Some(scene_path) = &args.scene.scene {
        let backend = Backend::open(BackendKind::Gpu)?;
        let (scene, sb) = args.scene.bake(scene_path, &backend)?;
        let Backend::Gpu(gpu) = backend else { unreachable!("opened as GPU") };
        let state = scene.view(sb.env.auto_exposure());
        let model = scene.model()?;
        let options = crate::view::ViewOptions {
            exit_after: args.exit_after.map(std::time::Duration::from_secs_f64),
            size: (scene.output.width, scene.output.height),
            ..Default::default()
        };
        crate::view::run(*gpu, &sb.env, model.as_ref(), state, options)?;
        return Ok(());
    }
    crate::render::check_size(args.width, args.height)?;
    // The model first: a model that cannot be read costs no bake.
    let model = args.look.load_model()?;
    let (env, name) = load_environment(args.env.as_deref(), args.bake.sanitize)?;
    let backend = Backend::open(BackendKind::Gpu)?;
    let (baked, seconds) = args.bake.bake(&env, &backend, args.scene.force)?;
    println!("{name} baked on {} in {seconds:.2} s", backend.describe());
    let Backend::Gpu(gpu) = backend else { unreachable!("opened as GPU") };
    let state = args.look.view(baked.auto_exposure());
    let options = crate::view::ViewOptions {
        exit_after: args.exit_after.map(std::time::Duration::from_secs_f64),
        exit_after_frames: None,
        on_presented: None,
        size: (args.width, args.height),
    };
    crate::view::run(*gpu, &baked, model.as_ref(), state, options)?;
    Ok(())
}
