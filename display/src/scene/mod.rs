//! Scene files (TOML): the environment, materials, objects, lights, camera, output size and
//! quality target that `runner plan`, `bake --scene`, `view --scene` and `render --scene`
//! read. Every problem is reported with the file it is in (and the line, for syntax).
//!
//! ```toml
//! environment = "assets/environments/city.exr"   # relative to this file; omit for the embedded one
//! sky_blur = 0.0                                  # the sky behind the scene, in specular mips
//!
//! [output]
//! width = 1280
//! height = 720
//!
//! [camera]                                        # degrees; distance and target optional
//! yaw = 20.0
//! pitch = 10.0
//! fov = 45.0
//!
//! [quality]                                       # every field optional
//! max_error = 0.02                                # mean error per product: the planner picks the cheapest settings
//! # max_seconds = 0.3                             # or a time budget: the lowest predicted error that fits
//! samples = 1024                                  # or fix them
//!
//! [[materials]]
//! name = "gold"
//! base_color = [1.0, 0.78, 0.34]
//! metallic = 1.0                                  # a number, a range [a, b], or "texture"
//! roughness = [0.3, 0.6]
//! diffuse = "lambert"                             # lambert | oren-nayar | fresnel-weighted
//! specular = "cook-torrance"                      # cook-torrance | phong | blinn-phong | none
//! fresnel = "schlick"                             # schlick | spherical-gaussian
//! ibl = true
//!
//! [[objects]]
//! kind = "sphere-grid"                            # metalness over the rows, roughness over the columns
//! material = "gold"
//!
//! [[objects]]
//! kind = "gltf"
//! path = "models/torus.glb"
//! material = "gold"                               # models, and ranges the textures are clamped to
//!
//! [[lights]]
//! kind = "directional"
//! direction = [-0.5, 0.8, 0.6]
//! radiance = [3.0, 3.0, 3.0]
//! ```

mod problem;
mod spec;
pub use problem::Problem;
pub use spec::{CameraSpec, DisplaySpec, LightSpec, MaterialSpec, ObjectSpec, OutputSpec, Param, QualitySpec, ShadingChoices, check_fetches};

use serde::{Deserialize, Serialize};
use splitsum::error::{Error, Result};
use std::path::{Path, PathBuf};

/// A scene file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// The environment, relative to the scene file [default: the embedded courtyard].
    pub environment: Option<PathBuf>,
    /// Replace NaN/∞ texels instead of refusing the environment.
    #[serde(default)]
    pub sanitize: bool,
    /// Blur of the sky behind the scene, in specular mips (0: the sharp source).
    #[serde(default)]
    pub sky_blur: f32,
    /// The image.
    #[serde(default)]
    pub output: OutputSpec,
    /// The camera.
    #[serde(default)]
    pub camera: CameraSpec,
    /// The quality.
    #[serde(default)]
    pub quality: QualitySpec,
    /// The display transform.
    #[serde(default)]
    pub display: DisplaySpec,
    /// Materials.
    #[serde(default)]
    pub materials: Vec<MaterialSpec>,
    /// Objects.
    #[serde(default)]
    pub objects: Vec<ObjectSpec>,
    /// Direct lights.
    #[serde(default)]
    pub lights: Vec<LightSpec>,
    /// The folder the scene file is in (paths are relative to it).
    #[serde(skip)]
    pub dir: PathBuf,
}

/// The largest scene file read (a scene is a few hundred bytes of TOML).
pub const MAX_SCENE_BYTES: u64 = 1 << 20;

impl Scene {
    /// Reads and checks a scene file.
    pub fn load(path: &Path) -> Result<Self> {
        let text = splitsum::files::read_text(path, MAX_SCENE_BYTES)?;
        let mut scene = Self::parse(&text).map_err(|e| Error::Invalid(format!("{}: {e}", path.display())))?;
        scene.dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        Ok(scene)
    }

