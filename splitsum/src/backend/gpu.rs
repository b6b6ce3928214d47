//! The GPU backend: wgpu running the rust-gpu kernels of `splitsum_shaders::kernels` from
//! the committed SPIR-V module of `splitsum-spirv`. Every entry point's name, workgroup
//! size and bindings come from that crate's generated linkage; nothing here spells one.
//!
//! Start-up (device and every pipeline) happens in [`Gpu::new`] or [`Gpu::on_device`], so
//! that the time of a bake excludes it. Each [`Gpu::run`] records its dispatches in one
//! command encoder and submits them: a step's levels together, and each chunk of a long sum
//! (at most `math::CHUNK` terms, under drivers' time limits per submission) on its own; the
//! chunks' partial sums are resolved on the device (`resolve_means`, `resolve_lut`) before
//! anything is read back.

use super::cpu::Cpu;
use super::kernels::{Kernels, Prefilter, chunks};
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
use splitsum_spirv::{self as spirv, Binding, Dimension, EntryPoint, Resource, Stage};
use std::borrow::Cow;
use std::collections::HashMap;

/// A wgpu device with every kernel's pipeline ready.
pub struct Gpu {
    /// The instance, when splitsum opened the device itself (the viewer presents with it);
    /// `None` on a caller's device.
    pub instance: Option<wgpu::Instance>,
    /// The adapter, likewise.
    pub adapter: Option<wgpu::Adapter>,
    /// The SPIR-V module of `splitsum-shaders` (compute, vertex and fragment entry points).
    pub module: wgpu::ShaderModule,
    /// The device.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
    /// What the adapter says of itself.
    pub info: wgpu::AdapterInfo,
    pipelines: HashMap<&'static str, (wgpu::ComputePipeline, wgpu::BindGroupLayout)>,
    empty: wgpu::Buffer,
}

/// One dispatch: a kernel, its parameter block, an optional input and the output buffer,
/// bound where the kernel's generated linkage says (its uniform, its read-only storage
/// buffer and its written one).
pub struct Dispatch<'a> {
    /// The kernel's entry point (a `splitsum_spirv::KERNELS_*` constant).
    pub kernel: &'static EntryPoint,
    /// The uniform parameter block (a `Pod` struct of `kernels`).
    pub params: &'a [u8],
    /// The read-only input, if the kernel reads one.
    pub input: Option<&'a wgpu::Buffer>,
    /// The output.
    pub output: &'a wgpu::Buffer,
    /// Invocations along x, y, z; rounded up to whole workgroups of the kernel's size.
    pub invocations: [u32; 3],
}

/// The bind-group-layout entry of `b`, visible to `visibility`.
pub fn layout_entry(b: &Binding, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
    let buffer = |ty| wgpu::BindingType::Buffer { ty, has_dynamic_offset: false, min_binding_size: None };
    let ty = match b.resource {
        Resource::Uniform => buffer(wgpu::BufferBindingType::Uniform),
        Resource::Storage { read_only } => buffer(wgpu::BufferBindingType::Storage { read_only }),
        Resource::Sampler => wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
        Resource::Texture { dimension } => wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: true },
            view_dimension: match dimension {
                Dimension::D1 => wgpu::TextureViewDimension::D1,
                Dimension::D2 => wgpu::TextureViewDimension::D2,
                Dimension::D2Array => wgpu::TextureViewDimension::D2Array,
                Dimension::D3 => wgpu::TextureViewDimension::D3,
                Dimension::Cube => wgpu::TextureViewDimension::Cube,
                Dimension::CubeArray => wgpu::TextureViewDimension::CubeArray,
            },
            multisampled: false,
        },
    };
    wgpu::BindGroupLayoutEntry { binding: b.binding, visibility, ty, count: None }
}

/// The layout entries of group `group` used by `entries` together (a vertex and a
/// fragment shader share one layout), each visible to the stages that use it.
pub fn group_layout(entries: &[&EntryPoint], group: u32) -> Vec<wgpu::BindGroupLayoutEntry> {
    let mut out: Vec<wgpu::BindGroupLayoutEntry> = Vec::new();
    for e in entries {
        let stage = match e.stage {
            Stage::Compute => wgpu::ShaderStages::COMPUTE,
            Stage::Vertex => wgpu::ShaderStages::VERTEX,
            Stage::Fragment => wgpu::ShaderStages::FRAGMENT,
        };
        for b in e.bindings.iter().filter(|b| b.group == group) {
            match out.iter_mut().find(|o| o.binding == b.binding) {
                Some(o) => o.visibility |= stage,
                None => out.push(layout_entry(b, stage)),
            }
        }
    }
    out.sort_by_key(|o| o.binding);
    out
}

