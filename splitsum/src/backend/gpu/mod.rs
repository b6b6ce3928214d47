//! The GPU backend: wgpu running the rust-gpu kernels of `splitsum_shaders::kernels` from
//! the committed SPIR-V modules of `splitsum-spirv`, one per entry point. Every entry
//! point's name, workgroup size, bindings and module come from that crate's generated
//! linkage; nothing here spells one.
//!
//! Start-up (device and the pipelines of every kernel a bake runs) happens in [`Gpu::new`]
//! or [`Gpu::on_device`], so that the time of a bake excludes it; the kernels only tools
//! run (`kernel::Kernel::on_demand`: the sampled table, the table's quadrature, calibration, probes) are
//! built when first needed, each checked as at start-up. Each [`Gpu::run`] records its dispatches in one
//! command encoder and submits them: a step's levels together, and each chunk of a long sum
//! (at most `math::CHUNK` terms, under drivers' time limits per submission) on its own; the
//! chunks' partial sums are resolved on the device (`resolve_means`, `resolve_lut`) before
//! anything is read back.

use crate::error::{Error, Result};
use splitsum_spirv::{self as spirv, Binding, Dimension, EntryPoint, Resource, Stage};
use std::borrow::Cow;
use std::collections::HashMap;

mod buffers;
pub mod kernel;
mod steps;
pub use buffers::{CubeReader, copies_cubes, filled, map_read, map_read_async};
pub use steps::Texels;

/// A wgpu device with every kernel's pipeline ready.
pub struct Gpu {
    /// The instance, when splitsum opened the device itself (the viewer presents with it);
    /// `None` on a caller's device.
    pub instance: Option<wgpu::Instance>,
    /// The adapter, likewise.
    pub adapter: Option<wgpu::Adapter>,
    /// The device.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
    /// What the adapter says of itself.
    pub info: wgpu::AdapterInfo,
    pipelines: std::sync::RwLock<HashMap<&'static str, Pipeline>>,
    empty: wgpu::Buffer,
}

/// A kernel's pipeline and its bind group layout.
type Pipeline = std::sync::Arc<(wgpu::ComputePipeline, wgpu::BindGroupLayout)>;

/// Whether the pipeline of `k` is built at start-up: not the cube reader's (it binds a
/// texture of the caller's format: `CubeReader`), and natively not those of the kernels a
/// bake never runs (`kernel::Kernel::on_demand`: the sampled BRDF table and the resolve of
/// its chunks, the table's quadrature (the defaults' table is embedded, others are computed
/// once per process), the calibration of the cost model and the probes of reports and
/// tests), built on first use (`Gpu::ensure`). In a browser, where nothing may block on
/// the error scope that checks a pipeline, every other pipeline is built at start-up.
fn at_start_up(k: &EntryPoint, on_demand: bool) -> bool {
    k.name != kernel::READ_CUBE.entry.name && !(cfg!(not(target_arch = "wasm32")) && on_demand)
}

