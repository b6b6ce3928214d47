//! Baking into textures a wgpu renderer binds directly, on the caller's device.
//!
//! [`Baker`] holds the caller's `wgpu::Device` and `Queue` and bakes with the kernels on
//! that device ([`Compute::Gpu`]: the products never leave it) or natively on the CPU
//! ([`Compute::Cpu`]: the products are uploaded). Either way the result is an [`Ibl`]: the
//! prefiltered specular cube with one roughness per mip, the irradiance cube (`E/π`) and
//! the split-sum BRDF table, as half-float textures. Halves are packed by
//! `splitsum_shaders::half::pack_radiance` on both backends (the GPU in a kernel, the CPU
//! natively), so the two agree bit for bit where their f32 products do; values beyond
//! 65504 (a sun) are clamped to 65504, never ∞.
//!
//! The source is CPU data ([`Source::Environment`]) or a texture of the caller's
//! ([`Source::Texture`]: an equirect `2h × h`, or a cube of six square layers; RGBA16F or
//! RGBA32F with `COPY_SRC`). Nothing is read back unless asked ([`Ibl::read`]).

use crate::backend::{Cpu, Gpu, Kernels, gpu, gpu::Texels};
use crate::bake::{self, Baked, Made, Timing};
use crate::estimate::Estimator;
use crate::environment::Environment;
use crate::error::{Error, Result};
use crate::product::{Item, Layout};
use crate::settings::{InputShape, Job, Product, Products, Settings};
use std::collections::BTreeMap;
use crate::texture::{Cube, Equirect, Lut};
use splitsum_shaders::choice::Choice;
use splitsum_shaders::cubemap::{CubeLayout, FACES};
use splitsum_shaders::glam::Vec4;
use splitsum_shaders::half::{clean_radiance, copied_texel, f16_bits_to_f32, pack_radiance};
use splitsum_shaders::kernels::RowsParams;
use splitsum_shaders::prefilter::RoughnessMapping;

/// Where the bake runs.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Compute {
    /// The kernels, on the caller's device.
    Gpu,
    /// The same functions natively on the CPU (rayon), the results uploaded.
    Cpu,
}

