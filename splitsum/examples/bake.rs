//! An application of its own: it opens a wgpu device, bakes image-based lighting there,
//! binds the three textures as a PBR renderer does, and writes the files.
//!
//! ```text
//! cargo run --release -p splitsum --example bake -- SKY.exr OUT [--cpu]
//! ```
//!
//! `WGPU_BACKEND` (`vulkan`, `metal`, `dx12`, `gl`) and `WGPU_ADAPTER_NAME` choose the
//! device, as in any wgpu application.

use splitsum::output::Manifest;
use splitsum::{Baker, Compute, Ibl, Settings, Source};
use std::path::Path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let paths: Vec<&str> = args.iter().map(String::as_str).filter(|a| !a.starts_with("--")).collect();
    let (sky, out) = match paths.as_slice() {
        [sky, out] => (Path::new(*sky), Path::new(*out)),
        _ => return Err("usage: bake SKY.exr OUT [--cpu]".into()),
    };
    let compute = if args.iter().any(|a| a == "--cpu") { Compute::Cpu } else { Compute::Gpu };
    let manifest = bake(wgpu::Backends::from_env().unwrap_or_default(), sky, out, compute)?;
    println!("baked on {} and wrote {} files to {}", manifest.backend, manifest.files.len() + 1, out.display());
    Ok(())
}

/// Device, bake, bind, files: the environment `sky` baked on a device of `backends`
/// (`compute`: with splitsum's kernels there, or on the CPU and uploaded), written as the
/// folder `out`.
pub fn bake(backends: wgpu::Backends, sky: &Path, out: &Path, compute: Compute) -> Result<Manifest, Box<dyn std::error::Error>> {
    // 1. The application's own device, on any API wgpu has here.
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor { backends, ..wgpu::InstanceDescriptor::new_without_display_handle() });
    let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions::default()))?;
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor { required_limits: adapter.limits(), ..Default::default() }))?;

    // 2. The bake, on that device. Settings left at their defaults derive from the size
    //    (mips, source size) and the target.
    let (env, _report) = splitsum::environment::load(sky, false)?;
    let baker = Baker::new(&device, &queue, compute)?;
    let ibl = baker.bake(Source::Environment(&env), &Settings { size: 128, ..Settings::default() })?;

    // 3. The three textures bound as a PBR shader samples them:
    //      @group(0) @binding(0) var specular: texture_cube<f32>;   // at lod = ibl.lod(roughness)
    //      @group(0) @binding(1) var irradiance: texture_cube<f32>; // E/π along the normal
    //      @group(0) @binding(2) var brdf: texture_2d<f32>;         // (A, B) at (n·v, roughness)
    //    and the specular term is prefiltered(r) · (F₀·A + B).
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("image-based light"),
        entries: &Ibl::layout_entries(0, wgpu::ShaderStages::FRAGMENT),
    });
    let views = ibl.views();
    let _bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some("image-based light"), layout: &layout, entries: &views.entries(0) });
    println!("roughness 0.5 reads specular mip {:.2} of {}", ibl.lod(0.5), ibl.roughness.len());

    // 4. The files: KTX2 cubes, the table, previews and bake.json, written as a folder
    //    (replaced whole, and only if everything in it is what splitsum wrote there).
    let baked = ibl.read(&device, &queue)?;
    Ok(splitsum::output::write(out, &baked, &ibl.job, splitsum::output::About { backend: format!("{:?}", adapter.get_info().backend), ..Default::default() })?)
}
