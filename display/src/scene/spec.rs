//! The scene file's tables as typed specs (serde, every field with its default): materials,
//! objects, lights, camera, quality, output and display.

use serde::{Deserialize, Serialize};
use splitsum::settings::named;
use splitsum_shaders::shade::{DiffuseModel, FresnelForm, ShadeOptions, SpecularModel};
use splitsum_shaders::tonemap::Tonemapper;
use std::path::PathBuf;

/// A material parameter: a constant, a range `[a, b]` (the values the material takes
/// somewhere, e.g. over a sphere grid or a texture), or `"texture"` (anything in [0, 1]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Param {
    /// One value.
    Value(f32),
    /// Every value in `[a, b]`.
    Range([f32; 2]),
    /// From a texture: `"texture"`.
    Texture(String),
}

impl MaterialSpec {
    /// Whether the material has a sheen layer (a sheen colour above black).
    pub fn has_sheen(&self) -> bool {
        self.sheen_color.iter().any(|&c| c > 0.0)
    }
}

impl Param {
    /// The range of values `[lo, hi]`.
    pub fn range(&self) -> (f32, f32) {
        match self {
            Param::Value(v) => (*v, *v),
            Param::Range([a, b]) => (*a, *b),
            Param::Texture(_) => (0.0, 1.0),
        }
    }
}

/// A material.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// Its name, for objects to refer to.
    pub name: String,
    /// Base colour (linear RGB).
    #[serde(default = "default_base")]
    pub base_color: [f32; 3],
    /// Metalness.
    #[serde(default = "zero")]
    pub metallic: Param,
    /// Perceptual roughness.
    #[serde(default = "half")]
    pub roughness: Param,
    /// Sheen colour (linear RGB; `KHR_materials_sheen`'s `sheenColorFactor`): black, the
    /// default, is no sheen. A sphere grid of a material with sheen gets a sheen row below
    /// its metalness rows.
    #[serde(default)]
    pub sheen_color: [f32; 3],
    /// Sheen roughness (`sheenRoughnessFactor`, perceptual; the lobe's `α` is its square),
    /// along the sheen row's columns where it is a range.
    #[serde(default = "zero")]
    pub sheen_roughness: Param,
    /// Diffuse model.
    #[serde(default, with = "named")]
    pub diffuse: DiffuseModel,
    /// Specular model.
    #[serde(default, with = "named")]
    pub specular: SpecularModel,
    /// Fresnel form.
    #[serde(default, with = "named")]
    pub fresnel: FresnelForm,
    /// Lit by the environment (image-based light).
    #[serde(default = "yes")]
    pub ibl: bool,
    /// Read the prefiltered cube along the mirror direction (see [`ShadingChoices`]).
    #[serde(default)]
    pub mirror_direction: bool,
    /// Multiple-scattering energy compensation.
    #[serde(default)]
    pub multiscatter: bool,
    /// Filtered importance sampling below mip 1's roughness.
    #[serde(default)]
    pub filtered: bool,
    /// Smith–Schlick instead of the exact Smith term for direct lights.
    #[serde(default)]
    pub smith_schlick: bool,
    /// Blend between mips linearly instead of in log luminance (see [`ShadingChoices`]).
    #[serde(default)]
    pub linear_mip_blend: bool,
    /// Read without lifting the read direction above the horizon (see [`ShadingChoices`]).
    #[serde(default)]
    pub no_horizon_lift: bool,
    /// The common roughness-aware Fresnel weights instead of the exact ones (see
    /// [`ShadingChoices`]).
    #[serde(default)]
    pub roughness_fresnel: bool,
    /// Prefiltered fetches per pixel of the shading ladder: 1, 2, 4, 8 or 16 (see
    /// [`ShadingChoices`]).
    #[serde(default = "one")]
    pub fetches: u32,
}

