//! glTF models on the GPU: each primitive's buffers and material textures uploaded once,
//! drawn by the mesh pass with the depth buffer's format and range.

use super::*;
use crate::model::{Model, Texture, Vertex};
use splitsum::backend::gpu::{Gpu, group_entries, group_layout};
use splitsum_spirv::{self as spirv};
use wgpu::util::DeviceExt;

/// Depth buffer format of the display.
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// Near and far planes of the camera.
pub const DEPTH_RANGE: (f32, f32) = (0.05, 500.0);

/// One primitive of a model on the GPU.
pub struct GpuPrimitive {
    pub(super) vertices: wgpu::Buffer,
    pub(super) indices: wgpu::Buffer,
    pub(super) count: u32,
    pub(super) bind_group: wgpu::BindGroup,
    pub(super) double_sided: bool,
}

/// A glTF model on the GPU: buffers, textures (with mipmaps) and the mesh pipelines.
pub struct GpuModel {
    pub(super) primitives: Vec<GpuPrimitive>,
    pipeline_layout: wgpu::PipelineLayout,
    pipelines: std::sync::Mutex<Vec<(wgpu::TextureFormat, bool, wgpu::RenderPipeline)>>,
}

impl GpuModel {
    /// Uploads `model` for drawing with `scene`.
    pub fn new(gpu: &Gpu, scene: &GpuScene, model: &Model) -> Self {
        let device = &gpu.device;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some("mesh material"), entries: &group_layout(&DISPLAY, 2) });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("mesh layout"),
            bind_group_layouts: &[None, Some(&scene.layout), Some(&layout)],
            immediate_size: 0,
        });
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("mesh textures"),
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::Repeat,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            ..Default::default()
        });
        let white = Texture { width: 1, height: 1, rgba: vec![255; 4], srgb: false };
        let primitives = model
            .primitives
            .iter()
            .map(|p| {
                let uniform = gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("mesh material"),
                    contents: bytemuck::bytes_of(&p.material),
                    usage: wgpu::BufferUsages::UNIFORM,
                });
                let views: Vec<wgpu::TextureView> = p.textures.iter().map(|t| upload_texture(gpu, t.as_ref().unwrap_or(&white))).collect();
                // Group 2 in binding order: the material, its texture slots, the sampler.
                let resources = std::iter::once(uniform.as_entire_binding())
                    .chain(views.iter().map(wgpu::BindingResource::TextureView))
                    .chain(std::iter::once(wgpu::BindingResource::Sampler(&sampler)))
                    .collect();
                let entries = group_entries(&DISPLAY, 2, resources);
                let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some("mesh"), layout: &layout, entries: &entries });
                GpuPrimitive {
                    vertices: gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                        label: Some("vertices"),
                        contents: bytemuck::cast_slice(&p.vertices),
                        usage: wgpu::BufferUsages::VERTEX,
                    }),
                    indices: gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                        label: Some("indices"),
                        contents: bytemuck::cast_slice(&p.indices),
                        usage: wgpu::BufferUsages::INDEX,
                    }),
                    count: p.indices.len() as u32,
                    bind_group,
                    double_sided: p.double_sided,
                }
            })
            .collect();
        Self { primitives, pipeline_layout, pipelines: Default::default() }
    }

    pub(super) fn pipeline(&self, gpu: &Gpu, _scene: &GpuScene, format: wgpu::TextureFormat, double_sided: bool) -> wgpu::RenderPipeline {
        let mut cache = self.pipelines.lock().expect("pipeline cache");
        if let Some((_, _, p)) = cache.iter().find(|(f, d, _)| *f == format && *d == double_sided) {
            return p.clone();
        }
        let attributes = wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x4, 3 => Float32x2];
        let p = gpu.device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("mesh"),
            layout: Some(&self.pipeline_layout),
            vertex: wgpu::VertexState {
                module: &gpu.module(&spirv::DISPLAY_MESH_VS),
                entry_point: Some(spirv::DISPLAY_MESH_VS.name),
                compilation_options: Default::default(),
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: std::mem::size_of::<Vertex>() as u64,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &attributes,
                })],
            },
            primitive: wgpu::PrimitiveState {
                front_face: wgpu::FrontFace::Ccw,
                cull_mode: if double_sided { None } else { Some(wgpu::Face::Back) },
                ..Default::default()
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Less),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &gpu.module(&spirv::DISPLAY_MESH_FS),
                entry_point: Some(spirv::DISPLAY_MESH_FS.name),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState { format, blend: None, write_mask: wgpu::ColorWrites::ALL })],
            }),
            multiview_mask: None,
            cache: None,
        });
        cache.push((format, double_sided, p.clone()));
        p
    }
}

/// Uploads an RGBA8 texture with its mip chain (box filter; sRGB textures averaged in
/// linear light) and returns a view of it.
fn upload_texture(gpu: &Gpu, t: &Texture) -> wgpu::TextureView {
    let levels = splitsum::texture::mip_chain_rgba8(t.width, t.height, &t.rgba, t.srgb);
    let format = if t.srgb { wgpu::TextureFormat::Rgba8UnormSrgb } else { wgpu::TextureFormat::Rgba8Unorm };
    let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("mesh texture"),
        size: wgpu::Extent3d { width: t.width, height: t.height, depth_or_array_layers: 1 },
        mip_level_count: levels.len() as u32,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    for (level, (w, h, data)) in levels.iter().enumerate() {
        gpu.queue.write_texture(
            wgpu::TexelCopyTextureInfo { texture: &texture, mip_level: level as u32, origin: wgpu::Origin3d::ZERO, aspect: wgpu::TextureAspect::All },
            data,
            wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(4 * w), rows_per_image: Some(*h) },
            wgpu::Extent3d { width: *w, height: *h, depth_or_array_layers: 1 },
        );
    }
    texture.create_view(&Default::default())
}
