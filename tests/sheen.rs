//! The sheen products (`KHR_materials_sheen`): the Charlie-prefiltered sheen cube and the
//! sheen tables, against independent references (the f64 sheen albedo over the light
//! direction, the f64 exact Charlie-weighted sum over a finely sub-sampled environment, a
//! constant environment), GPU against CPU, and a bake that leaves sheen out when nothing
//! reads it. glTF-IBL-Sampler's own Charlie output is compared in `targets.rs`.

use rayon::prelude::*;
use splitsum::Backend;
use splitsum::Product;
use splitsum::texture::Cube;
use splitsum_shaders::cubemap::{self, CubeLayout};
use splitsum_shaders::glam::{Vec3, Vec4};
use splitsum_shaders::prefilter::{Lobe, RoughnessMapping};
use support::{gpu, max_relative, reference};

/// Sheen roughness of each mip: linear, as the glTF Sample Viewer reads the cube.
fn roughness(mips: u32) -> Vec<f32> {
    (0..mips).map(|m| RoughnessMapping::Linear.roughness(m, mips)).collect()
}

fn sheen_cube(b: &Backend, src: &Cube, out: CubeLayout, samples: u32, exact: bool) -> Cube {
    let all: Vec<u32> = (0..out.levels).collect();
    b.prefilter_levels(Lobe::Charlie, src, out, &roughness(out.levels), &all, &vec![samples; out.levels as usize], exact, 0.5).unwrap()
}

/// Every texel of both sheen tables, as a bake uploads them (`splitsum::table::sheen_texels`),
/// against the f64 albedo (adaptive Gauss–Kronrod over the light direction, tolerance
/// 10⁻⁸): within 10⁻⁴, the target. The tables reach 1.8 at grazing, low-roughness
/// texels (the visibility terms are clamped at 1, not energy-conserving), where the quadrature's
/// error is largest.
#[test]
fn sheen_tables_match_the_f64_reference_at_every_texel() {
    let size = splitsum::table::SHEEN_TABLE_SIZE;
    let table = splitsum::table::sheen_texels();
    assert_eq!(table.len(), (size * size) as usize);
    let worst = (0..size * size)
        .into_par_iter()
        .map(|i| {
            let (x, y) = (i % size, i / size);
            let c = splitsum_shaders::lut::texel_coords(x, y, size);
            let t = table[i as usize];
            let charlie_table = reference::sheen::albedo(c.x as f64, c.y as f64, reference::sheen::Visibility::Neubelt, 1e-8);
            let sheen_e = reference::sheen::albedo(c.x as f64, c.y as f64, reference::sheen::Visibility::Charlie, 1e-8);
            let e = (t.x as f64 - charlie_table).abs().max((t.y as f64 - sheen_e).abs());
            (e, x, y)
        })
        .reduce(|| (0.0, 0, 0), |a, b| if b.0 > a.0 { b } else { a });
    println!("sheen tables {size}², both channels, against f64: worst {:.2e} at texel ({}, {})", worst.0, worst.1, worst.2);
    assert!(worst.0 <= 1e-4, "sheen table texel ({}, {}) off by {:.2e}", worst.1, worst.2, worst.0);
}

/// White furnace: a constant environment (with a sun-sized value in one channel) gives the
/// same constant at every sheen roughness, including 0 (the horizon ring, sampled), summed
/// exactly or sampled, on both backends. Normalised weights: only rounding remains, a ratio
/// of two compensated sums of up to 6·16² terms, within 5·10⁻⁶ (about 40 f32 ulp; measured
/// 2.2·10⁻⁶ on GL, where llvmpipe may contract multiply–adds).
#[test]
fn sheen_white_furnace() {
    let c = Vec4::new(1.0, 0.5, 25_000.0, 1.0);
    let src = support::cube_from_fn(16, |_| c);
    let out = CubeLayout::new(16, 5);
    for b in [&Backend::Cpu, gpu()] {
        for exact in [false, true] {
            let p = sheen_cube(b, &src, out, 256, exact);
            let rel = max_relative(&p.texels, &vec![c; p.texels.len()], 0.0);
            println!("{} (exact sums {exact}): sheen white furnace max relative error {rel:.1e}", b.describe());
            assert!(rel < 5e-6, "{rel:e}");
        }
    }
}

