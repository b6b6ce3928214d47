//! Buffers on the device and reading them back: filled buffers, the cube texture to
//! buffer copy ([`CubeReader`]), mapping a buffer for reading (native and browser).

use super::{group_layout, kernel_pipeline};
use crate::error::{Error, Result};
use splitsum_shaders::cubemap::{CubeLayout, FACES};
use splitsum_spirv::Resource;

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
        let k = super::kernel::READ_CUBE.entry;
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
        let pipeline = kernel_pipeline(device, k, &layout);
        // Nearest in every direction: the texel at the sampled point, at the exact level.
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor { label: Some("splitsum cube reader"), ..Default::default() });
        Self { pipeline, layout, sampler }
    }

    /// Records the reading of every mip of the cube `texture` into `out`, texels laid out
    /// as `layout` (level by level, face by face), cleaned (`half::clean_radiance`).
    pub fn record(&self, device: &wgpu::Device, queue: &wgpu::Queue, encoder: &mut wgpu::CommandEncoder, texture: &wgpu::Texture, layout: CubeLayout, out: &wgpu::Buffer) {
        use splitsum_shaders::kernels::ReadCubeParams;
        let k = super::kernel::READ_CUBE.entry;
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
    device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| Error::gpu_caused("waiting for the device", e))?;
    done.await.map_err(|e| Error::gpu_caused("readback", e))?;
    let bytes = buffer.slice(..).get_mapped_range().map_err(|e| Error::gpu_caused("readback", e))?.to_vec();
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