/// The bind group entries of `group` for `entries`: `resources` in the order of the
/// group's bindings (ascending, as [`group_layout`] lists them), each given its binding
/// number from the linkage. Panics if the counts differ: a shader and its host out of step.
pub fn group_entries<'a>(entries: &[&EntryPoint], group: u32, resources: Vec<wgpu::BindingResource<'a>>) -> Vec<wgpu::BindGroupEntry<'a>> {
    let layout = group_layout(entries, group);
    assert_eq!(layout.len(), resources.len(), "group {group}: the linkage has {} bindings, the host binds {}", layout.len(), resources.len());
    layout.iter().zip(resources).map(|(l, resource)| wgpu::BindGroupEntry { binding: l.binding, resource }).collect()
}

/// The graphics APIs splitsum looks for adapters on: `WGPU_BACKEND` (wgpu's own variable,
/// a comma-separated list such as `vulkan`, `gl`, `metal`, `dx12`) if set, else every API
/// this build of wgpu has.
pub fn backends_from_env() -> wgpu::Backends {
    wgpu::Backends::from_env().unwrap_or(wgpu::Backends::all())
}

/// A wgpu instance on `backends`.
pub fn instance(backends: wgpu::Backends) -> wgpu::Instance {
    wgpu::Instance::new(wgpu::InstanceDescriptor { backends, ..wgpu::InstanceDescriptor::new_without_display_handle() })
}

/// The graphics API of an adapter, as people name it.
pub fn api_name(backend: wgpu::Backend) -> &'static str {
    match backend {
        wgpu::Backend::Vulkan => "Vulkan",
        wgpu::Backend::Metal => "Metal",
        wgpu::Backend::Dx12 => "DX12",
        wgpu::Backend::Gl => "GL",
        wgpu::Backend::BrowserWebGpu => "WebGPU",
        wgpu::Backend::Noop => "no-op",
    }
}

/// The adapters `instance` sees on `backends`, best first: discrete, integrated, virtual,
/// other, then CPU (lavapipe, llvmpipe, WARP); among equals Vulkan, Metal, DX12, then GL.
/// Only those whose name contains `filter` (case-insensitive), if given.
pub fn adapters(instance: &wgpu::Instance, backends: wgpu::Backends, filter: Option<&str>) -> Vec<wgpu::Adapter> {
    let mut adapters = pollster::block_on(instance.enumerate_adapters(backends));
    let rank = |info: wgpu::AdapterInfo| {
        let device = match info.device_type {
            wgpu::DeviceType::DiscreteGpu => 0,
            wgpu::DeviceType::IntegratedGpu => 1,
            wgpu::DeviceType::VirtualGpu => 2,
            wgpu::DeviceType::Other => 3,
            wgpu::DeviceType::Cpu => 4,
        };
        let api = match info.backend {
            wgpu::Backend::Vulkan => 0,
            wgpu::Backend::Metal => 1,
            wgpu::Backend::Dx12 => 2,
            wgpu::Backend::BrowserWebGpu => 3,
            wgpu::Backend::Gl => 4,
            wgpu::Backend::Noop => 5,
        };
        (device, api)
    };
    adapters.sort_by_key(|a| rank(a.get_info()));
    if let Some(want) = filter {
        let want = want.to_lowercase();
        adapters.retain(|a| a.get_info().name.to_lowercase().contains(&want));
    }
    adapters
}

impl Gpu {
    /// Opens the best adapter (discrete, integrated, virtual, then CPU; Vulkan, Metal, DX12, then GL) on the APIs `WGPU_BACKEND` names (all, if
    /// unset) whose name contains `WGPU_ADAPTER_NAME` (any, if unset), wgpu's own
    /// variables, and builds every pipeline.
    pub fn new() -> Result<Self> {
        Self::matching(backends_from_env(), std::env::var("WGPU_ADAPTER_NAME").ok().as_deref())
    }