/// What to bake from.
///
/// ```no_run
/// # fn sources(device: &wgpu::Device, queue: &wgpu::Queue, sky_texture: &wgpu::Texture) -> Result<(), splitsum::Error> {
/// use splitsum::{Baker, Compute, Settings, Source};
/// let baker = Baker::new(device, queue, Compute::Gpu)?;
/// // From a file read into host memory (.hdr, .exr, or a folder of six faces)…
/// let (sky, _report) = splitsum::environment::load(std::path::Path::new("sky.hdr"), false)?;
/// let from_file = baker.bake(Source::Environment(&sky), &Settings::default())?;
/// // …or from a texture already on the device (an equirect or a six-layer cube).
/// let from_texture = baker.bake(Source::Texture(sky_texture), &Settings::default())?;
/// # Ok(()) }
/// ```
#[derive(Copy, Clone)]
pub enum Source<'a> {
    /// An equirect image or six cube faces in host memory (`crate::environment` reads
    /// them from files).
    Environment(&'a Environment),
    /// A texture on the caller's device: an equirect (`2h × h`, one layer) or a cube (six
    /// square layers; mip 0 is read), RGBA16F or RGBA32F, with `COPY_SRC` usage. NaN and
    /// negative texels are read as 0.
    Texture(&'a wgpu::Texture),
}

/// The sheen products (`KHR_materials_sheen`) as textures on the caller's device.
pub struct SheenTextures {
    /// Charlie-prefiltered radiance: a cube of `Rgba16Float` with the specular cube's size
    /// and mips, mip `m` at sheen roughness `roughness[m]` (`m/(mips − 1)`, read at
    /// `lod = sheen roughness · (mips − 1)` as the glTF Sample Viewer reads it).
    pub cube: wgpu::Texture,
    /// The sheen tables, `Rg16Float`: the Charlie table (the sheen albedo with Neubelt's
    /// visibility: sheen = cube · colour · R) and the sheen albedo with the Charlie
    /// visibility (the layers below keep `1 − max(colour)·G`); x = n·v, y = sheen roughness.
    pub tables: wgpu::Texture,
    /// Sheen roughness of each mip.
    pub roughness: Vec<f32>,
}

/// The baked products as textures on the caller's device.
///
/// ```no_run
/// # fn bind(device: &wgpu::Device, queue: &wgpu::Queue, ibl: &splitsum::Ibl) -> Result<(), splitsum::Error> {
/// use splitsum::Ibl;
/// // Bindings 0, 1, 2: the specular cube, the irradiance cube, the table.
/// let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
///     label: Some("ibl"),
///     entries: &Ibl::layout_entries(0, wgpu::ShaderStages::FRAGMENT),
/// });
/// let views = ibl.views();
/// let group = device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some("ibl"), layout: &layout, entries: &views.entries(0) });
/// // The shader reads the specular cube at this lod for roughness 0.5.
/// let lod = ibl.lod(0.5);
/// // Back to host memory, and as files.
/// let baked = ibl.read(device, queue)?;
/// splitsum::output::write(std::path::Path::new("out"), &baked, &ibl.job, Default::default())?;
/// # Ok(()) }
/// ```
pub struct Ibl {
    /// Prefiltered specular radiance: a cube (six layers) of `Rgba16Float`, mip `m` at
    /// roughness `roughness[m]` (GGX, `α = roughness²`).
    pub specular: wgpu::Texture,
    /// Irradiance divided by π: a cube of `Rgba16Float`; a Lambert surface of albedo `ρ`
    /// reflects `ρ` times the value.
    pub irradiance: wgpu::Texture,
    /// The split-sum BRDF table, `Rg16Float`: `(A, B)` with x = n·v, y = roughness; the
    /// specular reflectance is `F₀·A + B` (Karis 2013).
    pub brdf: wgpu::Texture,
    /// Roughness of each specular mip.
    pub roughness: Vec<f32>,
    /// How roughness is spread over the mips (`roughness[m] = mapping.roughness(m, mips)`).
    pub mapping: RoughnessMapping,
    /// The sheen products, where the bake made them ([`Baker::bake_with_sheen`]).
    pub sheen: Option<SheenTextures>,
    /// Wall time of each step.
    pub timings: Vec<Timing>,
    /// The bake, resolved: every setting it used (what `output::write` records).
    pub job: Job,
}

/// The views a renderer binds ([`Ibl::views`]): the two cubes as `Cube` views of every
/// mip, the table as a 2D view.
pub struct IblViews {
    /// The prefiltered specular cube.
    pub specular: wgpu::TextureView,
    /// The irradiance cube (`E/π`).
    pub irradiance: wgpu::TextureView,
    /// The BRDF table.
    pub brdf: wgpu::TextureView,
}

impl IblViews {
    /// Bind group entries for the specular cube, the irradiance cube and the table at
    /// bindings `first`, `first + 1` and `first + 2` (as [`Ibl::layout_entries`] lays them
    /// out).
    pub fn entries(&self, first: u32) -> [wgpu::BindGroupEntry<'_>; 3] {
        let entry = |k: u32, view| wgpu::BindGroupEntry { binding: first + k, resource: wgpu::BindingResource::TextureView(view) };
        [entry(0, &self.specular), entry(1, &self.irradiance), entry(2, &self.brdf)]
    }
}

/// Bakes on the caller's device.
///
/// ```no_run
/// # fn bake(device: &wgpu::Device, queue: &wgpu::Queue) -> Result<(), splitsum::Error> {
/// use splitsum::{Baker, Compute, Settings, Source};
/// let (sky, _report) = splitsum::environment::load(std::path::Path::new("sky.exr"), false)?;
/// // Pipelines are built once: keep the baker to bake again.
/// let baker = Baker::new(device, queue, Compute::Gpu)?;
/// let ibl = baker.bake(Source::Environment(&sky), &Settings::default())?;
/// let with_sheen = baker.bake_with_sheen(Source::Environment(&sky), &Settings::default())?;
/// assert!(ibl.sheen.is_none() && with_sheen.sheen.is_some());
/// # Ok(()) }
/// ```
pub struct Baker {
    device: wgpu::Device,
    queue: wgpu::Queue,
    gpu: Option<Gpu>,
}

/// Bytes per row of a texture copy: `bytes` rounded up to wgpu's 256-byte alignment.
fn pitch(bytes: u32) -> u32 {
    bytes.next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
}

impl Baker {
    /// A baker on `device` and `queue` (wgpu handles are shared: splitsum's work runs on
    /// the caller's queue). With [`Compute::Gpu`] this builds the kernels' pipelines (once;
    /// keep the baker to bake again without that cost).
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue, compute: Compute) -> Result<Self> {
        pollster::block_on(Self::new_async(device, queue, compute))
    }

    /// [`Baker::new`] without blocking: what a browser (wgpu's WebGPU backend) needs, where
    /// nothing may block; natively the same.
    pub async fn new_async(device: &wgpu::Device, queue: &wgpu::Queue, compute: Compute) -> Result<Self> {
        let gpu = match compute {
            Compute::Gpu => Some(Gpu::on_device_async(device, queue).await?),
            Compute::Cpu => None,
        };
        Ok(Self { device: device.clone(), queue: queue.clone(), gpu })
    }

    /// Where this baker bakes.
    pub fn compute(&self) -> Compute {
        if self.gpu.is_some() { Compute::Gpu } else { Compute::Cpu }
    }

    /// Bakes the specular cube, the irradiance cube and the BRDF table of `source` with
    /// `settings` (validated first) into textures on the baker's device.
    pub fn bake(&self, source: Source<'_>, settings: &Settings) -> Result<Ibl> {
        self.bake_products(source, settings, false)
    }

    /// As [`Baker::bake`], and the sheen cube and tables too ([`Ibl::sheen`]).
    pub fn bake_with_sheen(&self, source: Source<'_>, settings: &Settings) -> Result<Ibl> {
        self.bake_products(source, settings, true)
    }

    fn bake_products(&self, source: Source<'_>, settings: &Settings, sheen: bool) -> Result<Ibl> {
        let shape = match source {
            Source::Environment(env) => InputShape::of(env),
            Source::Texture(t) => match texture_shape(t)? {
                Shape::Equirect => InputShape::Equirect { width: t.width(), height: t.height() },
                Shape::Cube => InputShape::Cube { size: t.width() },
            },
        };
        let job = settings.resolve(shape, Products::DISPLAY.with_sheen(sheen))?;
        match &self.gpu {
            Some(g) => {
                let made = match source {
                    Source::Environment(env) => bake::make(g, &mut Estimator::built_in(true), env, &job)?,
                    Source::Texture(t) => {
                        let mut est = Estimator::built_in(true);
                        let mut timings = Vec::new();
                        let start = web_time::Instant::now();
                        let (src, layout) = texture_source_cube(g, t, &job)?;
                        g.finish()?;
                        timings.push(Timing { step: Product::SourceCube, seconds: start.elapsed().as_secs_f64(), estimate: None });
                        bake::products(g, src, layout, &job, &mut est, timings)?
                    }
                };
                self.gpu_textures(g, made, &job)
            }
            None => {
                let owned;
                let env = match source {
                    Source::Environment(env) => env,
                    Source::Texture(t) => {
                        owned = self.read_source(t)?;
                        &owned
                    }
                };
                let made = bake::make(&Cpu, &mut Estimator::built_in(false), env, &job)?;
                let baked = bake::read(&Cpu, made, &job)?;
                self.upload(&baked, &job)
            }
        }
    }

    /// An empty square texture for the products: `layers` layers (6 for a cube) of
    /// `size`², `mips` levels, sampled, written and read back by copies.
    fn texture(&self, label: &str, size: u32, layers: u32, mips: u32, format: wgpu::TextureFormat) -> wgpu::Texture {
        self.device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d { width: size, height: size, depth_or_array_layers: layers },
            mip_level_count: mips,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        })
    }

    /// The texture of each product of `job` a renderer reads (every cube and table but
    /// the source cube), empty: a cube of `Rgba16Float` in the product's layout, a table of
    /// `Rg16Float`.
    fn textures(&self, job: &Job) -> BTreeMap<Product, (wgpu::Texture, CubeLayout, u32, u32)> {
        let mut out = BTreeMap::new();
        for p in job.products.iter().filter(|p| *p != Product::SourceCube) {
            let label = format!("splitsum {p}");
            // (layout, layers, channels)
            let (layout, layers, channels, format) = match job.layout(p) {
                Layout::Cube(l) => (l, FACES, 4, wgpu::TextureFormat::Rgba16Float),
                Layout::Table(size) => (CubeLayout::new(size, 1), 1, 2, wgpu::TextureFormat::Rg16Float),
                Layout::Coefficients => continue,
            };
            out.insert(p, (self.texture(&label, layout.size, layers, layout.levels, format), layout, layers, channels));
        }
        out
    }

    /// The [`Ibl`] of `job` from the texture of each product.
    fn ibl(&self, job: &Job, mut textures: BTreeMap<Product, (wgpu::Texture, CubeLayout, u32, u32)>, timings: Vec<Timing>) -> Result<Ibl> {
        let mut take = |p: Product| textures.remove(&p).map(|t| t.0).ok_or_else(|| Error::Invalid(format!("a display bake made no {p}")));
        let (specular, irradiance, brdf) = (take(Product::Specular)?, take(Product::Irradiance)?, take(Product::BrdfTable)?);
        let sheen = if job.products.has(Product::Sheen) {
            Some(SheenTextures { cube: take(Product::Sheen)?, tables: take(Product::SheenTables)?, roughness: job.prefiltered[&Product::Sheen].roughness_per_mip.clone() })
        } else {
            None
        };
        Ok(Ibl { specular, irradiance, brdf, roughness: job.roughness_per_mip().to_vec(), mapping: job.mapping, sheen, timings, job: job.clone() })
    }

    /// Packs the products on the device and copies them into the textures.
    fn gpu_textures(&self, g: &Gpu, made: Made<Texels>, job: &Job) -> Result<Ibl> {
        let textures = self.textures(job);
        for (p, (texture, layout, layers, channels)) in &textures {
            let texels = made.cube(*p).or(made.table(*p)).ok_or_else(|| Error::Invalid(format!("a display bake made no {p}")))?;
            self.gpu_copy(g, texels, *layout, *layers, *channels, texture)?;
        }
        self.ibl(job, textures, made.timings)
    }

    /// Packs every level of `texels` (laid out as `layout` with `layers` layers) into
    /// halves, `channels` per texel, and copies them into `texture`.
    fn gpu_copy(&self, g: &Gpu, texels: &Texels, layout: CubeLayout, layers: u32, channels: u32, texture: &wgpu::Texture) -> Result<()> {
        let mut params = Vec::new();
        let mut words = 0u32;
        for m in 0..layout.levels {
            let s = layout.level_size(m);
            let row_words = pitch(s * channels * 2) / 4;
            let offset = if layers == 1 { 0 } else { layout.level_offset(m) };
            params.push(RowsParams { width: s, rows: layers * s, texel_offset: offset, row_words, word_offset: words, channels, half: 1 });
            words += row_words * layers * s;
        }
        let packed = g.output("packed halves", words as u64 * 4)?;
        let mut encoder = self.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("splitsum textures") });
        let dispatches: Vec<crate::backend::gpu::Dispatch> = params
            .iter()
            .map(|p| crate::backend::gpu::kernel::PACK_HALF.dispatch(p, Some(&texels.buffer), &packed, [p.width, p.rows, 1]))
            .collect();
        g.record(&mut encoder, &dispatches);
        for (m, p) in params.iter().enumerate() {
            encoder.copy_buffer_to_texture(
                wgpu::TexelCopyBufferInfo {
                    buffer: &packed,
                    layout: wgpu::TexelCopyBufferLayout {
                        offset: p.word_offset as u64 * 4,
                        bytes_per_row: Some(p.row_words * 4),
                        rows_per_image: Some(p.width),
                    },
                },
                wgpu::TexelCopyTextureInfo { texture, mip_level: m as u32, origin: wgpu::Origin3d::ZERO, aspect: wgpu::TextureAspect::All },
                wgpu::Extent3d { width: p.width, height: p.width, depth_or_array_layers: layers },
            );
        }
        self.queue.submit([encoder.finish()]);
        Ok(())
    }

    /// Packs host products into halves (the same function the kernel runs) and writes
    /// them into new textures.
    fn upload(&self, baked: &Baked, job: &Job) -> Result<Ibl> {
        let write = |texture: &wgpu::Texture, texels: &[Vec4], layout: CubeLayout, layers: u32, channels: u32| {
            for m in 0..layout.levels {
                let s = layout.level_size(m);
                let start = if layers == 1 { 0 } else { layout.level_offset(m) as usize };
                let level = &texels[start..start + (layers * s * s) as usize];
                let words: Vec<u32> = level
                    .iter()
                    .flat_map(|v| if channels == 4 { vec![pack_radiance(v.x, v.y), pack_radiance(v.z, v.w)] } else { vec![pack_radiance(v.x, v.y)] })
                    .collect();
                self.queue.write_texture(
                    wgpu::TexelCopyTextureInfo { texture, mip_level: m, origin: wgpu::Origin3d::ZERO, aspect: wgpu::TextureAspect::All },
                    bytemuck::cast_slice(&words),
                    wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(s * channels * 2), rows_per_image: Some(s) },
                    wgpu::Extent3d { width: s, height: s, depth_or_array_layers: layers },
                );
            }
        };
        let textures = self.textures(job);
        for (p, (texture, layout, layers, channels)) in &textures {
            match (baked.cube(*p), baked.table(*p)) {
                (Some(cube), _) => write(texture, &cube.texels, *layout, *layers, *channels),
                (None, Some(table)) => {
                    let texels: Vec<Vec4> = table.texels.iter().map(|t| t.extend(0.0).extend(0.0)).collect();
                    write(texture, &texels, *layout, *layers, *channels);
                }
                (None, None) => return Err(Error::Invalid(format!("a display bake made no {p}"))),
            }
        }
        self.ibl(job, textures, baked.timings.clone())
    }

    /// Copies mip 0 of `texture` (every layer) into a buffer of 256-byte-aligned rows:
    /// the buffer, its row pitch in bytes, and whether the texels are halves.
    fn copy_out(&self, texture: &wgpu::Texture, usage: wgpu::BufferUsages) -> Result<(wgpu::Buffer, u32, bool)> {
        let half = match texture.format() {
            wgpu::TextureFormat::Rgba16Float => true,
            wgpu::TextureFormat::Rgba32Float => false,
            f => return Err(Error::Invalid(format!("the source texture is {f:?}; splitsum reads Rgba16Float or Rgba32Float"))),
        };
        if !texture.usage().contains(wgpu::TextureUsages::COPY_SRC) {
            return Err(Error::Invalid("the source texture needs TextureUsages::COPY_SRC for splitsum to read it".into()));
        }
        let size = texture.size();
        let row = pitch(size.width * if half { 8 } else { 16 });
        let buffer = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("splitsum source texture"),
            size: row as u64 * size.height as u64 * size.depth_or_array_layers as u64,
            usage: usage | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = self.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("splitsum source") });
        encoder.copy_texture_to_buffer(
            texture.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(row), rows_per_image: Some(size.height) },
            },
            size,
        );
        self.queue.submit([encoder.finish()]);
        Ok((buffer, row, half))
    }

    /// A caller's texture read into host memory (the CPU backend's source).
    fn read_source(&self, texture: &wgpu::Texture) -> Result<Environment> {
        let shape = texture_shape(texture)?;
        if matches!(shape, Shape::Cube) && !gpu::copies_cubes(&self.device) {
            let size = texture.size().width;
            let layout = CubeLayout::new(size, 1);
            let texels = pollster::block_on(read_cube(&self.device, &self.queue, texture, layout))?;
            return Ok(Environment::Cube(Cube { layout, texels: texels.into_iter().map(|v| v.truncate().extend(1.0)).collect() }));
        }
        let (buffer, row, half) = self.copy_out(texture, wgpu::BufferUsages::MAP_READ)?;
        let bytes = crate::backend::gpu::map_read(&self.device, &buffer)?;
        let words: &[u32] = bytemuck::cast_slice(&bytes);
        let size = texture.size();
        let row_words = (row / 4) as usize;
        let mut texels = Vec::with_capacity((size.width * size.height * size.depth_or_array_layers) as usize);
        for r in 0..(size.height * size.depth_or_array_layers) as usize {
            for x in 0..size.width as usize {
                let v = clean_radiance(copied_texel(words, r * row_words, x, half));
                texels.push(v.truncate().extend(1.0));
            }
        }
        Ok(match shape {
            Shape::Equirect => Environment::Equirect(Equirect { width: size.width, height: size.height, texels }),
            Shape::Cube => Environment::Cube(Cube { layout: CubeLayout::new(size.width, 1), texels }),
        })
    }
}

