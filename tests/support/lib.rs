//! Shared support for the tests: independent references (written in f64, with other
//! formulas and other integration rules than the code under test), error measures, and
//! the GPU backend opened once per test binary.

pub mod quadrature;
pub mod reference;

use runner::{Backend, BackendKind};
use std::sync::OnceLock;

/// The GPU backend (lavapipe in CI), opened once. Panics with the runner's own message,
/// which says how to install lavapipe, when there is no Vulkan adapter.
pub fn gpu() -> &'static Backend {
    static GPU: OnceLock<Backend> = OnceLock::new();
    GPU.get_or_init(|| match Backend::open(BackendKind::Gpu) {
        Ok(b) => b,
        Err(e) => panic!("the GPU tests need a Vulkan adapter: {e}"),
    })
}

/// Distance in units in the last place between two finite f32 of the same sign, or across
/// zero (the count of representable floats between them).
pub fn ulp_diff(a: f32, b: f32) -> u64 {
    fn key(x: f32) -> i64 {
        let bits = x.to_bits() as i32 as i64;
        if bits < 0 { i32::MIN as i64 - bits } else { bits }
    }
    (key(a) - key(b)).unsigned_abs()
}

/// Maximum absolute and ULP differences between two equally long series of values.
pub fn max_diffs(a: impl IntoIterator<Item = f32>, b: impl IntoIterator<Item = f32>) -> (f32, u64) {
    let mut abs = 0.0f32;
    let mut ulp = 0u64;
    for (x, y) in a.into_iter().zip(b) {
        assert!(x.is_finite() && y.is_finite(), "non-finite value: {x} vs {y}");
        abs = abs.max((x - y).abs());
        ulp = ulp.max(ulp_diff(x, y));
    }
    (abs, ulp)
}