/// The sheen cube against the f64 exact Charlie-weighted sum (`reference::sheen::prefilter`,
/// written from the angle of `h`, sub-sampled where the ring is narrower than a texel), on
/// an analytic sky with three soft suns resampled to a 64² cube, over every mip of a 32²
/// cube with 6 mips (sheen roughness 0, 0.2, … 1), at three texels of every face (centre,
/// edge, corner). Mean relative error per mip: the estimator's. Summed exactly (the rough
/// mips) it is the coarse level's, below 0.1 %; sampled (256 samples, source-level bias
/// 0.5) it is the blur of the source level each sample reads (a sample's footprint is
/// isotropic, the ring is thin across) and quasi-Monte Carlo noise, measured 1.7–2.3 % on
/// this sky (0.4–0.6 % with 1024 samples): bound 4 % per mip, roughness 0 (the horizon
/// ring, traced by 256 samples) included.
#[test]
fn sheen_cube_matches_the_exact_integral() {
    let suns = [
        (Vec3::new(0.3, 0.5, -0.81), Vec3::new(40.0, 30.0, 20.0)),
        (Vec3::new(-0.8, 0.05, 0.56), Vec3::new(4.0, 8.0, 12.0)),
        (Vec3::new(0.2, -0.3, 0.93), Vec3::new(10.0, 6.0, 3.0)),
    ];
    let sky = |d: Vec3| {
        let t = 0.5 + 0.5 * d.y;
        let mut c = Vec3::new(0.2 + 0.6 * t, 0.3 + 0.6 * t, 0.5 + 0.8 * t);
        for (dir, col) in &suns {
            c += *col * ((d.dot(dir.normalize()) - 1.0) / 0.02).exp();
        }
        c.extend(1.0)
    };
    let src = support::cube_from_fn(64, sky);
    let env = reference::Environment::new(src.level(0), 64);
    let out = CubeLayout::new(32, 6);
    let r = roughness(6);
    let lum = |c: [f64; 3]| 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
    // Probe texels of each level: three per face, at the centre, near an edge and at a corner.
    let probes = |s: u32| -> Vec<(u32, u32, u32)> { (0..6).flat_map(|f| [(s / 2, s / 2), (0, s / 3), (s - 1, s - 1)].map(|(x, y)| (f, x, y))).collect() };
    // The reference at each probe: the exact sum, or at roughness 0 (α → 0: the weight
    // concentrates on the horizon) the mean of the sky round the horizon, by 4096 points.
    let want: Vec<Vec<f64>> =
        r.iter()
            .enumerate()
            .map(|(m, &rm)| {
                let s = out.level_size(m as u32);
                probes(s)
                    .par_iter()
                    .map(|&(f, x, y)| {
                        let n = cubemap::texel_dir(f, x, y, s);
                        if rm == 0.0 {
                            let (t, b) = splitsum_shaders::sampling::orthonormal_basis(n);
                            (0..4096)
                                .map(|k| {
                                    lum_of(sky((t * (k as f32 / 4096.0 * std::f32::consts::TAU).cos() + b * (k as f32 / 4096.0 * std::f32::consts::TAU).sin())
                                        .normalize()))
                                })
                                .sum::<f64>()
                                / 4096.0
                        } else {
                            lum(reference::sheen::prefilter(&env, [n.x as f64, n.y as f64, n.z as f64], rm as f64))
                        }
                    })
                    .collect()
            })
            .collect();
    for b in [&Backend::Cpu, gpu()] {
        let cube = sheen_cube(b, &src, out, 256, true);
        for (m, &rm) in r.iter().enumerate() {
            let s = out.level_size(m as u32);
            let level = cube.level(m as u32);
            let errors: Vec<f64> =
                probes(s).iter().zip(&want[m]).map(|(&(f, x, y), w)| (lum_of(level[((f * s + y) * s + x) as usize]) - w).abs() / w).collect();
            let mean = errors.iter().sum::<f64>() / errors.len() as f64;
            println!(
                "{}: sheen mip {m} (r {rm:.1}): mean relative error {:.3} %, worst {:.3} %",
                b.describe(),
                100.0 * mean,
                100.0 * errors.iter().copied().fold(0.0, f64::max)
            );
            assert!(mean < 0.04, "mip {m}: {mean}");
        }
    }
}