/// The shading options a user chooses beside the models, with their defaults: the
/// prefiltered cube read along the dominant direction, lifted above the horizon, blended between mips in log
/// luminance, single scattering, no filtered sampling, the exact Smith term for direct
/// lights. The one place their flags are made,
/// and (with the `cli` feature) the command line's flags themselves; a scene file spells
/// them as fields of its materials.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
pub struct ShadingChoices {
    /// Read the prefiltered cube along the mirror direction (the seed's choice) instead of
    /// the specular dominant direction.
    #[cfg_attr(feature = "cli", arg(long))]
    pub mirror_direction: bool,
    /// Multiple-scattering energy compensation of the image-based specular (Fdez-Agüera 2019).
    #[cfg_attr(feature = "cli", arg(long))]
    pub multiscatter: bool,
    /// Quality mode: filtered importance sampling at shading time below mip 1's roughness.
    #[cfg_attr(feature = "cli", arg(long))]
    pub filtered: bool,
    /// Smith–Schlick (UE4's `k = (r+1)²/8`) for direct lights instead of the exact
    /// height-correlated Smith term (the image-based light follows the table's own model,
    /// `--lut-masking`).
    #[cfg_attr(feature = "cli", arg(long))]
    pub smith_schlick: bool,
    /// Blend the two mips a roughness falls between linearly (the seed's choice) instead of
    /// in log luminance.
    #[cfg_attr(feature = "cli", arg(long))]
    pub linear_mip_blend: bool,
    /// Read the prefiltered cube along the read direction as it is, even where the lobe
    /// round it reaches under the surface's horizon, instead of lifting it above
    /// (`shade::above_horizon`).
    #[cfg_attr(feature = "cli", arg(long))]
    pub no_horizon_lift: bool,
    /// Weight the image-based light with the common roughness-aware Fresnel
    /// (`F·A + B`, diffuse `1 − F`) instead of the glTF BRDF's exact integrals (`F₀·A + B`,
    /// diffuse `(1 − 0.04)(1 − C(n·v))`; `shade::ambient_diffuse_weight`).
    #[cfg_attr(feature = "cli", arg(long))]
    pub roughness_fresnel: bool,
    /// Prefiltered fetches per pixel: 1 is the split sum; 2, 4, 8 or 16 follow the true
    /// specular lobe at grazing views (the shading ladder, `shade::lobe_radiance`), at that
    /// many fetches' cost. `runner report` measures each rung's error against its cost.
    #[cfg_attr(feature = "cli", arg(long, default_value_t = 1, value_parser = fetch_count))]
    pub fetches: u32,
}

/// `fetches` if it is a rung of the ladder (a power of two up to `shade::MAX_FETCHES`, as
/// `ShadeOptions::with_fetches` encodes them), else what is wrong with it (for `--fetches`
/// and the scene field `fetches`).
pub fn check_fetches(fetches: u32) -> std::result::Result<u32, String> {
    if fetches.is_power_of_two() && fetches <= splitsum_shaders::shade::MAX_FETCHES {
        return Ok(fetches);
    }
    let rungs: Vec<String> = (0..splitsum_shaders::shade::LADDER_RUNGS).map(|k| (1u32 << k).to_string()).collect();
    let (last, rest) = rungs.split_last().expect("the ladder has rungs");
    Err(format!("must be one of {} or {last} (the shading ladder's rungs), not {fetches}", rest.join(", ")))
}

#[cfg(feature = "cli")]
fn fetch_count(s: &str) -> std::result::Result<u32, String> {
    check_fetches(s.parse::<u32>().map_err(|e| format!("{s:?}: {e}"))?)
}

impl ShadingChoices {
    /// `ShadeOptions` flags for these choices, with image-based and direct light as given.
    pub fn flags(&self, ibl: bool, direct: bool) -> u32 {
        let mut f = 0;
        let mut set = |on: bool, bit: u32| {
            if on {
                f |= bit;
            }
        };
        set(ibl, ShadeOptions::IBL);
        set(direct, ShadeOptions::DIRECT);
        set(!self.mirror_direction, ShadeOptions::DOMINANT_DIRECTION);
        set(self.multiscatter, ShadeOptions::MULTISCATTER);
        set(self.filtered, ShadeOptions::FILTERED_SAMPLING);
        set(!self.smith_schlick, ShadeOptions::CORRELATED_SMITH);
        set(!self.linear_mip_blend, ShadeOptions::LOG_MIP_BLEND);
        set(!self.no_horizon_lift, ShadeOptions::LIFT_ABOVE_HORIZON);
        set(self.roughness_fresnel, ShadeOptions::ROUGHNESS_FRESNEL);
        ShadeOptions { flags: f, ..ShadeOptions::DEFAULT }.with_fetches(self.fetches).flags
    }
}

