//! The two ways to bake: on a GPU through wgpu, or natively on the CPU. Both call the same
//! `splitsum_shaders` functions; this module hides which one runs.
//!
//! On the GPU, long sums run one chunk of at most `math::CHUNK` terms per dispatch and
//! carry compensated partial sums from dispatch to dispatch; the final means are resolved
//! here with the same shared functions the CPU backend ends with, so both backends do the
//! same arithmetic in the same order.

use crate::cpu;
use crate::error::{Error, Result};
use crate::gpu::{self, Dispatch, Gpu, Kernel};
use crate::texture::{Cube, Equirect, Lut, Sh9};
use splitsum_shaders::brdf::microfacet::Masking;
use splitsum_shaders::cubemap::{CubeLayout, FACES};
use splitsum_shaders::glam::Vec4;
use splitsum_shaders::irradiance::SH9;
use splitsum_shaders::kernels::{self, DownsampleParams, EquirectParams, IrradianceParams, LutParams, PrefilterParams, ProbeParams, TableParams, probe_mode};
use splitsum_shaders::math::{CHUNK, MeanPartial};
use splitsum_shaders::{equirect, lut, prefilter};

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

/// The chunks `(start, count)` a sum of `n` terms is split into (see `math::CHUNK`).
pub fn chunks(n: u32) -> impl Iterator<Item = (u32, u32)> {
    let n = n.max(1);
    (0..n.div_ceil(CHUNK)).map(move |k| (k * CHUNK, CHUNK.min(n - k * CHUNK)))
}

fn read_vec4(g: &Gpu, buffer: &wgpu::Buffer, count: u32) -> Result<Vec<Vec4>> {
    let bytes = g.read(buffer)?;
    Ok(bytemuck::pod_collect_to_vec(&bytes[..count as usize * 16]))
}

/// Runs a table kernel over the rows of a `size`×`size` table, `per_texel` integrand
/// evaluations a texel, with the parameters `params(first row)`: about 2²⁶ evaluations per
/// submission, so that none runs long enough to trip a display driver's watchdog.
fn table_rows<P: bytemuck::Pod>(g: &Gpu, kernel: Kernel, size: u32, per_texel: u32, output: &wgpu::Buffer, params: impl Fn(u32) -> P) {
    let rows = ((1u64 << 26) / (size as u64 * per_texel.max(1) as u64)).clamp(1, size as u64) as u32;
    let rows = rows.div_ceil(kernels::TILE) * kernels::TILE;
    let mut row = 0;
    while row < size {
        let p = params(row);
        let h = rows.min(size - row);
        g.run(&[Dispatch {
            kernel,
            params: bytemuck::bytes_of(&p),
            input: None,
            output,
            groups: [gpu::groups(size, kernels::TILE), gpu::groups(h, kernels::TILE), 1],
        }]);
        row += h;
    }
}