/// What a source texture holds.
enum Shape {
    Equirect,
    Cube,
}

fn texture_shape(t: &wgpu::Texture) -> Result<Shape> {
    let s = t.size();
    if s.depth_or_array_layers == FACES && s.width == s.height && s.width.is_power_of_two() {
        Ok(Shape::Cube)
    } else if s.depth_or_array_layers == 1 && s.width == 2 * s.height && s.height > 0 {
        Ok(Shape::Equirect)
    } else {
        Err(Error::Invalid(format!(
            "the source texture is {}×{} with {} layers; splitsum reads an equirect (2h×h, one layer) or a cube (six square layers of a power-of-two size)",
            s.width, s.height, s.depth_or_array_layers
        )))
    }
}

/// Every level `layout` names of the cube `texture`, read on the device with the
/// `read_cube` kernel (where the device cannot copy cubes, `gpu::copies_cubes`), into host
/// memory.
async fn read_cube(device: &wgpu::Device, queue: &wgpu::Queue, texture: &wgpu::Texture, layout: CubeLayout) -> Result<Vec<Vec4>> {
    let bytes = layout.texel_count() as u64 * 16;
    let out = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("splitsum cube texels"),
        size: bytes,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("splitsum readback"),
        size: bytes,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("splitsum read cube") });
    gpu::CubeReader::new(device, texture.format()).record(device, queue, &mut encoder, texture, layout, &out);
    encoder.copy_buffer_to_buffer(&out, 0, &staging, 0, bytes);
    queue.submit([encoder.finish()]);
    Ok(bytemuck::cast_slice(&gpu::map_read_async(device, &staging).await?).to_vec())
}

