//! The [`Kernels`] operations on the GPU: each step's dispatches, recorded from the
//! generated linkage, its chunked sums resolved on the device, its buffers checked against
//! the device's binding limit before anything is allocated.

use super::{Dispatch, Gpu};
use crate::backend::cpu::Cpu;
use crate::backend::kernels::{Kernels, Prefilter, chunks};
use crate::error::{Error, Result};
use crate::texture::{Equirect, Sh9};
use splitsum_shaders::brdf::microfacet::Masking;
use splitsum_shaders::choice::Choice;
use splitsum_shaders::cubemap::{self, CubeLayout, FACES};
use splitsum_shaders::equirect::Facing;
use splitsum_shaders::glam::Vec4;
use splitsum_shaders::irradiance::SH9;
use splitsum_shaders::calibrate::Rate;
use splitsum_shaders::kernels::{CalibrateParams, DownsampleParams, EquirectParams, IrradianceParams, LutParams, PrefilterParams, ProbeParams, ResolveParams, TableParams};
use splitsum_shaders::{equirect, lut, prefilter};
use splitsum_spirv::{self as spirv, EntryPoint};

/// Texels on the device: `count` RGBA f32 texels in `buffer`.
pub struct Texels {
    /// The storage buffer.
    pub buffer: wgpu::Buffer,
    /// Texels it holds.
    pub count: u32,
}

/// Bytes of `texels` RGBA f32 texels.
fn bytes(texels: u64) -> u64 {
    texels * 16
}

impl Gpu {
    /// Whether each of `buffers` (bytes) fits in one storage binding of the device;
    /// otherwise a note on stderr that `step` runs on the CPU instead (the same shared
    /// functions, so the results agree within the GPU-vs-CPU bounds).
    fn fits(&self, step: &str, buffers: &[u64]) -> bool {
        let max = self.max_binding();
        match buffers.iter().copied().max() {
            Some(need) if need > max => {
                crate::progress::note(&format!(
                    "note: {step} needs a {:.0} MiB buffer, more than {} binds ({:.0} MiB): running this step on the CPU",
                    need as f64 / 1048576.0,
                    self.info.name,
                    max as f64 / 1048576.0
                ));
                false
            }
            _ => true,
        }
    }

    /// An output of `count` texels.
    fn texels(&self, what: &str, count: u32) -> Result<Texels> {
        Ok(Texels { buffer: self.output(what, bytes(count as u64))?, count })
    }

    /// Runs a table kernel over the rows of a `size`×`size` table, `per_texel` integrand
    /// evaluations a texel, with the parameters `params(first row)`: about 2²⁶ evaluations
    /// per submission, so that none runs long enough to trip a display driver's watchdog.
    fn table_rows<P: bytemuck::Pod>(&self, kernel: &'static EntryPoint, size: u32, per_texel: u32, output: &wgpu::Buffer, params: impl Fn(u32) -> P) {
        let rows = ((1u64 << 26) / (size as u64 * per_texel.max(1) as u64)).clamp(1, size as u64) as u32;
        let tile = kernel.workgroup_size[1];
        let rows = rows.div_ceil(tile) * tile;
        let mut row = 0;
        while row < size {
            let p = params(row);
            let h = rows.min(size - row);
            self.run(&[Dispatch { kernel, params: bytemuck::bytes_of(&p), input: None, output, invocations: [size, h, 1] }]);
            row += h;
        }
    }

    /// Means of `count` texels from partial sums `accum` (three `Vec4` each) from texel
    /// `offset` on, written at the same index of `out`.
    fn resolve(&self, accum: &wgpu::Buffer, out: &wgpu::Buffer, offset: u32, count: u32) {
        let p = ResolveParams { count, src_offset: offset, dst_offset: offset, samples: 0 };
        self.run(&[Dispatch {
            kernel: &spirv::KERNELS_RESOLVE_MEANS,
            params: bytemuck::bytes_of(&p),
            input: Some(accum),
            output: out,
            invocations: [count, 1, 1],
        }]);
    }

