//! The two ways to bake: on a GPU through wgpu, or natively on the CPU. Both call the same
//! `splitsum_shaders` functions; this module hides which one runs.

use crate::cpu;
use crate::error::{Error, Result};
use crate::gpu::{self, Dispatch, Gpu, Kernel};
use crate::texture::{Cube, Equirect, Lut, Sh9};
use splitsum_shaders::cubemap::{CubeLayout, FACES};
use splitsum_shaders::glam::{Vec2, Vec4};
use splitsum_shaders::irradiance::SH9;
use splitsum_shaders::kernels::{self, DownsampleParams, EquirectParams, IrradianceParams, LutParams, PrefilterParams};

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

impl Backend {
    /// The source cube: `env` resampled to faces of `size` with `supersample`² points per
    /// texel, and its full mip chain.
    pub fn equirect_to_cube(&self, env: &Equirect, size: u32, supersample: u32) -> Result<Cube> {
        match self {
            Backend::Cpu => {
                let mut cube = cpu::equirect_to_cube(env, size, supersample);
                cpu::build_mips(&mut cube);
                Ok(cube)
            }
            Backend::Gpu(g) => {
                let layout = CubeLayout::new(size, CubeLayout::full_chain(size));
                let src = g.upload("equirect", bytemuck::cast_slice(&env.texels));
                let out = g.output("source cube", layout.texel_count() as u64 * 16)?;
                let p = EquirectParams { width: env.width, height: env.height, face_size: size, supersample };
                let tile = gpu::groups(size, kernels::TILE);
                g.run(&[Dispatch {
                    kernel: Kernel::EquirectToCube,
                    params: bytemuck::bytes_of(&p),
                    input: Some(&src),
                    output: &out,
                    groups: [tile, tile, FACES],
                }]);
                self.gpu_mips(g, &out, layout);
                Ok(Cube { layout, texels: read_vec4(g, &out, layout.texel_count())? })
            }
        }
    }

    /// Fills levels 1.. of `cube` from its level 0.
    pub fn build_mips(&self, cube: &mut Cube) -> Result<()> {
        match self {
            Backend::Cpu => cpu::build_mips(cube),
            Backend::Gpu(g) => {
                let buf = g.upload("cube", bytemuck::cast_slice(&cube.texels));
                self.gpu_mips(g, &buf, cube.layout);
                cube.texels = read_vec4(g, &buf, cube.layout.texel_count())?;
            }
        }
        Ok(())
    }

    fn gpu_mips(&self, g: &Gpu, cube: &wgpu::Buffer, layout: CubeLayout) {
        let params: Vec<DownsampleParams> = (0..layout.levels.saturating_sub(1))
            .map(|level| DownsampleParams { size: layout.size, levels: layout.levels, level, pad: 0 })
            .collect();
        let dispatches: Vec<Dispatch> = params
            .iter()
            .map(|p| {
                let t = gpu::groups(layout.level_size(p.level + 1), kernels::TILE);
                Dispatch { kernel: Kernel::Downsample, params: bytemuck::bytes_of(p), input: None, output: cube, groups: [t, t, FACES] }
            })
            .collect();
        g.run(&dispatches);
    }

    /// The prefiltered specular cube with layout `out`, level `m` filtered for
    /// `roughness[m]` with `samples` GGX samples and source-level bias `lod_bias`.
    pub fn prefilter(&self, src: &Cube, out: CubeLayout, roughness: &[f32], samples: u32, lod_bias: f32) -> Result<Cube> {
        if samples == 0 {
            return Err(Error::Invalid("--samples must be at least 1".into()));
        }
        match self {
            Backend::Cpu => Ok(cpu::prefilter(src, out, roughness, samples, lod_bias)),
            Backend::Gpu(g) => {
                let input = g.upload("source cube", bytemuck::cast_slice(&src.texels));
                let dst = g.output("specular cube", out.texel_count() as u64 * 16)?;
                for m in 0..out.levels {
                    let s = out.level_size(m);
                    let p = PrefilterParams {
                        src_size: src.layout.size,
                        src_levels: src.layout.levels,
                        dst_size: s,
                        samples,
                        roughness: roughness[m as usize],
                        lod_bias,
                        dst_offset: out.level_offset(m),
                        pad: 0,
                    };
                    let t = gpu::groups(s, kernels::TILE);
                    g.run(&[Dispatch {
                        kernel: Kernel::PrefilterSpecular,
                        params: bytemuck::bytes_of(&p),
                        input: Some(&input),
                        output: &dst,
                        groups: [t, t, FACES],
                    }]);
                }
                Ok(Cube { layout: out, texels: read_vec4(g, &dst, out.texel_count())? })
            }
        }
    }

    /// The irradiance cube (`E/π`) of face size `size` from level `level` of `src`.
    pub fn irradiance(&self, src: &Cube, level: u32, size: u32) -> Result<Cube> {
        match self {
            Backend::Cpu => Ok(cpu::irradiance(src, level, size)),
            Backend::Gpu(g) => {
                let layout = CubeLayout::new(size, 1);
                let input = g.upload("source cube", bytemuck::cast_slice(&src.texels));
                let dst = g.output("irradiance cube", layout.texel_count() as u64 * 16)?;
                let p = IrradianceParams { src_size: src.layout.size, src_levels: src.layout.levels, src_level: level, dst_size: size };
                let t = gpu::groups(size, kernels::TILE);
                g.run(&[Dispatch {
                    kernel: Kernel::IrradianceCube,
                    params: bytemuck::bytes_of(&p),
                    input: Some(&input),
                    output: &dst,
                    groups: [t, t, FACES],
                }]);
                Ok(Cube { layout, texels: read_vec4(g, &dst, layout.texel_count())? })
            }
        }
    }

    /// The nine SH coefficients of radiance of level `level` of `src`.
    pub fn sh9(&self, src: &Cube, level: u32) -> Result<Sh9> {
        let rows = match self {
            Backend::Cpu => cpu::sh9_rows(src, level),
            Backend::Gpu(g) => {
                let s = src.layout.level_size(level);
                let input = g.upload("source cube", bytemuck::cast_slice(&src.texels));
                let n = FACES * s * (SH9 as u32 + 1);
                let dst = g.output("sh9 rows", n as u64 * 16)?;
                let p = IrradianceParams { src_size: src.layout.size, src_levels: src.layout.levels, src_level: level, dst_size: 0 };
                g.run(&[Dispatch {
                    kernel: Kernel::IrradianceSh9,
                    params: bytemuck::bytes_of(&p),
                    input: Some(&input),
                    output: &dst,
                    groups: [gpu::groups(s, 64), 1, FACES],
                }]);
                read_vec4(g, &dst, n)?.chunks_exact(SH9 + 1).map(|c| c.try_into().expect("10 per row")).collect()
            }
        };
        Ok(Sh9::from_rows(&rows))
    }
}

fn read_vec4(g: &Gpu, buffer: &wgpu::Buffer, count: u32) -> Result<Vec<Vec4>> {
    let bytes = g.read(buffer)?;
    Ok(bytemuck::pod_collect_to_vec(&bytes[..count as usize * 16]))
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
