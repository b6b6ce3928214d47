//! The interactive viewer: a winit window with a wgpu surface, the scene drawn by the
//! `display` shaders, an orbit camera on the mouse and keys for every model and setting.
//! The current choices are in the window title.

use crate::model::Model;
use crate::render::{GpuModel, GpuScene, ViewState};
use splitsum::backend::gpu::Gpu;
use splitsum::reading::BakedEnvironment;
use splitsum::error::{Error, Result};
use splitsum_shaders::choice::Choice;
use splitsum_shaders::shade::{self, DiffuseModel, FresnelForm, ShadeOptions, SpecularModel};
use splitsum_shaders::tonemap::Tonemapper;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};
use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowId};

/// The keys, as printed by `H` and in the README.
pub const HELP: &str = "\
mouse: drag to orbit, wheel to zoom
D  diffuse model (Lambert, Oren-Nayar, Fresnel-weighted)
S  specular model (Cook-Torrance, Phong, Blinn-Phong, none)
F  Fresnel form (Schlick, spherical Gaussian)
I  image-based light on/off      L  direct lights on/off
K  prefiltered fetches per pixel (1, 2, 4, 8, 16: the shading ladder)
+ -  exposure ±½ stop            T  tone curve (ACES, Reinhard, clamp)
[ ]  sky blur ±½ mip             R  reset the camera
G  sphere grid on/off            M  model on/off
P  save a screenshot (PNG)       H  this help          Esc/Q  quit";

/// How the viewer runs.
#[derive(Default)]
pub struct ViewOptions {
    /// Close after this long (tests, demos).
    pub exit_after: Option<Duration>,
    /// Close after this many presented frames (tests).
    pub exit_after_frames: Option<u64>,
    /// Called after each presented frame with its number (tests take screenshots here).
    pub on_presented: Option<Box<dyn FnMut(u64)>>,
    /// Initial window size.
    pub size: (u32, u32),
}

/// Whether a display server seems to be there.
pub fn display_available() -> bool {
    std::env::var_os("DISPLAY").is_some() || std::env::var_os("WAYLAND_DISPLAY").is_some()
}

struct App {
    gpu: Gpu,
    scene: GpuScene,
    model: Option<GpuModel>,
    depth: Option<(u32, u32, wgpu::TextureView)>,
    state: ViewState,
    initial: ViewState,
    options: ViewOptions,
    window: Option<Arc<Window>>,
    surface: Option<wgpu::Surface<'static>>,
    config: Option<wgpu::SurfaceConfiguration>,
    encode_srgb: bool,
    dragging: bool,
    cursor: Option<(f64, f64)>,
    start: Instant,
    frames: u64,
    screenshots: u32,
    done: bool,
    error: Option<Error>,
}

impl App {
    fn title(&self) -> String {
        format!("splitsum — {}", self.state.summary())
    }

    fn changed(&self) {
        if let Some(w) = &self.window {
            w.set_title(&self.title());
            w.request_redraw();
        }
    }

    fn configure(&mut self, width: u32, height: u32) {
        if let (Some(surface), Some(config)) = (&self.surface, &mut self.config) {
            config.width = width.max(1);
            config.height = height.max(1);
            surface.configure(&self.gpu.device, config);
        }
    }