    /// Opens the best adapter as [`Gpu::new`] does, unless it is a software rasteriser on
    /// the CPU (`wgpu::DeviceType::Cpu`: lavapipe, llvmpipe, SwiftShader, WARP): then, or
    /// where there is no adapter, nothing is opened and the adapter passed over is returned.
    pub fn unless_software() -> Result<std::result::Result<Self, Option<wgpu::AdapterInfo>>> {
        let backends = backends_from_env();
        let instance = instance(backends);
        let filter = std::env::var("WGPU_ADAPTER_NAME").ok();
        let Some(adapter) = adapters(&instance, backends, filter.as_deref()).into_iter().next() else { return Ok(Err(None)) };
        let info = adapter.get_info();
        if info.device_type == wgpu::DeviceType::Cpu {
            return Ok(Err(Some(info)));
        }
        Self::with_adapter(instance, adapter).map(Ok)
    }

    /// Opens the best adapter on `backends` whose name contains `filter` (any, if `None`).
    pub fn matching(backends: wgpu::Backends, filter: Option<&str>) -> Result<Self> {
        let instance = instance(backends);
        let adapter = adapters(&instance, backends, filter).into_iter().next().ok_or_else(|| Error::NoAdapter {
            detail: match (filter, backends == wgpu::Backends::all()) {
                (Some(want), true) => format!(" whose name contains {want:?} (WGPU_ADAPTER_NAME)"),
                (Some(want), false) => format!(" on {backends:?} (WGPU_BACKEND) whose name contains {want:?} (WGPU_ADAPTER_NAME)"),
                (None, true) => String::new(),
                (None, false) => format!(" on {backends:?} (WGPU_BACKEND)"),
            },
        })?;
        Self::with_adapter(instance, adapter)
    }

