//! The page side of the browser test of the library alone (`bash scripts/dev.sh webgpu`, and
//! `dev.sh test`): splitsum baking through `Baker` on the browser's WebGPU device.

use splitsum::glam::Vec4;
use splitsum::texture::Equirect;
use splitsum::environment::Environment;
use splitsum::{Baker, Compute, Product, Settings, Source};
use wasm_bindgen::prelude::*;

use super::console_log;

/// The browser's WebGPU adapter and device (with the instance, which must outlive them).
async fn open() -> Result<(wgpu::Instance, wgpu::Adapter, wgpu::Device, wgpu::Queue), JsValue> {
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor { backends: wgpu::Backends::BROWSER_WEBGPU, ..wgpu::InstanceDescriptor::new_without_display_handle() });
    let adapter = instance.request_adapter(&wgpu::RequestAdapterOptions::default()).await.map_err(|e| JsValue::from_str(&format!("no WebGPU adapter: {e}")))?;
    let (device, queue) = adapter
        .request_device(&wgpu::DeviceDescriptor { required_limits: adapter.limits(), ..Default::default() })
        .await
        .map_err(|e| JsValue::from_str(&format!("no WebGPU device: {e}")))?;
    Ok((instance, adapter, device, queue))
}

/// Bakes the equirect `texels` (RGB f32 per texel, `width`×`height`) at specular size
/// `size` (0: the default settings) with splitsum's kernels on the browser's device, and returns the textures read
/// back: the specular cube, the irradiance cube (RGBA each, every mip) and the table (RG).
/// Each step, and the device's loss if it is lost, is logged to the console.
#[wasm_bindgen]
pub async fn bake_textures(texels: Vec<f32>, width: u32, height: u32, size: u32) -> Result<Vec<f32>, JsValue> {
    std::panic::set_hook(Box::new(|info| console_log(&format!("panic: {info}"))));
    let (_instance, adapter, device, queue) = open().await?;
    console_log(&format!("adapter: {:?}", adapter.get_info()));
    device.set_device_lost_callback(|reason, message| console_log(&format!("device lost: {reason:?}: {message}")));
    let texels = texels.chunks_exact(3).map(|c| Vec4::new(c[0], c[1], c[2], 1.0)).collect();
    let env = Environment::Equirect(Equirect { width, height, texels });
    let err = |e: splitsum::Error| JsValue::from_str(&e.to_string());
    let baker = Baker::new_async(&device, &queue, Compute::Gpu).await.map_err(err)?;
    console_log("pipelines built");
    // Size 0: the default settings whole (what the page bakes); else small ones for the test.
    let settings = if size == 0 { Settings::default() } else { Settings { size, irradiance_size: 8, lut_size: 32, ..Settings::default() } };
    let ibl = baker.bake(Source::Environment(&env), &settings).map_err(err)?;
    console_log("baked");
    let baked = ibl.read_async(&device, &queue).await.map_err(err)?;
    console_log("read back");
    let mut out = Vec::new();
    for cube in [baked.cube(Product::Specular), baked.cube(Product::Irradiance)].into_iter().flatten() {
        out.extend(cube.texels.iter().flat_map(|v| v.to_array()));
    }
    out.extend(baked.table(Product::BrdfTable).iter().flat_map(|l| l.texels.iter().flat_map(|t| t.to_array())));
    Ok(out)
}
