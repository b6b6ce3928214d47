//! A wgpu application of its own that bakes image-based lighting with splitsum on its own
//! device, binds the three textures as any renderer would, and draws a sphere lit by
//! them, headlessly:
//!
//! ```text
//! cargo run --release -p splitsum --example sphere [OUT.png] [--cpu]
//! ```
//!
//! Nothing is read back from the bake: the textures splitsum makes are bound directly. The
//! shading here is the application's own (split sum: `E/π·ρ + prefiltered(r)·(F₀A + B)`),
//! written in WGSL as an engine would; splitsum provides what it samples.

use splitsum::environment::Environment;
use splitsum::{Baker, Compute, Settings, Source};

/// The sphere's material.
#[derive(Copy, Clone, Debug)]
pub struct Material {
    /// Diffuse albedo (linear RGB).
    pub albedo: [f32; 3],
    /// Specular reflectance at normal incidence.
    pub f0: [f32; 3],
    /// Perceptual roughness.
    pub roughness: f32,
}

/// A linear-radiance picture, row-major, RGBA.
pub struct Picture {
    /// Width and height.
    pub size: u32,
    /// Pixels (alpha 0 where the sphere is not).
    pub pixels: Vec<[f32; 4]>,
}

/// The application's own device: the first adapter wgpu offers on the APIs `WGPU_BACKEND`
/// names (all, if unset; lavapipe or llvmpipe where there is no GPU).
pub fn open_device() -> (wgpu::Device, wgpu::Queue) {
    let backends = wgpu::Backends::from_env().unwrap_or_default();
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor { backends, ..wgpu::InstanceDescriptor::new_without_display_handle() });
    let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions::default())).expect("a GPU adapter (lavapipe works)");
    pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor { label: Some("app"), required_limits: adapter.limits(), ..Default::default() }))
        .expect("a device")
}

const SHADER: &str = r#"
struct Material { albedo: vec4<f32>, f0: vec4<f32>, roughness: f32, lod: f32, pad0: f32, pad1: f32 }
@group(0) @binding(0) var specular: texture_cube<f32>;
@group(0) @binding(1) var irradiance: texture_cube<f32>;
@group(0) @binding(2) var brdf: texture_2d<f32>;
@group(0) @binding(3) var linear: sampler;
@group(0) @binding(4) var<uniform> m: Material;

@vertex fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let p = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(p * 2.0 - 1.0, 0.0, 1.0);
}

// An orthographic view down -Z of the unit sphere filling the picture.
@fragment fn fs(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let xy = (frag.xy / f32(SIZE)) * 2.0 - 1.0;
    let p = vec2<f32>(xy.x, -xy.y);
    let rr = dot(p, p);
    if rr >= 1.0 { return vec4<f32>(0.0); }
    let n = vec3<f32>(p, sqrt(1.0 - rr));
    let v = vec3<f32>(0.0, 0.0, 1.0);
    let nv = clamp(dot(n, v), 0.0, 1.0);
    let r = reflect(-v, n);
    let ab = textureSampleLevel(brdf, linear, vec2<f32>(nv, m.roughness), 0.0).xy;
    let spec = textureSampleLevel(specular, linear, r, m.lod).rgb;
    let diffuse = textureSampleLevel(irradiance, linear, n, 0.0).rgb;
    return vec4<f32>(diffuse * m.albedo.rgb + spec * (m.f0.rgb * ab.x + ab.y), 1.0);
}
"#;