    /// Builds the device and pipelines on `adapter` of `instance`.
    pub fn with_adapter(instance: wgpu::Instance, adapter: wgpu::Adapter) -> Result<Self> {
        let info = adapter.get_info();
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("splitsum"),
            required_features: wgpu::Features::empty(),
            required_limits: adapter.limits(),
            ..Default::default()
        }))
        .map_err(|e| Error::Gpu(format!("could not open {}: {e}", info.name)))?;
        let mut gpu = Self::on_device(&device, &queue)?;
        gpu.instance = Some(instance);
        gpu.adapter = Some(adapter);
        Ok(gpu)
    }

    /// The kernels' pipelines on a device the caller opened (wgpu handles are shared, so
    /// splitsum's work runs on the caller's queue and its textures live on that device).
    pub fn on_device(device: &wgpu::Device, queue: &wgpu::Queue) -> Result<Self> {
        pollster::block_on(Self::on_device_async(device, queue))
    }

    /// [`Gpu::on_device`] without blocking (in a browser, where nothing may block).
    pub async fn on_device_async(device: &wgpu::Device, queue: &wgpu::Queue) -> Result<Self> {
        let info = device.adapter_info();
        check_limits(&info, &device.limits())?;
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("splitsum-shaders"),
            source: wgpu::ShaderSource::SpirV(Cow::Borrowed(splitsum_spirv::words())),
        });
        if let Some(e) = scope.pop().await {
            return Err(Error::Gpu(format!("the shader module did not validate on {}: {e}", info.name)));
        }
        // Each pipeline checked in an error scope of its own, so that an error names its
        // kernel. The cube reader binds a texture of the caller's format: built when needed.
        let kernels: Vec<&EntryPoint> = splitsum_spirv::KERNELS.iter().filter(|k| k.name != spirv::KERNELS_READ_CUBE.name).collect();
        let build = |k: &EntryPoint| {
            let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
            let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some(k.name), entries: &group_layout(&[k], 0) });
            let pipeline = kernel_pipeline(device, &module, k, &layout);
            (pipeline, layout, scope)
        };
        let mut pipelines = HashMap::new();
        // Natively the pipelines are built on every core at once (the driver compiles each;
        // error scopes are per thread); in a browser, one after another. On GL too: wgpu
        // runs every GL call of a device under one lock, which a thread waits for at most
        // 6 s before it panics (wgpu-hal: "Could not lock adapter context"), and one
        // kernel's compile can hold it that long on a loaded machine (docs/HAZARDS.md).
        #[cfg(not(target_arch = "wasm32"))]
        let built: Vec<_> = {
            use rayon::prelude::*;
            let one = |k: &&EntryPoint| {
                let (pipeline, layout, scope) = build(k);
                (k.name, pipeline, layout, pollster::block_on(scope.pop()))
            };
            if info.backend == wgpu::Backend::Gl { kernels.iter().map(one).collect() } else { kernels.par_iter().map(one).collect() }
        };
        #[cfg(target_arch = "wasm32")]
        let built: Vec<_> = {
            let mut built = Vec::new();
            for k in &kernels {
                let (pipeline, layout, scope) = build(k);
                built.push((k.name, pipeline, layout, scope.pop().await));
            }
            built
        };
        for (name, pipeline, layout, error) in built {
            if let Some(e) = error {
                return Err(Error::Gpu(format!("kernel {name} did not validate on {}: {e}", info.name)));
            }
            pipelines.insert(name, (pipeline, layout));
        }
        let empty = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("empty input"),
            size: 16,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        Ok(Self { instance: None, adapter: None, module, device: device.clone(), queue: queue.clone(), info, pipelines, empty })
    }

    /// A one-line description of the adapter and its API.
    pub fn describe(&self) -> String {
        let driver = [self.info.driver.as_str(), self.info.driver_info.as_str()].iter().filter(|s| !s.is_empty()).copied().collect::<Vec<_>>().join(" ");
        format!("{} on {} ({:?}, {driver})", self.info.name, api_name(self.info.backend), self.info.device_type)
    }

    /// Whether the adapter is a software rasteriser on the CPU (lavapipe, SwiftShader).
    pub fn is_software(&self) -> bool {
        self.info.device_type == wgpu::DeviceType::Cpu
    }

    /// A storage buffer holding `data`.
    pub fn upload_bytes(&self, label: &str, data: &[u8]) -> wgpu::Buffer {
        filled(&self.device, &self.queue, label, data, wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST)
    }

    /// The largest buffer this device binds as one storage buffer.
    pub fn max_binding(&self) -> u64 {
        let limits = self.device.limits();
        limits.max_storage_buffer_binding_size.min(limits.max_buffer_size)
    }

    /// An output storage buffer of `bytes` bytes, checked against the device's limits.
    pub fn output(&self, label: &str, bytes: u64) -> Result<wgpu::Buffer> {
        let max = self.max_binding();
        if bytes > max {
            return Err(Error::Gpu(format!(
                "{label} needs {bytes} bytes, more than this device binds in one buffer ({max}); use a smaller size or the CPU backend"
            )));
        }
        Ok(self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: bytes.max(16),
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        }))
    }

    /// Records `dispatches` in order into `encoder`.
    pub fn record(&self, encoder: &mut wgpu::CommandEncoder, dispatches: &[Dispatch<'_>]) {
        // A uniform block's size is its struct's, rounded up to 16 bytes as uniform
        // layout rounds it: the parameter structs carry no padding fields.
        let params: Vec<wgpu::Buffer> = dispatches
            .iter()
            .map(|d| {
                let mut bytes = d.params.to_vec();
                bytes.resize(bytes.len().next_multiple_of(16).max(16), 0);
                filled(&self.device, &self.queue, "params", &bytes, wgpu::BufferUsages::UNIFORM)
            })
            .collect();
        let groups: Vec<wgpu::BindGroup> = dispatches
            .iter()
            .zip(&params)
            .map(|(d, p)| {
                let entries: Vec<wgpu::BindGroupEntry> = d
                    .kernel
                    .bindings
                    .iter()
                    .map(|b| {
                        let buffer = match b.resource {
                            Resource::Uniform => p,
                            Resource::Storage { read_only: true } => d.input.unwrap_or(&self.empty),
                            Resource::Storage { read_only: false } => d.output,
                            r => unreachable!("kernel {} binds a {r:?}", d.kernel.name),
                        };
                        wgpu::BindGroupEntry { binding: b.binding, resource: buffer.as_entire_binding() }
                    })
                    .collect();
                self.device.create_bind_group(&wgpu::BindGroupDescriptor { label: None, layout: &self.pipelines[d.kernel.name].1, entries: &entries })
            })
            .collect();
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor { label: None, timestamp_writes: None });
        for (d, g) in dispatches.iter().zip(&groups) {
            let [x, y, z] = d.kernel.workgroups(d.invocations);
            pass.set_pipeline(&self.pipelines[d.kernel.name].0);
            pass.set_bind_group(0, g, &[]);
            pass.dispatch_workgroups(x, y, z);
        }
    }

    /// Records and submits `dispatches` in order, in one submission.
    pub fn run(&self, dispatches: &[Dispatch<'_>]) {
        let mut encoder = self.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
        self.record(&mut encoder, dispatches);
        self.queue.submit([encoder.finish()]);
    }

    /// Waits for the queue and copies `buffer` back.
    pub fn read_bytes(&self, buffer: &wgpu::Buffer) -> Result<Vec<u8>> {
        let size = buffer.size();
        let staging = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = self.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
        encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, size);
        self.queue.submit([encoder.finish()]);
        map_read(&self.device, &staging)
    }
}