    fn draw(&mut self) {
        let (Some(surface), Some(config)) = (&self.surface, &self.config) else { return };
        let texture = match surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t) | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                let (w, h) = (config.width, config.height);
                self.configure(w, h);
                return;
            }
            _ => return,
        };
        let view = texture.texture.create_view(&Default::default());
        let frame = self.state.frame(self.scene.shape, config.width, config.height, self.encode_srgb);
        if self.depth.as_ref().is_none_or(|(w, h, _)| (*w, *h) != (config.width, config.height)) {
            self.depth = Some((config.width, config.height, GpuScene::depth_texture(&self.gpu, config.width, config.height)));
        }
        let depth = &self.depth.as_ref().expect("created above").2;
        let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
        let model = self.model.as_ref().filter(|_| self.state.show_model);
        self.scene.draw(&self.gpu, &mut encoder, &view, depth, config.format, &frame, model);
        self.gpu.queue.submit([encoder.finish()]);
        self.gpu.queue.present(texture);
        self.frames += 1;
        if let Some(hook) = &mut self.options.on_presented {
            hook(self.frames);
        }
        if self.options.exit_after_frames.is_some_and(|n| self.frames >= n) {
            self.done = true;
        } else if self.options.exit_after_frames.is_some() {
            // Keep presenting until the count is reached.
            if let Some(w) = &self.window {
                w.request_redraw();
            }
        }
    }

    fn screenshot(&mut self) {
        let (w, h) = self.config.as_ref().map(|c| (c.width, c.height)).unwrap_or((960, 540));
        // The next name no file has: a screenshot never replaces a file.
        let path = loop {
            self.screenshots += 1;
            let p = PathBuf::from(format!("splitsum-screenshot-{}.png", self.screenshots));
            if std::fs::symlink_metadata(&p).is_err() {
                break p;
            }
        };
        let frame = self.state.frame(self.scene.shape, w, h, true);
        let result = self
            .scene
            .render_offscreen(&self.gpu, &frame, self.model.as_ref().filter(|_| self.state.show_model))
            .and_then(|p| splitsum::files::write_png(&path, w, h, &crate::render::to_rgb8(&p)));
        match result {
            Ok(()) => println!("wrote {}", path.display()),
            Err(e) => eprintln!("screenshot: {}", splitsum::error::chain(&e)),
        }
    }

    fn key(&mut self, key: &Key, event_loop: &ActiveEventLoop) {
        let o = &mut self.state.options;
        match key {
            Key::Named(NamedKey::Escape) => event_loop.exit(),
            Key::Character(c) => match c.to_lowercase().as_str() {
                "q" => event_loop.exit(),
                "d" => o.diffuse = (o.diffuse + 1) % DiffuseModel::ALL.len() as u32,
                "s" => o.specular = (o.specular + 1) % SpecularModel::ALL.len() as u32,
                "f" => o.fresnel = (o.fresnel + 1) % FresnelForm::ALL.len() as u32,
                "i" => o.flags ^= ShadeOptions::IBL,
                "l" => o.flags ^= ShadeOptions::DIRECT,
                // The shading ladder: 1 → 2 → 4 → 8 → 16 → 1 fetches.
                "k" => *o = o.with_fetches(if o.fetches() >= shade::MAX_FETCHES { 1 } else { 2 * o.fetches() }),
                "+" | "=" => self.state.exposure *= std::f32::consts::SQRT_2,
                "-" | "_" => self.state.exposure /= std::f32::consts::SQRT_2,
                "t" => {
                    self.state.tonemapper = match self.state.tonemapper {
                        Tonemapper::Aces => Tonemapper::Reinhard,
                        Tonemapper::Reinhard => Tonemapper::Clamp,
                        Tonemapper::Clamp => Tonemapper::Aces,
                    }
                }
                "[" => self.state.sky_blur = (self.state.sky_blur - 0.5).max(0.0),
                "]" => self.state.sky_blur = (self.state.sky_blur + 0.5).min((self.scene.shape.specular_levels - 1) as f32),
                "r" => {
                    self.state.yaw = self.initial.yaw;
                    self.state.pitch = self.initial.pitch;
                    self.state.frame_contents();
                }
                "g" => {
                    self.state.spheres = !self.state.spheres;
                    self.state.frame_contents();
                }
                "m" if self.model.is_some() => {
                    self.state.show_model = !self.state.show_model;
                    self.state.frame_contents();
                }
                "p" => self.screenshot(),
                "h" => println!("{HELP}"),
                _ => return,
            },
            _ => return,
        }
        self.changed();
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.window.is_some() {
            return;
        }
        let (w, h) = self.options.size;
        let attributes = Window::default_attributes().with_title(self.title()).with_inner_size(winit::dpi::PhysicalSize::new(w, h));
        let window = match event_loop.create_window(attributes) {
            Ok(w) => Arc::new(w),
            Err(e) => {
                self.error = Some(Error::gpu_caused("could not open a window", e));
                event_loop.exit();
                return;
            }
        };
        let (Some(instance), Some(adapter)) = (&self.gpu.instance, &self.gpu.adapter) else {
            self.error = Some(Error::gpu("the viewer presents on a device it opened itself (Gpu::new), not a caller's"));
            event_loop.exit();
            return;
        };
        let surface = match instance.create_surface(window.clone()) {
            Ok(s) => s,
            Err(e) => {
                self.error = Some(Error::gpu_caused("could not create a surface for the window", e));
                event_loop.exit();
                return;
            }
        };
        let caps = surface.get_capabilities(adapter);
        if caps.formats.is_empty() {
            self.error = Some(Error::gpu(format!("{} cannot present to this window", self.gpu.info.name)));
            event_loop.exit();
            return;
        }
        // Prefer a UNORM format: the shader then encodes sRGB itself, exactly as the CPU does.
        let format = caps.formats.iter().copied().find(|f| !f.is_srgb()).unwrap_or(caps.formats[0]);
        self.encode_srgb = !format.is_srgb();
        let size = window.inner_size();
        let config = wgpu::SurfaceConfiguration {
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            format,
            color_space: Default::default(),
            width: size.width.max(1),
            height: size.height.max(1),
            present_mode: wgpu::PresentMode::AutoVsync,
            desired_maximum_frame_latency: 2,
            alpha_mode: caps.alpha_modes[0],
            view_formats: vec![],
        };
        surface.configure(&self.gpu.device, &config);
        self.surface = Some(surface);
        self.config = Some(config);
        self.window = Some(window);
        self.changed();
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => {
                self.configure(size.width, size.height);
                self.changed();
            }
            WindowEvent::RedrawRequested => self.draw(),
            WindowEvent::KeyboardInput { event, .. } if event.state == ElementState::Pressed => self.key(&event.logical_key, event_loop),
            WindowEvent::MouseInput { button: MouseButton::Left, state, .. } => {
                self.dragging = state == ElementState::Pressed;
            }
            WindowEvent::CursorMoved { position, .. } => {
                if let (true, Some((x, y))) = (self.dragging, self.cursor) {
                    self.state.yaw -= ((position.x - x) * 0.008) as f32;
                    self.state.pitch = (self.state.pitch + ((position.y - y) * 0.008) as f32).clamp(-1.5, 1.5);
                    self.changed();
                }
                self.cursor = Some((position.x, position.y));
            }
            WindowEvent::MouseWheel { delta, .. } => {
                let lines = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => (p.y / 40.0) as f32,
                };
                self.state.distance = (self.state.distance * 0.9f32.powf(lines)).clamp(1.0, 100.0);
                self.changed();
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        if self.done {
            event_loop.exit();
            return;
        }
        match self.options.exit_after {
            Some(limit) => {
                if self.start.elapsed() >= limit {
                    event_loop.exit();
                } else {
                    event_loop.set_control_flow(ControlFlow::WaitUntil(Instant::now() + Duration::from_millis(50)));
                }
            }
            None => event_loop.set_control_flow(ControlFlow::Wait),
        }
    }
}

