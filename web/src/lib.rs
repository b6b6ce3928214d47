//! splitsum's web page (`bash scripts/web.sh` builds it into `web/dist/`).
//!
//! An HDRI dropped on the page is read with the library's own reader
//! ([`environment::read_bytes`]), baked with the rust-gpu kernels on the browser's WebGPU
//! device (the display's bake, as `runner render` and `runner view` bake), and shown as the
//! display's sphere grid through its own vertex and fragment shaders
//! (`splitsum_display::render::GpuScene`) on the page's canvas. A download bakes the chosen
//! target's folder with the default settings on the CPU backend compiled to wasm (the
//! command line's code: SH9 reads back mid-bake, which a page cannot wait for on the GPU)
//! and zips what `output::in_memory` makes: the files `runner bake --target T` writes.
//! Where the browser has no WebGPU the CPU backend bakes and the CPU reference renderer
//! (`render::render_cpu`) draws.
//!
//! `check` is the page side of the browser test of the library alone.

mod check;
mod zip;

use splitsum::backend::Gpu;
use splitsum::bake;
use splitsum::reading::{self, BakedEnvironment};
use splitsum::environment::{self, Environment, InputReport};
use splitsum::estimate::Estimator;
use splitsum::{Backend, Choice, Products, Settings, Target, output};
use splitsum_display::render::{GpuScene, ViewState, render_cpu, to_rgb8};
use splitsum_display::scene::ShadingChoices;
use splitsum_shaders::shade::{DiffuseModel, FresnelForm, ShadeOptions, SpecularModel};
use std::cell::RefCell;
use std::rc::Rc;
use std::sync::Mutex;
use wasm_bindgen::prelude::*;
use wasm_bindgen_futures::future_to_promise;
use web_sys::HtmlCanvasElement;

#[wasm_bindgen]
extern "C" {
    #[wasm_bindgen(js_namespace = console, js_name = log)]
    fn console_log(s: &str);
}

/// A library error as the page shows it.
fn shown(e: impl std::fmt::Display) -> JsValue {
    JsValue::from_str(&e.to_string())
}

/// The page: its canvas, the browser's GPU (if it has WebGPU), and what was dropped on it.
#[wasm_bindgen]
pub struct Page {
    state: Rc<RefCell<State>>,
}

struct State {
    canvas: HtmlCanvasElement,
    gpu: Option<Shown>,
    loaded: Option<Loaded>,
}

/// WebGPU: the kernels on the browser's device, and the canvas as a surface.
struct Shown {
    _instance: wgpu::Instance,
    gpu: Rc<Gpu>,
    surface: wgpu::Surface<'static>,
    format: wgpu::TextureFormat,
    depth: Option<((u32, u32), wgpu::TextureView)>,
}

/// An environment dropped on the page, and its display bake.
struct Loaded {
    name: String,
    env: Environment,
    input: InputReport,
    baked: BakedEnvironment,
    scene: Option<GpuScene>,
}

/// The steps a bake has started, with their estimates (seconds): what the page's progress
/// bar reads while the device works.
static PROGRESS: Mutex<Vec<(String, f64)>> = Mutex::new(Vec::new());

fn follow_progress() {
    PROGRESS.lock().unwrap_or_else(|e| e.into_inner()).clear();
    splitsum::progress::report_to(Some(std::sync::Arc::new(|e: &splitsum::progress::Event<'_>| {
        if let splitsum::progress::Event::Started { what, estimate } = e {
            PROGRESS.lock().unwrap_or_else(|e| e.into_inner()).push((what.to_string(), estimate.map_or(0.0, |e| e.seconds)));
        }
    })));
}

/// Opens the page on `canvas`: WebGPU where the browser has it (every kernel's pipeline
/// built), else the CPU backend.
#[wasm_bindgen]
pub async fn open(canvas: HtmlCanvasElement) -> Result<Page, JsValue> {
    std::panic::set_hook(Box::new(|info| console_log(&format!("panic: {info}"))));
    let gpu = if wgpu::util::is_browser_webgpu_supported().await { Some(open_gpu(&canvas).await?) } else { None };
    Ok(Page { state: Rc::new(RefCell::new(State { canvas, gpu, loaded: None })) })
}