/// Refuses a device whose limits cannot run the kernels, naming what is missing: compute
/// shaders with 8×8 workgroups, two storage buffers and a uniform block per kernel, and
/// the largest parameter block. (A step whose buffer exceeds the storage binding limit runs
/// on the CPU instead, with a note: see `Gpu::fits`.)
fn check_limits(info: &wgpu::AdapterInfo, l: &wgpu::Limits) -> Result<()> {
    let widest = spirv::KERNELS.iter().map(|k| k.workgroup_size).fold([1, 1, 1], |a, b| [a[0].max(b[0]), a[1].max(b[1]), a[2].max(b[2])]);
    let invocations = spirv::KERNELS.iter().map(|k| k.workgroup_size.iter().product::<u32>()).max().unwrap_or(1);
    let storage = spirv::KERNELS.iter().map(|k| k.bindings.iter().filter(|b| matches!(b.resource, Resource::Storage { .. })).count() as u32).max().unwrap_or(0);
    let mut missing = Vec::new();
    if l.max_compute_invocations_per_workgroup == 0 {
        missing.push("compute shaders (a WebGL2-class device has none)".to_string());
    } else {
        if l.max_compute_invocations_per_workgroup < invocations {
            missing.push(format!("{invocations} compute invocations per workgroup (it has {})", l.max_compute_invocations_per_workgroup));
        }
        let has = [l.max_compute_workgroup_size_x, l.max_compute_workgroup_size_y, l.max_compute_workgroup_size_z];
        if (0..3).any(|k| has[k] < widest[k]) {
            missing.push(format!("workgroups of {}×{}×{} (it has {}×{}×{})", widest[0], widest[1], widest[2], has[0], has[1], has[2]));
        }
    }
    if l.max_storage_buffers_per_shader_stage < storage {
        missing.push(format!("{storage} storage buffers per shader stage (it has {})", l.max_storage_buffers_per_shader_stage));
    }
    if l.max_uniform_buffers_per_shader_stage < 1 {
        missing.push("a uniform buffer per shader stage".into());
    }
    if missing.is_empty() {
        return Ok(());
    }
    Err(Error::Gpu(format!(
        "{} ({}) cannot run splitsum's kernels: it lacks {}; bake on the CPU instead (Compute::Cpu)",
        info.name,
        api_name(info.backend),
        missing.join(", ")
    )))
}

/// Whether `device` copies cube textures to buffers. wgpu's GL backend makes every square
/// six-layer texture a GL cube map and copies none of them ("Not implemented yet: cubemap
/// texture copy to buffer", and the buffer stays zero); there [`CubeReader`] reads them.
pub fn copies_cubes(device: &wgpu::Device) -> bool {
    device.adapter_info().backend != wgpu::Backend::Gl
}

/// Reads cube textures into storage buffers with the `read_cube` kernel, where the device
/// cannot copy them ([`copies_cubes`]): every texel sampled at its centre direction with a
/// nearest-texel sampler at its exact level, which returns the texel unchanged.
pub struct CubeReader {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
}

