//! Scene files, the bake planner and the cache: each rule leaves out exactly what it should,
//! a render from the reduced bake equals the render from a full bake, unchanged bakes come
//! from the cache, and corrupt or foreign entries are rebuilt, never used.

use splitsum::Backend;
use splitsum::Product;
use splitsum::reading::BakedEnvironment;
use splitsum::cache::{Cache, Lookup, Rejection};
use splitsum::cost::Calibration;
use splitsum::environment::Environment;
use splitsum::settings::{InputShape, Products};
use splitsum_display::plan::{self, Cause, Plan, Subject};
use splitsum_display::prepare::{self as bake, Outcome};
use splitsum_display::scene::{Problem, Scene};
use splitsum_shaders::glam::Vec4;
use splitsum_shaders::scene::Frame;
use std::path::{Path, PathBuf};

fn assets() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../assets")
}

/// A scene over the vendored courtyard, with `body` (materials, objects, quality …) after
/// the top-level keys in `head`.
fn scene(head: &str, body: &str) -> Scene {
    let env = support::environment_path("courtyard");
    let text = format!("environment = {:?}\n{head}\n{body}", env.display().to_string());
    Scene::parse(&text).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

fn material(name: &str, fields: &str) -> String {
    format!("[[materials]]\nname = {name:?}\n{fields}\n\n[[objects]]\nkind = \"sphere-grid\"\nmaterial = {name:?}\n")
}

/// A material on the glTF torus (a scene draws one sphere grid and one model).
fn model(name: &str, fields: &str) -> String {
    let torus = concat!(env!("CARGO_MANIFEST_DIR"), "/../display/assets/torus.glb");
    format!("[[materials]]\nname = {name:?}\n{fields}\n\n[[objects]]\nkind = \"gltf\"\npath = {torus:?}\nmaterial = {name:?}\n")
}

/// The plan over a 256² environment of width 1024 (the vendored ones).
fn planned(s: &Scene) -> Plan {
    plan::plan(s, 256, InputShape::Equirect { width: 1024, height: 512 }, &Calibration::default()).unwrap()
}

fn skipped(p: &Plan, subject: Subject) -> bool {
    p.decisions.iter().any(|d| !d.kept && d.subject == subject)
}

#[test]
fn a_full_scene_keeps_everything() {
    let p = planned(&scene("", &material("all", "metallic = [0.0, 1.0]\nroughness = [0.0, 1.0]")));
    assert_eq!((p.job.products.has(Product::Specular), p.job.products.has(Product::BrdfTable), p.job.products.has(Product::Irradiance)), (true, true, true));
    assert_eq!(p.job.prefiltered[&Product::Specular].levels, (0..p.job.mips).collect::<Vec<_>>());
    assert_eq!(p.job.size, 256, "roughness 0 needs the environment's full resolution");
    assert!(!p.job.products.has(Product::Sh9), "the display reads the irradiance cube, not SH9");
    assert!((p.cost.cpu_seconds - p.full_cost.cpu_seconds).abs() < 1e-9);
}

/// Sheen is baked only for a lit material with a sheen colour, and only the mips its
/// sheen roughness reads (linear: lod = r·(M − 1)), or for a glTF model whose file uses
/// `KHR_materials_sheen`; a scene without sheen does no sheen work: no sheen step runs in
/// its bake, no sheen product is made.
#[test]
fn sheen_is_baked_only_where_a_material_has_it() {
    let plain = planned(&scene("", &material("plain", "roughness = [0.2, 0.6]")));
    assert!(!plain.job.products.has(Product::Sheen) && skipped(&plain, Subject::Sheen));
    let env = Environment::Equirect(support::environment("courtyard"));
    let baked = splitsum::bake::bake_job(&Backend::Cpu, &env, &plain.job).unwrap();
    assert!(baked.cube(Product::Sheen).is_none() && baked.table(Product::SheenTables).is_none());
    assert!(!baked.timings.iter().any(|t| matches!(t.step, Product::Sheen | Product::SheenTables)), "{:?}", baked.timings);
    let black = planned(&scene("", &material("black", "sheen_color = [0.0, 0.0, 0.0]\nsheen_roughness = 0.5")));
    assert!(!black.job.products.has(Product::Sheen), "a black sheen colour is no sheen");
    let unlit = planned(&scene("", &material("unlit", "ibl = false\nsheen_color = [1.0, 1.0, 1.0]")));
    assert!(!unlit.job.products.has(Product::Sheen), "a material not lit by the environment reads no sheen cube");
    // A glTF model whose file has KHR_materials_sheen needs the sheen cube, every mip.
    let dir = std::env::temp_dir().join(format!("splitsum-plan-sheen-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let glb = dir.join("velvet.glb");
    std::fs::write(&glb, support::model::sample_glb_with(Some(serde_json::json!({"KHR_materials_sheen": {"sheenColorFactor": [0.5, 0.5, 0.5]}})))).unwrap();
    let text = format!(
        "[[materials]]\nname = \"m\"\nroughness = \"texture\"\nmetallic = \"texture\"\n\n[[objects]]\nkind = \"gltf\"\npath = {:?}\nmaterial = \"m\"\n",
        glb.display().to_string()
    );
    let p = planned(&scene("", &text));
    assert!(p.job.products.has(Product::Sheen) && p.job.prefiltered[&Product::Sheen].levels == (0..p.job.mips).collect::<Vec<_>>(), "{:?}", p.decisions);
    let torus = planned(&scene("", &model("m", "roughness = \"texture\"\nmetallic = \"texture\"")));
    assert!(!torus.job.products.has(Product::Sheen), "the torus has no sheen");
    let _ = std::fs::remove_dir_all(&dir);
    let velvet = planned(&scene("", &material("velvet", "sheen_color = [0.8, 0.2, 0.2]\nsheen_roughness = [0.3, 0.5]")));
    assert!(velvet.job.products.has(Product::Sheen));
    let top = (velvet.job.mips - 1) as f32;
    let want: Vec<u32> = ((0.3 * top).floor() as u32..=(0.5 * top).ceil() as u32).collect();
    assert_eq!(velvet.job.prefiltered[&Product::Sheen].levels, want, "the sheen mips around sheen roughness 0.3–0.5 of {} mips", velvet.job.mips);
}

#[test]
fn no_specular_image_light_drops_the_prefilter_and_the_table() {
    for fields in ["specular = \"none\"", "specular = \"none\"\ndiffuse = \"oren-nayar\""] {
        let p = planned(&scene("", &material("clay", fields)));
        assert!(
            !p.job.products.has(Product::Specular) && !p.job.products.has(Product::BrdfTable) && p.job.products.has(Product::Irradiance),
            "{fields}: {p:?}"
        );
        assert!(p.job.prefiltered[&Product::Specular].levels.is_empty());
        assert!(skipped(&p, Subject::SpecularCube) && skipped(&p, Subject::BrdfTable));
        assert!(p.cost.cpu_seconds < p.full_cost.cpu_seconds);
    }
}

#[test]
fn a_blurred_sky_keeps_only_the_mips_it_reads() {
    let p = planned(&scene("sky_blur = 2.5", &material("clay", "specular = \"none\"")));
    assert!(p.job.products.has(Product::Specular) && !p.job.products.has(Product::BrdfTable));
    assert_eq!(p.job.prefiltered[&Product::Specular].levels, vec![2, 3]);
}

#[test]
fn only_metals_drop_the_irradiance() {
    let p = planned(&scene("", &material("steel", "metallic = 1.0\nroughness = [0.0, 1.0]")));
    assert!(p.job.products.has(Product::Specular) && p.job.products.has(Product::BrdfTable) && !p.job.products.has(Product::Irradiance));
    assert!(skipped(&p, Subject::IrradianceCube));
    // A metalness range that reaches below 1 needs it again.
    let p = planned(&scene("", &material("alloy", "metallic = [0.9, 1.0]")));
    assert!(p.job.products.has(Product::Irradiance));
}

#[test]
fn a_roughness_range_keeps_the_mips_around_it() {
    // The geometric mapping on the 64² cube this range asks for: M = 4 mips, α of mip m ≥ 1
    // is 2^(−4(3−m)/2), lod = 1 + 2(log₂α + 4)/4 above α₁ = 1/16. r = 0.4 (α = 0.16) reads
    // lod 1.68 and r = 0.7 (α = 0.49) lod 2.49: mips 1, 2 and 3 (trilinear filtering's
    // upper neighbour).
    let p = planned(&scene("", &material("steel", "metallic = 1.0\nroughness = [0.4, 0.7]")));
    assert_eq!(p.job.mips, 4);
    assert_eq!(p.job.prefiltered[&Product::Specular].levels, vec![1, 2, 3]);
    assert!(skipped(&p, Subject::SpecularMips));
    // A single roughness: 0.6 (α = 0.36) on a 32² cube (M = 3) reads lod 1 + (log₂0.36 + 3)/3
    // = 1.51: mips 1 and 2.
    let p = planned(&scene("", &material("satin", "roughness = 0.6")));
    assert_eq!((p.job.size, p.job.prefiltered[&Product::Specular].levels.clone()), (32, vec![1, 2]));
    // Two materials: the union of their mips. r = 0.2 needs the 256² cube (M = 6, lod 1.90);
    // r = 0.85 and 0.9 read lod 4.69 and 4.80.
    let two = format!("{}{}", material("a", "roughness = 0.2"), model("b", "roughness = [0.85, 0.9]"));
    assert_eq!(planned(&scene("", &two)).job.prefiltered[&Product::Specular].levels, vec![1, 2, 4, 5]);
}

#[test]
fn phong_and_blinn_phong_need_no_ggx_table() {
    for model in ["phong", "blinn-phong"] {
        let p = planned(&scene("", &material("plastic", &format!("specular = {model:?}\nroughness = [0.2, 0.6]"))));
        assert!(p.job.products.has(Product::Specular) && p.job.products.has(Product::Irradiance) && !p.job.products.has(Product::BrdfTable), "{model}");
        assert!(skipped(&p, Subject::BrdfTable));
    }
    // One Cook–Torrance material among them brings it back.
    let two = format!("{}{}", material("a", "specular = \"phong\""), model("b", "specular = \"cook-torrance\""));
    assert!(planned(&scene("", &two)).job.products.has(Product::BrdfTable));
}

#[test]
fn a_scene_draws_every_object_or_is_refused() {
    // Two grids, or two models, cannot all be drawn: refused by the field, not drawn in part.
    let env = support::environment_path("courtyard");
    for two in [format!("{}{}", material("a", ""), material("b", "")), format!("{}{}", model("a", ""), model("b", ""))] {
        let text = format!("environment = {:?}\n{two}", env.display().to_string());
        let e = Scene::parse(&text).expect_err("refused");
        assert!(matches!(e, Problem::TooManyObjects { count: 2, .. }), "{e}");
    }
    // A grid and a model, each with its own material and options.
    let s = scene("", &format!("{}{}", material("a", "specular = \"phong\""), model("b", "roughness = 0.5")));
    let view = s.view(1.0);
    let m = s.model().unwrap().expect("the model");
    assert!(view.spheres && view.show_model);
    assert_eq!(view.options.specular, splitsum_shaders::shade::SpecularModel::Phong as u32);
    assert!(m.primitives.iter().all(|p| p.material.options.specular == splitsum_shaders::shade::SpecularModel::CookTorrance as u32));
}

#[test]
fn no_image_light_bakes_nothing() {
    for body in [material("unlit", "ibl = false"), String::new()] {
        let p = planned(&scene("", &body));
        assert!(
            !p.job.products.has(Product::Specular)
                && !p.job.products.has(Product::BrdfTable)
                && !p.job.products.has(Product::Irradiance)
                && !p.job.products.has(Product::Sh9)
        );
        assert!(p.job.prefiltered[&Product::Specular].levels.is_empty());
        assert!(skipped(&p, Subject::Everything));
    }
}

#[test]
fn the_smallest_roughness_and_the_output_set_the_cube_size() {
    // Roughness ≥ 0.4 (α = 0.16): half its lobe, 0.08 rad, needs a texel of at most 0.08 rad
    // in the mip it reads. On a 32² cube (M = 3) it reads lod 1.12, mip 1 of 16² (texel
    // π/2 / 16 = 0.098: too coarse); on a 64² cube (M = 4) lod 1.68, mip 1 of 32² (0.049).
    let p = planned(&scene("", &material("steel", "metallic = 1.0\nroughness = [0.4, 0.7]")));
    assert_eq!(p.job.size, 64);
    // Rougher still: r ≥ 0.8, half its lobe 0.32 rad. An 8² cube (M = 2: the mirror and
    // r = 1) reads mip 1 of 4² (0.39 rad, too coarse); a 16² cube mip 1 of 8² (0.196 rad).
    let p = planned(&scene("", &material("rough", "roughness = [0.8, 1.0]")));
    assert_eq!(p.job.size, 16);
    // A mirror needs a pixel's resolution, capped by the environment's own.
    let mirror = material("mirror", "metallic = 1.0\nroughness = 0.0");
    assert_eq!(planned(&scene("", &mirror)).job.size, 256);
    assert_eq!(plan::plan(&scene("", &mirror), 64, InputShape::Equirect { width: 256, height: 128 }, &Calibration::default()).unwrap().job.size, 64);
    // A tiny output: 30 pixels over 45° are 0.026 rad each; mip 0 of a 64² cube has
    // texels of 0.0245 rad, of a 32² cube 0.049 rad.
    let tiny = scene("[output]\nwidth = 30\nheight = 30", &mirror);
    assert_eq!(planned(&tiny).job.size, 64);
    // [quality] size overrides.
    assert_eq!(planned(&scene("", &format!("{mirror}\n[quality]\nsize = 32"))).job.size, 32);
}

#[test]
fn a_maximum_error_picks_the_cheapest_settings_that_meet_it() {
    let body = material("plastic", "roughness = [0.3, 1.0]");
    let loose = planned(&scene("", &format!("{body}\n[quality]\nmax_error = 0.1")));
    let tight = planned(&scene("", &format!("{body}\n[quality]\nmax_error = 0.05")));
    // Loose, from the built-in end-to-end table (the bake's share of the shaded colour's
    // error, worse of city and courtyard): r ∈ [0.3, 1] reads the bands around 0.3, 0.425,
    // 0.625, 0.875 and 1; 16 samples at mip 1 give at most 0.0998 (at r 0.2–0.35). The
    // irradiance: the 4² level (0.035). The table is by quadrature (within 1e-5), whatever
    // the target.
    assert_eq!((loose.job.samples, loose.job.irradiance_source), (16, 4));
    assert_eq!(loose.job.lut_method, splitsum::settings::TableMethod::Quadrature);
    // Tight: no measured count reaches 0.05 at r 0.2–0.35 (256 give 0.0596: mip
    // interpolation, not sampling, is what is left), and the plan says so; the irradiance
    // from 4² still meets it (0.035).
    assert_eq!((tight.job.samples, tight.job.irradiance_source), (256, 4));
    let strict = planned(&scene("", &format!("{body}\n[quality]\nmax_error = 0.01")));
    // At 0.01 the irradiance needs the 16² level (0.0067; 8² gives 0.0181).
    assert_eq!(strict.job.irradiance_source, 16);
    assert_eq!(tight.job.lut_method, splitsum::settings::TableMethod::Quadrature);
    // A sample count in the scene asks for the sampled table.
    let sampled = planned(&scene("", &format!("{body}\n[quality]\nlut_samples = 64")));
    assert_eq!((sampled.job.lut_method, sampled.job.lut_samples), (splitsum::settings::TableMethod::Sampled, 64));
    assert!(tight.decisions.iter().any(|d| d.subject == Subject::PrefilterSamples && matches!(d.cause, Cause::MostAccurate { .. })));
    assert!(tight.cost.cpu_seconds > 2.0 * loose.cost.cpu_seconds);
    // Fixed settings are kept as given.
    let fixed = planned(&scene("", &format!("{body}\n[quality]\nmax_error = 0.05\nsamples = 77")));
    assert_eq!(fixed.job.samples, 77);
}

#[test]
fn the_calibration_reads_a_report() {
    let dir = temp("calibration");
    let env = assets().join("environments/studio.exr");
    runner::cli::run(["runner", "report", env.to_str().unwrap(), "--quick", "--backends", "cpu", "--out", dir.to_str().unwrap()]).expect("report");
    let cal = Calibration::from_report_csv(&std::fs::read_to_string(dir.join("report.csv")).unwrap()).expect("a calibration");
    // The quick sweep's irradiance sources, and the defaults' three sample counts in every
    // roughness band, read from their columns.
    assert_eq!(cal.irradiance.iter().map(|r| r.0).collect::<Vec<_>>(), vec![4, 8, 16]);
    assert!(cal.irradiance.iter().all(|r| r.1.is_finite() && r.1 > 0.0));
    assert!(!cal.prefilter.is_empty());
    for (_, by_samples) in &cal.prefilter {
        assert_eq!(by_samples.iter().map(|r| r.0).collect::<Vec<_>>(), vec![16, 64, 256]);
    }
    assert!(Calibration::from_report_csv("product,backend\nnothing,here\n").is_none());
}

// --- Reduced bake against full bake -------------------------------------------------------

/// Small, fast settings for the equality tests.
const QUICK: &str = "[quality]\nsize = 32\nsamples = 32\nlut_size = 16\nlut_samples = 32\nirradiance_source = 8";

fn environment() -> Environment {
    splitsum::environment::load(&support::environment_path("courtyard"), false).unwrap().0
}

/// The plan's bake and the full bake at the same settings (every product, every mip).
fn reduced_and_full(s: &Scene, env: &Environment) -> (Plan, BakedEnvironment, BakedEnvironment) {
    let p = plan::plan_for(s, env, &Calibration::default()).unwrap();
    let (reduced, _) = bake::bake_plan(&Backend::Cpu, env, &p).unwrap();
    let mut all = p.clone();
    all.job = p.job.given.resolve(InputShape::of(env), Products::ALL).unwrap();
    let (full, _) = bake::bake_plan(&Backend::Cpu, env, &all).unwrap();
    (p, reduced, full)
}

fn render(s: &Scene, env: &BakedEnvironment, backend: &Backend) -> Vec<Vec4> {
    let view = s.view(env.auto_exposure());
    let mut frame = view.frame(env.shape(), 96, 54, true);
    frame.flags |= Frame::LINEAR;
    let model = s.model().unwrap();
    splitsum_display::render::render(backend, env, &frame, model.as_ref()).unwrap()
}

fn max_abs(a: &[Vec4], b: &[Vec4]) -> f32 {
    assert_eq!(a.len(), b.len());
    a.iter().zip(b).map(|(x, y)| (*x - *y).abs().max_element()).fold(0.0, f32::max)
}

#[test]
fn renders_from_reduced_bakes_equal_renders_from_full_bakes() {
    let env = environment();
    let torus = assets().join("../display/assets/torus.glb");
    let cases = [
        ("metals", String::new(), material("steel", "metallic = 1.0\nroughness = [0.4, 0.7]\nbase_color = [0.9, 0.9, 0.9]")),
        ("clay", String::new(), material("clay", "specular = \"none\"\ndiffuse = \"oren-nayar\"\nroughness = 0.8")),
        ("phong", String::new(), material("plastic", "specular = \"blinn-phong\"\nroughness = [0.2, 0.6]")),
        ("blurred sky", "sky_blur = 1.5".to_string(), material("clay", "specular = \"none\"")),
        (
            "textured model",
            String::new(),
            format!(
                "{}\n[[objects]]\nkind = \"gltf\"\npath = {:?}\nmaterial = \"torus\"\n[[materials]]\nname = \"torus\"\nmetallic = \"texture\"\nroughness = [0.5, 0.9]\n",
                material("steel", "metallic = 1.0\nroughness = [0.5, 0.9]"),
                torus.display().to_string()
            ),
        ),
    ];
    let gpu = support::gpu();
    for (name, head, body) in cases {
        let s = scene(&head, &format!("{body}\n{QUICK}\n[[lights]]\nkind = \"directional\"\ndirection = [0.3, 1.0, 0.5]\nradiance = [2.0, 2.0, 2.0]"));
        let (p, reduced, full) = reduced_and_full(&s, &env);
        let left_out = !(p.job.products.has(Product::Specular) && p.job.products.has(Product::BrdfTable) && p.job.products.has(Product::Irradiance))
            || p.job.prefiltered[&Product::Specular].levels.len() < p.job.mips as usize;
        assert!(left_out, "{name}: the plan should leave something out");
        let cpu = max_abs(&render(&s, &reduced, &Backend::Cpu), &render(&s, &full, &Backend::Cpu));
        let lava = max_abs(&render(&s, &reduced, gpu), &render(&s, &full, gpu));
        println!(
            "{name}: levels {:?} of {}, products {:?}: reduced vs full, CPU {cpu:e}, GPU {lava:e}",
            p.job.prefiltered[&Product::Specular].levels,
            p.job.mips,
            p.job.products
        );
        assert_eq!(cpu, 0.0, "{name}: the reduced bake changed the CPU render");
        assert!(lava <= 1e-6, "{name}: the reduced bake changed the GPU render by {lava}");
    }
}

// --- The cache ----------------------------------------------------------------------------

fn temp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("splitsum-plan-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn same(a: &BakedEnvironment, b: &BakedEnvironment) -> bool {
    a.cube(Product::SourceCube).texels == b.cube(Product::SourceCube).texels
        && a.cube(Product::Specular).texels == b.cube(Product::Specular).texels
        && a.cube(Product::Irradiance).texels == b.cube(Product::Irradiance).texels
        && a.table(Product::BrdfTable).texels == b.table(Product::BrdfTable).texels
}

fn entry_file(dir: &Path, key: &str, name: &str) -> PathBuf {
    dir.join(key).join(name)
}

#[test]
fn the_cache_reuses_unchanged_bakes_and_rebuilds_bad_entries() {
    let dir = temp("cache");
    let cache = Cache::new(&dir);
    let cal = Calibration::default();
    let s = scene("", &format!("{}\n{QUICK}", material("steel", "metallic = 1.0\nroughness = [0.4, 0.7]")));
    let first = bake::bake_scene(&Backend::Cpu, &s, &cal, Some(&cache), false).unwrap();
    assert_eq!(first.outcome, Outcome::Baked);
    assert!(!first.timings.is_empty());
    let second = bake::bake_scene(&Backend::Cpu, &s, &cal, Some(&cache), false).unwrap();
    assert_eq!(second.outcome, Outcome::CacheHit);
    assert!(second.timings.is_empty() && second.key == first.key && same(&first.env, &second.env));
    // --force bakes again.
    assert_eq!(bake::bake_scene(&Backend::Cpu, &s, &cal, Some(&cache), true).unwrap().outcome, Outcome::Forced);

    // Any parameter changes the key: a sample count, the roughness range, the backend.
    let more =
        scene("", &format!("{}\n{}", material("steel", "metallic = 1.0\nroughness = [0.4, 0.7]"), QUICK.replace("samples = 32\nlut", "samples = 33\nlut")));
    let other = bake::bake_scene(&Backend::Cpu, &more, &cal, Some(&cache), false).unwrap();
    assert_eq!(other.outcome, Outcome::Baked);
    assert_ne!(other.key, first.key);
    let k = |env: &[u8], plan: &str, backend: &str| splitsum::cache::key(env, plan, backend);
    assert_ne!(k(b"abc", "{}", "cpu"), k(b"abd", "{}", "cpu"), "a byte of the input");
    assert_ne!(k(b"abc", "{}", "cpu"), k(b"abc", "{}", "gpu"), "the backend");
    assert_ne!(k(b"ab", "c{}", "cpu"), k(b"abc", "{}", "cpu"), "the parts are length-delimited");

    // A corrupt entry: one flipped byte in a product.
    let spec = entry_file(&dir, &first.key, "specular.bin");
    let mut bytes = std::fs::read(&spec).unwrap();
    let mid = bytes.len() / 2;
    bytes[mid] ^= 0x40;
    std::fs::write(&spec, &bytes).unwrap();
    match cache.get(&first.key) {
        Lookup::Rejected(why) => assert!(matches!(why, Rejection::WrongHash("specular.bin")), "{why}"),
        _ => panic!("a corrupt entry must be rejected"),
    }
    assert_eq!(bake::bake_scene(&Backend::Cpu, &s, &cal, Some(&cache), false).unwrap().outcome, Outcome::Baked, "a rejected entry is removed");
    // A truncated product, found by the bake itself.
    let lut = entry_file(&dir, &first.key, "lut.bin");
    let mut bytes = std::fs::read(&lut).unwrap();
    bytes.truncate(bytes.len() - 3);
    std::fs::write(&lut, &bytes).unwrap();
    let rebuilt = bake::bake_scene(&Backend::Cpu, &s, &cal, Some(&cache), false).unwrap();
    assert!(matches!(&rebuilt.outcome, Outcome::Rebuilt(why) if matches!(**why, Rejection::WrongSize { name: "lut.bin", .. })), "{:?}", rebuilt.outcome);
    assert!(same(&rebuilt.env, &first.env), "the rebuilt bake is the bake");
    assert_eq!(bake::bake_scene(&Backend::Cpu, &s, &cal, Some(&cache), false).unwrap().outcome, Outcome::CacheHit);

    // A foreign entry: another bake's folder under this key.
    let _ = std::fs::remove_dir_all(dir.join(&first.key));
    copy_dir(&dir.join(&other.key), &dir.join(&first.key));
    let r = bake::bake_scene(&Backend::Cpu, &s, &cal, Some(&cache), false).unwrap();
    assert!(matches!(&r.outcome, Outcome::Rebuilt(why) if matches!(**why, Rejection::Foreign { .. })), "{:?}", r.outcome);
    assert!(same(&r.env, &first.env));

    // A manifest that is not JSON, and an entry with no manifest.
    std::fs::write(entry_file(&dir, &first.key, "manifest.json"), "{ not json").unwrap();
    assert!(matches!(cache.get(&first.key), Lookup::Rejected(Rejection::MalformedManifest(_))));
    std::fs::create_dir_all(dir.join(&first.key)).unwrap();
    assert!(matches!(cache.get(&first.key), Lookup::Rejected(Rejection::NoManifest(_))));
    assert!(matches!(cache.get(&first.key), Lookup::Miss), "a rejected entry is removed");

    // An entry that also holds a file the cache did not write is never removed: the bake
    // fails, naming it, and the file stays.
    bake::bake_scene(&Backend::Cpu, &s, &cal, Some(&cache), false).unwrap();
    std::fs::write(entry_file(&dir, &first.key, "specular.bin"), b"corrupt").unwrap();
    std::fs::write(entry_file(&dir, &first.key, "notes.txt"), b"mine").unwrap();
    let e = bake::bake_scene(&Backend::Cpu, &s, &cal, Some(&cache), false).err().expect("a foreign file in the entry").to_string();
    assert!(e.contains("notes.txt") && e.contains("did not write"), "{e}");
    assert_eq!(std::fs::read(entry_file(&dir, &first.key, "notes.txt")).unwrap(), b"mine");
    // A manifest that claims a product far larger than its file: refused by size, unread.
    std::fs::remove_file(entry_file(&dir, &first.key, "notes.txt")).unwrap();
    let manifest = entry_file(&dir, &first.key, "manifest.json");
    let mut m: serde_json::Value = serde_json::from_slice(&std::fs::read(&manifest).unwrap()).unwrap();
    m["files"]["specular.bin"]["bytes"] = serde_json::json!(1u64 << 40);
    std::fs::write(&manifest, serde_json::to_vec(&m).unwrap()).unwrap();
    assert!(matches!(cache.get(&first.key), Lookup::Rejected(Rejection::WrongSize { name: "specular.bin", bytes: 7, .. })));
    let _ = std::fs::remove_dir_all(&dir);
}

/// The cache trusts nothing it finds (issue 31): an entry that is a link to a folder of
/// the user's holding files named as the cache names its own is refused and nothing
/// behind it removed; a lock file planted as a link to a file elsewhere is not followed
/// (the file is neither created nor opened).
#[test]
fn the_cache_follows_no_link_it_finds() {
    let dir = temp("cache-links");
    let cache = Cache::new(&dir);
    let cal = Calibration::default();
    let s = scene("", &format!("{}\n{QUICK}", material("steel", "metallic = 1.0\nroughness = [0.4, 0.7]")));
    let key = bake::bake_scene(&Backend::Cpu, &s, &cal, Some(&cache), false).unwrap().key;
    // The user's folder, with files named as an entry's.
    let mine = temp("cache-links-mine");
    std::fs::create_dir_all(&mine).unwrap();
    for name in ["manifest.json", "specular.bin"] {
        std::fs::write(mine.join(name), b"mine").unwrap();
    }
    std::fs::remove_dir_all(dir.join(&key)).unwrap();
    std::os::unix::fs::symlink(&mine, dir.join(&key)).unwrap();
    let e = bake::bake_scene(&Backend::Cpu, &s, &cal, Some(&cache), false).err().expect("a linked entry").to_string();
    assert!(e.contains("symbolic link"), "{e}");
    for name in ["manifest.json", "specular.bin"] {
        assert_eq!(std::fs::read(mine.join(name)).unwrap(), b"mine", "{name} behind the link");
    }
    std::fs::remove_file(dir.join(&key)).unwrap();
    // A planted lock link to a file that does not exist yet.
    let elsewhere = mine.join("created-through-the-lock");
    let _ = std::fs::remove_file(dir.join(format!("{key}.lock")));
    std::os::unix::fs::symlink(&elsewhere, dir.join(format!("{key}.lock"))).unwrap();
    let e = bake::bake_scene(&Backend::Cpu, &s, &cal, Some(&cache), false).err().expect("a linked lock").to_string();
    assert!(e.contains("cache lock"), "{e}");
    assert!(!elsewhere.exists(), "the lock link was followed");
    let _ = std::fs::remove_dir_all(&dir);
    let _ = std::fs::remove_dir_all(&mine);
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        std::fs::copy(e.path(), to.join(e.file_name())).unwrap();
    }
}

// --- Scene files and the command line -------------------------------------------------------

fn load_error(text: &str) -> String {
    let dir = temp("scene-errors");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("bad.toml");
    std::fs::write(&path, text).unwrap();
    let e = Scene::load(&path).expect_err(text).to_string();
    assert!(e.contains("bad.toml"), "the error must name the file: {e}");
    e
}

#[test]
fn scene_errors_name_the_file_and_the_problem() {
    assert!(load_error("[output]\nwidth = 64\nheigth = 64\n").contains("heigth"));
    let e = load_error("[[materials]]\nname = \"a\"\nroughness = 0.5\nroughness = 0.6\n");
    assert!(e.contains("line 4"), "{e}");
    assert!(load_error("[[objects]]\nkind = \"sphere-grid\"\nmaterial = \"gold\"\n").contains("\"gold\""));
    assert!(load_error("[[materials]]\nname = \"a\"\nroughness = [0.7, 0.2]\n").contains("roughness range"));
    assert!(load_error("[[materials]]\nname = \"a\"\nmetallic = \"wood\"\n").contains("metallic"));
    assert!(load_error("[[materials]]\nname = \"a\"\nspecular = \"ward\"\n").contains("ward"));
    assert!(load_error("[quality]\nmax_error = -1.0\n").contains("max_error"));
    let e = load_error("[[materials]]\nname = \"a\"\nfetches = 3\n");
    assert!(e.contains("fetches") && e.contains("1, 2, 4, 8 or 16"), "{e}");
    assert!(load_error("[[objects]]\nkind = \"teapot\"\n").contains("teapot"));
    // The same checks, typed, as `Scene::parse` returns them.
    let parsed = |text: &str| Scene::parse(text).expect_err(text);
    assert!(matches!(parsed("[[objects]]\nkind = \"sphere-grid\"\nmaterial = \"gold\"\n"), Problem::UndefinedMaterial(m) if m == "gold"));
    assert!(matches!(parsed("[[materials]]\nname = \"a\"\nroughness = [0.7, 0.2]\n"), Problem::Range { key: "roughness", range: (0.7, 0.2), .. }));
    assert!(matches!(parsed("[[materials]]\nname = \"a\"\nmetallic = \"wood\"\n"), Problem::NotAParameter { key: "metallic", .. }));
    assert!(matches!(parsed("[quality]\nmax_error = -1.0\n"), Problem::MaxError(_)));
    assert!(matches!(parsed("[[materials]]\nname = \"a\"\nfetches = 3\n"), Problem::Fetches { .. }));
    assert!(matches!(parsed("[output]\nwidth = 64\nheigth = 64\n"), Problem::Syntax(_)));
    let missing = std::env::temp_dir().join("splitsum-no-such-scene.toml");
    assert!(Scene::load(&missing).unwrap_err().to_string().contains("splitsum-no-such-scene.toml"));
}

#[test]
fn the_example_scenes_plan_and_a_scene_bake_is_cached() {
    let scenes = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenes");
    for name in ["showroom", "brushed-metal", "matte-clay", "retro-phong", "unlit"] {
        let path = scenes.join(format!("{name}.toml"));
        runner::cli::run(["runner", "plan", path.to_str().unwrap()]).unwrap_or_else(|e| panic!("{name}: {e:#}"));
    }
    // bake --scene twice: the second is a cache hit and rewrites the same files.
    let dir = temp("scene-bake");
    let cache = dir.join("cache");
    let out = dir.join("out");
    let file = dir.join("small.toml");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(&file, format!("{}\n{QUICK}", material("steel", "metallic = 1.0\nroughness = [0.4, 0.7]"))).unwrap();
    let args = ["runner", "bake", "--scene", file.to_str().unwrap(), "--backend", "cpu", "--cache", cache.to_str().unwrap(), "--out", out.to_str().unwrap()];
    runner::cli::run(args).expect("first bake");
    let plan_json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out.join("plan.json")).unwrap()).unwrap();
    assert!(!plan_json["plan"]["job"]["products"].as_array().unwrap().iter().any(|p| p == "irradiance"), "{}", plan_json["plan"]["job"]["products"]);
    assert!(out.join("specular.ktx2").exists() && out.join("brdf_lut.exr").exists());
    assert!(!out.join("irradiance.ktx2").exists(), "left-out products are not written");
    // specular.ktx2 holds mips 1 … 2 of the 32² cube (M = 3: r = 0, √⅛, 1; r ∈ [0.4, 0.7]
    // reads lod 1.12 … 1.66): a 16² cube with two mips.
    let ktx = std::fs::read(out.join("specular.ktx2")).unwrap();
    let reader = ktx2::Reader::new(&ktx[..]).expect("a KTX2 file");
    let h = reader.header();
    assert_eq!((h.pixel_width, h.face_count, h.level_count), (16, 6, 2));
    let r: Vec<f64> = plan_json["specular_roughness_per_mip"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
    assert!(r.len() == 2 && r.iter().zip([0.125f64.sqrt(), 1.0]).all(|(a, b)| (a - b).abs() < 1e-6), "{r:?}");
    // The scene sets the quality: a quality flag beside --scene is refused, not ignored.
    let mut with_flag = args.to_vec();
    with_flag.extend(["--samples", "128"]);
    let e = runner::cli::run(with_flag).expect_err("--samples with --scene");
    assert!(format!("{e:#}").contains("[quality]"), "{e:#}");
    let entries = std::fs::read_dir(&cache).unwrap().count();
    runner::cli::run(args).expect("second bake");
    assert_eq!(std::fs::read_dir(&cache).unwrap().count(), entries, "no new cache entry");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The time-budget planner (`splitsum::estimate::for_budget`) on a fixed machine: a larger
/// budget never predicts a larger error, every choice whose estimate fits is within its
/// budget, and a budget below every candidate gets the cheapest (stated as over). The
/// machine's rates are the calibration kernel's on lavapipe here (rounded), fixed so the
/// test does not time anything.
#[test]
fn a_larger_budget_never_predicts_more_error() {
    use splitsum::cost::Machine;
    use splitsum::estimate::for_budget;
    use splitsum::estimate::{Estimator, Rates};
    let machine = Machine { filtered_reads: 0.25e9, summed_reads: 0.75e9, flops: 18e9 };
    let estimator = Estimator::new(machine, true, Rates::Measured { seconds: 0.0 });
    let shape = splitsum::InputShape::Equirect { width: 1024, height: 512 };
    let settings = splitsum::Settings::default();
    let cal = Calibration::default();
    let mut last = f64::INFINITY;
    let mut cheapest = f64::INFINITY;
    for budget in [0.01, 0.1, 0.3, 0.5, 1.0, 2.0, 10.0] {
        let (chosen, error, seconds) = for_budget(&settings, shape, splitsum::Products::ALL, budget, &estimator, &cal).expect("a choice");
        println!("budget {budget}: {} samples, irradiance {:?}, error {error:.4}, estimate {seconds:.3}", chosen.samples, chosen.irradiance_source);
        assert!(error <= last + 1e-12, "budget {budget}: error {error} above the smaller budget's {last}");
        cheapest = cheapest.min(seconds);
        assert!(seconds <= budget || seconds <= cheapest + 1e-12, "budget {budget}: {seconds} s neither fits nor is the cheapest");
        last = error;
    }
}

/// `[quality] max_seconds`: the planner picks, over the roughness the scene reads, the
/// measured settings with the lowest predicted error whose estimate (lavapipe's built-in
/// rates, the levels the plan keeps) fits; a larger budget never predicts more error, the
/// estimate of a choice that fits is within the budget, and the choice is stated. Beside a
/// setting it would choose, or not a positive number, it is refused by the field's name.
#[test]
fn a_time_budget_picks_the_lowest_predicted_error_that_fits() {
    let body = material("plastic", "roughness = [0.3, 1.0]");
    let plan_for = |b: f64| planned(&scene("", &format!("{body}\n[quality]\nmax_seconds = {b}")));
    let predicted = |p: &Plan| p.decisions.iter().find(|d| d.subject == Subject::TimeBudget).map(|d| d.cause.clone()).expect("the budget's decision is stated");
    let mut last = f64::INFINITY;
    for budget in [0.01, 0.2, 0.5, 1.0, 5.0] {
        let p = plan_for(budget);
        let why = predicted(&p);
        let Cause::Budget { error, estimate, .. } = why else { panic!("the budget's cause: {why:?}") };
        println!("budget {budget}: {} samples, irradiance {}: {why}", p.job.samples, p.job.irradiance_source);
        assert!(error <= last + 1e-12, "budget {budget}: {error} above the smaller budget's {last}");
        // A choice over the budget is the cheapest measured, and says so.
        assert!(
            p.cost.gpu_seconds <= budget || (estimate > budget && why.to_string().contains("cheapest")),
            "budget {budget}: estimated {} s: {why}",
            p.cost.gpu_seconds
        );
        last = error;
    }
    for (extra, field) in [("max_error = 0.1", "max_error"), ("samples = 64", "samples"), ("irradiance_source = 16", "irradiance_source")] {
        let text = format!("environment = \"x.exr\"\n{body}\n[quality]\nmax_seconds = 0.5\n{extra}");
        let e = Scene::parse(&text).expect_err("refused");
        assert!(matches!(e, Problem::BudgetAndSetting(f) if f == field), "{e}");
    }
    let e = Scene::parse(&format!("environment = \"x.exr\"\n{body}\n[quality]\nmax_seconds = -1")).expect_err("refused");
    assert!(matches!(e, Problem::MaxSeconds(b) if b == -1.0), "{e}");
}