async fn open_gpu(canvas: &HtmlCanvasElement) -> Result<Shown, JsValue> {
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor { backends: wgpu::Backends::BROWSER_WEBGPU, ..wgpu::InstanceDescriptor::new_without_display_handle() });
    let surface = instance.create_surface(wgpu::SurfaceTarget::Canvas(canvas.clone())).map_err(shown)?;
    let adapter = instance
        .request_adapter(&wgpu::RequestAdapterOptions { compatible_surface: Some(&surface), ..Default::default() })
        .await
        .map_err(|e| shown(format!("no WebGPU adapter: {e}")))?;
    let (device, queue) = adapter
        .request_device(&wgpu::DeviceDescriptor { required_limits: adapter.limits(), ..Default::default() })
        .await
        .map_err(|e| shown(format!("no WebGPU device: {e}")))?;
    device.set_device_lost_callback(|reason, message| console_log(&format!("device lost: {reason:?}: {message}")));
    device.on_uncaptured_error(std::sync::Arc::new(|e| console_log(&format!("WebGPU error: {e}"))));
    // A format the canvas stores as given: the display's shader encodes sRGB itself.
    let caps = surface.get_capabilities(&adapter);
    let format = caps.formats.iter().copied().find(|f| !f.is_srgb()).unwrap_or(caps.formats[0]);
    let gpu = Gpu::on_device_async(&device, &queue).await.map_err(shown)?;
    Ok(Shown { _instance: instance, gpu: Rc::new(gpu), surface, format, depth: None })
}

#[wasm_bindgen]
impl Page {
    /// Where the page bakes and draws, in words.
    pub fn backend(&self) -> String {
        match &self.state.borrow().gpu {
            Some(s) => match s.gpu.info.name.as_str() {
                "" => "this browser's WebGPU".into(),
                name => format!("this browser's WebGPU ({name})"),
            },
            None => "the CPU (wasm, one thread): this browser has no WebGPU".into(),
        }
    }

    /// Estimated seconds of the bake under way, and of its steps started so far.
    pub fn estimate(&self) -> f64 {
        PROGRESS.lock().unwrap_or_else(|e| e.into_inner()).iter().map(|s| s.1).sum()
    }

    /// The step the bake under way started last.
    pub fn step(&self) -> String {
        PROGRESS.lock().unwrap_or_else(|e| e.into_inner()).last().map_or_else(String::new, |s| s.0.clone())
    }

    /// Reads `bytes` (a file called `name`) and bakes it for display; resolves to a line
    /// saying what was baked and how long it took.
    pub fn load(&self, name: String, bytes: Vec<u8>) -> js_sys::Promise {
        let state = self.state.clone();
        future_to_promise(async move {
            let (env, input) = environment::read_bytes(&name, &bytes, false).map_err(shown)?;
            drop(bytes);
            // The display's bake, as `runner render` and `runner view` make it.
            let job = Settings::display(env.native_face_size()).resolve(splitsum::InputShape::of(&env), Products::DISPLAY).map_err(shown)?;
            follow_progress();
            let start = web_time::Instant::now();
            let gpu = state.borrow().gpu.as_ref().map(|s| s.gpu.clone());
            let baked = match &gpu {
                Some(g) => reading::for_display_async(g, &mut Estimator::built_in(true), &env, &job).await.map_err(shown)?,
                None => reading::for_display(&Backend::Cpu, &env, &job).map_err(shown)?.0,
            };
            splitsum::progress::report_to(None);
            let seconds = start.elapsed().as_secs_f64();
            let scene = gpu.as_ref().map(|g| GpuScene::new(g, &baked));
            let said = format!("{name}: baked {}² specular, {} mips, in {seconds:.1} s", job.size, job.mips);
            state.borrow_mut().loaded = Some(Loaded { name, env, input, baked, scene });
            Ok(JsValue::from_str(&said))
        })
    }