impl CubeReader {
    /// The kernel's pipeline on `device` for textures of `format` (filterable or not, as
    /// `Rgba32Float` is not).
    pub fn new(device: &wgpu::Device, format: wgpu::TextureFormat) -> Self {
        let k = &spirv::KERNELS_READ_CUBE;
        let filterable = format.guaranteed_format_features(device.features()).flags.contains(wgpu::TextureFormatFeatureFlags::FILTERABLE);
        let entries: Vec<wgpu::BindGroupLayoutEntry> = group_layout(&[k], 0)
            .into_iter()
            .map(|mut e| {
                e.ty = match e.ty {
                    wgpu::BindingType::Texture { view_dimension, multisampled, .. } => {
                        wgpu::BindingType::Texture { sample_type: wgpu::TextureSampleType::Float { filterable }, view_dimension, multisampled }
                    }
                    wgpu::BindingType::Sampler(_) if !filterable => wgpu::BindingType::Sampler(wgpu::SamplerBindingType::NonFiltering),
                    t => t,
                };
                e
            })
            .collect();
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some(k.name), entries: &entries });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("splitsum-shaders"),
            source: wgpu::ShaderSource::SpirV(Cow::Borrowed(splitsum_spirv::words())),
        });
        let pipeline = kernel_pipeline(device, &module, k, &layout);
        // Nearest in every direction: the texel at the sampled point, at the exact level.
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor { label: Some("splitsum cube reader"), ..Default::default() });
        Self { pipeline, layout, sampler }
    }

    /// Records the reading of every mip of the cube `texture` into `out`, texels laid out
    /// as `layout` (level by level, face by face), cleaned (`half::clean_radiance`).
    pub fn record(&self, device: &wgpu::Device, queue: &wgpu::Queue, encoder: &mut wgpu::CommandEncoder, texture: &wgpu::Texture, layout: CubeLayout, out: &wgpu::Buffer) {
        use splitsum_shaders::kernels::ReadCubeParams;
        let k = &spirv::KERNELS_READ_CUBE;
        let view = texture.create_view(&wgpu::TextureViewDescriptor { dimension: Some(wgpu::TextureViewDimension::Cube), ..Default::default() });
        let groups: Vec<(wgpu::BindGroup, [u32; 3])> = (0..layout.levels)
            .map(|level| {
                let size = layout.level_size(level);
                let p = ReadCubeParams { size, level, texel_offset: layout.level_offset(level) };
                let mut bytes = bytemuck::bytes_of(&p).to_vec();
                bytes.resize(bytes.len().next_multiple_of(16), 0);
                let params = filled(device, queue, "params", &bytes, wgpu::BufferUsages::UNIFORM);
                let entries: Vec<wgpu::BindGroupEntry> = k
                    .bindings
                    .iter()
                    .map(|b| wgpu::BindGroupEntry {
                        binding: b.binding,
                        resource: match b.resource {
                            Resource::Uniform => params.as_entire_binding(),
                            Resource::Storage { .. } => out.as_entire_binding(),
                            Resource::Texture { .. } => wgpu::BindingResource::TextureView(&view),
                            Resource::Sampler => wgpu::BindingResource::Sampler(&self.sampler),
                        },
                    })
                    .collect();
                let group = device.create_bind_group(&wgpu::BindGroupDescriptor { label: None, layout: &self.layout, entries: &entries });
                (group, k.workgroups([size, size, FACES]))
            })
            .collect();
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("read cube"), timestamp_writes: None });
        pass.set_pipeline(&self.pipeline);
        for (group, [x, y, z]) in &groups {
            pass.set_bind_group(0, group, &[]);
            pass.dispatch_workgroups(*x, *y, *z);
        }
    }
}

/// A buffer of `usage` holding `data` (a multiple of 4 bytes), written through the queue
/// rather than mapped at creation: browsers limit buffers mapped at creation (Chromium's
/// WebGPU on SwiftShader refuses 64 KiB: "createBuffer failed, size (65024) is too large
/// for the implementation when mappedAtCreation == true").
pub fn filled(device: &wgpu::Device, queue: &wgpu::Queue, label: &str, data: &[u8], usage: wgpu::BufferUsages) -> wgpu::Buffer {
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: (data.len() as u64).next_multiple_of(wgpu::COPY_BUFFER_ALIGNMENT).max(wgpu::COPY_BUFFER_ALIGNMENT),
        usage: usage | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    queue.write_buffer(&buffer, 0, data);
    buffer
}

/// The compute pipeline of kernel `k` of `module`, with the bind group layout `layout`.
fn kernel_pipeline(device: &wgpu::Device, module: &wgpu::ShaderModule, k: &EntryPoint, layout: &wgpu::BindGroupLayout) -> wgpu::ComputePipeline {
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor { label: Some(k.name), bind_group_layouts: &[Some(layout)], immediate_size: 0 });
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(k.name),
        layout: Some(&pipeline_layout),
        module,
        entry_point: Some(k.name),
        compilation_options: Default::default(),
        cache: None,
    })
}

