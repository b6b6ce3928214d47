//! The two ways to bake: on a GPU through wgpu, or natively on the CPU. Both call the same
//! `splitsum_shaders` functions; this module hides which one runs.

use crate::cpu;
use crate::error::{Error, Result};
use crate::gpu::{self, Dispatch, Gpu, Kernel};
use crate::texture::Lut;
use splitsum_shaders::glam::Vec2;
use splitsum_shaders::kernels::{self, LutParams};

/// Which backend to bake with.
#[derive(Copy, Clone, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum BackendKind {
    /// wgpu on a Vulkan adapter (a real GPU, or Mesa's lavapipe on the CPU).
    Gpu,
    /// The shader functions compiled natively, multi-threaded with rayon.
    Cpu,
}

/// An open backend.
pub enum Backend {
    /// The GPU, with its device and pipelines.
    Gpu(Box<Gpu>),
    /// The CPU.
    Cpu,
}

impl Backend {
    /// Opens `kind` (for the GPU: adapter, device and pipelines, outside any timing).
    pub fn open(kind: BackendKind) -> Result<Self> {
        Ok(match kind {
            BackendKind::Gpu => Backend::Gpu(Box::new(Gpu::new()?)),
            BackendKind::Cpu => Backend::Cpu,
        })
    }

    /// A one-line description.
    pub fn describe(&self) -> String {
        match self {
            Backend::Gpu(g) => format!("gpu: {}", g.describe()),
            Backend::Cpu => format!("cpu: {} threads", rayon::current_num_threads()),
        }
    }

    /// The `size`×`size` BRDF table from `samples` points per texel.
    pub fn brdf_lut(&self, size: u32, samples: u32) -> Result<Lut> {
        check_lut_args(size, samples)?;
        match self {
            Backend::Cpu => Ok(cpu::brdf_lut(size, samples)),
            Backend::Gpu(g) => {
                let out = g.output("brdf lut", size as u64 * size as u64 * 8)?;
                // Rows per submission: about 2²⁶ sample evaluations each, so that no single
                // submission runs long enough to trip a display driver's watchdog.
                let rows = ((1u64 << 26) / (size as u64 * samples as u64)).clamp(8, size as u64) as u32;
                let rows = rows.div_ceil(kernels::TILE) * kernels::TILE;
                let mut row = 0;
                while row < size {
                    let p = LutParams { size, samples, row_offset: row, pad: 0 };
                    let n = rows.min(size - row);
                    g.run(&[Dispatch {
                        kernel: Kernel::BrdfLut,
                        params: bytemuck::bytes_of(&p),
                        input: None,
                        output: &out,
                        groups: [gpu::groups(size, kernels::TILE), gpu::groups(n, kernels::TILE), 1],
                    }]);
                    row += n;
                }
                let bytes = g.read(&out)?;
                let texels: Vec<Vec2> = bytemuck::pod_collect_to_vec(&bytes[..(size * size * 8) as usize]);
                Ok(Lut { size, texels })
            }
        }
    }
}

/// Largest BRDF table accepted (a 4096² table is 128 MiB; beyond that nothing gains).
pub const MAX_LUT_SIZE: u32 = 4096;

fn check_lut_args(size: u32, samples: u32) -> Result<()> {
    if size == 0 || size > MAX_LUT_SIZE {
        return Err(Error::Invalid(format!("--size must be between 1 and {MAX_LUT_SIZE}, not {size}")));
    }
    if samples == 0 {
        return Err(Error::Invalid("--samples must be at least 1".into()));
    }
    Ok(())
}
