//! splitsum as a library, the way an application uses it: `splitsum/examples/sphere.rs`
//! (compiled into this test and run) opens its own wgpu device, bakes with `Baker` into
//! textures on that device, binds them and draws a sphere; these tests check what it
//! draws against closed forms and across backends, and the texture-source route.

#[path = "../splitsum/examples/sphere.rs"]
#[allow(dead_code)]
mod sphere;

#[path = "../splitsum/examples/bake.rs"]
#[allow(dead_code)]
mod app;

use splitsum::Product;
use splitsum::texture::{Cube, Equirect};
use splitsum::{Baker, Compute, Environment, Settings, Source};
use splitsum_reference as reference;
use splitsum_shaders::glam::Vec4;
use std::sync::OnceLock;

/// One device for every test here (the application's, not splitsum's).
fn device() -> &'static (wgpu::Device, wgpu::Queue) {
    static D: OnceLock<(wgpu::Device, wgpu::Queue)> = OnceLock::new();
    D.get_or_init(sphere::open_device)
}

fn small() -> Settings {
    Settings { size: 16, source_size: Some(32), lut_size: 128, irradiance_size: 8, ..Settings::default() }
}

/// What `Ibl::read` gives, unwrapped: the two cubes and the table as `(A, B, 0, 0)`.
struct Data {
    specular: splitsum::texture::Cube,
    irradiance: splitsum::texture::Cube,
    brdf: Vec<Vec4>,
}

fn data(b: splitsum::Baked) -> Data {
    Data {
        specular: b.cube(Product::Specular).cloned().expect("read back"),
        irradiance: b.cube(Product::Irradiance).cloned().expect("read back"),
        brdf: b.table(Product::BrdfTable).cloned().expect("read back").texels.iter().map(|t| t.extend(0.0).extend(0.0)).collect(),
    }
}

fn constant(l: f32) -> Environment {
    Environment::Equirect(Equirect { width: 64, height: 32, texels: vec![Vec4::new(l, l, l, 1.0); 64 * 32] })
}

/// The furnace: in a constant environment `L` every prefiltered and irradiance texel is
/// `L` (both are normalised means), so the centre of the sphere (n·v → 1) shows
/// `ρ·L + L·(F₀·A + B)` with `(A, B)` the split-sum table at n·v = 1, here from the f64
/// reference integral (exact Smith, as the default table). Tolerance 1 %: half floats
/// (2⁻¹¹ relative per value), the table's last texel centre at n·v = 1 − 1/256 rather
/// than 1 (A + B changes by under 10⁻³ there), and the pixel's n·v of 1 − 10⁻⁵.
#[test]
fn the_example_lights_a_sphere_in_a_furnace_as_the_closed_form_says() {
    let (d, q) = device();
    let (l, rho, roughness) = (0.5f32, 0.5f32, 0.5f32);
    let (a, b) = reference::brdf_lut_with(1.0, roughness as f64, 1e-9, reference::Smith::Correlated);
    let want = (rho * l) as f64 + l as f64 * (a + b);
    for compute in [Compute::Gpu, Compute::Cpu] {
        let material = sphere::Material { albedo: [rho; 3], f0: [1.0; 3], roughness };
        let pic = sphere::draw(d, q, &constant(l), &small(), compute, material, 64).unwrap();
        let centre = pic.pixels[(32 * 64 + 32) as usize];
        for (c, &got) in centre.iter().enumerate().take(3) {
            let rel = (got as f64 - want).abs() / want;
            if c == 0 {
                eprintln!("{compute:?}: furnace centre {got} against the closed form {want:.5}: {rel:.2e} relative");
            }
            assert!(rel < 1e-2, "{compute:?}: centre channel {c} = {got}, the closed form {want:.5} ({rel:.2e})");
        }
        assert_eq!(pic.pixels[0][3], 0.0, "{compute:?}: a corner is outside the sphere");
    }
}