/// The source cube of `job` from a texture on the device, without leaving it.
fn texture_source_cube(g: &Gpu, texture: &wgpu::Texture, job: &Job) -> Result<(Texels, CubeLayout)> {
    let shape = texture_shape(texture)?;
    if matches!(shape, Shape::Cube) && !gpu::copies_cubes(&g.device) {
        let size = texture.size().width;
        let count = CubeLayout::new(size, CubeLayout::full_chain(size)).texel_count();
        let texels = Texels { buffer: g.output("source texels", count as u64 * 16)?, count };
        let mut encoder = g.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("splitsum source cube") });
        gpu::CubeReader::new(&g.device, texture.format()).record(&g.device, &g.queue, &mut encoder, texture, CubeLayout::new(size, 1), &texels.buffer);
        g.queue.submit([encoder.finish()]);
        return cube_from_texture(g, texels, size, job);
    }
    let baker = Baker { device: g.device.clone(), queue: g.queue.clone(), gpu: None };
    let (words, row, half) = baker.copy_out(texture, wgpu::BufferUsages::STORAGE)?;
    let size = texture.size();
    let rows = size.height * size.depth_or_array_layers;
    let count = match shape {
        Shape::Equirect => splitsum_shaders::equirect::pyramid_len(size.width, size.height),
        Shape::Cube => CubeLayout::new(size.width, CubeLayout::full_chain(size.width)).texel_count(),
    };
    let texels = Texels { buffer: g.output("source texels", count as u64 * 16)?, count };
    let p = RowsParams { width: size.width, rows, texel_offset: 0, row_words: row / 4, word_offset: 0, channels: 4, half: half as u32 };
    g.run(&[crate::backend::gpu::kernel::UNPACK_ROWS.dispatch(&p, Some(&words), &texels.buffer, [size.width, rows, 1])]);
    match shape {
        Shape::Equirect => Ok((g.pyramid_to_cube(&texels.buffer, size.width, size.height, job.source_size, job.supersample, job.facing)?, job.source_layout())),
        Shape::Cube => cube_from_texture(g, texels, size.width, job),
    }
}

