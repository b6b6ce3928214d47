//! Shared support for the tests: independent references (written in f64, with other
//! formulas and other integration rules than the code under test), error measures, and
//! the GPU backend opened once per test binary.

pub mod figure;
pub mod model;

pub use splitsum_reference as reference;
pub use splitsum_reference::quadrature;

use splitsum::{Backend, BackendKind};
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

/// Whether the GPU backend runs on a software Vulkan driver (lavapipe, in CI): LLVM with
/// correctly rounded division and square root and no fused multiply–add contraction, so
/// its results follow the CPU's closely.
pub fn gpu_is_software() -> bool {
    match gpu() {
        Backend::Gpu(g) => g.is_software(),
        Backend::Cpu => unreachable!("opened as a GPU"),
    }
}

/// A GPU-vs-CPU bound: `software` on a software driver, `hardware` on a real GPU, where the
/// Vulkan specification ("Precision and Operation of SPIR-V Instructions") lets division
/// be off by 2.5 ULP and square root by about 3, and lets `a·b + c` be fused into one
/// rounding unless the SPIR-V says NoContraction (rust-gpu never does). The hardware bounds
/// were measured on an NVIDIA H100 (driver 580.159) with a margin; each test names its
/// figures.
pub fn gpu_bound(software: f64, hardware: f64) -> f64 {
    if gpu_is_software() { software } else { hardware }
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

/// The path of a vendored CC0 environment: `assets/environments/NAME.exr`, or
/// `splitsum/assets/courtyard.exr` (the one the library embeds).
pub fn environment_path(name: &str) -> std::path::PathBuf {
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    if name == "courtyard" { root.join("splitsum/assets/courtyard.exr") } else { root.join("assets/environments").join(format!("{name}.exr")) }
}

/// One of the vendored CC0 environments ([`environment_path`]), as an equirect.
pub fn environment(name: &str) -> splitsum::texture::Equirect {
    let path = environment_path(name);
    match splitsum::environment::load(&path, false).expect("vendored environment") {
        (splitsum::environment::Environment::Equirect(e), _) => e,
        _ => unreachable!(),
    }
}

/// The source cube (with mips) of a vendored environment at face size `size`, on the CPU.
pub fn source_cube(name: &str, size: u32) -> splitsum::texture::Cube {
    let e = environment(name);
    let n = splitsum_shaders::equirect::supersampling(size, e.width, 2.0);
    Backend::Cpu.equirect_to_cube(&e, size, n, splitsum_shaders::equirect::Facing::NegZ).expect("cpu bake")
}

/// A small, quick bake of the courtyard for the display tests (32² specular and sheen
/// cubes with 4 mips at 64 samples, 8² irradiance, 32² table, the sheen tables), on the CPU.
pub fn small_display_bake() -> splitsum::reading::BakedEnvironment {
    let settings = splitsum::settings::Settings {
        size: 32,
        source_size: Some(64),
        mips: Some(4),
        samples: 64,
        irradiance_size: 8,
        irradiance_source: Some(16),
        sh_source: Some(16),
        lut_size: 32,
        lut_samples: 64,
        ..splitsum::settings::Settings::default()
    };
    let env = splitsum::environment::Environment::Equirect(environment("courtyard"));
    let job = settings.resolve(splitsum::InputShape::of(&env), splitsum::Products::DISPLAY.with_sheen(true)).expect("settings");
    splitsum::reading::for_display(&Backend::Cpu, &env, &job).expect("cpu bake").0
}

/// A cube with full mips whose level 0 is `f(direction)` at the texel centres.
pub fn cube_from_fn(size: u32, f: impl Fn(splitsum_shaders::glam::Vec3) -> splitsum_shaders::glam::Vec4) -> splitsum::texture::Cube {
    use splitsum_shaders::cubemap::{self, CubeLayout};
    let layout = CubeLayout::new(size, CubeLayout::full_chain(size));
    let mut texels = vec![splitsum_shaders::glam::Vec4::ZERO; layout.texel_count() as usize];
    for face in 0..6 {
        for y in 0..size {
            for x in 0..size {
                texels[layout.index(0, face, x, y) as usize] = f(cubemap::texel_dir(face, x, y, size));
            }
        }
    }
    let mut cube = splitsum::texture::Cube { layout, texels };
    Backend::Cpu.build_mips(&mut cube).expect("mips");
    cube
}

/// Largest relative difference between two cubes, per channel, relative to
/// `max(|b|, floor)`.
pub fn max_relative(a: &[splitsum_shaders::glam::Vec4], b: &[splitsum_shaders::glam::Vec4], floor: f32) -> f32 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(x, y)| {
            assert!(x.is_finite() && y.is_finite(), "non-finite texel {x} / {y}");
            ((*x - *y).abs() / y.abs().max(splitsum_shaders::glam::Vec4::splat(floor))).truncate().max_element()
        })
        .fold(0.0, f32::max)
}