fn lum_of(c: Vec4) -> f64 {
    0.2126 * c.x as f64 + 0.7152 * c.y as f64 + 0.0722 * c.z as f64
}

/// The sheen cube on the GPU equals the CPU's within the bounds the GGX cube keeps
/// (`prefilter::exact_sums_gpu_match_cpu_and_keep_a_constant`): the same functions, the
/// same samples; on lavapipe only the rounding of a few operations differs.
#[test]
fn sheen_cube_gpu_matches_cpu() {
    let city = support::source_cube("city", 32);
    let out = CubeLayout::new(32, 6);
    for exact in [false, true] {
        let g = sheen_cube(gpu(), &city, out, 64, exact);
        let c = sheen_cube(&Backend::Cpu, &city, out, 64, exact);
        let rel = max_relative(&g.texels, &c.texels, 1e-3);
        println!("sheen cube (exact sums {exact}), gpu vs cpu: max relative {rel:.2e}");
        let bound = support::gpu_bound(1e-5, 5e-5) as f32;
        assert!(rel < bound, "{rel:e}");
    }
}

/// The sheen tables the library embeds (`splitsum::table::sheen_texels`, what every bake
/// with sheen uploads) are a fresh CPU computation (`lut::sheen_texel` on every texel) bit
/// for bit, decoded once per process. Their accuracy is
/// `sheen_tables_match_the_f64_reference_at_every_texel`.
#[test]
fn embedded_sheen_tables_are_a_fresh_computation_bit_for_bit() {
    let fresh = splitsum::table::compute_sheen();
    let embedded = splitsum::table::sheen_texels();
    assert_eq!(embedded.len(), fresh.len());
    let differ = embedded.iter().zip(&fresh).filter(|(e, f)| e.x.to_bits() != f.x.to_bits() || e.y.to_bits() != f.y.to_bits()).count();
    assert_eq!(differ, 0, "{differ} texels of the embedded sheen tables differ from a fresh computation: run `bash scripts/dev.sh table`");
    assert!(std::sync::Arc::ptr_eq(&splitsum::table::sheen_texels(), &embedded), "decoded once per process");
}