/// The same bake on the application's device and on the CPU, read back from the textures:
/// within 2 half-float ULPs (2⁻¹⁰ relative, above a floor of 10⁻³ of the largest value),
/// the quantisation of the halves around GPU-vs-CPU f32 differences of about 10⁻⁵.
#[test]
fn textures_baked_on_the_device_match_those_baked_on_the_cpu() {
    let (d, q) = device();
    let env = splitsum::environment::embedded_default().unwrap();
    let s = small();
    let gpu = Baker::new(d, q, Compute::Gpu).unwrap().bake(Source::Environment(&env), &s).unwrap().read(d, q).map(data).unwrap();
    let cpu = Baker::new(d, q, Compute::Cpu).unwrap().bake(Source::Environment(&env), &s).unwrap().read(d, q).map(data).unwrap();
    let compare = |what: &str, a: &[Vec4], b: &[Vec4]| {
        assert_eq!(a.len(), b.len(), "{what}");
        let peak = b.iter().map(|v| v.max_element()).fold(0.0f32, f32::max);
        let floor = 1e-3 * peak;
        let worst = a.iter().zip(b).map(|(x, y)| ((*x - *y).abs() / y.abs().max(Vec4::splat(floor))).max_element()).fold(0.0f32, f32::max);
        eprintln!("{what}: GPU vs CPU textures, largest relative difference {worst:.2e}");
        assert!(worst <= 2.0f32.powi(-10), "{what}: GPU and CPU textures differ by {worst:.2e} relative");
    };
    assert_eq!(gpu.specular.layout.levels, Settings::default_mips(16), "a mip per roughness, derived from the size");
    compare("specular", &gpu.specular.texels, &cpu.specular.texels);
    compare("irradiance", &gpu.irradiance.texels, &cpu.irradiance.texels);
    compare("brdf", &gpu.brdf, &cpu.brdf);
    // The table's own values against the f64 reference, as read from the texture.
    let n = s.lut_size as usize;
    for (x, y) in [(n - 1, n / 2), (n / 4, n / 8), (n / 2, n - 1)] {
        let (nv, r) = ((x as f64 + 0.5) / n as f64, (y as f64 + 0.5) / n as f64);
        let (a, b) = reference::brdf_lut_with(nv, r, 1e-9, reference::Smith::Correlated);
        let t = gpu.brdf[y * n + x];
        assert!((t.x as f64 - a).abs() < 2e-3 && (t.y as f64 - b).abs() < 2e-3, "table at n·v {nv}, r {r}: {t:?} vs ({a}, {b}) (half floats: 2⁻¹¹ of 1)");
    }
}

/// `Baker::bake_with_sheen`: the sheen cube and tables as textures on the application's
/// device, on the GPU and on the CPU, read back: the sheen cube within 2 half-float ULPs of
/// each other (as the other cubes above), and the tables equal to the embedded ones to half
/// precision (2⁻¹¹ relative, the tables reach 1.8); `Baker::bake` makes no sheen.
#[test]
fn the_baker_makes_sheen_textures_when_asked() {
    let (d, q) = device();
    let env = splitsum::environment::embedded_default().unwrap();
    let s = small();
    let read = |compute| {
        let ibl = Baker::new(d, q, compute).unwrap().bake_with_sheen(Source::Environment(&env), &s).unwrap();
        let t = ibl.sheen.as_ref().expect("sheen textures");
        assert_eq!((t.cube.mip_level_count(), t.roughness.len() as u32), (ibl.specular.mip_level_count(), ibl.specular.mip_level_count()));
        ibl.read(d, q).unwrap()
    };
    let (gpu, cpu) = (read(Compute::Gpu), read(Compute::Cpu));
    let (g, c) = (gpu.cube(Product::Sheen).cloned().expect("read back"), cpu.cube(Product::Sheen).cloned().expect("read back"));
    let peak = c.texels.iter().map(|v| v.max_element()).fold(0.0f32, f32::max);
    let worst = g.texels.iter().zip(&c.texels).map(|(x, y)| ((*x - *y).abs() / y.abs().max(Vec4::splat(1e-3 * peak))).max_element()).fold(0.0f32, f32::max);
    eprintln!("sheen: GPU vs CPU textures, largest relative difference {worst:.2e}");
    assert!(worst <= 2.0f32.powi(-10), "{worst:e}");
    let embedded = splitsum::table::sheen_texels();
    for tables in [gpu.table(Product::SheenTables).cloned().expect("read back"), cpu.table(Product::SheenTables).cloned().expect("read back")] {
        for (t, e) in tables.texels.iter().zip(embedded.iter()) {
            assert!((t.x - e.x).abs() <= 2.0f32.powi(-11) * e.x.max(1e-3) && (t.y - e.y).abs() <= 2.0f32.powi(-11) * e.y.max(1e-3), "{t} against {e}");
        }
    }
    assert!(Baker::new(d, q, Compute::Cpu).unwrap().bake(Source::Environment(&env), &s).unwrap().sheen.is_none());
}

