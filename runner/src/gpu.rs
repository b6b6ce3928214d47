//! The GPU backend: wgpu on a Vulkan adapter, running the rust-gpu kernels of
//! `splitsum_shaders::kernels` from the SPIR-V module that `build.rs` compiles.
//!
//! Start-up (instance, adapter, device, every pipeline) happens in [`Gpu::new`], so that
//! the time of a bake excludes it. Dispatches are recorded into one command encoder per
//! product and submitted together; results come back through a staging buffer.

use crate::error::{Error, Result};
use std::borrow::Cow;
use std::collections::HashMap;
use wgpu::util::DeviceExt;

/// The SPIR-V module compiled from `shaders/` by rust-gpu.
pub static SPIRV: &[u8] = include_bytes!(env!("SPLITSUM_SPV"));

/// A compute kernel of the shader module.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum Kernel {
    /// `kernels::brdf_lut`.
    BrdfLut,
    /// `kernels::brdf_table`.
    BrdfTable,
    /// `kernels::equirect_pyramid`.
    EquirectPyramid,
    /// `kernels::equirect_to_cube`.
    EquirectToCube,
    /// `kernels::downsample`.
    Downsample,
    /// `kernels::prefilter_specular`.
    PrefilterSpecular,
    /// `kernels::irradiance_cube`.
    IrradianceCube,
    /// `kernels::irradiance_sh9`.
    IrradianceSh9,
    /// `kernels::probe`.
    Probe,
}

impl Kernel {
    /// Every kernel.
    pub const ALL: [Kernel; 9] = [
        Kernel::BrdfLut,
        Kernel::BrdfTable,
        Kernel::EquirectPyramid,
        Kernel::EquirectToCube,
        Kernel::Downsample,
        Kernel::PrefilterSpecular,
        Kernel::IrradianceCube,
        Kernel::IrradianceSh9,
        Kernel::Probe,
    ];

    /// The entry point's name in the SPIR-V module.
    pub fn entry_point(self) -> &'static str {
        match self {
            Kernel::BrdfLut => "kernels::brdf_lut",
            Kernel::BrdfTable => "kernels::brdf_table",
            Kernel::EquirectPyramid => "kernels::equirect_pyramid",
            Kernel::EquirectToCube => "kernels::equirect_to_cube",
            Kernel::Downsample => "kernels::downsample",
            Kernel::PrefilterSpecular => "kernels::prefilter_specular",
            Kernel::IrradianceCube => "kernels::irradiance_cube",
            Kernel::IrradianceSh9 => "kernels::irradiance_sh9",
            Kernel::Probe => "kernels::probe",
        }
    }
}

/// A wgpu device with every kernel's pipeline ready.
pub struct Gpu {
    /// The instance (kept for creating window surfaces).
    pub instance: wgpu::Instance,
    /// The adapter.
    pub adapter: wgpu::Adapter,
    /// The SPIR-V module of `splitsum-shaders` (compute, vertex and fragment entry points).
    pub module: wgpu::ShaderModule,
    /// The device.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
    /// What the adapter says of itself.
    pub info: wgpu::AdapterInfo,
    layout: wgpu::BindGroupLayout,
    pipelines: HashMap<Kernel, wgpu::ComputePipeline>,
    empty: wgpu::Buffer,
}

/// One dispatch: a kernel, its parameter block, an optional input and the output buffer.
pub struct Dispatch<'a> {
    /// The kernel.
    pub kernel: Kernel,
    /// The uniform parameter block (a `Pod` struct of `kernels`).
    pub params: &'a [u8],
    /// Binding 1, read-only input, if the kernel reads one.
    pub input: Option<&'a wgpu::Buffer>,
    /// Binding 2, the output.
    pub output: &'a wgpu::Buffer,
    /// Workgroup counts.
    pub groups: [u32; 3],
}

/// A Vulkan-only wgpu instance.
pub fn vulkan_instance() -> wgpu::Instance {
    wgpu::Instance::new(wgpu::InstanceDescriptor { backends: wgpu::Backends::VULKAN, ..wgpu::InstanceDescriptor::new_without_display_handle() })
}

/// The adapters `instance` can see through Vulkan, best first: discrete, integrated,
/// virtual, then CPU (lavapipe); only those whose name contains `filter`, if given.
pub fn vulkan_adapters(instance: &wgpu::Instance, filter: Option<&str>) -> Vec<wgpu::Adapter> {
    let mut adapters = pollster::block_on(instance.enumerate_adapters(wgpu::Backends::VULKAN));
    let rank = |t: wgpu::DeviceType| match t {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Other => 3,
        wgpu::DeviceType::Cpu => 4,
    };
    adapters.sort_by_key(|a| rank(a.get_info().device_type));
    if let Some(want) = filter {
        let want = want.to_lowercase();
        adapters.retain(|a| a.get_info().name.to_lowercase().contains(&want));
    }
    adapters
}

impl Gpu {
    /// Opens the best Vulkan adapter and builds every pipeline. The environment variable
    /// `SPLITSUM_ADAPTER` restricts the choice to adapters whose name contains its value.
    pub fn new() -> Result<Self> {
        Self::matching(std::env::var("SPLITSUM_ADAPTER").ok().as_deref())
    }