    /// Parses and checks scene text (paths relative to the current folder).
    pub fn parse(text: &str) -> std::result::Result<Self, Problem> {
        let scene: Scene = toml::from_str(text).map_err(Problem::Syntax)?;
        scene.check()?;
        Ok(scene)
    }

    fn check(&self) -> std::result::Result<(), Problem> {
        for m in &self.materials {
            if let Err(problem) = check_fetches(m.fetches) {
                return Err(Problem::Fetches { material: m.name.clone(), problem });
            }
            for (what, p) in [("metallic", &m.metallic), ("roughness", &m.roughness)] {
                if let Param::Texture(t) = p
                    && t != "texture"
                {
                    return Err(Problem::NotAParameter { material: m.name.clone(), key: what, text: t.clone() });
                }
                let (a, b) = p.range();
                if !(0.0..=1.0).contains(&a) || !(0.0..=1.0).contains(&b) || a > b {
                    return Err(Problem::Range { material: m.name.clone(), key: what, range: (a, b) });
                }
            }
        }
        for o in &self.objects {
            if !self.materials.iter().any(|m| m.name == o.material()) {
                return Err(Problem::UndefinedMaterial(o.material().to_string()));
            }
        }
        // The display draws one sphere grid and one glTF model, each with its own material;
        // a scene that lists more is refused rather than drawn in part.
        let grids = self.objects.iter().filter(|o| matches!(o, ObjectSpec::SphereGrid { .. })).count();
        let models = self.objects.iter().filter(|o| matches!(o, ObjectSpec::Gltf { .. })).count();
        for (n, kind) in [(grids, "sphere-grid"), (models, "gltf")] {
            if n > 1 {
                return Err(Problem::TooManyObjects { count: n, kind });
            }
        }
        if self.output.width == 0 || self.output.height == 0 || self.output.width > 8192 || self.output.height > 8192 {
            return Err(Problem::OutputSize(self.output.width, self.output.height));
        }
        if !(self.camera.fov > 1.0 && self.camera.fov < 170.0) {
            return Err(Problem::FieldOfView(self.camera.fov));
        }
        if let Some(e) = self.quality.max_error
            && !(e > 0.0)
        {
            return Err(Problem::MaxError(e));
        }
        if let Some(b) = self.quality.max_seconds {
            if !(b > 0.0 && b.is_finite()) {
                return Err(Problem::MaxSeconds(b));
            }
            for (set, field) in [
                (self.quality.max_error.is_some(), "max_error"),
                (self.quality.samples.is_some(), "samples"),
                (self.quality.irradiance_source.is_some(), "irradiance_source"),
            ] {
                if set {
                    return Err(Problem::BudgetAndSetting(field));
                }
            }
        }
        // The [quality] fields that are bake settings go through the one validation,
        // `Settings::validate`, which names them as the scene does.
        let q = &self.quality;
        let d = splitsum::Settings::default();
        let settings = splitsum::Settings {
            size: q.size.unwrap_or(d.size),
            samples: q.samples.unwrap_or(d.samples),
            lut_samples: q.lut_samples.unwrap_or(d.lut_samples),
            lut_size: q.lut_size.unwrap_or(d.lut_size),
            irradiance_source: q.irradiance_source,
            lod_bias: q.lod_bias.unwrap_or(d.lod_bias),
            ..d
        };
        match settings.validate() {
            Err(splitsum::Error::Setting { field, problem }) => return Err(Problem::Setting { field, problem }),
            Err(e) => return Err(Problem::Refused(e)),
            Ok(()) => {}
        }
        Ok(())
    }

    /// The material called `name`.
    pub fn material(&self, name: &str) -> &MaterialSpec {
        self.materials.iter().find(|m| m.name == name).expect("checked when loading")
    }

    /// The materials objects use, each once, in order.
    pub fn used_materials(&self) -> Vec<&MaterialSpec> {
        let mut out: Vec<&MaterialSpec> = Vec::new();
        for o in &self.objects {
            let m = self.material(o.material());
            if !out.iter().any(|x| x.name == m.name) {
                out.push(m);
            }
        }
        out
    }

