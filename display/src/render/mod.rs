//! Drawing the scene: the view state a user changes (camera, models, exposure…), the frame
//! block it becomes, the GPU renderer (the `display` shaders on a window or an offscreen
//! texture) and the CPU reference renderer (the same `scene::pixel`, per pixel, with rayon).

mod meshes;
pub use meshes::{DEPTH_FORMAT, DEPTH_RANGE, GpuModel, GpuPrimitive};

use crate::model::Model;
use rayon::prelude::*;
use splitsum::Product;
use splitsum::backend::gpu::{Gpu, group_entries, group_layout};
use splitsum::reading::BakedEnvironment;
use splitsum::error::{Error, Result};
use splitsum_shaders::choice::Choice;
use splitsum_shaders::glam::camera::rh;
use splitsum_shaders::glam::{Vec2, Vec3, Vec4};
use splitsum_shaders::scene::{self, Frame, Light, MAX_LIGHTS};
use splitsum_shaders::shade::{DiffuseModel, EnvironmentShape, FresnelForm, ShadeOptions, SpecularModel};
use splitsum_shaders::tonemap::Tonemapper;
use splitsum_spirv::{self as spirv, EntryPoint};

/// The display's entry points: they share the scene's bind group (1) and the meshes' (2).
const DISPLAY: [&EntryPoint; 4] = [&spirv::DISPLAY_FULLSCREEN_VS, &spirv::DISPLAY_SCENE_FS, &spirv::DISPLAY_MESH_VS, &spirv::DISPLAY_MESH_FS];

/// Everything a user can change while looking.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewState {
    /// Orbit angle about the vertical axis, radians.
    pub yaw: f32,
    /// Orbit elevation, radians.
    pub pitch: f32,
    /// Distance from the target.
    pub distance: f32,
    /// The point orbited.
    pub target: Vec3,
    /// Vertical field of view, radians.
    pub fov: f32,
    /// Exposure multiplier.
    pub exposure: f32,
    /// Tone curve.
    pub tonemapper: Tonemapper,
    /// Sky blur, in specular mips.
    pub sky_blur: f32,
    /// Models and lights.
    pub options: ShadeOptions,
    /// Sphere grid rows (metalness) and columns (roughness); with a sheen colour, a sheen
    /// row below them.
    pub grid: (u32, u32),
    /// Draw the sphere grid.
    pub spheres: bool,
    /// Draw the model (when there is one).
    pub show_model: bool,
    /// Base colour of the spheres.
    pub base_color: Vec3,
    /// The grid's metalness range (top to bottom row) and roughness range (left to right).
    pub grid_ranges: Vec4,
    /// Sheen colour of the grid's sheen row (black: no sheen row).
    pub sheen_color: Vec3,
    /// The grid's sheen roughness range (left to right column).
    pub sheen_ranges: (f32, f32),
    /// Direct lights.
    pub lights: Vec<Light>,
}

impl Default for ViewState {
    fn default() -> Self {
        Self {
            yaw: 0.0,
            pitch: 0.0,
            distance: 8.0,
            target: Vec3::ZERO,
            fov: 45f32.to_radians(),
            exposure: 1.0,
            tonemapper: Tonemapper::Aces,
            sky_blur: 0.0,
            options: ShadeOptions::DEFAULT,
            grid: (5, 7),
            spheres: true,
            show_model: false,
            base_color: Vec3::new(0.9, 0.45, 0.2),
            grid_ranges: Vec4::new(0.0, 1.0, 0.0, 1.0),
            sheen_color: Vec3::ZERO,
            sheen_ranges: (0.0, 0.0),
            lights: vec![
                Light { position: Vec4::new(-0.5, 0.8, 0.6, 0.0).normalize() * Vec4::new(1.0, 1.0, 1.0, 0.0), radiance: Vec4::new(3.0, 2.9, 2.7, 0.0) },
                Light { position: Vec4::new(3.0, 2.0, 4.0, 1.0), radiance: Vec4::new(20.0, 20.0, 24.0, 0.0) },
            ],
        }
    }
}

impl ViewState {
    /// Points the camera at what is shown: the grid, the model beside it, or both.
    pub fn frame_contents(&mut self) {
        let (centre, size) = crate::model::PLACE_BESIDE_GRID;
        (self.target, self.distance) = match (self.spheres, self.show_model) {
            (true, true) => (Vec3::new(0.5 * (centre.x - 3.4), 0.0, 0.0), 11.0),
            (false, true) => (centre, 2.2 * size),
            _ => (Vec3::ZERO, 8.0),
        };
    }