/// Bakes `env` on `device` (with the kernels there, or on the CPU with `compute`) and draws
/// a `size`² picture of a sphere of `material` lit by it.
pub fn draw(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    env: &Environment,
    settings: &Settings,
    compute: Compute,
    material: Material,
    size: u32,
) -> splitsum::Result<Picture> {
    let baker = Baker::new(device, queue, compute)?;
    let ibl = baker.bake(Source::Environment(env), settings)?;

    let cube = |t: &wgpu::Texture| t.create_view(&wgpu::TextureViewDescriptor { dimension: Some(wgpu::TextureViewDimension::Cube), ..Default::default() });
    let (specular, irradiance, brdf) = (cube(&ibl.specular), cube(&ibl.irradiance), ibl.brdf.create_view(&Default::default()));
    let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        mipmap_filter: wgpu::MipmapFilterMode::Linear,
        address_mode_u: wgpu::AddressMode::ClampToEdge,
        address_mode_v: wgpu::AddressMode::ClampToEdge,
        ..Default::default()
    });
    let a = material.albedo;
    let f = material.f0;
    let uniform: [f32; 12] = [a[0], a[1], a[2], 0.0, f[0], f[1], f[2], 0.0, material.roughness, ibl.lod(material.roughness), 0.0, 0.0];
    let uniform = wgpu::util::DeviceExt::create_buffer_init(
        device,
        &wgpu::util::BufferInitDescriptor { label: Some("material"), contents: bytemuck::cast_slice(&uniform), usage: wgpu::BufferUsages::UNIFORM },
    );
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("sphere"),
        source: wgpu::ShaderSource::Wgsl(SHADER.replace("SIZE", &size.to_string()).into()),
    });
    let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("sphere"),
        layout: None,
        vertex: wgpu::VertexState { module: &module, entry_point: Some("vs"), compilation_options: Default::default(), buffers: &[] },
        primitive: Default::default(),
        depth_stencil: None,
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs"),
            compilation_options: Default::default(),
            targets: &[Some(wgpu::TextureFormat::Rgba16Float.into())],
        }),
        multiview_mask: None,
        cache: None,
    });
    let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("ibl"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&specular) },
            wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&irradiance) },
            wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(&brdf) },
            wgpu::BindGroupEntry { binding: 3, resource: wgpu::BindingResource::Sampler(&sampler) },
            wgpu::BindGroupEntry { binding: 4, resource: uniform.as_entire_binding() },
        ],
    });
    let target = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("picture"),
        size: wgpu::Extent3d { width: size, height: size, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        // Half floats, the usual HDR target, which every backend renders to (wgpu's GL
        // backend renders to no 32-bit float format on some drivers).
        format: wgpu::TextureFormat::Rgba16Float,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    let row = (size * 8).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
    let readback = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("picture readback"),
        size: row as u64 * size as u64,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let view = target.create_view(&Default::default());
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("sphere"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT), store: wgpu::StoreOp::Store },
            })],
            ..Default::default()
        });
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind, &[]);
        pass.draw(0..3, 0..1);
    }
    encoder.copy_texture_to_buffer(
        target.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &readback,
            layout: wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(row), rows_per_image: Some(size) },
        },
        target.size(),
    );
    queue.submit([encoder.finish()]);
    let (tx, rx) = std::sync::mpsc::channel();
    readback.slice(..).map_async(wgpu::MapMode::Read, move |r| tx.send(r).expect("the receiver waits"));
    device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| splitsum::Error::gpu(e.to_string()))?;
    rx.recv().expect("mapped").map_err(|e| splitsum::Error::gpu(e.to_string()))?;
    let bytes = readback.slice(..).get_mapped_range().map_err(|e| splitsum::Error::gpu(e.to_string()))?.to_vec();
    let pixels = (0..size as usize)
        .flat_map(|y| {
            let line: &[[u16; 4]] = bytemuck::cast_slice(&bytes[y * row as usize..y * row as usize + size as usize * 8]);
            line.iter().map(|p| p.map(|h| half::f16::from_bits(h).to_f32())).collect::<Vec<_>>()
        })
        .collect();
    Ok(Picture { size, pixels })
}

fn main() -> splitsum::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let out = args.iter().find(|a| !a.starts_with("--")).cloned().unwrap_or_else(|| "sphere.png".into());
    let compute = if args.iter().any(|a| a == "--cpu") { Compute::Cpu } else { Compute::Gpu };
    let (device, queue) = open_device();
    let env = splitsum::environment::embedded_default()?;
    let settings = Settings { size: 64, source_size: Some(128), ..Settings::default() };
    let material = Material { albedo: [0.5, 0.25, 0.1], f0: [0.04; 3], roughness: 0.3 };
    let start = std::time::Instant::now();
    let picture = draw(&device, &queue, &env, &settings, compute, material, 256)?;
    let seconds = start.elapsed().as_secs_f64();
    // Reinhard and sRGB-ish gamma for a look; the pixels themselves are linear radiance.
    let rgb: Vec<u8> = picture.pixels.iter().flat_map(|p| [p[0], p[1], p[2]].map(|c| ((c / (1.0 + c)).powf(1.0 / 2.2) * 255.0).round() as u8)).collect();
    image::RgbImage::from_raw(picture.size, picture.size, rgb)
        .expect("size² pixels")
        .save(&out)
        .map_err(|e| splitsum::Error::Invalid(format!("{out}: {e}")))?;
    println!("baked on {compute:?} and drew {out} in {seconds:.2} s (pipelines, bake, draw and the picture's readback)");
    Ok(())
}