/// The source cube of `job` from a cube texture's level 0, read into `texels` (its full
/// mip chain long), faces `face` wide.
fn cube_from_texture(g: &Gpu, texels: Texels, face: u32, job: &Job) -> Result<(Texels, CubeLayout)> {
    if job.mirror_faces {
        return Err(Error::setting(
            crate::settings::Field::Target,
            format!("{}: a cube texture is not mirrored on the device; pass its faces as host data (Source::Environment) or an equirect", job.target.name()),
        ));
    }
    bake::cube_source(g, texels, face, job)
}

impl Ibl {
    /// Bind group layout entries for the specular cube, the irradiance cube (both
    /// `texture_cube<f32>`) and the table (`texture_2d<f32>`), filterable float textures at
    /// bindings `first`, `first + 1` and `first + 2`, visible to `visibility`. Sample them
    /// with a linear, mipmapped sampler: the specular cube at [`Ibl::lod`] of the surface's
    /// roughness, the irradiance along the normal, the table at `(n·v, roughness)`.
    pub fn layout_entries(first: u32, visibility: wgpu::ShaderStages) -> [wgpu::BindGroupLayoutEntry; 3] {
        let entry = |k: u32, view_dimension| wgpu::BindGroupLayoutEntry {
            binding: first + k,
            visibility,
            ty: wgpu::BindingType::Texture { sample_type: wgpu::TextureSampleType::Float { filterable: true }, view_dimension, multisampled: false },
            count: None,
        };
        [entry(0, wgpu::TextureViewDimension::Cube), entry(1, wgpu::TextureViewDimension::Cube), entry(2, wgpu::TextureViewDimension::D2)]
    }