    /// Camera position.
    pub fn eye(&self) -> Vec3 {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        self.target + Vec3::new(cp * sy, sp, cp * cy) * self.distance
    }

    /// A one-line summary of the choices (the window title).
    pub fn summary(&self) -> String {
        /// The image-based light's options, as ` (a, b)`, or nothing.
        fn ibl_options(flags: u32) -> String {
            let names: Vec<String> = [
                (ShadeOptions::DOMINANT_DIRECTION, "dominant direction"),
                (ShadeOptions::LIFT_ABOVE_HORIZON, "lifted above the horizon"),
                (ShadeOptions::MULTISCATTER, "multiple scattering"),
                (ShadeOptions::FILTERED_SAMPLING, "filtered"),
                (ShadeOptions::CORRELATED_SMITH, "exact Smith for lights"),
                (ShadeOptions::LOG_MIP_BLEND, "log mip blend"),
                (ShadeOptions::ROUGHNESS_FRESNEL, "roughness-aware Fresnel"),
            ]
            .iter()
            .filter(|(bit, _)| flags & bit != 0)
            .map(|&(_, name)| name.to_string())
            .chain((ShadeOptions::fetches_of(flags) > 1).then(|| format!("{} fetches", ShadeOptions::fetches_of(flags))))
            .collect();
            if names.is_empty() { String::new() } else { format!(" ({})", names.join(", ")) }
        }
        let o = self.options;
        format!(
            "diffuse {} | specular {} | Fresnel {} | IBL {}{} | lights {} | exposure {:.2} | {} | sky blur {:.1}{}",
            DiffuseModel::from_code(o.diffuse).name(),
            SpecularModel::from_code(o.specular).name(),
            FresnelForm::from_code(o.fresnel).name(),
            if o.flags & ShadeOptions::IBL != 0 { "on" } else { "off" },
            ibl_options(o.flags),
            if o.flags & ShadeOptions::DIRECT != 0 { "on" } else { "off" },
            self.exposure,
            self.tonemapper.name(),
            self.sky_blur,
            match (self.spheres, self.show_model) {
                (true, true) => " | grid + model",
                (false, true) => " | model",
                (true, false) => "",
                (false, false) => " | sky only",
            }
        )
    }

    /// The frame block for a `width`×`height` target. `encode_srgb`: the target stores what
    /// it is given (a UNORM format), so the shader encodes sRGB itself.
    pub fn frame(&self, shape: EnvironmentShape, width: u32, height: u32, encode_srgb: bool) -> Frame {
        let eye = self.eye();
        let forward = (self.target - eye).normalize();
        let right = forward.cross(Vec3::Y).try_normalize().unwrap_or(Vec3::X);
        let up = right.cross(forward);
        let mut lights = [Light { position: Vec4::ZERO, radiance: Vec4::ZERO }; MAX_LIGHTS];
        for (slot, l) in lights.iter_mut().zip(&self.lights) {
            *slot = *l;
        }
        let mut flags = 0;
        if encode_srgb {
            flags |= Frame::ENCODE_SRGB;
        }
        if self.spheres {
            flags |= Frame::SPHERES;
        }
        Frame {
            eye: eye.extend(0.0),
            forward: forward.extend(0.0),
            right: right.extend(0.0),
            up: up.extend(0.0),
            width: width as f32,
            height: height as f32,
            exposure: self.exposure,
            sky_blur: self.sky_blur,
            rows: self.grid.0 + (self.sheen_color.max_element() > 0.0) as u32,
            columns: self.grid.1,
            tonemapper: self.tonemapper as u32,
            light_count: self.lights.len().min(MAX_LIGHTS) as u32,
            flags,
            near: DEPTH_RANGE.0,
            far: DEPTH_RANGE.1,
            tan_half_fov: (0.5 * self.fov).tan(),
            options: self.options,
            shape,
            base_color: self.base_color.extend(1.0),
            lights,
            // Right-handed, depth in [0, 1] (`surface::depth` assumes it): view-space
            // `z = −near` maps to 0 and `−far` to 1.
            view_proj: rh::proj::directx::perspective(self.fov, width as f32 / height as f32, DEPTH_RANGE.0, DEPTH_RANGE.1)
                * rh::view::look_to_mat4(eye, forward, up),
            grid_ranges: self.grid_ranges,
            sheen_color: self.sheen_color.extend(0.0),
            sheen_ranges: Vec4::new(self.sheen_ranges.0, self.sheen_ranges.1, 0.0, 0.0),
        }
    }
}