    /// Draws the sphere grid seen from `yaw` and `pitch` (degrees), `exposure` stops above
    /// the environment's automatic exposure, with `fetches` prefiltered fetches per pixel:
    /// what `runner render --no-model --yaw --pitch --exposure --fetches` draws.
    pub fn draw(&self, yaw: f32, pitch: f32, exposure: f32, fetches: u32) -> Result<(), JsValue> {
        let mut state = self.state.borrow_mut();
        let State { canvas, gpu, loaded } = &mut *state;
        let Some(loaded) = loaded else { return Ok(()) };
        let fetches = splitsum_display::scene::check_fetches(fetches).map_err(|e| shown(format!("fetches {e}")))?;
        let view = view(loaded.baked.auto_exposure(), yaw, pitch, exposure, fetches);
        let (w, h) = (canvas.width(), canvas.height());
        match (gpu, &loaded.scene) {
            (Some(s), Some(scene)) => {
                let device = &s.gpu.device;
                s.surface.configure(device, &wgpu::SurfaceConfiguration {
                    usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
                    format: s.format,
                    width: w,
                    height: h,
                    present_mode: wgpu::PresentMode::Fifo,
                    desired_maximum_frame_latency: 2,
                    alpha_mode: wgpu::CompositeAlphaMode::Opaque,
                    view_formats: vec![],
                    color_space: wgpu::SurfaceColorSpace::Auto,
                });
                if s.depth.as_ref().is_none_or(|d| d.0 != (w, h)) {
                    s.depth = Some(((w, h), GpuScene::depth_texture(&s.gpu, w, h)));
                }
                let target = match s.surface.get_current_texture() {
                    wgpu::CurrentSurfaceTexture::Success(t) | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
                    other => return Err(shown(format!("the canvas gave no texture to draw on ({other:?})"))),
                };
                let frame = view.frame(scene.shape, w, h, !s.format.is_srgb());
                let mut encoder = device.create_command_encoder(&Default::default());
                let depth = &s.depth.as_ref().expect("made above").1;
                scene.draw(&s.gpu, &mut encoder, &target.texture.create_view(&Default::default()), depth, s.format, &frame, None);
                s.gpu.queue.submit([encoder.finish()]);
                s.gpu.queue.present(target);
            }
            _ => {
                let pixels = render_cpu(&loaded.baked, &view.frame(loaded.baked.shape(), w, h, true));
                let rgba: Vec<u8> = to_rgb8(&pixels).chunks_exact(3).flat_map(|c| [c[0], c[1], c[2], 255]).collect();
                let image = web_sys::ImageData::new_with_u8_clamped_array_and_sh(wasm_bindgen::Clamped(&rgba), w, h)?;
                let context: web_sys::CanvasRenderingContext2d = canvas.get_context("2d")?.ok_or_else(|| shown("the canvas has no 2D context"))?.dyn_into()?;
                context.put_image_data(&image, 0.0, 0.0)?;
            }
        }
        Ok(())
    }

    /// The folder `runner bake --target TARGET` writes for the environment dropped, with
    /// the default settings, as a zip (the folder named for the environment); baked on the
    /// CPU backend, the command line's code. Resolves to the zip's bytes.
    pub fn download(&self, target: String) -> js_sys::Promise {
        let state = self.state.clone();
        future_to_promise(async move {
            let state = state.borrow();
            let loaded = state.loaded.as_ref().ok_or_else(|| shown("drop an HDRI on the page first"))?;
            let target = Target::from_name(&target).ok_or_else(|| shown(format!("--target {target}: not a target")))?;
            let job = Settings::default().with_target(target).resolve(splitsum::InputShape::of(&loaded.env), target.products()).map_err(shown)?;
            let baked = bake::bake_job(&Backend::Cpu, &loaded.env, &job).map_err(shown)?;
            let folder = loaded.name.rsplit_once('.').map_or(loaded.name.as_str(), |(stem, _)| stem);
            let about = output::About { environment: loaded.name.clone(), backend: "CPU (wasm32, one thread)".into(), input: Some(loaded.input.clone()) };
            let (_, files) = output::in_memory(folder, &baked, &job, about).map_err(shown)?;
            let zipped = zip::folder(folder, &files).map_err(shown)?;
            Ok(js_sys::Uint8Array::from(zipped.as_slice()).into())
        })
    }
}

/// The view of the grid `runner render` draws with `--no-model`, `--yaw`, `--pitch`,
/// `--exposure` and `--fetches` (every other look flag at its default).
fn view(auto_exposure: f32, yaw: f32, pitch: f32, stops: f32, fetches: u32) -> ViewState {
    let flags = ShadingChoices { fetches, ..ShadingChoices::default() }.flags(true, true);
    let mut view = ViewState {
        show_model: false,
        yaw: yaw.to_radians(),
        pitch: pitch.to_radians(),
        exposure: auto_exposure * 2f32.powf(stops),
        options: ShadeOptions { diffuse: DiffuseModel::default().code(), specular: SpecularModel::default().code(), fresnel: FresnelForm::default().code(), flags },
        ..ViewState::default()
    };
    view.frame_contents();
    view
}
