//! One row of an error-against-time measurement, and the error metrics the report and the
//! end-to-end measure share.

use splitsum_reference as reference;
use splitsum_shaders::glam::Vec3;

/// One measurement.
#[derive(Clone, Debug)]
pub struct Measurement {
    /// Product (and, for the prefilter, its roughness).
    pub product: String,
    /// Backend.
    pub backend: String,
    /// The knob's value.
    pub setting: String,
    /// Wall time in milliseconds (`NaN` where nothing was run).
    pub time_ms: f64,
    /// Mean error.
    pub mean_error: f64,
    /// Largest error.
    pub max_error: f64,
    /// What the errors measure.
    pub metric: &'static str,
}

/// The metric of the BRDF table's errors.
pub const ABS: &str = "absolute";
/// The metric of radiance errors.
pub const REL: &str = "relative luminance";

impl Measurement {
    /// A row from its `errors`: their mean and largest.
    pub fn of(product: impl Into<String>, backend: impl Into<String>, setting: impl Into<String>, time_ms: f64, errors: &[f64], metric: &'static str) -> Self {
        let mean_error = errors.iter().sum::<f64>() / errors.len().max(1) as f64;
        let max_error = errors.iter().copied().fold(0.0, f64::max);
        Self { product: product.into(), backend: backend.into(), setting: setting.into(), time_ms, mean_error, max_error, metric }
    }
}

/// `[x, y, z]` in f64.
pub fn arr(v: Vec3) -> [f64; 3] {
    [v.x as f64, v.y as f64, v.z as f64]
}

/// Relative error of the luminance of `got` against `want`.
pub fn rel(got: Vec3, want: [f64; 3]) -> f64 {
    rel64(arr(got), want)
}

/// Relative error of the luminance of `got` against `want`, both f64.
pub fn rel64(got: [f64; 3], want: [f64; 3]) -> f64 {
    let w = reference::luminance(want);
    (reference::luminance(got) - w).abs() / w.max(1e-12)
}