/// One dispatch: a kernel, its parameter block, an optional input and the output buffer,
/// bound where the kernel's generated linkage says (its uniform, its read-only storage
/// buffer and its written one). Made only by [`kernel::Kernel::dispatch`], which takes the
/// kernel's own parameter block.
pub struct Dispatch<'a> {
    kernel: &'static EntryPoint,
    params: &'a [u8],
    input: Option<&'a wgpu::Buffer>,
    output: &'a wgpu::Buffer,
    invocations: [u32; 3],
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

    internal! {
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
    }

    internal! {
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
    }

    internal! {
        /// Builds the device and pipelines on `adapter` of `instance`.
        pub fn with_adapter(instance: wgpu::Instance, adapter: wgpu::Adapter) -> Result<Self> {
            let info = adapter.get_info();
            let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
                label: Some("splitsum"),
                required_features: wgpu::Features::empty(),
                required_limits: adapter.limits(),
                ..Default::default()
            }))
            .map_err(|e| Error::gpu_caused(format!("could not open {}", info.name), e))?;
            let mut gpu = Self::on_device(&device, &queue)?;
            gpu.instance = Some(instance);
            gpu.adapter = Some(adapter);
            Ok(gpu)
        }
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
        // Each pipeline (and its module) checked in an error scope of its own, so that an
        // error names its kernel; those built on demand are not built here (`at_start_up`).
        let kernels: Vec<&EntryPoint> = kernel::ALL.iter().filter(|(k, on_demand)| at_start_up(k, *on_demand)).map(|(k, _)| *k).collect();
        let build = |k: &EntryPoint| {
            let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
            let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some(k.name), entries: &group_layout(&[k], 0) });
            let pipeline = kernel_pipeline(device, k, &layout);
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
                return Err(Error::gpu_caused(format!("kernel {name} did not validate on {}", info.name), e.to_string()));
            }
            pipelines.insert(name, std::sync::Arc::new((pipeline, layout)));
        }
        let empty = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("empty input"),
            size: 16,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        Ok(Self {
            instance: None,
            adapter: None,
            device: device.clone(),
            queue: queue.clone(),
            info,
            pipelines: std::sync::RwLock::new(pipelines),
            empty,
        })
    }

    internal! {
        /// The shader module of entry point `e` on this device (the viewer's vertex and
        /// fragment shaders; each entry point has a module of its own).
        pub fn module(&self, e: &EntryPoint) -> wgpu::ShaderModule {
            shader_module(&self.device, e)
        }
    }

    /// Builds the pipeline of kernel `k` if it is not built yet (a kernel built on
    /// demand), checked in an error scope of its own as at start-up.
    #[cfg(not(target_arch = "wasm32"))]
    pub(crate) fn ensure<P>(&self, k: &kernel::Kernel<P>) -> Result<()> {
        let k = k.entry;
        if self.pipelines.read().unwrap_or_else(|e| e.into_inner()).contains_key(k.name) {
            return Ok(());
        }
        let scope = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let layout = self.device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some(k.name), entries: &group_layout(&[k], 0) });
        let pipeline = kernel_pipeline(&self.device, k, &layout);
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(Error::gpu_caused(format!("kernel {} did not validate on {}", k.name, self.info.name), e.to_string()));
        }
        self.pipelines.write().unwrap_or_else(|e| e.into_inner()).entry(k.name).or_insert_with(|| std::sync::Arc::new((pipeline, layout)));
        Ok(())
    }

    /// In a browser every pipeline is built at start-up.
    #[cfg(target_arch = "wasm32")]
    pub(crate) fn ensure<P>(&self, _k: &kernel::Kernel<P>) -> Result<()> {
        Ok(())
    }

    /// The pipeline of kernel `k`, built at start-up or by [`Gpu::ensure`].
    fn pipeline(&self, k: &EntryPoint) -> Pipeline {
        match self.pipelines.read().unwrap_or_else(|e| e.into_inner()).get(k.name) {
            Some(p) => p.clone(),
            None => panic!("kernel {} is run before its pipeline is built (Gpu::ensure)", k.name),
        }
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

    internal! {
        /// A storage buffer holding `data`.
        pub fn upload_bytes(&self, label: &str, data: &[u8]) -> wgpu::Buffer {
            filled(&self.device, &self.queue, label, data, wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST)
        }
    }

    internal! {
        /// The largest buffer this device binds as one storage buffer.
        pub fn max_binding(&self) -> u64 {
            let limits = self.device.limits();
            limits.max_storage_buffer_binding_size.min(limits.max_buffer_size)
        }
    }

    internal! {
        /// An output storage buffer of `bytes` bytes, checked against the device's limits.
        pub fn output(&self, label: &str, bytes: u64) -> Result<wgpu::Buffer> {
            let max = self.max_binding();
            if bytes > max {
                return Err(Error::gpu(format!(
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
    }

    internal! {
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
            let pipelines: Vec<Pipeline> = dispatches.iter().map(|d| self.pipeline(d.kernel)).collect();
            let groups: Vec<wgpu::BindGroup> = dispatches
                .iter()
                .zip(&params)
                .zip(&pipelines)
                .map(|((d, p), pipeline)| {
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
                    self.device.create_bind_group(&wgpu::BindGroupDescriptor { label: None, layout: &pipeline.1, entries: &entries })
                })
                .collect();
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor { label: None, timestamp_writes: None });
            for ((d, g), pipeline) in dispatches.iter().zip(&groups).zip(&pipelines) {
                let [x, y, z] = d.kernel.workgroups(d.invocations);
                pass.set_pipeline(&pipeline.0);
                pass.set_bind_group(0, g, &[]);
                pass.dispatch_workgroups(x, y, z);
            }
        }
    }

    internal! {
        /// Records and submits `dispatches` in order, in one submission.
        pub fn run(&self, dispatches: &[Dispatch<'_>]) {
            let mut encoder = self.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
            self.record(&mut encoder, dispatches);
            self.queue.submit([encoder.finish()]);
        }
    }

    internal! {
        /// Waits for the queue and copies `buffer` back.
        pub fn read_bytes(&self, buffer: &wgpu::Buffer) -> Result<Vec<u8>> {
            pollster::block_on(self.read_bytes_async(buffer))
        }
    }

    internal! {
        /// [`Gpu::read_bytes`] without blocking (in a browser, where nothing may block).
        pub async fn read_bytes_async(&self, buffer: &wgpu::Buffer) -> Result<Vec<u8>> {
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
            map_read_async(&self.device, &staging).await
        }
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
    Err(Error::gpu(format!(
        "{} ({}) cannot run splitsum's kernels: it lacks {}; bake on the CPU instead (Compute::Cpu)",
        info.name,
        api_name(info.backend),
        missing.join(", ")
    )))
}

/// The shader module of entry point `e` (its own module, holding only what it calls).
fn shader_module(device: &wgpu::Device, e: &EntryPoint) -> wgpu::ShaderModule {
    device.create_shader_module(wgpu::ShaderModuleDescriptor { label: Some(e.name), source: wgpu::ShaderSource::SpirV(Cow::Borrowed(e.words())) })
}

/// The compute pipeline of kernel `k`, from its own module, with the bind group layout
/// `layout`.
fn kernel_pipeline(device: &wgpu::Device, k: &EntryPoint, layout: &wgpu::BindGroupLayout) -> wgpu::ComputePipeline {
    let module = &shader_module(device, k);
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