/// A half-float overflow: a sun of 10⁶ in a texel is clamped to 65504 in the halves, never
/// ∞ (an ∞ would turn every filtered lookup that touches it into ∞ or NaN).
#[test]
fn a_sun_beyond_half_floats_stays_finite_in_the_textures() {
    let (d, q) = device();
    let mut texels = vec![Vec4::new(0.1, 0.1, 0.1, 1.0); 64 * 32];
    texels[10 * 64 + 20] = Vec4::new(1e6, 1e6, 1e6, 1.0);
    let env = Environment::Equirect(Equirect { width: 64, height: 32, texels });
    for compute in [Compute::Gpu, Compute::Cpu] {
        let data = Baker::new(d, q, compute).unwrap().bake(Source::Environment(&env), &small()).unwrap().read(d, q).map(data).unwrap();
        let max = data.specular.texels.iter().map(|v| v.max_element()).fold(0.0f32, f32::max);
        assert!(data.specular.texels.iter().all(|v| v.is_finite()), "{compute:?}: every texel finite");
        assert_eq!(max, 65504.0, "{compute:?}: the sun's mirror texel is clamped to the largest half");
    }
}

/// A source given as the application's texture (RGBA32F equirect, and an RGBA16F cube)
/// bakes what the same texels given as host data bake: the texture route reads exactly the
/// texels (halves are exact in f32).
#[test]
fn a_texture_source_bakes_what_the_same_host_data_bakes() {
    let (d, q) = device();
    let env = splitsum::environment::embedded_default().unwrap();
    let Environment::Equirect(e) = &env else { panic!("an equirect") };
    let s = small();
    let upload = |width: u32, height: u32, layers: u32, format: wgpu::TextureFormat, bytes: &[u8]| {
        let t = d.create_texture(&wgpu::TextureDescriptor {
            label: Some("app texture"),
            size: wgpu::Extent3d { width, height, depth_or_array_layers: layers },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::COPY_SRC | wgpu::TextureUsages::COPY_DST | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let texel = format.block_copy_size(None).unwrap();
        q.write_texture(
            t.as_image_copy(),
            bytes,
            wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(width * texel), rows_per_image: Some(height) },
            t.size(),
        );
        t
    };
    let baker = Baker::new(d, q, Compute::Gpu).unwrap();
    let equirect = upload(e.width, e.height, 1, wgpu::TextureFormat::Rgba32Float, bytemuck::cast_slice(&e.texels));
    let from_texture = baker.bake(Source::Texture(&equirect), &s).unwrap().read(d, q).map(data).unwrap();
    let from_host = baker.bake(Source::Environment(&env), &s).unwrap().read(d, q).map(data).unwrap();
    assert_eq!(from_texture.specular.texels, from_host.specular.texels, "equirect texture vs host data");
    assert_eq!(from_texture.irradiance.texels, from_host.irradiance.texels);

    // A cube of halves, on both backends.
    let face = 32u32;
    let cube = support::cube_from_fn(face, |dir| Vec4::new(1.0 + dir.x, 1.0 + dir.y, 1.0 + dir.z, 1.0));
    let level0: Vec<half::f16> = cube.level(0).iter().flat_map(|v| v.to_array()).map(half::f16::from_f32).collect();
    let exact: Vec<Vec4> = level0.chunks(4).map(|c| Vec4::new(c[0].to_f32(), c[1].to_f32(), c[2].to_f32(), c[3].to_f32())).collect();
    let host = Environment::Cube(Cube { layout: splitsum_shaders::cubemap::CubeLayout::new(face, 1), texels: exact });
    let bits: Vec<u16> = level0.iter().map(|h| h.to_bits()).collect();
    let texture = upload(face, face, 6, wgpu::TextureFormat::Rgba16Float, bytemuck::cast_slice(&bits));
    for compute in [Compute::Gpu, Compute::Cpu] {
        let baker = Baker::new(d, q, compute).unwrap();
        let a = baker.bake(Source::Texture(&texture), &s).unwrap().read(d, q).map(data).unwrap();
        let b = baker.bake(Source::Environment(&host), &s).unwrap().read(d, q).map(data).unwrap();
        assert_eq!(a.specular.texels, b.specular.texels, "{compute:?}: cube texture vs host data");
        assert_eq!(a.irradiance.texels, b.irradiance.texels, "{compute:?}");
    }
}

/// What the library refuses, in its own terms.
#[test]
fn the_library_says_what_is_wrong_in_its_own_terms() {
    let (d, q) = device();
    let baker = Baker::new(d, q, Compute::Cpu).unwrap();
    let e = baker.bake(Source::Environment(&constant(1.0)), &Settings { size: 48, ..Settings::default() }).err().expect("48 is no power of two").to_string();
    assert_eq!(e, "size must be a power of two from 1 to 4096, not 48");
    let odd = d.create_texture(&wgpu::TextureDescriptor {
        label: None,
        size: wgpu::Extent3d { width: 30, height: 20, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba16Float,
        usage: wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    let e = baker.bake(Source::Texture(&odd), &small()).err().expect("not an equirect").to_string();
    assert!(e.contains("30×20") && e.contains("equirect"), "{e}");
}

/// The library takes the engine target the CLI does: `Settings::with_target` on the
/// caller's device gives the glTF-IBL-Sampler's mip count and roughness per mip, and a
/// bright texel lands where that sampler puts it (`filter.frag` `dirToUV`: `u = ½ +
/// atan2(z, x)/2π`), on the GPU and the CPU alike.
#[test]
fn the_baker_takes_an_engine_target() {
    let (d, q) = device();
    let (w, h, px, py) = (128usize, 64usize, 20usize, 25usize);
    let mut texels = vec![Vec4::new(0.01, 0.01, 0.01, 1.0); w * h];
    texels[py * w + px] = Vec4::new(5000.0, 5000.0, 5000.0, 1.0);
    let env = Environment::Equirect(Equirect { width: w as u32, height: h as u32, texels });
    let s = Settings { size: 32, irradiance_size: 8, lut_size: 32, ..Settings::default() }.with_target(splitsum::Target::Khronos);
    let job = s.resolve(splitsum::settings::InputShape::of(&env), splitsum::Products::DISPLAY).unwrap();
    assert_eq!((job.mips, job.roughness_per_mip()[1]), (5, 0.25), "floor(log2 32) mips at m/(M - 1)");
    let (u, v) = ((px as f64 + 0.5) / w as f64, (py as f64 + 0.5) / h as f64);
    let (phi, theta) = (std::f64::consts::TAU * (u - 0.5), std::f64::consts::PI * v);
    let want = [theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin()];
    for compute in [Compute::Gpu, Compute::Cpu] {
        let data = Baker::new(d, q, compute).unwrap().bake(Source::Environment(&env), &s).unwrap().read(d, q).map(self::data).unwrap();
        assert_eq!(data.specular.layout.levels, 5);
        let level = data.specular.level(0);
        let k = (0..level.len()).max_by(|&a, &b| level[a].x.total_cmp(&level[b].x)).unwrap() as u32;
        let got = reference::texel_dir(k / (32 * 32), k % 32, (k / 32) % 32, 32);
        let angle = reference::dot(got, want).clamp(-1.0, 1.0).acos();
        // Within one and a half texels of the 32² face (a texel spans about 2/32 rad).
        assert!(angle < 1.5 * 2.0 / 32.0, "{compute:?}: peak at {got:?}, glTF-IBL-Sampler's at {want:?}");
    }
}

/// The specular cube a bake folder's `specular.ktx2` holds, every level, decoded from halves.
fn ktx2_specular(dir: &std::path::Path) -> Vec<f32> {
    let bytes = std::fs::read(dir.join("specular.ktx2")).unwrap();
    let reader = ktx2::Reader::new(&bytes[..]).unwrap();
    reader.levels().flat_map(|l| l.data.chunks_exact(2).map(|h| half::f16::from_le_bytes([h[0], h[1]]).to_f32()).collect::<Vec<_>>()).collect()
}

/// The crate documentation's example, an application written from it alone
/// (`splitsum/examples/bake.rs`: its own device, a bake, the textures bound, the files
/// written), runs on Vulkan (lavapipe), on GL (llvmpipe, headless through EGL) and with
/// `Compute::Cpu`, and the three agree: the GPU's cube within 2⁻¹⁰ of the CPU's relative
/// (halves hold 11 bits; the kernels agree with the CPU to about 10⁻⁶ before packing), with
/// the same files written.
#[test]
fn the_crate_documentation_example_bakes_on_vulkan_on_gl_and_on_the_cpu() {
    let sky = support::environment_path("courtyard");
    let root = std::env::temp_dir().join(format!("splitsum-app-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root);
    let mut cubes = Vec::new();
    for (name, backends, compute) in
        [("vulkan", wgpu::Backends::VULKAN, Compute::Gpu), ("gl", wgpu::Backends::GL, Compute::Gpu), ("cpu", wgpu::Backends::VULKAN, Compute::Cpu)]
    {
        let out = root.join(name);
        let manifest = app::bake(backends, &sky, &out, compute).unwrap_or_else(|e| panic!("{name}: {e}"));
        let mut files: Vec<&str> = manifest.files.iter().map(|f| f.name.as_str()).collect();
        files.sort();
        assert!(files.contains(&"specular.ktx2") && files.contains(&"irradiance.ktx2") && files.contains(&"brdf_lut.exr"), "{name}: {files:?}");
        assert!(out.join("bake.json").exists() && out.join(splitsum::files::OUTPUT_MANIFEST).exists(), "{name}");
        cubes.push((name, ktx2_specular(&out)));
    }
    let cpu = &cubes[2].1;
    let peak = cpu.iter().copied().fold(0.0f32, f32::max);
    for (name, cube) in &cubes[..2] {
        assert_eq!(cube.len(), cpu.len(), "{name}");
        let worst = cube.iter().zip(cpu).map(|(a, b)| (a - b).abs() / b.abs().max(1e-3 * peak)).fold(0.0f32, f32::max);
        eprintln!("{name}: the crate example's specular cube against the CPU's, largest relative difference {worst:.2e}");
        assert!(worst <= 2.0f32.powi(-10), "{name}: {worst:.2e}");
    }
    let _ = std::fs::remove_dir_all(&root);
}

/// A device whose limits cannot run the kernels (here lavapipe opened with WebGL2's limits:
/// no compute shaders, no storage buffers) is refused by `Baker::new(.., Compute::Gpu)`,
/// naming what it lacks, never baked on; `Compute::Cpu` still bakes on it.
#[test]
fn a_device_that_cannot_run_the_kernels_is_refused_by_name() {
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor { backends: wgpu::Backends::VULKAN, ..wgpu::InstanceDescriptor::new_without_display_handle() });
    let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions::default())).expect("an adapter");
    let (d, q) = pollster::block_on(
        adapter.request_device(&wgpu::DeviceDescriptor { required_limits: wgpu::Limits::downlevel_webgl2_defaults(), ..Default::default() }),
    )
    .expect("a device with WebGL2's limits");
    let e = Baker::new(&d, &q, Compute::Gpu).err().expect("refused").to_string();
    assert!(e.contains("cannot run splitsum's kernels") && e.contains("compute shaders") && e.contains("storage buffers") && e.contains("Compute::Cpu"), "{e}");
    let ibl = Baker::new(&d, &q, Compute::Cpu).unwrap().bake(Source::Environment(&constant(1.0)), &small()).unwrap();
    assert_eq!(ibl.specular.mip_level_count(), Settings::default_mips(16));
}

/// splitsum in a browser: the library built for wasm32 bakes on headless Chromium's
/// WebGPU device (SwiftShader) through `tests/webgpu` (wasm-bindgen, puppeteer-core), and
/// the textures it reads back agree with a CPU bake of the same environment within a half
/// float's step (2⁻¹⁰ relative above 10⁻³ of the peak), as on Vulkan and GL. Needs what
/// `bash scripts/dev.sh webgpu` builds and installs (it runs this test, and so does
/// `dev.sh test`); ignored otherwise.
#[test]
#[ignore = "needs Chromium and the wasm build: bash scripts/dev.sh webgpu"]
fn a_bake_in_the_browsers_webgpu_matches_the_cpu() {
    let (w, h, size) = (64u32, 32u32, 16u32);
    let mut texels = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let sun = (x as i32 - 20).pow(2) + (y as i32 - 10).pow(2) < 3;
            let v = if sun { 500.0 } else { 0.2 + 0.8 * (1.0 - y as f32 / h as f32) };
            texels.push(Vec4::new(0.6 * v, 0.8 * v, v, 1.0));
        }
    }
    let dir = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../target/webgpu");
    std::fs::create_dir_all(&dir).unwrap();
    let mut input: Vec<u8> = [w, h, size].iter().flat_map(|v| v.to_le_bytes()).collect();
    input.extend(texels.iter().flat_map(|t| [t.x, t.y, t.z]).flat_map(f32::to_le_bytes));
    let (inp, out) = (dir.join("input.bin"), dir.join("output.bin"));
    std::fs::write(&inp, input).unwrap();
    for stale in [out.clone(), out.with_extension("bin.err"), out.with_extension("bin.txt"), out.with_extension("bin.peak")] {
        let _ = std::fs::remove_file(stale);
    }
    let script = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("webgpu/run.mjs");
    let status = std::process::Command::new("node").arg(&script).arg(&inp).arg(&out).status().expect("node");
    assert!(status.success(), "node {}", script.display());
    if let Ok(message) = std::fs::read_to_string(out.with_extension("bin.err")) {
        panic!("the browser refused the bake: {message}");
    }
    let got: Vec<f32> = std::fs::read(&out).unwrap().chunks_exact(4).map(|b| f32::from_le_bytes(b.try_into().unwrap())).collect();
    let env = Environment::Equirect(Equirect { width: w, height: h, texels });
    let settings = Settings { size, irradiance_size: 8, lut_size: 32, ..Settings::default() };
    let (d, q) = device();
    let cpu = Baker::new(d, q, Compute::Cpu).unwrap().bake(Source::Environment(&env), &settings).unwrap().read(d, q).map(data).unwrap();
    let want: Vec<f32> =
        cpu.specular.texels.iter().chain(&cpu.irradiance.texels).flat_map(|v| v.to_array()).chain(cpu.brdf.iter().flat_map(|t| [t.x, t.y])).collect();
    assert_eq!(got.len(), want.len(), "specular, irradiance and table values");
    let peak = want.iter().copied().fold(0.0f32, f32::max);
    let worst = got.iter().zip(&want).map(|(a, b)| (a - b).abs() / b.abs().max(1e-3 * peak)).fold(0.0f32, f32::max);
    eprintln!(
        "WebGPU in Chromium against the CPU: largest relative difference {worst:.2e} ({})",
        std::fs::read_to_string(out.with_extension("bin.txt")).unwrap_or_default()
    );
    assert!(worst <= 2.0f32.powi(-10), "{worst:.2e}");
    // The GPU process's peak resident memory (sampled by run.mjs): within 2 GiB, where one
    // module holding every kernel took it to 13.9 GB and it exited (issue 33).
    let peak: u64 = std::fs::read_to_string(out.with_extension("bin.peak")).unwrap().trim().parse().unwrap();
    assert!(peak <= 2 << 30, "the GPU process peaked at {} MiB", peak >> 20);
}

/// Settings derive what depends on the size unless given, so any combination of defaults
/// resolves: 512² faces bake 7 mips from a 512² source, 64² faces 4 mips (down to 8²,
/// as the command line), an engine target its own count; a value given against the target
/// is refused by its field.
#[test]
fn settings_derive_what_depends_on_the_size() {
    use splitsum::settings::InputShape;
    let shape = InputShape::Equirect { width: 1024, height: 512 };
    let job = |s: Settings| s.resolve(shape, splitsum::Products::ALL).unwrap();
    let big = job(Settings { size: 512, ..Settings::default() });
    assert_eq!((big.mips, big.source_size, big.irradiance_source, big.sh_source), (7, 512, 16, 32));
    let small = job(Settings { size: 64, ..Settings::default() });
    assert_eq!((small.mips, small.source_size), (4, 64));
    let tiny = job(Settings { size: 8, ..Settings::default() });
    assert_eq!((tiny.mips, tiny.irradiance_source, tiny.sh_source), (2, 8, 8));
    let bevy = job(Settings { size: 64, ..Settings::default() }.with_target(splitsum::Target::Bevy));
    assert_eq!((bevy.mips, bevy.mapping), (6, splitsum::RoughnessMapping::Linear));
    let e = Settings { size: 64, mips: Some(4), ..Settings::default() }.with_target(splitsum::Target::Bevy).validate().unwrap_err();
    assert!(matches!(e, splitsum::Error::Setting { field: splitsum::Field::Mips, .. }), "{e}");
}