fn partial(sums: &[Vec4], texel: usize) -> MeanPartial {
    MeanPartial { sum: sums[3 * texel], carry: sums[3 * texel + 1], weight: sums[3 * texel + 2] }
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

/// Bytes of `texels` RGBA f32 texels.
fn bytes(texels: u64) -> u64 {
    texels * 16
}

impl Backend {
    /// The GPU, if this is the GPU backend and each of `buffers` (bytes) fits in one storage
    /// binding of the device; otherwise `None`, and where the GPU is too small for them, a
    /// note on stderr that `step` runs on the CPU instead (the same shared functions, so
    /// the results agree within the GPU-vs-CPU bounds).
    fn gpu_for(&self, step: &str, buffers: &[u64]) -> Option<&Gpu> {
        let Backend::Gpu(g) = self else { return None };
        let max = g.max_binding();
        match buffers.iter().copied().max() {
            Some(need) if need > max => {
                eprintln!(
                    "note: {step} needs a {:.0} MiB buffer, more than {} binds ({:.0} MiB): running this step on the CPU",
                    need as f64 / 1048576.0,
                    g.info.name,
                    max as f64 / 1048576.0
                );
                None
            }
            _ => Some(g),
        }
    }

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

    /// What the backend's results depend on, for cache keys: the adapter and driver, or
    /// `cpu` (results on the CPU do not depend on the number of threads).
    pub fn identity(&self) -> String {
        match self {
            Backend::Gpu(g) => format!("gpu: {}", g.describe()),
            Backend::Cpu => "cpu".into(),
        }
    }

    /// The `size`×`size` BRDF table from `samples` points per texel.
    pub fn brdf_lut(&self, size: u32, samples: u32) -> Result<Lut> {
        check_lut_args(size, samples)?;
        let n = size as u64 * size as u64;
        let Some(g) = self.gpu_for("the BRDF table", &[bytes(n)]) else { return Ok(cpu::brdf_lut(size, samples)) };
        let accum = g.output("brdf lut sums", n * 16)?;
        for (start, count) in chunks(samples) {
            table_rows(g, Kernel::BrdfLut, size, count, &accum, |row_offset| LutParams { size, samples, row_offset, start, count, pad0: 0, pad1: 0, pad2: 0 });
        }
        let sums = read_vec4(g, &accum, n as u32)?;
        Ok(Lut { size, texels: sums.iter().map(|&st| lut::resolve(st, samples)).collect() })
    }

    /// The `size`×`size` BRDF table by deterministic quadrature with `masking`
    /// (`lut::integrate_brdf_quadrature`).
    pub fn brdf_table(&self, size: u32, masking: Masking) -> Result<Lut> {
        check_lut_args(size, 1)?;
        let n = size as u64 * size as u64;
        let Some(g) = self.gpu_for("the BRDF table", &[bytes(n)]) else { return Ok(cpu::brdf_table(size, masking)) };
        let out = g.output("brdf table", n * 16)?;
        let per_texel = splitsum_shaders::lut::QUADRATURE_MEAN_EVALUATIONS;
        table_rows(g, Kernel::BrdfTable, size, per_texel, &out, |row_offset| TableParams { size, masking: masking as u32, row_offset, pad: 0 });
        let texels = read_vec4(g, &out, n as u32)?;
        Ok(Lut { size, texels: texels.iter().map(|t| t.truncate().truncate()).collect() })
    }

    /// The source cube: `env` resampled to faces of `size` with `supersample`² points per
    /// texel, and its full mip chain.
    pub fn equirect_to_cube(&self, env: &Equirect, size: u32, supersample: u32) -> Result<Cube> {
        let layout = CubeLayout::new(size, CubeLayout::full_chain(size));
        let (w, h) = (env.width, env.height);
        let pyramid_bytes = bytes(equirect::pyramid_len(w, h) as u64);
        let Some(g) = self.gpu_for(&format!("resampling the {w}×{h} equirect (its row pyramid)"), &[pyramid_bytes, bytes(layout.texel_count() as u64)]) else {
            let mut cube = cpu::equirect_to_cube(env, size, supersample);
            self.build_mips(&mut cube)?;
            return Ok(cube);
        };
        let levels = equirect::pyramid_levels(w);
        let mut texels = env.texels.clone();
        texels.resize(equirect::pyramid_len(w, h) as usize, Vec4::ZERO);
        let pyramid = g.upload("equirect pyramid", bytemuck::cast_slice(&texels));
        let base = EquirectParams { width: w, height: h, face_size: size, supersample, levels, level: 0, pad0: 0, pad1: 0 };
        let params: Vec<EquirectParams> = (1..levels).map(|level| EquirectParams { level, ..base }).collect();
        let dispatches: Vec<Dispatch> = params
            .iter()
            .map(|p| Dispatch {
                kernel: Kernel::EquirectPyramid,
                params: bytemuck::bytes_of(p),
                input: None,
                output: &pyramid,
                groups: [gpu::groups(w >> p.level, kernels::TILE), gpu::groups(h, kernels::TILE), 1],
            })
            .collect();
        g.run(&dispatches);
        let out = g.output("source cube", layout.texel_count() as u64 * 16)?;
        let tile = gpu::groups(size, kernels::TILE);
        g.run(&[Dispatch {
            kernel: Kernel::EquirectToCube,
            params: bytemuck::bytes_of(&base),
            input: Some(&pyramid),
            output: &out,
            groups: [tile, tile, FACES],
        }]);
        self.gpu_mips(g, &out, layout);
        Ok(Cube { layout, texels: read_vec4(g, &out, layout.texel_count())? })
    }

    /// Fills levels 1.. of `cube` from its level 0.
    pub fn build_mips(&self, cube: &mut Cube) -> Result<()> {
        let s = cube.layout.size;
        match self.gpu_for(&format!("the mips of the {s}² cube"), &[bytes(cube.texels.len() as u64)]) {
            None => cpu::build_mips(cube),
            Some(g) => {
                let buf = g.upload("cube", bytemuck::cast_slice(&cube.texels));
                self.gpu_mips(g, &buf, cube.layout);
                cube.texels = read_vec4(g, &buf, cube.layout.texel_count())?;
            }
        }
        Ok(())
    }

    fn gpu_mips(&self, g: &Gpu, cube: &wgpu::Buffer, layout: CubeLayout) {
        let params: Vec<DownsampleParams> =
            (0..layout.levels.saturating_sub(1)).map(|level| DownsampleParams { size: layout.size, levels: layout.levels, level, pad: 0 }).collect();
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
        let all: Vec<u32> = (0..out.levels).collect();
        self.prefilter_levels(src, out, roughness, &all, &vec![samples; out.levels as usize], false, lod_bias)
    }

    /// As [`Backend::prefilter`], baking only `levels` (the other levels stay zero: a plan
    /// leaves out what nothing reads), level `m` from `samples[m]` GGX samples, or with
    /// `exact` summed exactly over a source level where that is cheaper
    /// (`prefilter::exact_level`).
    #[allow(clippy::too_many_arguments)]
    pub fn prefilter_levels(
        &self,
        src: &Cube,
        out: CubeLayout,
        roughness: &[f32],
        levels: &[u32],
        samples: &[u32],
        exact: bool,
        lod_bias: f32,
    ) -> Result<Cube> {
        if samples.contains(&0) {
            return Err(Error::Invalid("--samples must be at least 1".into()));
        }
        let exact_levels: Vec<u32> =
            roughness.iter().zip(samples).map(|(&r, &n)| if exact { prefilter::exact_level(r, n, src.layout) } else { prefilter::SAMPLED }).collect();
        let buffers = [bytes(src.texels.len() as u64), 3 * bytes(out.texel_count() as u64)];
        let Some(g) = self.gpu_for(&format!("prefiltering from the {}² source cube", src.layout.size), &buffers) else {
            return Ok(cpu::prefilter(src, out, roughness, levels, samples, &exact_levels, lod_bias));
        };
        let input = g.upload("source cube", bytemuck::cast_slice(&src.texels));
        let accum = g.output("specular sums", out.texel_count() as u64 * 48)?;
        for &m in levels {
            let (r, samples) = (roughness[m as usize], samples[m as usize]);
            if r <= 0.0 {
                continue; // a mirror: resolved from the source below
            }
            let s = out.level_size(m);
            let t = gpu::groups(s, kernels::TILE);
            let exact_level = exact_levels[m as usize];
            // An exact sum runs over every texel of its source level, in chunks.
            let terms = if exact_level == prefilter::SAMPLED { samples } else { FACES * src.layout.level_size(exact_level).pow(2) };
            for (start, count) in chunks(terms) {
                let p = PrefilterParams {
                    src_size: src.layout.size,
                    src_levels: src.layout.levels,
                    dst_size: s,
                    samples,
                    roughness: r,
                    lod_bias,
                    dst_offset: out.level_offset(m),
                    start,
                    count,
                    exact_level,
                    pad1: 0,
                    pad2: 0,
                };
                g.run(&[Dispatch {
                    kernel: Kernel::PrefilterSpecular,
                    params: bytemuck::bytes_of(&p),
                    input: Some(&input),
                    output: &accum,
                    groups: [t, t, FACES],
                }]);
            }
        }
        let sums = read_vec4(g, &accum, 3 * out.texel_count())?;
        let mut texels = Vec::with_capacity(out.texel_count() as usize);
        for m in 0..out.levels {
            let s = out.level_size(m);
            let r = roughness[m as usize];
            if !levels.contains(&m) {
                texels.resize(texels.len() + (FACES * s * s) as usize, Vec4::ZERO);
                continue;
            }
            for face in 0..FACES {
                for y in 0..s {
                    for x in 0..s {
                        texels.push(if r <= 0.0 {
                            prefilter::prefilter_texel(&src.texels, src.layout, face, x, y, s, r, samples[m as usize], lod_bias, prefilter::SAMPLED)
                        } else {
                            partial(&sums, out.index(m, face, x, y) as usize).resolve()
                        });
                    }
                }
            }
        }
        Ok(Cube { layout: out, texels })
    }

    /// The irradiance cube (`E/π`) of face size `size` from level `level` of `src`.
    pub fn irradiance(&self, src: &Cube, level: u32, size: u32) -> Result<Cube> {
        let layout = CubeLayout::new(size, 1);
        let buffers = [bytes(src.texels.len() as u64), 3 * bytes(layout.texel_count() as u64)];
        let Some(g) = self.gpu_for(&format!("the irradiance from the {}² source cube", src.layout.size), &buffers) else {
            return Ok(cpu::irradiance(src, level, size));
        };
        let input = g.upload("source cube", bytemuck::cast_slice(&src.texels));
        let accum = g.output("irradiance sums", layout.texel_count() as u64 * 48)?;
        let s = src.layout.level_size(level);
        let t = gpu::groups(size, kernels::TILE);
        for (start, count) in chunks(FACES * s * s) {
            let p =
                IrradianceParams { src_size: src.layout.size, src_levels: src.layout.levels, src_level: level, dst_size: size, start, count, pad0: 0, pad1: 0 };
            g.run(&[Dispatch { kernel: Kernel::IrradianceCube, params: bytemuck::bytes_of(&p), input: Some(&input), output: &accum, groups: [t, t, FACES] }]);
        }
        let sums = read_vec4(g, &accum, 3 * layout.texel_count())?;
        let texels = (0..layout.texel_count() as usize).map(|i| partial(&sums, i).resolve()).collect();
        Ok(Cube { layout, texels })
    }

    /// The nine SH coefficients of radiance of level `level` of `src`.
    pub fn sh9(&self, src: &Cube, level: u32) -> Result<Sh9> {
        let rows = match self.gpu_for(&format!("SH9 from the {}² source cube", src.layout.size), &[bytes(src.texels.len() as u64)]) {
            None => cpu::sh9_rows(src, level),
            Some(g) => {
                let s = src.layout.level_size(level);
                let input = g.upload("source cube", bytemuck::cast_slice(&src.texels));
                let n = FACES * s * (SH9 as u32 + 1);
                let dst = g.output("sh9 rows", n as u64 * 16)?;
                let p = IrradianceParams {
                    src_size: src.layout.size,
                    src_levels: src.layout.levels,
                    src_level: level,
                    dst_size: 0,
                    start: 0,
                    count: 0,
                    pad0: 0,
                    pad1: 0,
                };
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

    /// Evaluates `probes` with `params` (see `kernels::probe_chunk`) over `cube`, if any:
    /// the BRDF table `(A, B)` in `xy`, a prefiltered or irradiance mean, or a cube lookup.
    pub fn probe(&self, params: ProbeParams, cube: Option<&Cube>, probes: &[Vec4]) -> Result<Vec<Vec4>> {
        let texels: &[Vec4] = cube.map_or(&[], |c| &c.texels);
        let p = ProbeParams {
            count: probes.len() as u32,
            probe_offset: texels.len() as u32,
            src_size: cube.map_or(1, |c| c.layout.size),
            src_levels: cube.map_or(1, |c| c.layout.levels),
            ..params
        };
        let layout = CubeLayout::new(p.src_size, p.src_levels);
        // Terms of the sum each probe runs, in chunks.
        let terms = match p.mode {
            probe_mode::LUT | probe_mode::PREFILTER => p.samples.max(1),
            probe_mode::IRRADIANCE => FACES * layout.level_size(p.src_level).pow(2),
            _ => 1,
        };
        let raw = match self.gpu_for("the probes", &[bytes((texels.len() + probes.len()) as u64), 3 * bytes(probes.len() as u64)]) {
            None => {
                let mut out = vec![Vec4::ZERO; 3 * probes.len()];
                for (i, &q) in probes.iter().enumerate() {
                    for (start, chunk) in chunks(terms) {
                        kernels::probe_chunk(&ProbeParams { start, chunk, ..p }, texels, q, &mut out, i);
                    }
                }
                out
            }
            Some(g) => {
                let mut input = texels.to_vec();
                input.extend_from_slice(probes);
                let buf = g.upload("probes", bytemuck::cast_slice(&input));
                let out = g.output("probe results", probes.len() as u64 * 48)?;
                for (start, chunk) in chunks(terms) {
                    let pc = ProbeParams { start, chunk, ..p };
                    g.run(&[Dispatch {
                        kernel: Kernel::Probe,
                        params: bytemuck::bytes_of(&pc),
                        input: Some(&buf),
                        output: &out,
                        groups: [gpu::groups(p.count, 64), 1, 1],
                    }]);
                }
                read_vec4(g, &out, 3 * p.count)?
            }
        };
        Ok(raw
            .chunks_exact(3)
            .zip(probes)
            .enumerate()
            .map(|(i, (c, q))| match p.mode {
                probe_mode::LUT => lut::resolve(c[0], p.samples).extend(0.0).extend(0.0),
                // A mirror is no sum: the lookup itself.
                probe_mode::PREFILTER if splitsum_shaders::math::saturate(q.w) <= 0.0 => {
                    prefilter::prefilter_dir(texels, layout, q.truncate(), 0.0, p.samples, p.lod_bias)
                }
                probe_mode::PREFILTER | probe_mode::IRRADIANCE => partial(&raw, i).resolve(),
                _ => c[0],
            })
            .collect())
    }
}
