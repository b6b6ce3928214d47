//! The report's rows (`splitsum::measured`, typed: what `report.csv` holds and the
//! planner's calibration reads), and the error metrics the report and the end-to-end
//! measure share.

use splitsum_reference as reference;
use splitsum_shaders::glam::Vec3;

pub use splitsum::measured::{Knob, Measurement, Method, Metric, Part, Product, Set};

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