/// The one render path: `frame` (with `model`, if any) on `backend`, as linear RGBA, row
/// 0 at the top. On the GPU, the renderer's passes; on the CPU, the reference renderers
/// (`raster` with a model, the ray-cast scene without), which the GPU is tested against.
pub fn render(backend: &splitsum::Backend, env: &BakedEnvironment, frame: &Frame, model: Option<&Model>) -> Result<Vec<Vec4>> {
    Ok(match (backend, model) {
        (splitsum::Backend::Gpu(g), m) => {
            let scene = GpuScene::new(g, env);
            let gm = m.map(|m| GpuModel::new(g, &scene, m));
            scene.render_offscreen(g, frame, gm.as_ref())?
        }
        (splitsum::Backend::Cpu, Some(m)) => crate::raster::render(env, frame, m),
        (splitsum::Backend::Cpu, None) => render_cpu(env, frame),
    })
}

/// What shading one pixel of a sphere costs with `options` on `backend`, in nanoseconds: a
/// `size`² frame of the default view's sphere grid, less the same frame without the
/// spheres (the sky, the pass and the read-back), over the pixels the spheres cover (found
/// by casting the frame's rays, `scene::hit_grid`). Each frame is the best of `repeats`;
/// on the GPU one untimed frame first pays for pipelines and uploads. The spheres show
/// every `n·v` in proportion to its projected area, so this is the mean over a sphere.
pub fn shading_ns_per_pixel(backend: &splitsum::Backend, env: &BakedEnvironment, options: ShadeOptions, size: u32, repeats: u32) -> Result<f64> {
    let view = ViewState { options, ..ViewState::default() };
    let frame = view.frame(env.shape(), size, size, false);
    let sky = ViewState { spheres: false, ..view }.frame(env.shape(), size, size, false);
    let covered = (0..size * size)
        .into_par_iter()
        .filter(|i| {
            let px = Vec2::new((i % size) as f32 + 0.5, (i / size) as f32 + 0.5);
            scene::hit_grid(&frame, frame.eye.truncate(), scene::camera_ray(&frame, px)).0 > 0.0
        })
        .count()
        .max(1);
    let best = |f: &dyn Fn() -> Result<()>| -> Result<f64> {
        let mut best = f64::INFINITY;
        for _ in 0..repeats.max(1) {
            let start = std::time::Instant::now();
            f()?;
            best = best.min(start.elapsed().as_secs_f64());
        }
        Ok(best)
    };
    let (with, without) = match backend {
        splitsum::Backend::Gpu(g) => {
            let scene = GpuScene::new(g, env);
            scene.render_offscreen(g, &frame, None)?;
            (best(&|| scene.render_offscreen(g, &frame, None).map(drop))?, best(&|| scene.render_offscreen(g, &sky, None).map(drop))?)
        }
        splitsum::Backend::Cpu => {
            let time = |f: &Frame| {
                best(&|| {
                    std::hint::black_box(render_cpu(env, f));
                    Ok(())
                })
            };
            (time(&frame)?, time(&sky)?)
        }
    };
    Ok((with - without).max(0.0) * 1e9 / covered as f64)
}

/// The CPU reference renderer: `scene::pixel` at every pixel centre, row 0 at the top.
pub fn render_cpu(env: &BakedEnvironment, frame: &Frame) -> Vec<Vec4> {
    let specular = env.specular_buffer();
    let (w, h) = (frame.width as u32, frame.height as u32);
    let mut out = vec![Vec4::ZERO; (w * h) as usize];
    out.par_chunks_mut(w as usize).enumerate().for_each(|(y, row)| {
        for (x, p) in row.iter_mut().enumerate() {
            let px = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            *p = scene::pixel(
                frame,
                env.cube(Product::SourceCube).level(0),
                &specular,
                &env.cube(Product::Irradiance).texels,
                &env.table(Product::BrdfTable).texels,
                &env.cube(Product::Sheen).texels,
                &env.table(Product::SheenTables).texels,
                px,
            );
        }
    });
    out
}