    /// The views a renderer binds (see [`Ibl::layout_entries`]).
    pub fn views(&self) -> IblViews {
        let cube = |t: &wgpu::Texture| t.create_view(&wgpu::TextureViewDescriptor { dimension: Some(wgpu::TextureViewDimension::Cube), ..Default::default() });
        IblViews { specular: cube(&self.specular), irradiance: cube(&self.irradiance), brdf: self.brdf.create_view(&Default::default()) }
    }

    /// The specular mip (fractional, for trilinear lookups) that holds `roughness`.
    pub fn lod(&self, roughness: f32) -> f32 {
        self.mapping.lod(roughness, self.roughness.len() as u32)
    }

    /// Reads the textures back (decoding the halves) into host memory, as [`Baked`]
    /// products (the specular and irradiance cubes and the table; no source cube or SH9):
    /// for files (`output::write`), tests and inspection.
    pub fn read(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Result<Baked> {
        pollster::block_on(self.read_async(device, queue))
    }

    /// [`Ibl::read`] without blocking (in a browser, where nothing may block).
    pub async fn read_async(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Result<Baked> {
        let cube = async |t: &wgpu::Texture| -> Result<Cube> {
            let layout = CubeLayout::new(t.size().width, t.mip_level_count());
            let texels = if gpu::copies_cubes(device) { read_halves(device, queue, t, 4).await? } else { read_cube(device, queue, t, layout).await? };
            Ok(Cube { layout, texels })
        };
        let table = async |t: &wgpu::Texture| -> Result<Lut> {
            Ok(Lut { size: t.size().width, texels: read_halves(device, queue, t, 2).await?.into_iter().map(|v| v.truncate().truncate()).collect() })
        };
        let mut baked = Baked::new(self.timings.clone());
        baked.insert(Product::Specular, Item::Cube(cube(&self.specular).await?));
        baked.insert(Product::Irradiance, Item::Cube(cube(&self.irradiance).await?));
        baked.insert(Product::BrdfTable, Item::Table(table(&self.brdf).await?));
        if let Some(t) = &self.sheen {
            baked.insert(Product::Sheen, Item::Cube(cube(&t.cube).await?));
            baked.insert(Product::SheenTables, Item::Table(table(&t.tables).await?));
        }
        Ok(baked)
    }
}

/// Every level and layer of the half-float texture `t` (`channels` per texel: 4, or 2 read
/// as `(x, y, 0, 0)`) copied out and decoded.
async fn read_halves(device: &wgpu::Device, queue: &wgpu::Queue, t: &wgpu::Texture, channels: u32) -> Result<Vec<Vec4>> {
    let mut out = Vec::new();
    let layers = t.size().depth_or_array_layers;
    for m in 0..t.mip_level_count() {
        let s = (t.size().width >> m).max(1);
        let row = pitch(s * channels * 2);
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("splitsum readback"),
            size: row as u64 * s as u64 * layers as u64,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo { texture: t, mip_level: m, origin: wgpu::Origin3d::ZERO, aspect: wgpu::TextureAspect::All },
            wgpu::TexelCopyBufferInfo { buffer: &buffer, layout: wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(row), rows_per_image: Some(s) } },
            wgpu::Extent3d { width: s, height: s, depth_or_array_layers: layers },
        );
        queue.submit([encoder.finish()]);
        let bytes = gpu::map_read_async(device, &buffer).await.map_err(|e| Error::gpu(format!("{e} ({:?} {:?}, mip {m} of {})", t.format(), t.size(), t.mip_level_count())))?;
        let words: &[u32] = bytemuck::cast_slice(&bytes);
        for r in 0..(s * layers) as usize {
            let w = &words[r * (row / 4) as usize..];
            for x in 0..s as usize {
                let h = |k: usize| f16_bits_to_f32(if k.is_multiple_of(2) { w[k / 2] & 0xffff } else { w[k / 2] >> 16 });
                let c = channels as usize * x;
                out.push(if channels == 4 { Vec4::new(h(c), h(c + 1), h(c + 2), h(c + 3)) } else { Vec4::new(h(c), h(c + 1), 0.0, 0.0) });
            }
        }
    }
    Ok(out)
}
