//! The report's rows (`splitsum::measured`, typed: what `report.csv` holds and the
//! planner's calibration reads), and the error metrics the report and the end-to-end
//! measure share.

use splitsum_reference as reference;
use splitsum_shaders::glam::Vec3;

pub use splitsum::measured::{Knob, Measurement, Method, Metric, Part, Quantity, Set};

/// The backend rows are measured on: its kind's name (`gpu`, `cpu`) and its description.
pub struct Device {
    engine: &'static str,
    description: String,
}

impl Device {
    /// The device of `backend`.
    pub fn of(backend: &splitsum::backend::Backend) -> Self {
        use splitsum_shaders::choice::Choice;
        Self { engine: backend.kind().name(), description: backend.describe() }
    }

    /// A row of `product` by `method` on this device.
    pub fn row(&self, product: Quantity, method: Method, errors: &[f64], metric: Metric) -> Measurement {
        Measurement { backend: self.engine.into(), device: self.description.clone(), ..Measurement::of(product, method, errors, metric) }
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