/// The sheen layer as the display shades it (`shade::sheen_ibl`, the glTF Sample Viewer's
/// formula) under a constant sky of radiance `c` (its sheen cube the same constant at every
/// mip, as `sheen_white_furnace` shows the bake makes it): `c · colour · E_N(n·v, r)`, with
/// `E_N` the f64 sheen albedo (Neubelt's visibility, adaptive quadrature), and the base
/// layer kept at `1 − max(colour)·E_C(n·v, r)` with the Charlie visibility's. Bound 2·10⁻³
/// relative to `c` (bilinear interpolation of the 64² tables between texel centres, where
/// the albedo curves most at grazing views and low roughness; the texels themselves are
/// within 10⁻⁴); outside the outermost texel centres the read holds the edge value, and so
/// does the reference here. Every value is finite for radiance up to 10⁶ at n·v down to 10⁻⁴ (a view in
/// the surface), sheen roughness 0 and 1, a cube corner and the poles.
#[test]
fn sheen_shading_under_a_constant_sky_is_the_sheen_albedo() {
    use splitsum_shaders::shade::{self, EnvironmentShape, Material};
    let tables = splitsum::table::sheen_texels();
    let tables: Vec<splitsum_shaders::glam::Vec2> = tables.iter().map(|t| t.truncate().truncate()).collect();
    let size = 8;
    let shape_of = |levels: u32| EnvironmentShape {
        specular_size: 1,
        specular_levels: 1,
        mapping: 0,
        irradiance_size: 1,
        lut_size: 1,
        source_size: 1,
        irradiance_levels: 1,
        sheen_size: size,
        sheen_levels: levels,
        sheen_mapping: RoughnessMapping::Linear as u32,
        sheen_table_size: splitsum::table::SHEEN_TABLE_SIZE,
        excess_entries: 0,
    };
    let mut worst = 0.0f64;
    for c in [1.0f32, 1e4, 1e6] {
        let cube = support::cube_from_fn(size, |_| Vec4::splat(c));
        let shape = shape_of(cube.layout.levels);
        let colour = Vec3::new(0.9, 0.4, 0.1);
        for n in [Vec3::Z, Vec3::Y, -Vec3::Y, Vec3::ONE.normalize()] {
            let (t, _) = splitsum_shaders::sampling::orthonormal_basis(n);
            for nv in [1e-4f32, 0.05, 0.3, 0.7, 1.0] {
                let v = (n * nv + t * (1.0 - nv * nv).max(0.0).sqrt()).normalize();
                for r in [0.0f32, 0.1, 0.37, 0.8, 1.0] {
                    let m = Material {
                        base_color: Vec3::ONE,
                        metallic: 0.0,
                        roughness: 0.5,
                        occlusion: 1.0,
                        emissive: Vec3::ZERO,
                        sheen_color: colour,
                        sheen_roughness: r,
                    };
                    let (layer, keep) = shade::sheen_ibl(shape, &cube.texels, &tables, &m, n, v);
                    assert!(layer.is_finite() && keep.is_finite(), "c {c} n {n} n·v {nv} r {r}: {layer} {keep}");
                    // A bilinear read holds outside the outermost texel centres.
                    let edge = 0.5 / splitsum::table::SHEEN_TABLE_SIZE as f64;
                    let nv64 = (n.dot(v) as f64).clamp(edge, 1.0 - edge);
                    let r64 = (r as f64).clamp(edge, 1.0 - edge);
                    let e_n = reference::sheen::albedo(nv64, r64, reference::sheen::Visibility::Neubelt, 1e-8);
                    let e_c = reference::sheen::albedo(nv64, r64, reference::sheen::Visibility::Charlie, 1e-8);
                    for k in 0..3 {
                        let e = (layer[k] as f64 - c as f64 * colour[k] as f64 * e_n).abs() / c as f64;
                        worst = worst.max(e);
                        assert!(e <= 2e-3, "c {c} n·v {nv} r {r}: sheen {} against {}", layer[k], c as f64 * colour[k] as f64 * e_n);
                    }
                    let want_keep = 1.0 - 0.9 * e_c;
                    assert!((keep as f64 - want_keep).abs() <= 2e-3, "n·v {nv} r {r}: base kept {keep} against {want_keep}");
                }
            }
        }
    }
    println!("sheen under a constant sky against c·colour·E_N (f64): worst {worst:.2e} of c");
}