    /// A path of the scene, relative to the scene file.
    pub fn resolve(&self, p: &Path) -> PathBuf {
        if p.is_absolute() { p.to_path_buf() } else { self.dir.join(p) }
    }
}

impl Scene {
    /// The view of this scene: camera, direct lights, its sphere grid (a scene has at most
    /// one, `check`) with its material, exposure and tone curve.
    pub fn view(&self, auto_exposure: f32) -> crate::render::ViewState {
        use splitsum_shaders::glam::{Vec3, Vec4};
        let grid = self.objects.iter().find_map(|o| match o {
            ObjectSpec::SphereGrid { material, rows, columns } => Some((self.material(material), *rows, *columns)),
            ObjectSpec::Gltf { .. } => None,
        });
        let model = self.objects.iter().find_map(|o| match o {
            ObjectSpec::Gltf { material, .. } => Some(self.material(material)),
            ObjectSpec::SphereGrid { .. } => None,
        });
        let mut v = crate::render::ViewState {
            yaw: self.camera.yaw.to_radians(),
            pitch: self.camera.pitch.to_radians(),
            fov: self.camera.fov.to_radians(),
            exposure: auto_exposure * 2f32.powf(self.display.exposure),
            tonemapper: self.display.tonemapper,
            sky_blur: self.sky_blur,
            spheres: grid.is_some(),
            show_model: model.is_some(),
            lights: self
                .lights
                .iter()
                .map(|l| match l {
                    LightSpec::Directional { direction, radiance } => splitsum_shaders::scene::Light {
                        position: Vec3::from(*direction).normalize_or(Vec3::Y).extend(0.0),
                        radiance: Vec3::from(*radiance).extend(0.0),
                    },
                    LightSpec::Point { position, intensity } => {
                        splitsum_shaders::scene::Light { position: Vec3::from(*position).extend(1.0), radiance: Vec3::from(*intensity).extend(0.0) }
                    }
                })
                .collect(),
            ..Default::default()
        };
        if let Some((m, rows, columns)) = grid {
            let (m0, m1) = m.metallic.range();
            let (r0, r1) = m.roughness.range();
            v.grid = (rows.max(1), columns.max(1));
            v.grid_ranges = Vec4::new(m0, m1, r0, r1);
            v.sheen_color = Vec3::from(m.sheen_color);
            v.sheen_ranges = m.sheen_roughness.range();
            v.base_color = Vec3::from(m.base_color);
            v.options = m.options();
        } else if let Some(m) = model {
            v.options = m.options();
        }
        v.frame_contents();
        if let Some(d) = self.camera.distance {
            v.distance = d;
        }
        if let Some(t) = self.camera.target {
            v.target = Vec3::from(t);
        }
        v
    }

    /// The path of the scene's glTF model, if it has one (resolved against the scene file).
    pub fn model_path(&self) -> Option<PathBuf> {
        self.objects.iter().find_map(|o| match o {
            ObjectSpec::Gltf { path, .. } => Some(self.resolve(path)),
            ObjectSpec::SphereGrid { .. } => None,
        })
    }

    /// The scene's glTF model (at most one, `check`), with its material's models and
    /// ranges, placed beside the grid (or where the camera frames it alone).
    pub fn model(&self) -> Result<Option<crate::model::Model>> {
        let Some((path, material)) = self.objects.iter().find_map(|o| match o {
            ObjectSpec::Gltf { path, material } => Some((path, self.material(material))),
            ObjectSpec::SphereGrid { .. } => None,
        }) else {
            return Ok(None);
        };
        let mut m = crate::model::load(&self.resolve(path))?;
        m.set_material(material.options(), material.roughness.range(), material.metallic.range());
        let (centre, size) = crate::model::PLACE_BESIDE_GRID;
        m.fit(centre, size);
        Ok(Some(m))
    }
}
