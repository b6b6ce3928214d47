//! `runner plan SCENE`: what a scene needs baked and why, and the cost.

use super::*;

#[derive(Args)]
pub(super) struct PlanArgs {
    /// The scene file.
    scene: PathBuf,
    /// Error and cost measurements to plan with (a report.csv) [default: built in].
    #[arg(long)]
    calibration: Option<PathBuf>,
}

pub(super) fn plan_command(args: PlanArgs) -> anyhow::Result<()> {
    let scene = crate::scene::Scene::load(&args.scene)?;
    let cal = SceneArgs { scene: None, force: false, cache: None, calibration: args.calibration.clone() }.calibration()?;
    let env_path = scene.environment.as_ref().map(|p| scene.resolve(p));
    let (env, name) = load_environment(env_path.as_deref(), scene.sanitize)?;
    let plan = crate::plan::plan_for(&scene, &env, &cal)?;
    print!("{}", crate::plan::describe(&plan, &args.scene.display().to_string(), &name));
    Ok(())
}
