//! A scene's bake: its plan ([`crate::plan`]) baked by `splitsum::bake`'s one sequence, or
//! taken from the cache when an entry for exactly this input, plan, backend and shader
//! build is there.

use splitsum::Backend;
use splitsum::bake::{Timing, check_duration};
use splitsum::reading::{BakedEnvironment, for_display};
use splitsum::error::Result;

/// What happened to a scene's bake.
#[derive(Clone, Debug)]
pub enum Outcome {
    /// Found in the cache: nothing baked.
    CacheHit,
    /// Baked (and stored, when there is a cache).
    Baked,
    /// The cache held an entry that could not be used (why); baked again.
    Rebuilt(std::sync::Arc<splitsum::cache::Rejection>),
    /// `--force`: baked again regardless of the cache.
    Forced,
}

/// Outcomes are equal when they are the same kind; two rebuilds, when for the same rejection.
impl PartialEq for Outcome {
    fn eq(&self, other: &Self) -> bool {
        match (self, other) {
            (Outcome::Rebuilt(a), Outcome::Rebuilt(b)) => std::sync::Arc::ptr_eq(a, b),
            _ => std::mem::discriminant(self) == std::mem::discriminant(other),
        }
    }
}

impl Eq for Outcome {}

/// A scene's bake: the plan, the products and how they were obtained.
pub struct SceneBake {
    /// The plan.
    pub plan: crate::plan::Plan,
    /// The products the display reads (stand-ins for what the plan left out).
    pub env: BakedEnvironment,
    /// Cache key.
    pub key: String,
    /// Cache hit, baked, or rebuilt.
    pub outcome: Outcome,
    /// Wall time per product (empty on a cache hit).
    pub timings: Vec<Timing>,
}

/// Bakes what `plan` keeps of `env` into what the display reads (stand-ins for the rest).
pub fn bake_plan(backend: &Backend, env: &splitsum::Environment, plan: &crate::plan::Plan) -> Result<(BakedEnvironment, Vec<Timing>)> {
    for_display(backend, env, &plan.job)
}

/// Plans `scene` and bakes it, or takes it from `cache` when an entry for exactly this
/// input, plan, backend and shader build is there (`force` bakes regardless).
pub fn bake_scene(
    backend: &Backend,
    scene: &crate::scene::Scene,
    cal: &splitsum::cost::Calibration,
    cache: Option<&splitsum::cache::Cache>,
    force: bool,
) -> Result<SceneBake> {
    let env_path = scene.environment.as_ref().map(|p| scene.resolve(p));
    let (env, _) = match &env_path {
        Some(p) => splitsum::environment::load(p, scene.sanitize)?,
        None => (splitsum::environment::embedded_default()?, Default::default()),
    };
    let identity = splitsum::environment::identity(env_path.as_deref())?;
    let plan = crate::plan::plan_for(scene, &env, cal)?;
    let plan_json = serde_json::to_string(&(&plan.job, scene.sanitize)).expect("serialisable");
    let key = splitsum::cache::key(&identity, &plan_json, &backend.identity());
    let mut outcome = if force { Outcome::Forced } else { Outcome::Baked };
    // Held until this bake is stored: a concurrent run of the same key waits, then hits.
    let _lock = cache.map(|c| c.lock(&key)).transpose()?;
    if let (Some(c), false) = (cache, force) {
        match c.get(&key) {
            splitsum::cache::Lookup::Hit(env) => return Ok(SceneBake { plan, env: *env, key, outcome: Outcome::CacheHit, timings: Vec::new() }),
            splitsum::cache::Lookup::Miss => {}
            splitsum::cache::Lookup::Rejected(why) => outcome = Outcome::Rebuilt(std::sync::Arc::new(why)),
            splitsum::cache::Lookup::Foreign(e) => return Err(e),
        }
    }
    check_duration(&splitsum::estimate::step_seconds(&plan.job, backend.is_gpu()), force)?;
    let (baked, timings) = bake_plan(backend, &env, &plan)?;
    if let Some(c) = cache {
        c.put(&key, &baked)?;
    }
    Ok(SceneBake { plan, env: baked, key, outcome, timings })
}
