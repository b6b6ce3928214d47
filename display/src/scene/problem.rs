//! What is wrong with a scene file, as a type ([`Problem`]): each check of
//! `Scene::check` one variant, in the file's own terms (its tables and keys), rendered to
//! words only where it is shown.

use splitsum::settings::Field;

/// A scene file that cannot be used, and why.
#[derive(Debug)]
pub enum Problem {
    /// Not TOML of a scene's form (a misspelt key, a repeated one, a wrong type); the
    /// parser's error names the line.
    Syntax(toml::de::Error),
    /// A material's `fetches` is not a rung of the shading ladder.
    Fetches {
        /// The material.
        material: String,
        /// Why, in words (`check_fetches`).
        problem: String,
    },
    /// A material's `metallic` or `roughness` names something other than `"texture"`.
    NotAParameter {
        /// The material.
        material: String,
        /// `metallic` or `roughness`.
        key: &'static str,
        /// What it says.
        text: String,
    },
    /// A material's range is outside `[0, 1]` or reversed.
    Range {
        /// The material.
        material: String,
        /// `metallic` or `roughness`.
        key: &'static str,
        /// The range given.
        range: (f32, f32),
    },
    /// An object names a material no `[[materials]]` entry defines.
    UndefinedMaterial(String),
    /// More than one object of a kind (the display draws one grid and one model).
    TooManyObjects {
        /// How many.
        count: usize,
        /// Their kind (`sphere-grid`, `gltf`).
        kind: &'static str,
    },
    /// `[output]` size outside `1..8192`.
    OutputSize(u32, u32),
    /// `[camera] fov` outside `(1, 170)` degrees.
    FieldOfView(f32),
    /// `[quality] max_error` not positive.
    MaxError(f64),
    /// `[quality] max_seconds` not a positive number.
    MaxSeconds(f64),
    /// `[quality] max_seconds` beside a setting it would choose.
    BudgetAndSetting(&'static str),
    /// A `[quality]` bake setting out of its range (the one validation, `Settings::validate`).
    Setting {
        /// The setting.
        field: Field,
        /// What is wrong with its value.
        problem: String,
    },
    /// Any other refusal of the one validation.
    Refused(splitsum::Error),
}

impl std::fmt::Display for Problem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Problem::Syntax(e) => write!(f, "not a valid scene: {e}"),
            Problem::Fetches { material, problem } => write!(f, "material {material:?}: fetches {problem}"),
            Problem::NotAParameter { material, key, text } => write!(f, "material {material:?}: {key} must be a number, [a, b] or \"texture\", not {text:?}"),
            Problem::Range { material, key, range: (a, b) } => write!(f, "material {material:?}: {key} range [{a}, {b}] must lie in [0, 1] with a ≤ b"),
            Problem::UndefinedMaterial(m) => write!(f, "an object uses material {m:?}, which no [[materials]] entry defines"),
            Problem::TooManyObjects { count, kind } => write!(
                f,
                "[[objects]] lists {count} objects of kind {kind:?}; the display draws one sphere grid and one glTF model a scene, each with its own material: give the others scenes of their own"
            ),
            Problem::OutputSize(w, h) => write!(f, "[output] must be 1..8192 pixels each way, not {w}×{h}"),
            Problem::FieldOfView(fov) => write!(f, "[camera] fov must be between 1 and 170 degrees, not {fov}"),
            Problem::MaxError(e) => write!(f, "[quality] max_error must be positive, not {e}"),
            Problem::MaxSeconds(b) => write!(f, "[quality] max_seconds must be a positive number of seconds, not {b}"),
            Problem::BudgetAndSetting(field) => write!(f, "[quality] max_seconds chooses the settings itself: give it or {field}, not both"),
            Problem::Setting { field, problem } => write!(f, "[quality] {field} {problem}"),
            Problem::Refused(e) => write!(f, "[quality] {e}"),
        }
    }
}

impl std::error::Error for Problem {}

/// A scene's problem where a splitsum error is expected: a request refused as written.
impl From<Problem> for splitsum::Error {
    fn from(p: Problem) -> Self {
        splitsum::Error::Invalid(p.to_string())
    }
}