/// The display's sheen (`KHR_materials_sheen` shading, `shade::sheen_ibl` and
/// `shade::sheen_direct`): a sphere grid with a sheen row (sheen roughness 0 to 1 across the
/// columns) on the GPU against the CPU reference renderer, within the render tests' bound
/// (`render::frame_bound`'s: float rounding, plus a half-float step where the GL backend
/// renders to RGBA16F); the row below the metalness rows, the only one with sheen; and the
/// sheen visibly there (the frame differs from the same layout with a sheen colour of
/// 10⁻³⁰ by more than 0.05 in display value somewhere).
#[test]
fn a_sheen_grid_renders_the_same_on_gpu_and_cpu() {
    use splitsum_display::render::{GpuScene, ViewState, render_cpu};
    let env = support::small_display_bake();
    assert!(env.cube(Product::Sheen).layout.size > 1, "the display bake holds a sheen cube");
    let Backend::Gpu(gpu) = gpu() else { unreachable!() };
    let scene = GpuScene::new(gpu, &env);
    let view = ViewState { sheen_color: Vec3::new(1.0, 0.3, 0.6), sheen_ranges: (0.0, 1.0), base_color: Vec3::new(0.1, 0.1, 0.15), ..ViewState::default() };
    let frame = view.frame(scene.shape, 96, 64, true);
    let g = scene.render_offscreen(gpu, &frame, None).unwrap();
    let c = render_cpu(&env, &frame);
    let worst = g
        .iter()
        .zip(&c)
        .map(|(a, b)| {
            assert!(a.is_finite() && b.is_finite());
            (*a - *b).abs().max_element()
        })
        .fold(0.0f32, f32::max);
    // The layout: the grid's rows, then the sheen row, the only one with sheen, its
    // metalness the top row's, its sheen roughness across the columns.
    let f = view.frame(scene.shape, 96, 64, true);
    assert_eq!(f.rows, view.grid.0 + 1);
    for row in 0..f.rows {
        for col in 0..f.columns {
            let m = splitsum_shaders::scene::grid_material(&f, row, col);
            let last = row + 1 == f.rows;
            assert_eq!(m.sheen_color, if last { view.sheen_color } else { Vec3::ZERO }, "row {row}");
            let metallic = if last { 0.0 } else { row as f32 / (view.grid.0 - 1) as f32 };
            assert!((m.metallic - metallic).abs() < 1e-6, "row {row}: metallic {}", m.metallic);
            assert!((m.sheen_roughness - col as f32 / (f.columns - 1) as f32).abs() < 1e-6);
        }
    }
    let plain = render_cpu(&env, &ViewState { sheen_color: Vec3::splat(1e-30), ..view.clone() }.frame(scene.shape, 96, 64, true));
    let effect = c.iter().zip(&plain).map(|(a, b)| (*a - *b).abs().max_element()).fold(0.0f32, f32::max);
    let half = GpuScene::offscreen_format(gpu) == wgpu::TextureFormat::Rgba16Float;
    let bound = support::gpu_bound(1e-5, 2e-4) as f32 + if half { 2f32.powi(-11) } else { 0.0 };
    println!("sheen grid 96×64: GPU vs CPU max |Δ| {worst:.2e} (bound {bound:.1e}); sheen changes display values by up to {effect:.3}");
    assert!(worst < bound, "{worst:e}");
    assert!(effect > 0.05, "the sheen does not show: {effect}");
}

