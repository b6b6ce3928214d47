//! The [`Kernels`] operations on the GPU: each step's dispatches, recorded from the
//! generated linkage, its chunked sums resolved on the device, its buffers checked against
//! the device's binding limit before anything is allocated.

use super::kernel::{self, Kernel};
use super::{Dispatch, Gpu};
use crate::backend::kernels::{Kernels, Prefilter, chunks};
use crate::backend::split::Split;
use crate::error::{Error, Result};
use crate::placement::{self, texel_bytes as bytes};
use crate::texture::{Equirect, Sh9};
use splitsum_shaders::brdf::microfacet::Masking;
use splitsum_shaders::choice::Choice;
use splitsum_shaders::cubemap::{self, CubeLayout, FACES};
use splitsum_shaders::equirect::Facing;
use splitsum_shaders::glam::Vec4;
use splitsum_shaders::irradiance::SH9;
use splitsum_shaders::calibrate::Rate;
use splitsum_shaders::kernels::{CalibrateParams, DownsampleParams, EquirectParams, IrradianceParams, LutParams, PrefilterParams, ProbeParams, ResolveParams, TableParams};
use splitsum_shaders::{bright, equirect, lut, prefilter};

/// Texels on the device: `count` RGBA f32 texels in `buffer`.
pub struct Texels {
    /// The storage buffer.
    pub buffer: wgpu::Buffer,
    /// Texels it holds.
    pub count: u32,
}

impl Gpu {
    /// Refuses a step whose largest buffer (`needs` bytes) is more than one storage binding
    /// of the device holds: the bake sequence places such a step on the CPU beforehand
    /// (`crate::placement`), and so do the host-data conveniences (`crate::host`).
    fn binds(&self, step: &str, needs: u64) -> Result<()> {
        match placement::place_buffer(needs, Some(self.max_binding())) {
            placement::Place::Device => Ok(()),
            placement::Place::Host { needs, binds } => Err(Error::gpu(format!(
                "{step} needs a {:.0} MiB buffer, more than {} binds ({:.0} MiB): place it on the CPU (splitsum::placement)",
                needs as f64 / 1048576.0,
                self.info.name,
                binds as f64 / 1048576.0
            ))),
        }
    }

    /// An output of `count` texels.
    fn texels(&self, what: &str, count: u32) -> Result<Texels> {
        Ok(Texels { buffer: self.output(what, bytes(count as u64))?, count })
    }

    /// Runs a table kernel over the rows of a `size`×`size` table, `per_texel` integrand
    /// evaluations a texel, with the parameters `params(first row)`: about 2²⁶ evaluations
    /// per submission, so that none runs long enough to trip a display driver's watchdog.
    fn table_rows<P: bytemuck::Pod>(&self, kernel: &Kernel<P>, size: u32, per_texel: u32, output: &wgpu::Buffer, params: impl Fn(u32) -> P) {
        let rows = ((1u64 << 26) / (size as u64 * per_texel.max(1) as u64)).clamp(1, size as u64) as u32;
        let tile = kernel.entry.workgroup_size[1];
        let rows = rows.div_ceil(tile) * tile;
        let mut row = 0;
        while row < size {
            let p = params(row);
            let h = rows.min(size - row);
            self.run(&[kernel.dispatch(&p, None, output, [size, h, 1])]);
            row += h;
        }
    }

    /// Means of `count` texels from partial sums `accum` (three `Vec4` each) from texel
    /// `offset` on, written at the same index of `out`.
    fn resolve(&self, accum: &wgpu::Buffer, out: &wgpu::Buffer, offset: u32, count: u32) {
        let p = ResolveParams { count, src_offset: offset, dst_offset: offset, samples: 0 };
        self.run(&[kernel::RESOLVE_MEANS.dispatch(&p, Some(accum), out, [count, 1, 1])]);
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
                .map(|p| kernel::EQUIRECT_PYRAMID.dispatch(p, None, pyramid, [w >> p.level, h, 1]))
                .collect();
            self.run(&dispatches);
            let out = self.texels("source cube", layout.texel_count())?;
            self.run(&[kernel::EQUIRECT_TO_CUBE.dispatch(&base, Some(pyramid), &out.buffer, [size, size, FACES])]);
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
                kernel::DOWNSAMPLE.dispatch(p, None, cube, [s, s, FACES])
            })
            .collect();
        self.run(&dispatches);
    }
}