fn default_base() -> [f32; 3] {
    [0.9, 0.45, 0.2]
}
fn zero() -> Param {
    Param::Value(0.0)
}
fn half() -> Param {
    Param::Value(0.5)
}
fn yes() -> bool {
    true
}
fn one() -> u32 {
    1
}

impl MaterialSpec {
    /// The shader options of this material (direct lights on).
    pub fn options(&self) -> ShadeOptions {
        ShadeOptions {
            diffuse: self.diffuse as u32,
            specular: self.specular as u32,
            fresnel: self.fresnel as u32,
            flags: ShadingChoices {
                mirror_direction: self.mirror_direction,
                multiscatter: self.multiscatter,
                filtered: self.filtered,
                smith_schlick: self.smith_schlick,
                linear_mip_blend: self.linear_mip_blend,
                no_horizon_lift: self.no_horizon_lift,
                roughness_fresnel: self.roughness_fresnel,
                fetches: self.fetches,
            }
            .flags(self.ibl, true),
        }
    }
}

/// An object of the scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum ObjectSpec {
    /// The sphere grid: metalness over the rows, roughness over the columns, in the
    /// material's ranges.
    SphereGrid {
        /// Material name.
        material: String,
        /// Rows.
        #[serde(default = "rows")]
        rows: u32,
        /// Columns.
        #[serde(default = "columns")]
        columns: u32,
    },
    /// A glTF 2.0 model; its roughness and metalness are clamped to the material's ranges.
    Gltf {
        /// The `.gltf`/`.glb` file, relative to the scene file.
        path: PathBuf,
        /// Material name (models and ranges).
        material: String,
    },
}

fn rows() -> u32 {
    5
}
fn columns() -> u32 {
    7
}

impl ObjectSpec {
    /// The material's name.
    pub fn material(&self) -> &str {
        match self {
            ObjectSpec::SphereGrid { material, .. } | ObjectSpec::Gltf { material, .. } => material,
        }
    }
}

/// A direct light.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum LightSpec {
    /// A distant light.
    Directional {
        /// Towards the light.
        direction: [f32; 3],
        /// Radiance arriving.
        radiance: [f32; 3],
    },
    /// A point light.
    Point {
        /// Position.
        position: [f32; 3],
        /// Radiance at distance 1.
        intensity: [f32; 3],
    },
}

/// The image to produce.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
}

impl Default for OutputSpec {
    fn default() -> Self {
        Self { width: 960, height: 540 }
    }
}

/// The camera, in degrees.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CameraSpec {
    /// Orbit angle.
    pub yaw: f32,
    /// Elevation.
    pub pitch: f32,
    /// Vertical field of view.
    pub fov: f32,
    /// Distance from the target [default: framing the objects].
    pub distance: Option<f32>,
    /// The point looked at [default: framing the objects].
    pub target: Option<[f32; 3]>,
}

impl Default for CameraSpec {
    fn default() -> Self {
        Self { yaw: 0.0, pitch: 0.0, fov: 45.0, distance: None, target: None }
    }
}

/// The quality asked for.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct QualitySpec {
    /// Largest acceptable mean error per product (relative for radiance, absolute for the
    /// table): the planner picks the cheapest measured settings that meet it.
    pub max_error: Option<f64>,
    /// A time budget for the bake in seconds, on lavapipe's built-in rates
    /// (`cost::Calibration`): the planner picks the measured settings (samples, irradiance
    /// source) with the lowest predicted error over the roughness the scene reads that fit.
    pub max_seconds: Option<f64>,
    /// GGX samples per specular texel.
    pub samples: Option<u32>,
    /// Source-mip bias.
    pub lod_bias: Option<f32>,
    /// Width of the BRDF table.
    pub lut_size: Option<u32>,
    /// Samples per texel of the BRDF table.
    pub lut_samples: Option<u32>,
    /// Face size of the source level the irradiance sums over.
    pub irradiance_source: Option<u32>,
    /// Face size of mip 0 of the specular cube [default: from the output and the
    /// smallest roughness].
    pub size: Option<u32>,
}

/// How the frame is shown.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DisplaySpec {
    /// Exposure in stops over the automatic one.
    pub exposure: f32,
    /// Tone curve.
    #[serde(with = "named")]
    pub tonemapper: Tonemapper,
}