    internal! {
        /// The source cube (faces of `size`, full mip chain) from the `w`×`h` equirect in level
        /// 0 of `pyramid` (a buffer of `equirect::pyramid_len` texels): its row pyramid, then
        /// `supersample`² points per cube texel.
        pub fn pyramid_to_cube(&self, pyramid: &wgpu::Buffer, w: u32, h: u32, size: u32, supersample: u32, facing: Facing) -> Result<Texels> {
            let layout = CubeLayout::new(size, CubeLayout::full_chain(size));
            let levels = equirect::pyramid_levels(w);
            let base = EquirectParams { width: w, height: h, face_size: size, supersample, levels, level: 0, facing: facing.code() };
            let params: Vec<EquirectParams> = (1..levels).map(|level| EquirectParams { level, ..base }).collect();
            let dispatches: Vec<Dispatch> = params
                .iter()
                .map(|p| Dispatch {
                    kernel: &spirv::KERNELS_EQUIRECT_PYRAMID,
                    params: bytemuck::bytes_of(p),
                    input: None,
                    output: pyramid,
                    invocations: [w >> p.level, h, 1],
                })
                .collect();
            self.run(&dispatches);
            let out = self.texels("source cube", layout.texel_count())?;
            self.run(&[Dispatch {
                kernel: &spirv::KERNELS_EQUIRECT_TO_CUBE,
                params: bytemuck::bytes_of(&base),
                input: Some(pyramid),
                output: &out.buffer,
                invocations: [size, size, FACES],
            }]);
            self.mips(&out.buffer, layout);
            Ok(out)
        }
    }

    fn mips(&self, cube: &wgpu::Buffer, layout: CubeLayout) {
        let params: Vec<DownsampleParams> =
            (0..layout.levels.saturating_sub(1)).map(|level| DownsampleParams { size: layout.size, levels: layout.levels, level }).collect();
        let dispatches: Vec<Dispatch> = params
            .iter()
            .map(|p| {
                let s = layout.level_size(p.level + 1);
                Dispatch { kernel: &spirv::KERNELS_DOWNSAMPLE, params: bytemuck::bytes_of(p), input: None, output: cube, invocations: [s, s, FACES] }
            })
            .collect();
        self.run(&dispatches);
    }
}

impl Gpu {
    internal! {
        /// `texels` back in host memory.
        pub fn read_texels(&self, texels: &Texels) -> Result<Vec<Vec4>> {
            let bytes = self.read_bytes(&texels.buffer)?;
            Ok(bytemuck::pod_collect_to_vec(&bytes[..texels.count as usize * 16]))
        }
    }
}

impl Kernels for Gpu {
    type Texels = Texels;