/// Opens a window on `gpu` showing `env` (and `model`, if any) and runs until it is closed.
pub fn run(gpu: Gpu, env: &BakedEnvironment, model: Option<&Model>, state: ViewState, options: ViewOptions) -> Result<()> {
    let mut builder = EventLoop::builder();
    #[cfg(all(unix, not(target_os = "macos")))]
    {
        // Tests drive the viewer from a non-main thread.
        use winit::platform::wayland::EventLoopBuilderExtWayland;
        use winit::platform::x11::EventLoopBuilderExtX11;
        EventLoopBuilderExtX11::with_any_thread(&mut builder, true);
        EventLoopBuilderExtWayland::with_any_thread(&mut builder, true);
    }
    let event_loop = builder.build().map_err(|e| Error::gpu(format!("no display to open a window on ({e}); use `runner render` instead")))?;
    let scene = GpuScene::new(&gpu, env);
    let model = model.map(|m| GpuModel::new(&gpu, &scene, m));
    println!("{HELP}");
    let mut app = App {
        gpu,
        scene,
        model,
        depth: None,
        initial: state.clone(),
        state,
        options,
        window: None,
        surface: None,
        config: None,
        encode_srgb: true,
        dragging: false,
        cursor: None,
        start: Instant::now(),
        frames: 0,
        screenshots: 0,
        done: false,
        error: None,
    };
    event_loop.run_app(&mut app).map_err(|e| Error::gpu_caused("window event loop", e))?;
    match app.error {
        Some(e) => Err(e),
        None => Ok(()),
    }
}
