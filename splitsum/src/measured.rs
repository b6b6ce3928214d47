//! What `runner report` measures, typed: one row of error against run time
//! ([`Measurement`]), the product it measures, the method, the part of the error, the knob
//! swept and its value in numeric columns. `report.csv` is these rows through serde, and
//! [`crate::cost::Calibration`] reads them back by their columns: no label is parsed.

use serde::{Deserialize, Serialize};

/// What is measured.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Quantity {
    /// The BRDF table at its texel centres.
    BrdfTable,
    /// The BRDF table read bilinearly between texel centres.
    BrdfTableLookup,
    /// One level of the prefiltered cube against the exact prefiltered radiance.
    Prefilter,
    /// The irradiance (convolution or SH9) against the exact `E/π`.
    Irradiance,
    /// The shaded colour against the full reflectance integral.
    ShadedColour,
    /// The prefiltered radiance a renderer reads at any roughness (the mips blended).
    PrefilteredLookup,
    /// What shading a pixel costs (`ns_per_pixel`) at a rung of the shading ladder
    /// (`fetches`); its errors are the shaded colour's rows of the same rung.
    ShadingCost,
}

impl Quantity {
    /// Its name in the report.
    pub fn title(self) -> &'static str {
        match self {
            Quantity::BrdfTable => "BRDF table",
            Quantity::BrdfTableLookup => "BRDF table, bilinear lookup",
            Quantity::Prefilter => "prefiltered cube",
            Quantity::Irradiance => "irradiance",
            Quantity::ShadedColour => "shaded colour",
            Quantity::PrefilteredLookup => "prefiltered lookup, any roughness",
            Quantity::ShadingCost => "shading cost per pixel",
        }
    }
}

/// How it was made: the seed's method (splitsum's first bake), today's defaults, and the
/// alternatives measured beside them.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// The seed: six linear mips, 1024 GGX samples at bias 0.5, the sampled table.
    Seed,
    /// `Settings::default()` and the default shading.
    Defaults,
    /// The defaults, reading along the mirror direction (no dominant direction).
    MirrorDirection,
    /// The defaults with multiple-scattering compensation.
    MultipleScattering,
    /// The defaults with filtered sampling of the lookup.
    FilteredSampling,
    /// The defaults with a Smith–Schlick table.
    SmithSchlickTable,
    /// The defaults, blending between mips linearly (before the log-luminance blend).
    LinearMipBlend,
    /// The defaults, reading without lifting the read direction above the horizon.
    NoHorizonLift,
    /// The defaults with the common ambient weights, `F·A + B` and `1 − F` with the
    /// roughness-aware Fresnel `F` (`ShadeOptions::ROUGHNESS_FRESNEL`; the default before
    /// the exact weights).
    RoughnessFresnel,
    /// The defaults with the shading ladder's `fetches` prefiltered fetches per pixel.
    Ladder,
    /// The Khronos and Bevy targets' levels (roughness `m/(M−1)`, `⌊log₂ size⌋` mips) read
    /// as their engines read them: trilinear, linear between mips, at mip `r·(M−1)`.
    KhronosBevyLookup,
    /// The Filament target's levels (`1 − √(1 − m/(M−1))`, down to 16²) read as Filament
    /// reads them: trilinear at mip `(M−1)·r(2 − r)`.
    FilamentLookup,
    /// SH9 in place of the irradiance convolution.
    Sh9,
    /// The split sum from exact ingredients: the error of the approximation itself.
    ExactIngredients,
    /// The settings `estimate::for_budget` chooses for a time budget (`budget_s`) on the
    /// backend, and the default shading.
    TimeBudget,
}

impl Method {
    /// Its name in the report.
    pub fn title(self) -> &'static str {
        match self {
            Method::Seed => "seed method",
            Method::Defaults => "defaults",
            Method::MirrorDirection => "defaults, mirror direction",
            Method::MultipleScattering => "defaults + multiple scattering",
            Method::FilteredSampling => "defaults + filtered sampling",
            Method::SmithSchlickTable => "defaults, Smith-Schlick table",
            Method::LinearMipBlend => "defaults, linear mip blend",
            Method::NoHorizonLift => "defaults, read not lifted above the horizon",
            Method::RoughnessFresnel => "defaults, roughness-aware Fresnel weights",
            Method::Ladder => "shading ladder",
            Method::KhronosBevyLookup => "khronos/bevy target, engine's trilinear read",
            Method::FilamentLookup => "filament target, engine's trilinear read",
            Method::Sh9 => "SH9",
            Method::ExactIngredients => "exact ingredients (split sum alone)",
            Method::TimeBudget => "settings for a time budget",
        }
    }
}

/// Which part of the error a row holds (for the shaded colour: the total splits into
/// the bake's, the split sum's and the shading model's shares).
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Part {
    /// Against the truth.
    Total,
    /// (a) the baked products against exact ingredients.
    Bake,
    /// (b) the split sum from exact ingredients against the full integral of its model.
    SplitSum,
    /// (c) the model's masking (Smith–Schlick) against exact Smith.
    Model,
}

/// The knob a row's series sweeps.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Knob {
    /// Samples per texel (`samples`).
    Samples,
    /// The table's or the cube's size (`size`).
    Size,
    /// The prefilter's source-mip bias (`bias`).
    Bias,
    /// The source level summed (`source_size`).
    SourceSize,
    /// A whole quality level (`samples` holds its sample count).
    Quality,
    /// Prefiltered fetches per shaded pixel (`fetches`).
    Fetches,
    /// A time budget per bake (`budget_s`).
    Budget,
    /// Nothing: one measurement.
    None,
}