/// Waits for `device` and maps `buffer` (created with `MAP_READ`) to read it.
pub fn map_read(device: &wgpu::Device, buffer: &wgpu::Buffer) -> Result<Vec<u8>> {
    pollster::block_on(map_read_async(device, buffer))
}

/// [`map_read`] without blocking: in a browser the mapping completes only when the page's
/// event loop runs, so it must be awaited there.
pub async fn map_read_async(device: &wgpu::Device, buffer: &wgpu::Buffer) -> Result<Vec<u8>> {
    let done = Oneshot::default();
    let sender = done.clone();
    buffer.slice(..).map_async(wgpu::MapMode::Read, move |r| sender.send(r));
    // Drives the mapping on native backends; nothing to drive in a browser.
    device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| Error::Gpu(format!("waiting for the device: {e}")))?;
    done.await.map_err(|e| Error::Gpu(format!("readback: {e}")))?;
    let bytes = buffer.slice(..).get_mapped_range().map_err(|e| Error::Gpu(format!("readback: {e}")))?.to_vec();
    buffer.unmap();
    Ok(bytes)
}

/// A value sent once from a wgpu callback, awaited.
struct Oneshot<T>(std::sync::Arc<std::sync::Mutex<(Option<T>, Option<std::task::Waker>)>>);

impl<T> Default for Oneshot<T> {
    fn default() -> Self {
        Self(Default::default())
    }
}

impl<T> Clone for Oneshot<T> {
    fn clone(&self) -> Self {
        Self(self.0.clone())
    }
}

impl<T> Oneshot<T> {
    fn send(&self, v: T) {
        let mut slot = self.0.lock().unwrap_or_else(|e| e.into_inner());
        slot.0 = Some(v);
        if let Some(w) = slot.1.take() {
            w.wake();
        }
    }
}

impl<T> std::future::Future for Oneshot<T> {
    type Output = T;
    fn poll(self: std::pin::Pin<&mut Self>, cx: &mut std::task::Context<'_>) -> std::task::Poll<T> {
        let mut slot = self.0.lock().unwrap_or_else(|e| e.into_inner());
        match slot.0.take() {
            Some(v) => std::task::Poll::Ready(v),
            None => {
                slot.1 = Some(cx.waker().clone());
                std::task::Poll::Pending
            }
        }
    }
}

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
    /// `texels` back in host memory.
    pub fn read_texels(&self, texels: &Texels) -> Result<Vec<Vec4>> {
        let bytes = self.read_bytes(&texels.buffer)?;
        Ok(bytemuck::pod_collect_to_vec(&bytes[..texels.count as usize * 16]))
    }
}

impl Kernels for Gpu {
    type Texels = Texels;

    fn finish(&self) -> Result<()> {
        self.device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| Error::Gpu(format!("waiting for the device: {e}")))?;
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
        let out = self.texels("brdf table", n)?;
        let per_texel = lut::QUADRATURE_MEAN_EVALUATIONS;
        self.table_rows(&spirv::KERNELS_BRDF_TABLE, size, per_texel, &out.buffer, |row_offset| TableParams { size, masking: masking as u32, row_offset });
        Ok(out)
    }

    fn calibrate(&self, src: &Texels, src_layout: CubeLayout, rate: Rate, size: u32, count: u32) -> Result<Texels> {
        let out = self.texels("calibration", FACES * size * size)?;
        let p = CalibrateParams { rate: rate as u32, size, src_size: src_layout.size, src_levels: src_layout.levels, count };
        self.run(&[Dispatch { kernel: &spirv::KERNELS_CALIBRATE, params: bytemuck::bytes_of(&p), input: Some(&src.buffer), output: &out.buffer, invocations: [size, size, FACES] }]);
        Ok(out)
    }

    fn probe_raw(&self, p: ProbeParams, texels: &[Vec4], probes: &[Vec4], terms: u32) -> Result<Vec<Vec4>> {
        if !self.fits("the probes", &[bytes((texels.len() + probes.len()) as u64), 3 * bytes(probes.len() as u64)]) {
            return Cpu.probe_raw(p, texels, probes, terms);
        }
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