    /// Opens the best Vulkan adapter whose name contains `filter` (any, if `None`).
    pub fn matching(filter: Option<&str>) -> Result<Self> {
        let instance = vulkan_instance();
        let adapter = vulkan_adapters(&instance, filter).into_iter().next().ok_or_else(|| Error::NoAdapter {
            detail: match filter {
                Some(want) => format!(" whose name contains {want:?} (SPLITSUM_ADAPTER)"),
                None => String::new(),
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

        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("splitsum-shaders"),
            source: wgpu::ShaderSource::SpirV(Cow::Owned(spirv_words())),
        });
        let storage = |binding, read_only| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer { ty: wgpu::BufferBindingType::Storage { read_only }, has_dynamic_offset: false, min_binding_size: None },
            count: None,
        };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("kernel bindings"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::Buffer { ty: wgpu::BufferBindingType::Uniform, has_dynamic_offset: false, min_binding_size: None },
                    count: None,
                },
                storage(1, true),
                storage(2, false),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("kernel layout"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipelines = Kernel::ALL
            .iter()
            .map(|&k| {
                let p = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                    label: Some(k.entry_point()),
                    layout: Some(&pipeline_layout),
                    module: &module,
                    entry_point: Some(k.entry_point()),
                    compilation_options: Default::default(),
                    cache: None,
                });
                (k, p)
            })
            .collect();
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(Error::Gpu(format!("the kernels did not validate on {}: {e}", info.name)));
        }
        let empty = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("empty input"),
            size: 16,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        Ok(Self { instance, adapter, module, device, queue, info, layout, pipelines, empty })
    }

    /// A one-line description of the adapter.
    pub fn describe(&self) -> String {
        format!("{} ({:?}, {} {})", self.info.name, self.info.device_type, self.info.driver, self.info.driver_info)
    }

    /// Whether the adapter is a software rasteriser on the CPU (lavapipe, SwiftShader).
    pub fn is_software(&self) -> bool {
        self.info.device_type == wgpu::DeviceType::Cpu
    }

    /// A storage buffer holding `data`.
    pub fn upload(&self, label: &str, data: &[u8]) -> wgpu::Buffer {
        self.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents: data,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
        })
    }

    /// The largest buffer this device binds as one storage buffer.
    pub fn max_binding(&self) -> u64 {
        let limits = self.device.limits();
        (limits.max_storage_buffer_binding_size as u64).min(limits.max_buffer_size)
    }

    /// An output storage buffer of `bytes` bytes, checked against the device's limits.
    pub fn output(&self, label: &str, bytes: u64) -> Result<wgpu::Buffer> {
        let max = self.max_binding();
        if bytes > max {
            return Err(Error::Gpu(format!(
                "{label} needs {bytes} bytes, more than this device binds in one buffer ({max}); use a smaller size or --backend cpu"
            )));
        }
        Ok(self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: bytes.max(16),
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        }))
    }

    /// Records and submits `dispatches` in order, in one submission.
    pub fn run(&self, dispatches: &[Dispatch<'_>]) {
        let mut encoder = self.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
        let params: Vec<wgpu::Buffer> = dispatches
            .iter()
            .map(|d| {
                self.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("params"),
                    contents: d.params,
                    usage: wgpu::BufferUsages::UNIFORM,
                })
            })
            .collect();
        let groups: Vec<wgpu::BindGroup> = dispatches
            .iter()
            .zip(&params)
            .map(|(d, p)| {
                self.device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: None,
                    layout: &self.layout,
                    entries: &[
                        wgpu::BindGroupEntry { binding: 0, resource: p.as_entire_binding() },
                        wgpu::BindGroupEntry { binding: 1, resource: d.input.unwrap_or(&self.empty).as_entire_binding() },
                        wgpu::BindGroupEntry { binding: 2, resource: d.output.as_entire_binding() },
                    ],
                })
            })
            .collect();
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor { label: None, timestamp_writes: None });
            for (d, g) in dispatches.iter().zip(&groups) {
                pass.set_pipeline(&self.pipelines[&d.kernel]);
                pass.set_bind_group(0, g, &[]);
                pass.dispatch_workgroups(d.groups[0], d.groups[1], d.groups[2]);
            }
        }
        self.queue.submit([encoder.finish()]);
    }

    /// Waits for the queue and copies `buffer` back.
    pub fn read(&self, buffer: &wgpu::Buffer) -> Result<Vec<u8>> {
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
        let (tx, rx) = std::sync::mpsc::channel();
        staging.slice(..).map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        self.device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| Error::Gpu(format!("waiting for the device: {e}")))?;
        rx.recv().map_err(|e| Error::Gpu(format!("readback: {e}")))?.map_err(|e| Error::Gpu(format!("readback: {e}")))?;
        let bytes = staging.slice(..).get_mapped_range().map_err(|e| Error::Gpu(format!("readback: {e}")))?.to_vec();
        staging.unmap();
        Ok(bytes)
    }
}

/// The SPIR-V module as words (`include_bytes!` gives no alignment guarantee).
fn spirv_words() -> Vec<u32> {
    SPIRV.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect()
}

/// Workgroup count covering `n` invocations at `per_group` each.
pub fn groups(n: u32, per_group: u32) -> u32 {
    n.div_ceil(per_group)
}
