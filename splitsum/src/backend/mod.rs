//! The two ways to bake: on a GPU through wgpu ([`gpu`]), or natively on the CPU
//! ([`cpu`]). Both implement [`Kernels`] with the same `splitsum_shaders` functions, and
//! keep what they make where they made it (`Kernels::Texels`: host memory, or device
//! buffers), so one bake sequence (`crate::bake`) runs on either and nothing comes back
//! from the GPU unless asked.
//!
//! On the GPU, long sums run one chunk of at most `math::CHUNK` terms per dispatch and
//! carry compensated partial sums from dispatch to dispatch; the means are resolved with
//! the same shared functions the CPU backend ends with (`MeanPartial::resolve`,
//! `lut::resolve`), so both backends do the same arithmetic in the same order.

pub mod cpu;
pub mod gpu;
pub mod kernels;
pub mod split;

use crate::error::Result;

pub use cpu::Cpu;
pub use gpu::Gpu;
pub use kernels::{Kernels, Prefilter, chunks};
pub use split::Split;

/// Which backend to bake with.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum BackendKind {
    /// The GPU where the best adapter is one; the CPU where it is a software rasteriser on
    /// the CPU (lavapipe, llvmpipe, SwiftShader, WARP), which runs the same kernels several
    /// times slower than the CPU backend runs them natively, or where there is none.
    Auto,
    /// wgpu on the best adapter, whatever it is (a real GPU, or a software one).
    Gpu,
    /// The shader functions compiled natively, multi-threaded with rayon.
    Cpu,
}

splitsum_shaders::choice!(BackendKind: Auto => "auto", Gpu => "gpu", Cpu => "cpu");

/// An open backend.
pub enum Backend {
    /// The GPU, with its device and pipelines.
    Gpu(Box<Gpu>),
    /// The CPU.
    Cpu,
}

/// Runs `$body` with `$k` bound to the backend's [`Kernels`].
macro_rules! with_kernels {
    ($backend:expr, $k:ident => $body:expr) => {
        match $backend {
            Backend::Gpu(g) => {
                let $k: &$crate::backend::Gpu = g;
                $body
            }
            Backend::Cpu => {
                let $k: &$crate::backend::Cpu = &$crate::backend::Cpu;
                $body
            }
        }
    };
}
pub(crate) use with_kernels;

impl Backend {
    /// Opens `kind` (for the GPU: adapter, device and pipelines, outside any timing). For
    /// [`BackendKind::Auto`], a note says when the CPU is chosen, and why.
    pub fn open(kind: BackendKind) -> Result<Self> {
        Ok(match kind {
            BackendKind::Gpu => Backend::Gpu(Box::new(Gpu::new()?)),
            BackendKind::Cpu => Backend::Cpu,
            BackendKind::Auto => match gpu::Gpu::unless_software()? {
                Ok(gpu) => Backend::Gpu(Box::new(gpu)),
                Err(passed) => {
                    crate::progress::note(&match passed {
                        Some(info) => format!(
                            "note: the best GPU adapter here, {} on {}, is a software rasteriser on the CPU: baking on the CPU backend, which runs the same functions natively and faster (--backend gpu uses the adapter anyway)",
                            info.name,
                            gpu::api_name(info.backend)
                        ),
                        None => "note: no GPU adapter here: baking on the CPU backend".to_string(),
                    });
                    Backend::Cpu
                }
            },
        })
    }

    /// A one-line description.
    pub fn describe(&self) -> String {
        match self {
            Backend::Gpu(g) => format!("gpu: {}", g.describe()),
            Backend::Cpu => format!("cpu: {} threads", rayon::current_num_threads()),
        }
    }

    internal! {
        /// What the backend's results depend on, for cache keys: the adapter and driver, or
        /// `cpu` (results on the CPU do not depend on the number of threads).
        pub fn identity(&self) -> String {
            match self {
                Backend::Gpu(g) => format!("gpu: {}", g.describe()),
                Backend::Cpu => "cpu".into(),
            }
        }
    }

    /// Whether this is the GPU backend.
    pub fn is_gpu(&self) -> bool {
        matches!(self, Backend::Gpu(_))
    }

    /// Which backend this is.
    pub fn kind(&self) -> BackendKind {
        if self.is_gpu() { BackendKind::Gpu } else { BackendKind::Cpu }
    }
}