impl Gpu {
    internal! {
        /// `texels` back in host memory.
        pub fn read_texels(&self, texels: &Texels) -> Result<Vec<Vec4>> {
            pollster::block_on(self.read_texels_async(texels))
        }
    }

    internal! {
        /// [`Gpu::read_texels`] without blocking (in a browser, where nothing may block).
        pub async fn read_texels_async(&self, texels: &Texels) -> Result<Vec<Vec4>> {
            let bytes = self.read_bytes_async(&texels.buffer).await?;
            Ok(bytemuck::pod_collect_to_vec(&bytes[..texels.count as usize * 16]))
        }
    }
}

impl Kernels for Gpu {
    type Texels = Texels;

    fn max_binding(&self) -> Option<u64> {
        Some(Gpu::max_binding(self))
    }

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
        self.binds(&format!("resampling the {w}×{h} equirect (its row pyramid)"), placement::resampling_buffer(w, h, layout))?;
        let mut texels = env.texels.clone();
        texels.resize(equirect::pyramid_len(w, h) as usize, Vec4::ZERO);
        let pyramid = self.upload_bytes("equirect pyramid", bytemuck::cast_slice(&texels));
        self.pyramid_to_cube(&pyramid, w, h, size, supersample, facing)
    }

    fn build_mips(&self, cube: &mut Texels, layout: CubeLayout) -> Result<()> {
        self.binds(&format!("the mips of the {}² cube", layout.size), bytes(cube.count as u64))?;
        self.mips(&cube.buffer, layout);
        Ok(())
    }

    fn prefilter(&self, src: &Texels, src_layout: CubeLayout, job: &Prefilter<'_>, split: Option<&Split<Texels>>) -> Result<Texels> {
        let out = job.layout;
        self.binds(&format!("the {} cube from the {}² source cube", job.what, src_layout.size), placement::sums_buffer(src.count as u64, out))?;
        let accum = self.output("prefilter sums", 3 * bytes(out.texel_count() as u64))?;
        let result = self.texels(job.what, out.texel_count())?;
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
                self.run(&[kernel::PREFILTER_MIRROR.dispatch(&p, Some(&src.buffer), &result.buffer, [s, s, FACES])]);
                continue;
            }
            if let Some(split) = split.filter(|_| crate::backend::split::uses_split(job.lobe, r, src_layout.size)) {
                // The residual's samples or exact sum, then the excess list: on the level's
                // own sums, or traced at the split level's size into a buffer that holds the
                // list after it, each texel then read from it with the list's terms.
                let residual_level = split.level_of(src_layout, exact_level);
                let exact_level = if exact_level == prefilter::SAMPLED { exact_level } else { residual_level };
                let q = PrefilterParams { src_size: split.layout.size, src_levels: split.layout.levels, exact_level, ..p };
                let kernel = if exact_level == prefilter::SAMPLED { &kernel::PREFILTER_SAMPLED } else { &kernel::PREFILTER_EXACT };
                let terms = split.terms(exact_level, residual_level, samples);
                if let Some(ts) = split.traced(job.lobe, r, s, src_layout.size) {
                    // The ring reads its tile's entries (`split::ring_table`), any other
                    // level the whole list and its density table (`bright`), written after it.
                    let ring = r <= 0.0;
                    let tail = if ring { split.ring.as_ref().expect("a job with a ring has its table") } else { &split.list };
                    let (copied, table) = if ring { (tail.count, Vec::new()) } else { (bright::ENTRY * split.entries, bright::density_table(job.lobe.alpha(r)).collect()) };
                    let traced = FACES * ts * ts;
                    let buf = self.output("sheen traced level", bytes((traced + copied + table.len() as u32) as u64))?;
                    let mut encoder = self.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
                    if copied > 0 {
                        encoder.copy_buffer_to_buffer(&tail.buffer, 0, &buf, bytes(traced as u64), bytes(copied as u64));
                    }
                    if !table.is_empty() {
                        self.queue.write_buffer(&buf, bytes((traced + copied) as u64), bytemuck::cast_slice(&table));
                    }
                    self.queue.submit([encoder.finish()]);
                    let sums = self.output("sheen traced sums", 3 * bytes(traced as u64))?;
                    let q = PrefilterParams { dst_size: ts, dst_offset: 0, ..q };
                    for (start, count) in chunks(terms) {
                        let q = PrefilterParams { start, count, ..q };
                        self.run(&[kernel.dispatch(&q, Some(&split.residual.buffer), &sums, [ts, ts, FACES])]);
                    }
                    self.resolve(&sums, &buf, 0, traced);
                    let q = PrefilterParams { src_size: ts, start: traced, count: split.entries, ..p };
                    self.run(&[kernel::PREFILTER_TRACED.dispatch(&q, Some(&buf), &result.buffer, [s, s, FACES])]);
                    continue;
                }
                for (start, count) in chunks(terms) {
                    let q = PrefilterParams { start, count, ..q };
                    self.run(&[kernel.dispatch(&q, Some(&split.residual.buffer), &accum, [s, s, FACES])]);
                }
                // `chunks` runs at least one chunk; an empty list needs none.
                if split.entries > 0 {
                    // The level's density table, then the list (`bright::list_start`).
                    let table: Vec<Vec4> = bright::density_table(job.lobe.alpha(r)).collect();
                    let list = self.output("sheen excess and table", bytes((table.len() as u32 + split.list.count) as u64))?;
                    if !table.is_empty() {
                        self.queue.write_buffer(&list, 0, bytemuck::cast_slice(&table));
                    }
                    let mut encoder = self.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
                    encoder.copy_buffer_to_buffer(&split.list.buffer, 0, &list, bytes(table.len() as u64), bytes(split.list.count as u64));
                    self.queue.submit([encoder.finish()]);
                    for (start, count) in chunks(split.entries) {
                        let q = PrefilterParams { start, count, ..q };
                        self.run(&[kernel::PREFILTER_BRIGHT.dispatch(&q, Some(&list), &accum, [s, s, FACES])]);
                    }
                }
                self.resolve(&accum, &result.buffer, out.level_offset(m), FACES * s * s);
                continue;
            }
            // An exact sum runs over every texel of its source level, in chunks.
            let (terms, kernel) = if exact_level == prefilter::SAMPLED {
                (samples, &kernel::PREFILTER_SAMPLED)
            } else {
                (FACES * src_layout.level_size(exact_level).pow(2), &kernel::PREFILTER_EXACT)
            };
            for (start, count) in chunks(terms) {
                let p = PrefilterParams { start, count, ..p };
                self.run(&[kernel.dispatch(&p, Some(&src.buffer), &accum, [s, s, FACES])]);
            }
            self.resolve(&accum, &result.buffer, out.level_offset(m), FACES * s * s);
        }
        Ok(result)
    }

    fn irradiance(&self, src: &Texels, src_layout: CubeLayout, level: u32, size: u32) -> Result<Texels> {
        let layout = CubeLayout::new(size, 1);
        self.binds(&format!("the irradiance from the {}² source cube", src_layout.size), placement::sums_buffer(src.count as u64, layout))?;
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
            self.run(&[kernel::IRRADIANCE_CUBE.dispatch(&p, Some(&input), &accum, [size, size, FACES])]);
        }
        let result = self.texels("irradiance", layout.texel_count())?;
        self.resolve(&accum, &result.buffer, 0, layout.texel_count());
        Ok(result)
    }

    fn sh9(&self, src: &Texels, src_layout: CubeLayout, level: u32) -> Result<Sh9> {
        self.binds(&format!("SH9 from the {}² source cube", src_layout.size), bytes(src.count as u64))?;
        let s = src_layout.level_size(level);
        let n = FACES * s * (SH9 as u32 + 1);
        let dst = self.texels("sh9 rows", n)?;
        let p = IrradianceParams { src_size: src_layout.size, src_levels: src_layout.levels, src_level: level, dst_size: 0, start: 0, count: 0, geometry: cubemap::INLINE_GEOMETRY };
        self.run(&[kernel::IRRADIANCE_SH9_PROJECT.dispatch(&p, Some(&src.buffer), &dst.buffer, [s, 1, FACES])]);
        let rows: Vec<[Vec4; SH9 + 1]> = self.read_texels(&dst)?.chunks_exact(SH9 + 1).map(|c| c.try_into().expect("10 per row")).collect();
        Ok(Sh9::from_rows(&rows))
    }

    fn brdf_lut(&self, size: u32, samples: u32) -> Result<Texels> {
        let n = size * size;
        self.binds("the BRDF table", bytes(n as u64))?;
        self.ensure(&kernel::BRDF_LUT)?;
        self.ensure(&kernel::RESOLVE_LUT)?;
        let accum = self.output("brdf lut sums", bytes(n as u64))?;
        for (start, count) in chunks(samples) {
            self.table_rows(&kernel::BRDF_LUT, size, count, &accum, |row_offset| LutParams { size, samples, row_offset, start, count });
        }
        let out = self.texels("brdf lut", n)?;
        let p = ResolveParams { count: n, src_offset: 0, dst_offset: 0, samples };
        self.run(&[kernel::RESOLVE_LUT.dispatch(&p, Some(&accum), &out.buffer, [n, 1, 1])]);
        Ok(out)
    }

    fn brdf_table(&self, size: u32, masking: Masking) -> Result<Texels> {
        let n = size * size;
        self.binds("the BRDF table", bytes(n as u64))?;
        self.ensure(&kernel::BRDF_TABLE)?;
        let out = self.texels("brdf table", n)?;
        let per_texel = lut::QUADRATURE_MEAN_EVALUATIONS;
        self.table_rows(&kernel::BRDF_TABLE, size, per_texel, &out.buffer, |row_offset| TableParams { size, masking: masking as u32, row_offset });
        Ok(out)
    }

    fn calibrate(&self, src: &Texels, src_layout: CubeLayout, rate: Rate, size: u32, count: u32) -> Result<Texels> {
        self.ensure(&kernel::CALIBRATE)?;
        let out = self.texels("calibration", FACES * size * size)?;
        let p = CalibrateParams { rate: rate as u32, size, src_size: src_layout.size, src_levels: src_layout.levels, count };
        self.run(&[kernel::CALIBRATE.dispatch(&p, Some(&src.buffer), &out.buffer, [size, size, FACES])]);
        Ok(out)
    }

    fn probe_raw(&self, p: ProbeParams, texels: &[Vec4], probes: &[Vec4], terms: u32) -> Result<Vec<Vec4>> {
        self.binds("the probes", placement::probes_buffer(texels.len() as u64, probes.len() as u64))?;
        self.ensure(&kernel::PROBE)?;
        let mut input = texels.to_vec();
        input.extend_from_slice(probes);
        let buf = self.upload_bytes("probes", bytemuck::cast_slice(&input));
        let out = self.texels("probe results", 3 * p.count)?;
        for (start, chunk) in chunks(terms) {
            let pc = ProbeParams { start, chunk, ..p };
            self.run(&[kernel::PROBE.dispatch(&pc, Some(&buf), &out.buffer, [p.count, 1, 1])]);
        }
        self.read_texels(&out)
    }
}