/// `KHR_materials_sheen` on a glTF model: the factors and both textures are read (the
/// material's bits and factors), and the model renders on the GPU as the CPU rasteriser
/// renders it, within the model test's bounds (`model::gpu_draws_the_model_as_the_cpu_reference`:
/// the hardware sampler against the CPU's filtering).
#[test]
fn a_gltf_model_with_sheen_loads_and_renders() {
    use splitsum_display::render::{GpuModel, GpuScene, ViewState};
    use splitsum_shaders::surface::MeshMaterial;
    let glb = support::model::sample_glb_with(Some(serde_json::json!({"KHR_materials_sheen": {
        "sheenColorFactor": [1.0, 0.5, 0.8], "sheenColorTexture": {"index": 0},
        "sheenRoughnessFactor": 0.6, "sheenRoughnessTexture": {"index": 1}
    }})));
    let dir = std::env::temp_dir().join(format!("splitsum-sheen-model-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("sheen.glb");
    std::fs::write(&path, &glb).unwrap();
    let mut model = splitsum_display::model::load(&path).unwrap();
    let m = model.primitives[0].material;
    assert_eq!(m.sheen, Vec4::new(1.0, 0.5, 0.8, 0.6));
    assert_eq!(m.textures.x & (MeshMaterial::SHEEN_COLOR | MeshMaterial::SHEEN_ROUGHNESS), MeshMaterial::SHEEN_COLOR | MeshMaterial::SHEEN_ROUGHNESS);
    // A bad factor is refused, naming the extension and the field.
    let bad = support::model::sample_glb_with(Some(serde_json::json!({"KHR_materials_sheen": {"sheenRoughnessFactor": 2.0}})));
    std::fs::write(&path, &bad).unwrap();
    let e = splitsum_display::model::load(&path).unwrap_err().to_string();
    assert!(e.contains("KHR_materials_sheen") && e.contains("sheenRoughnessFactor"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);

    let baked = support::small_display_bake();
    model.fit(Vec3::new(0.0, 0.0, 1.5), 4.0);
    let Backend::Gpu(gpu) = gpu() else { unreachable!() };
    let scene = GpuScene::new(gpu, &baked);
    let gpu_model = GpuModel::new(gpu, &scene, &model);
    let view = ViewState { exposure: baked.auto_exposure(), pitch: 0.35, spheres: false, ..ViewState::default() };
    let frame = view.frame(scene.shape, 256, 160, true);
    let g = scene.render_offscreen(gpu, &frame, Some(&gpu_model)).unwrap();
    let c = splitsum_display::raster::render(&baked, &frame, &model);
    let sky = splitsum_display::render::render_cpu(&baked, &frame);
    // The background (where the CPU rasteriser draws no mesh) and the model, apart, so that
    // a failure says which of the two passes went wrong.
    let (mut n, mut over, mut sum) = (0usize, 0usize, 0.0f64);
    let (mut background, mut background_off, mut background_worst) = (0usize, 0usize, 0.0f32);
    for i in 0..g.len() {
        if (c[i] - sky[i]).abs().max_element() == 0.0 {
            let d = (g[i] - sky[i]).abs().max_element();
            background += 1;
            background_worst = background_worst.max(d);
            if d < 1e-3 {
                continue;
            }
            background_off += 1;
        }
        n += 1;
        let d = (g[i] - c[i]).abs().max_element();
        sum += d as f64;
        over += (d > 2.0 / 255.0) as usize;
    }
    let mean = sum / n as f64;
    println!(
        "sheen model: {n} pixels; GPU vs CPU mean |Δ| {mean:.2e}, {:.2} % above 2/255; background {background} pixels, {background_off} off by 1e-3 or more (worst {background_worst:.2e})",
        100.0 * over as f64 / n as f64
    );
    // The background is the sphere-grid pass, held to the render tests' bounds elsewhere;
    // edge pixels where the mesh covers part of a pixel on one side only may differ.
    assert!(background_off < background / 50, "the background differs from the CPU's at {background_off} of {background} pixels (worst {background_worst:e})");
    assert!((over as f64) < support::gpu_bound(0.12, 0.25) * n as f64, "{over} of {n}");
}

/// The default sheen cube (`Settings::default()`, the CPU backend) on a held-out sunny sky:
/// a blue gradient and a sun `5·10⁴` bright, Gaussian with `σ = 0.02` rad, 8° above the
/// horizon, written to a 1024×512 equirect. At 160 texels of every mip (a fixed
/// pseudo-random set), the relative error of the luminance against
/// `reference::sheen::prefilter_of`, a product quadrature of the analytic sky in the lobe's
/// own coordinates (Gauss–Legendre in `n·l`, midpoint in the azimuth; independent of the
/// cube and of the bake's sampling; it agrees with the texel sum `reference::sheen::prefilter`
/// over the bake's 64² source level within 0.5 %, where the sun fills a texel). The
/// targets: mean within 3 % at every mip, within 1 % at sheen roughness ≥ 0.7. The quadrature resolves the sun (`σ` spans 7
/// azimuth steps and 2 or more `n·l` nodes); the equirect's point samples and the
/// source cube's resampling stay below 0.1 % at this sun's width.
#[test]
fn the_default_sheen_cube_on_a_sunny_sky() {
    // Measured: 0.07–0.48 % at every mip (the source split, `bright`, its entries at the
    // excess's centroids; before the centroids 0.13–1.89 %, the ring the worst).
    sunny_sheen(5e4, true);
}

/// The same sky with a sun of 10⁶, the top of the range the project holds: the same
/// bounds. Measured 0.18–0.87 % (0.48–4.51 % with each excess texel at its centre).
#[test]
fn the_default_sheen_cube_under_a_sun_of_a_million() {
    sunny_sheen(1e6, false);
}

/// [`the_default_sheen_cube_on_a_sunny_sky`] with a sun `amplitude` bright, asserting its
/// bounds; writes the guide's figure where `figure`.
fn sunny_sheen(amplitude: f64, figure: bool) {
    let e = 8f64.to_radians();
    let sun = reference::normalize([0.6 * e.cos(), e.sin(), -0.8 * e.cos()]);
    let sky = move |d: [f64; 3]| {
        let t = 0.5 + 0.5 * d[1];
        let c = reference::dot(d, sun).clamp(-1.0, 1.0);
        // 1 − cos θ ≈ θ²/2: exp(−θ²/(2σ²)).
        let g = amplitude * (-(1.0 - c) / (0.02f64 * 0.02)).exp();
        [0.3 + 0.4 * t + g, 0.4 + 0.5 * t + g, 0.6 + 0.8 * t + g]
    };
    let (w, h) = (1024u32, 512u32);
    let texels = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| {
            let (u, v) = ((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
            let (phi, theta) = (std::f64::consts::TAU * (u - 0.5), std::f64::consts::PI * v);
            let c = sky([theta.sin() * phi.sin(), theta.cos(), -theta.sin() * phi.cos()]);
            Vec4::new(c[0] as f32, c[1] as f32, c[2] as f32, 1.0)
        })
        .collect();
    let env = splitsum::Environment::Equirect(splitsum::texture::Equirect { width: w, height: h, texels });
    let job = splitsum::Settings::default().resolve(splitsum::InputShape::of(&env), splitsum::Products::DISPLAY.with_sheen(true)).unwrap();
    let t = std::time::Instant::now();
    let baked = splitsum::bake::bake_job(&Backend::Cpu, &env, &job).unwrap();
    let sheen = baked.cube(Product::Sheen).unwrap();
    let roughness = &job.prefiltered[&Product::Sheen].roughness_per_mip;
    println!("default bake with sheen, {}² cube, {} mips: {:.2} s", sheen.layout.size, sheen.layout.levels, t.elapsed().as_secs_f64());
    let lum = |c: [f64; 3]| 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
    let mut state = 0x2545f491u32;
    let mut next = move |m: u32| {
        state = state.wrapping_mul(1664525).wrapping_add(1013904223);
        (state >> 8) % m
    };
    let seconds = t.elapsed().as_secs_f64();
    let mut table = support::figure::Figure::new(
        "sheen-sunny",
        "cargo test --release -p splitsum-tests --test suite sheen::the_default_sheen_cube_on_a_sunny_sky",
        &["mip", "sheen roughness", "mean relative error", "worst texel"],
    );
    let mut errs = Vec::new();
    for (m, &r) in roughness.iter().enumerate() {
        let s = sheen.layout.level_size(m as u32);
        let probes: Vec<(u32, u32, u32)> = (0..160).map(|_| (next(6), next(s), next(s))).collect();
        let level = sheen.level(m as u32);
        let errors: Vec<f64> = probes
            .par_iter()
            .map(|&(f, x, y)| {
                let n = reference::texel_dir(f, x, y, s);
                let want = lum(reference::sheen::prefilter_of(&sky, n, r as f64, 24, 1024));
                (lum_of(level[((f * s + y) * s + x) as usize]) - want).abs() / want
            })
            .collect();
        let mean = errors.iter().sum::<f64>() / errors.len() as f64;
        let worst = errors.iter().copied().fold(0.0, f64::max);
        println!("sun {amplitude:e}, sheen mip {m} (sheen roughness {r:.2}): mean relative error {:.2} %, worst {:.1} %", 100.0 * mean, 100.0 * worst);
        table.row(vec![format!("{m}"), format!("{r:.2}"), format!("{:.2} %", 100.0 * mean), format!("{:.0} %", 100.0 * worst)]);
        errs.push(mean);
    }
    if figure {
        table.note(format!(
            "The default sheen cube ({}², {} mips, CPU backend, {seconds:.2} s for the whole bake) of a held-out sky with a sun of 5·10⁴ (Gaussian, σ = 0.02 rad, 8° up), 1024×512, against the product quadrature of the analytic sky in the lobe's own coordinates (`reference::sheen::prefilter_of`), 160 texels a mip.",
            sheen.layout.size,
            sheen.layout.levels
        ));
        table.write();
    }
    // The targets: within 3 % at every mip, within 1 % at sheen roughness ≥ 0.7.
    for (m, (&e, &r)) in errs.iter().zip(roughness.iter()).enumerate() {
        let bound = if r >= 0.7 { 0.01 } else { 0.03 };
        assert!(e <= bound, "sun {amplitude:e}, sheen mip {m} (roughness {r:.2}): {:.2} % against {:.0} %", 100.0 * e, 100.0 * bound);
    }
}