/// Which set of environments a row belongs to: choices are made on the tuning set and
/// confirmed on the held-out set, which no choice looked at.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Set {
    /// Environments the defaults may be chosen on.
    Tuning,
    /// Environments no choice looked at.
    HeldOut,
}

splitsum_shaders::choice!(Set: Tuning => "tuning", HeldOut => "held-out");

impl Set {
    /// Its name in the report.
    pub fn title(self) -> &'static str {
        match self {
            Set::Tuning => "tuning set",
            Set::HeldOut => "held-out set",
        }
    }
}

/// What the errors measure; both are relative.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Metric {
    /// `|L(got) − L(want)| / L(want)`, `L` the luminance.
    RelativeLuminance,
    /// The BRDF table's directional albedo `F₀·A + B`, relative, the larger of `F₀ = 0.04`
    /// and `F₀ = 1`.
    RelativeAlbedo,
}

/// One measurement: a product made by a method on a backend, with the swept knob's value
/// in its own column, its wall time and its errors.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Measurement {
    /// What is measured.
    pub product: Quantity,
    /// How it was made.
    pub method: Method,
    /// Which part of the error.
    pub part: Part,
    /// The knob its series sweeps.
    pub knob: Knob,
    /// `gpu` or `cpu`; empty where nothing ran on a backend.
    pub backend: String,
    /// The backend's adapter and driver, or the CPU's threads.
    pub device: String,
    /// The environment measured on (empty for the report's own).
    pub environment: String,
    /// The set the environment belongs to, for the measure over sets.
    pub set: Option<Set>,
    /// Samples per texel (of specular mip 1, for a bake).
    pub samples: Option<u32>,
    /// The table's or the cube's face size.
    pub size: Option<u32>,
    /// Face size of the source level summed.
    pub source_size: Option<u32>,
    /// Source-mip bias of the prefilter.
    pub bias: Option<f32>,
    /// Prefiltered fetches per shaded pixel (the shading ladder's rung).
    pub fetches: Option<u32>,
    /// Shading time per pixel in nanoseconds (the shading ladder, timed on a frame).
    pub ns_per_pixel: Option<f64>,
    /// The time budget per bake in seconds the settings were chosen for
    /// (`Method::TimeBudget`).
    #[serde(default)]
    pub budget_s: Option<f64>,
    /// The estimated seconds of the settings chosen for `budget_s`.
    #[serde(default)]
    pub estimate_s: Option<f64>,
    /// Roughness band `[lo, hi)` of the points (or the level's roughness, `lo = hi`).
    pub roughness_lo: Option<f32>,
    /// Upper end of the roughness band.
    pub roughness_hi: Option<f32>,
    /// `n·v` band `(lo, hi]` of the shading points.
    pub nv_lo: Option<f32>,
    /// Upper end of the `n·v` band.
    pub nv_hi: Option<f32>,
    /// Lookups within 10° of the brightest texel (`true`), elsewhere (`false`), or all.
    pub near_sun: Option<bool>,
    /// Wall time of the bake or step in milliseconds (`None` for a row that shares a
    /// bake's time with the row above it, or where nothing ran).
    pub time_ms: Option<f64>,
    /// Mean error.
    pub mean_error: f64,
    /// Largest error.
    pub max_error: f64,
    /// What the errors measure.
    pub metric: Metric,
}

impl Measurement {
    /// A row of `product` by `method` from its `errors` (their mean and largest), every
    /// knob column empty: set them with struct update syntax.
    pub fn of(product: Quantity, method: Method, errors: &[f64], metric: Metric) -> Self {
        let mean_error = errors.iter().sum::<f64>() / errors.len().max(1) as f64;
        let max_error = errors.iter().copied().fold(0.0, f64::max);
        Self {
            product,
            method,
            part: Part::Total,
            knob: Knob::None,
            backend: String::new(),
            device: String::new(),
            environment: String::new(),
            set: None,
            samples: None,
            size: None,
            source_size: None,
            bias: None,
            fetches: None,
            ns_per_pixel: None,
            budget_s: None,
            estimate_s: None,
            roughness_lo: None,
            roughness_hi: None,
            nv_lo: None,
            nv_hi: None,
            near_sun: None,
            time_ms: None,
            mean_error,
            max_error,
            metric,
        }
    }

    /// What sets it apart in a table: the knobs that have values, in words.
    pub fn setting(&self) -> String {
        let mut parts = Vec::new();
        if let Some(n) = self.samples {
            parts.push(format!("{n} samples"));
        }
        if let Some(s) = self.size {
            parts.push(format!("{s}x{s}"));
        }
        if let Some(s) = self.source_size {
            parts.push(format!("{s}x{s} source"));
        }
        if let Some(b) = self.bias {
            parts.push(format!("bias {b}"));
        }
        if let Some(b) = self.budget_s {
            parts.push(format!("budget {b} s"));
        }
        match self.fetches {
            Some(1) => parts.push("1 fetch".into()),
            Some(k) => parts.push(format!("{k} fetches")),
            None => {}
        }
        if parts.is_empty() { "-".into() } else { parts.join(", ") }
    }
}

/// Reads `report.csv`'s rows.
pub fn read_csv(text: &str) -> Result<Vec<Measurement>, csv::Error> {
    csv::Reader::from_reader(text.as_bytes()).deserialize().collect()
}

/// Writes rows as `report.csv` does.
pub fn write_csv<W: std::io::Write>(w: W, rows: &[Measurement]) -> Result<(), csv::Error> {
    let mut out = csv::Writer::from_writer(w);
    for r in rows {
        out.serialize(r)?;
    }
    out.flush()?;
    Ok(())
}