    fn finish(&self) -> Result<()> {
        self.device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| Error::gpu_caused("waiting for the device", e))?;
        Ok(())
    }

    fn upload(&self, what: &str, texels: &[Vec4]) -> Result<Texels> {
        Ok(Texels { buffer: self.upload_bytes(what, bytemuck::cast_slice(texels)), count: texels.len() as u32 })
    }

    fn read(&self, texels: &Texels) -> Result<Vec<Vec4>> {
        self.read_texels(texels)
    }

    fn slice(&self, texels: &Texels, start: u32, count: u32) -> Result<Texels> {
        let out = self.texels("slice", count)?;
        let mut encoder = self.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
        encoder.copy_buffer_to_buffer(&texels.buffer, bytes(start as u64), &out.buffer, 0, bytes(count as u64));
        self.queue.submit([encoder.finish()]);
        Ok(out)
    }

    fn equirect_to_cube(&self, env: &Equirect, size: u32, supersample: u32, facing: Facing) -> Result<Texels> {
        let layout = CubeLayout::new(size, CubeLayout::full_chain(size));
        let (w, h) = (env.width, env.height);
        let pyramid_bytes = bytes(equirect::pyramid_len(w, h) as u64);
        if !self.fits(&format!("resampling the {w}×{h} equirect (its row pyramid)"), &[pyramid_bytes, bytes(layout.texel_count() as u64)]) {
            return self.upload("source cube", &Cpu.equirect_to_cube(env, size, supersample, facing)?);
        }
        let mut texels = env.texels.clone();
        texels.resize(equirect::pyramid_len(w, h) as usize, Vec4::ZERO);
        let pyramid = self.upload_bytes("equirect pyramid", bytemuck::cast_slice(&texels));
        self.pyramid_to_cube(&pyramid, w, h, size, supersample, facing)
    }

    fn build_mips(&self, cube: &mut Texels, layout: CubeLayout) -> Result<()> {
        let s = layout.size;
        if !self.fits(&format!("the mips of the {s}² cube"), &[bytes(cube.count as u64)]) {
            let mut host = self.read_texels(cube)?;
            Cpu.build_mips(&mut host, layout)?;
            *cube = self.upload("cube", &host)?;
            return Ok(());
        }
        self.mips(&cube.buffer, layout);
        Ok(())
    }

    fn prefilter(&self, src: &Texels, src_layout: CubeLayout, job: &Prefilter<'_>) -> Result<Texels> {
        let out = job.layout;
        let buffers = [bytes(src.count as u64), 3 * bytes(out.texel_count() as u64)];
        if !self.fits(&format!("the {} cube from the {}² source cube", job.what(), src_layout.size), &buffers) {
            return self.upload(job.what(), &Cpu.prefilter(&self.read_texels(src)?, src_layout, job)?);
        }
        let accum = self.output("prefilter sums", 3 * bytes(out.texel_count() as u64))?;
        let result = self.texels(job.what(), out.texel_count())?;
        for &m in job.levels {
            let (r, samples, exact_level) = (job.roughness[m as usize], job.samples[m as usize], job.exact[m as usize]);
            let s = out.level_size(m);
            let p = PrefilterParams {
                src_size: src_layout.size,
                src_levels: src_layout.levels,
                dst_size: s,
                samples,
                roughness: r,
                lod_bias: job.lod_bias,
                dst_offset: out.level_offset(m),
                start: 0,
                count: 0,
                exact_level,
                lobe: job.lobe as u32,
            };
            if job.lobe.is_mirror(r) {
                // A mirror: the source read along each texel's direction, no sum.
                self.run(&[Dispatch {
                    kernel: &spirv::KERNELS_PREFILTER_MIRROR,
                    params: bytemuck::bytes_of(&p),
                    input: Some(&src.buffer),
                    output: &result.buffer,
                    invocations: [s, s, FACES],
                }]);
                continue;
            }
            // An exact sum runs over every texel of its source level, in chunks.
            let (terms, kernel) = if exact_level == prefilter::SAMPLED {
                (samples, &spirv::KERNELS_PREFILTER_SPECULAR)
            } else {
                (FACES * src_layout.level_size(exact_level).pow(2), &spirv::KERNELS_PREFILTER_EXACT)
            };
            for (start, count) in chunks(terms) {
                let p = PrefilterParams { start, count, ..p };
                self.run(&[Dispatch {
                    kernel,
                    params: bytemuck::bytes_of(&p),
                    input: Some(&src.buffer),
                    output: &accum,
                    invocations: [s, s, FACES],
                }]);
            }
            self.resolve(&accum, &result.buffer, out.level_offset(m), FACES * s * s);
        }
        Ok(result)
    }

    fn irradiance(&self, src: &Texels, src_layout: CubeLayout, level: u32, size: u32) -> Result<Texels> {
        let layout = CubeLayout::new(size, 1);
        let buffers = [bytes(src.count as u64), 3 * bytes(layout.texel_count() as u64)];
        if !self.fits(&format!("the irradiance from the {}² source cube", src_layout.size), &buffers) {
            return self.upload("irradiance", &Cpu.irradiance(&self.read_texels(src)?, src_layout, level, size)?);
        }
        let accum = self.output("irradiance sums", 3 * bytes(layout.texel_count() as u64))?;
        let s = src_layout.level_size(level);
        // The summed level alone, as a one-level cube, followed by its geometry table.
        let n = FACES * s * s;
        let input = self.output("irradiance input", 2 * bytes(n as u64))?;
        let mut encoder = self.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
        encoder.copy_buffer_to_buffer(&src.buffer, bytes(src_layout.level_offset(level) as u64), &input, 0, bytes(n as u64));
        self.queue.submit([encoder.finish()]);
        let geometry: Vec<Vec4> = cubemap::level_geometry(s).collect();
        self.queue.write_buffer(&input, bytes(n as u64), bytemuck::cast_slice(&geometry));
        for (start, count) in chunks(n) {
            let p = IrradianceParams { src_size: s, src_levels: 1, src_level: 0, dst_size: size, start, count, geometry: n };
            self.run(&[Dispatch {
                kernel: &spirv::KERNELS_IRRADIANCE_CUBE,
                params: bytemuck::bytes_of(&p),
                input: Some(&input),
                output: &accum,
                invocations: [size, size, FACES],
            }]);
        }
        let result = self.texels("irradiance", layout.texel_count())?;
        self.resolve(&accum, &result.buffer, 0, layout.texel_count());
        Ok(result)
    }

    fn sh9(&self, src: &Texels, src_layout: CubeLayout, level: u32) -> Result<Sh9> {
        if !self.fits(&format!("SH9 from the {}² source cube", src_layout.size), &[bytes(src.count as u64)]) {
            return Cpu.sh9(&self.read_texels(src)?, src_layout, level);
        }
        let s = src_layout.level_size(level);
        let n = FACES * s * (SH9 as u32 + 1);
        let dst = self.texels("sh9 rows", n)?;
        let p = IrradianceParams { src_size: src_layout.size, src_levels: src_layout.levels, src_level: level, dst_size: 0, start: 0, count: 0, geometry: cubemap::INLINE_GEOMETRY };
        self.run(&[Dispatch {
            kernel: &spirv::KERNELS_IRRADIANCE_SH9_PROJECT,
            params: bytemuck::bytes_of(&p),
            input: Some(&src.buffer),
            output: &dst.buffer,
            invocations: [s, 1, FACES],
        }]);
        let rows: Vec<[Vec4; SH9 + 1]> = self.read_texels(&dst)?.chunks_exact(SH9 + 1).map(|c| c.try_into().expect("10 per row")).collect();
        Ok(Sh9::from_rows(&rows))
    }

    fn brdf_lut(&self, size: u32, samples: u32) -> Result<Texels> {
        let n = size * size;
        if !self.fits("the BRDF table", &[bytes(n as u64)]) {
            return self.upload("brdf lut", &Cpu.brdf_lut(size, samples)?);
        }
        self.ensure(&spirv::KERNELS_BRDF_LUT)?;
        self.ensure(&spirv::KERNELS_RESOLVE_LUT)?;
        let accum = self.output("brdf lut sums", bytes(n as u64))?;
        for (start, count) in chunks(samples) {
            self.table_rows(&spirv::KERNELS_BRDF_LUT, size, count, &accum, |row_offset| LutParams { size, samples, row_offset, start, count });
        }
        let out = self.texels("brdf lut", n)?;
        let p = ResolveParams { count: n, src_offset: 0, dst_offset: 0, samples };
        self.run(&[Dispatch {
            kernel: &spirv::KERNELS_RESOLVE_LUT,
            params: bytemuck::bytes_of(&p),
            input: Some(&accum),
            output: &out.buffer,
            invocations: [n, 1, 1],
        }]);
        Ok(out)
    }

    fn brdf_table(&self, size: u32, masking: Masking) -> Result<Texels> {
        let n = size * size;
        if !self.fits("the BRDF table", &[bytes(n as u64)]) {
            return self.upload("brdf table", &Cpu.brdf_table(size, masking)?);
        }
        self.ensure(&spirv::KERNELS_BRDF_TABLE)?;
        let out = self.texels("brdf table", n)?;
        let per_texel = lut::QUADRATURE_MEAN_EVALUATIONS;
        self.table_rows(&spirv::KERNELS_BRDF_TABLE, size, per_texel, &out.buffer, |row_offset| TableParams { size, masking: masking as u32, row_offset });
        Ok(out)
    }

    fn calibrate(&self, src: &Texels, src_layout: CubeLayout, rate: Rate, size: u32, count: u32) -> Result<Texels> {
        self.ensure(&spirv::KERNELS_CALIBRATE)?;
        let out = self.texels("calibration", FACES * size * size)?;
        let p = CalibrateParams { rate: rate as u32, size, src_size: src_layout.size, src_levels: src_layout.levels, count };
        self.run(&[Dispatch { kernel: &spirv::KERNELS_CALIBRATE, params: bytemuck::bytes_of(&p), input: Some(&src.buffer), output: &out.buffer, invocations: [size, size, FACES] }]);
        Ok(out)
    }

    fn probe_raw(&self, p: ProbeParams, texels: &[Vec4], probes: &[Vec4], terms: u32) -> Result<Vec<Vec4>> {
        if !self.fits("the probes", &[bytes((texels.len() + probes.len()) as u64), 3 * bytes(probes.len() as u64)]) {
            return Cpu.probe_raw(p, texels, probes, terms);
        }
        self.ensure(&spirv::KERNELS_PROBE)?;
        let mut input = texels.to_vec();
        input.extend_from_slice(probes);
        let buf = self.upload_bytes("probes", bytemuck::cast_slice(&input));
        let out = self.texels("probe results", 3 * p.count)?;
        for (start, chunk) in chunks(terms) {
            let pc = ProbeParams { start, chunk, ..p };
            self.run(&[Dispatch {
                kernel: &spirv::KERNELS_PROBE,
                params: bytemuck::bytes_of(&pc),
                input: Some(&buf),
                output: &out.buffer,
                invocations: [p.count, 1, 1],
            }]);
        }
        self.read_texels(&out)
    }
}