/// The scene pipeline and the baked buffers on the GPU.
pub struct GpuScene {
    layout: wgpu::BindGroupLayout,
    pipeline_layout: wgpu::PipelineLayout,
    pipelines: std::sync::Mutex<Vec<(wgpu::TextureFormat, wgpu::RenderPipeline)>>,
    frame_buffer: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
    /// The shapes of the baked buffers.
    pub shape: EnvironmentShape,
}

impl GpuScene {
    /// Uploads `env` and prepares the bindings.
    pub fn new(gpu: &Gpu, env: &BakedEnvironment) -> Self {
        let device = &gpu.device;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some("scene bindings"), entries: &group_layout(&DISPLAY, 1) });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("scene layout"),
            bind_group_layouts: &[None, Some(&layout)],
            immediate_size: 0,
        });
        let frame_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("frame"),
            size: std::mem::size_of::<Frame>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let specular = gpu.upload_bytes("specular", bytemuck::cast_slice(&env.specular_buffer()));
        let irradiance = gpu.upload_bytes("irradiance", bytemuck::cast_slice(&env.cube(Product::Irradiance).texels));
        let lut = gpu.upload_bytes("brdf lut", bytemuck::cast_slice(&env.table(Product::BrdfTable).texels));
        let source = gpu.upload_bytes("source", bytemuck::cast_slice(env.cube(Product::SourceCube).level(0)));
        let sheen = gpu.upload_bytes("sheen", bytemuck::cast_slice(&env.cube(Product::Sheen).texels));
        let sheen_tables = gpu.upload_bytes("sheen tables", bytemuck::cast_slice(&env.table(Product::SheenTables).texels));
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("scene"),
            layout: &layout,
            // In the order of `splitsum_shaders::display`'s group 1: frame, specular,
            // irradiance, table, source, sheen cube, sheen tables.
            entries: &group_entries(
                &DISPLAY,
                1,
                vec![
                    frame_buffer.as_entire_binding(),
                    specular.as_entire_binding(),
                    irradiance.as_entire_binding(),
                    lut.as_entire_binding(),
                    source.as_entire_binding(),
                    sheen.as_entire_binding(),
                    sheen_tables.as_entire_binding(),
                ],
            ),
        });
        Self { layout, pipeline_layout, pipelines: Default::default(), frame_buffer, bind_group, shape: env.shape() }
    }

    fn pipeline(&self, gpu: &Gpu, format: wgpu::TextureFormat) -> wgpu::RenderPipeline {
        let mut cache = self.pipelines.lock().expect("pipeline cache");
        if let Some((_, p)) = cache.iter().find(|(f, _)| *f == format) {
            return p.clone();
        }
        let p = gpu.device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("scene"),
            layout: Some(&self.pipeline_layout),
            vertex: wgpu::VertexState {
                module: &gpu.module(&spirv::DISPLAY_FULLSCREEN_VS),
                entry_point: Some(spirv::DISPLAY_FULLSCREEN_VS.name),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Always),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &gpu.module(&spirv::DISPLAY_SCENE_FS),
                entry_point: Some(spirv::DISPLAY_SCENE_FS.name),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState { format, blend: None, write_mask: wgpu::ColorWrites::ALL })],
            }),
            multiview_mask: None,
            cache: None,
        });
        cache.push((format, p.clone()));
        p
    }

    /// Records drawing `frame` into `view` (of `format`) with depth buffer `depth` (of
    /// [`DEPTH_FORMAT`]): the spheres and sky, then `model` if any.
    pub fn draw(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        view: &wgpu::TextureView,
        depth: &wgpu::TextureView,
        format: wgpu::TextureFormat,
        frame: &Frame,
        model: Option<&GpuModel>,
    ) {
        gpu.queue.write_buffer(&self.frame_buffer, 0, bytemuck::bytes_of(frame));
        let pipeline = self.pipeline(gpu, format);
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("scene"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load: wgpu::LoadOp::Clear(wgpu::Color::BLACK), store: wgpu::StoreOp::Store },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: depth,
                depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: wgpu::StoreOp::Store }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(1, &self.bind_group, &[]);
        pass.draw(0..3, 0..1);
        if let Some(m) = model {
            for p in &m.primitives {
                pass.set_pipeline(&m.pipeline(gpu, self, format, p.double_sided));
                pass.set_bind_group(1, &self.bind_group, &[]);
                pass.set_bind_group(2, &p.bind_group, &[]);
                pass.set_vertex_buffer(0, p.vertices.slice(..));
                pass.set_index_buffer(p.indices.slice(..), wgpu::IndexFormat::Uint32);
                pass.draw_indexed(0..p.count, 0, 0..1);
            }
        }
    }

    /// A depth buffer for a `width`×`height` target.
    pub fn depth_texture(gpu: &Gpu, width: u32, height: u32) -> wgpu::TextureView {
        gpu.device
            .create_texture(&wgpu::TextureDescriptor {
                label: Some("depth"),
                size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: DEPTH_FORMAT,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
                view_formats: &[],
            })
            .create_view(&Default::default())
    }

    /// The format frames are rendered into offscreen: RGBA32F where the device renders to
    /// it, else RGBA16F (wgpu's GL backend on Mesa's llvmpipe renders to no 32-bit float
    /// format): linear radiance above 65504 then reads as the largest half, and below it to
    /// 11 bits.
    pub fn offscreen_format(gpu: &Gpu) -> wgpu::TextureFormat {
        let renders = |f: wgpu::TextureFormat| match &gpu.adapter {
            Some(a) => a.get_texture_format_features(f).allowed_usages.contains(wgpu::TextureUsages::RENDER_ATTACHMENT),
            None => f.guaranteed_format_features(gpu.device.features()).allowed_usages.contains(wgpu::TextureUsages::RENDER_ATTACHMENT),
        };
        if renders(wgpu::TextureFormat::Rgba32Float) { wgpu::TextureFormat::Rgba32Float } else { wgpu::TextureFormat::Rgba16Float }
    }

    /// Renders `frame` offscreen (in [`GpuScene::offscreen_format`]) and reads it back as
    /// f32 (row 0 at the top).
    pub fn render_offscreen(&self, gpu: &Gpu, frame: &Frame, model: Option<&GpuModel>) -> Result<Vec<Vec4>> {
        let (w, h) = (frame.width as u32, frame.height as u32);
        let format = Self::offscreen_format(gpu);
        let texel = format.block_copy_size(None).expect("a colour format") as u64;
        let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("offscreen"),
            size: wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let view = texture.create_view(&Default::default());
        let depth = Self::depth_texture(gpu, w, h);
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        self.draw(gpu, &mut encoder, &view, &depth, format, frame, model);
        let row = (w as u64 * texel).div_ceil(256) * 256;
        let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("offscreen readback"),
            size: row * h as u64,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        encoder.copy_texture_to_buffer(
            texture.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(row as u32), rows_per_image: Some(h) },
            },
            wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
        );
        gpu.queue.submit([encoder.finish()]);
        let bytes = gpu.read_bytes(&buffer)?;
        let mut out = Vec::with_capacity((w * h) as usize);
        for y in 0..h as usize {
            let line = &bytes[y * row as usize..y * row as usize + (w as u64 * texel) as usize];
            if texel == 16 {
                out.extend(bytemuck::pod_collect_to_vec::<u8, Vec4>(line));
            } else {
                // Halves, decoded by the shared binary16 function; ∞ (a value past 65504
                // written by the render target) is read as the largest half.
                let h = |k: usize| {
                    let v = splitsum_shaders::half::f16_bits_to_f32(u16::from_le_bytes([line[2 * k], line[2 * k + 1]]) as u32);
                    if v.is_infinite() { v.signum() * 65504.0 } else { v }
                };
                out.extend((0..w as usize).map(|x| Vec4::new(h(4 * x), h(4 * x + 1), h(4 * x + 2), h(4 * x + 3))));
            }
        }
        Ok(out)
    }
}

/// Display values in [0, 1] to 8-bit RGB.
pub fn to_rgb8(pixels: &[Vec4]) -> Vec<u8> {
    pixels.iter().flat_map(|p| [p.x, p.y, p.z].map(|v| (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8)).collect()
}

/// Checks an output size.
pub fn check_size(width: u32, height: u32) -> Result<()> {
    if width == 0 || height == 0 || width > 8192 || height > 8192 {
        return Err(Error::Invalid(format!("--width and --height must be 1..8192, not {width}×{height}")));
    }
    Ok(())
}
