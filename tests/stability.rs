//! Numerical stability on stiff and extreme inputs, as a matrix run natively and on the GPU
//! (the `probe` kernel evaluates the same functions at arbitrary inputs). Every output must
//! be finite; the BRDF table stays within [0, 1]; a constant environment stays constant.
//! `docs/HAZARDS.md` lists each hazard with the rule the code applies.

use splitsum::Backend;
use splitsum::Product;
use splitsum::texture::Cube;
use splitsum_shaders::cubemap::CubeLayout;
use splitsum_shaders::glam::{Vec3, Vec4};
use splitsum_shaders::kernels::{ProbeMode, ProbeParams};
use splitsum_shaders::math::{self, MAX_RADIANCE};

const ROUGHNESS: [f32; 5] = [0.0, 1e-7, 1e-4, 0.02, 1.0];
const N_DOT_V: [f32; 4] = [0.0, 1e-7, 1e-3, 1.0];
const RADIANCE: [f32; 6] = [0.0, 1e-40, 1e4, 65504.0, 1e6, f32::MAX];

fn backends() -> [&'static Backend; 2] {
    [&Backend::Cpu, support::gpu()]
}

fn params(mode: u32, samples: u32) -> ProbeParams {
    ProbeParams { mode, count: 0, probe_offset: 0, samples, src_size: 0, src_levels: 0, src_level: 0, lod_bias: 1.0, start: 0, chunk: 0 }
}

/// Directions where cube and sphere parametrisations break: poles, face centres, edges,
/// corners, points a hair off them, and the zero vector.
fn hard_directions() -> Vec<Vec3> {
    let mut v = vec![Vec3::ZERO, Vec3::Y, -Vec3::Y, Vec3::X, -Vec3::Z];
    for (a, b) in [(1.0f32, 1.0f32), (1.0, -1.0), (-1.0, -1.0)] {
        v.push(Vec3::new(a, b, 0.0).normalize());
        v.push(Vec3::new(0.0, a, b).normalize());
        v.push(Vec3::new(a, 0.0, b).normalize());
        v.push(Vec3::new(a, b, 1.0).normalize());
        v.push(Vec3::new(a, b, -1.0).normalize());
        v.push(Vec3::new(a, b, 1.0 + 1e-7).normalize());
    }
    v.push(Vec3::new(1e-7, 1.0, -1e-7).normalize());
    v.push(Vec3::new(0.0, -1.0, 1e-30));
    v
}

/// The BRDF table at every (n·v, roughness) of the matrix, for 1, 2 and 2²⁴+1 samples.
#[test]
fn lut_corners_of_the_domain() {
    for b in backends() {
        for samples in [1u32, 2, 1024, (1 << 24) + 1] {
            let probes: Vec<Vec4> = if samples > 1 << 24 {
                // The huge count on a few cells only: 2²⁴ samples each.
                vec![Vec4::new(0.0, 0.0, 0.0, 0.0), Vec4::new(1e-7, 1e-7, 0.0, 0.0), Vec4::new(1.0, 1.0, 0.0, 0.0), Vec4::new(1e-3, 0.02, 0.0, 0.0)]
            } else {
                N_DOT_V.iter().flat_map(|&nv| ROUGHNESS.iter().map(move |&r| Vec4::new(nv, r, 0.0, 0.0))).collect()
            };
            let out = b.probe(params(ProbeMode::Lut as u32, samples), None, &probes).unwrap();
            for (q, v) in probes.iter().zip(&out) {
                assert!(v.x.is_finite() && v.y.is_finite(), "{}: n·v {} r {} n {samples}: {v}", b.describe(), q.x, q.y);
                assert!(v.x >= 0.0 && v.y >= 0.0, "{}: {q} {v}", b.describe());
                // Rounding of the sum only; the integrand is bounded by 1.
                assert!(v.x + v.y <= 1.0 + 1e-6, "{}: {q} {v}", b.describe());
            }
        }
    }
}

fn constant_cube(size: u32, c: f32) -> Cube {
    let layout = CubeLayout::new(size, CubeLayout::full_chain(size));
    Cube { layout, texels: vec![Vec4::new(c, c, c, 1.0); layout.texel_count() as usize] }
}

/// A constant environment, at every radiance of the matrix, prefilters, convolves and
/// samples to itself in every hard direction and at every roughness. Subnormals may be
/// flushed to zero by a GPU (Vulkan allows it), so for them 0 is accepted too.
#[test]
fn constant_environments_stay_constant_everywhere() {
    for b in backends() {
        for &c in &RADIANCE {
            let cube = constant_cube(8, c);
            let dirs = hard_directions();
            let check = |what: &str, q: &Vec4, v: &Vec4| {
                assert!(v.is_finite(), "{} {what}: L = {c:e}, probe {q}: {v}", b.describe());
                let ok = |x: f32| {
                    if c == 0.0 {
                        x == 0.0
                    } else if c < f32::MIN_POSITIVE {
                        x == 0.0 || ((x - c) / c).abs() < 1e-3
                    } else if c > math::LARGEST {
                        // A mean of f32::MAX that rounds past it is held to math::LARGEST,
                        // 8.3·10⁻⁴ below f32::MAX (the largest value WGSL takes as a literal),
                        // then weighted by sums within a few ULP of 1.
                        ((x - c) / c).abs() < 1e-3
                    } else {
                        ((x - c) / c).abs() < 1e-5
                    }
                };
                assert!(ok(v.x) && ok(v.y) && ok(v.z), "{} {what}: L = {c:e}, probe {q}: {v}", b.describe());
            };
            for samples in [1u32, 2, 256] {
                let probes: Vec<Vec4> = dirs.iter().flat_map(|d| ROUGHNESS.iter().map(move |&r| d.extend(r))).collect();
                let out = b.probe(params(ProbeMode::Prefilter as u32, samples), Some(&cube), &probes).unwrap();
                probes.iter().zip(&out).for_each(|(q, v)| check("prefilter", q, v));
            }
            let probes: Vec<Vec4> = dirs.iter().map(|d| d.extend(0.0)).collect();
            let p = ProbeParams { src_level: 1, ..params(ProbeMode::Irradiance as u32, 0) };
            let out = b.probe(p, Some(&cube), &probes).unwrap();
            probes.iter().zip(&out).for_each(|(q, v)| check("irradiance", q, v));
            let probes: Vec<Vec4> = dirs.iter().flat_map(|d| [-2.0f32, 0.0, 0.5, 1.7, 3.0, 40.0].map(|l| d.extend(l))).collect();
            let out = b.probe(params(ProbeMode::Sample as u32, 0), Some(&cube), &probes).unwrap();
            probes.iter().zip(&out).for_each(|(q, v)| check("sample", q, v));
        }
    }
}

/// Shading at every roughness and n·v of the matrix, lights from 0 to 10²⁰ and the
/// environment at its extremes: finite everywhere (native).
#[test]
fn shading_is_finite_at_the_extremes() {
    use splitsum_shaders::shade::{self, IblSample, Material, ShadeOptions};
    let n = Vec3::Z;
    for &r in &ROUGHNESS {
        for &nv in &N_DOT_V {
            let v = Vec3::new((1.0 - nv * nv).sqrt(), 0.0, nv);
            for metallic in [0.0f32, 1.0] {
                for &radiance in &[0.0f32, 1e-40, 1e4, 1e6, MAX_RADIANCE] {
                    let m = Material {
                        base_color: Vec3::ONE,
                        metallic,
                        roughness: r,
                        occlusion: 1.0,
                        emissive: Vec3::ZERO,
                        sheen_color: Vec3::ZERO,
                        sheen_roughness: 0.0,
                    };
                    for diffuse in 0..(<shade::DiffuseModel as splitsum_shaders::choice::Choice>::ALL.len() as u32) {
                        for specular in 0..(<shade::SpecularModel as splitsum_shaders::choice::Choice>::ALL.len() as u32) {
                            for fresnel in 0..(<shade::FresnelForm as splitsum_shaders::choice::Choice>::ALL.len() as u32) {
                                let o = ShadeOptions { diffuse, specular, fresnel, flags: 3 };
                                for l in [n, v, Vec3::new(-v.x, 0.0, v.z), Vec3::new(0.0, 1.0, 1e-7).normalize()] {
                                    let c = shade::direct(o, &m, n, v, l, Vec3::splat(radiance));
                                    assert!(c.is_finite() && c.min_element() >= 0.0, "direct r {r} nv {nv} L {radiance:e} l {l}: {c}");
                                }
                                let s = IblSample {
                                    prefiltered: Vec3::splat(radiance),
                                    irradiance: Vec3::splat(radiance),
                                    brdf: splitsum_shaders::lut::integrate_brdf(nv, r, 16),
                                };
                                let c = shade::ibl(o, &m, n, v, s);
                                assert!(c.is_finite() && c.min_element() >= 0.0, "ibl r {r} nv {nv} L {radiance:e}: {c}");
                            }
                        }
                    }
                }
            }
        }
    }
    // The display transform maps anything, ∞ and NaN included, into [0, 1].
    use splitsum_shaders::tonemap::{self, Tonemapper};
    for x in [0.0f32, 1e-40, 1.0, 1e6, MAX_RADIANCE, f32::MAX, f32::INFINITY, f32::NAN] {
        for t in [Tonemapper::Aces, Tonemapper::Reinhard, Tonemapper::Clamp] {
            let d = tonemap::display(Vec3::splat(x), 1.0, t);
            assert!(d.is_finite() && d.min_element() >= 0.0 && d.max_element() <= 1.0, "{x} {t:?}: {d}");
        }
    }
}

/// The shading ladder (`shade::lobe_radiance`, 2 to 16 fetches) on a constant sky, at every
/// roughness, `n·v` and radiance of the matrix (radiance up to 10⁶, past which a weighted
/// mean of f32 values may overflow before it is divided), normals in the hard directions
/// (poles, cube edges and corners) and views turned about them: the closed form is the
/// constant itself, since the estimator is a weighted mean of reads of a constant cube.
/// Bound: relative 10⁻⁵, the rounding of a mean of at most 16 weighted f32 terms; for the
/// subnormal radiance (10⁻⁴⁰) relative 10⁻², since each weighted term `w·L` lands on the
/// subnormal grid (steps of 1.4·10⁻⁴⁵, 10⁻⁴ of a term of 10⁻⁴¹); 0 gives 0.
#[test]
fn the_shading_ladder_keeps_a_constant_sky_constant() {
    use splitsum_shaders::prefilter::RoughnessMapping;
    use splitsum_shaders::sampling;
    use splitsum_shaders::shade::{self, EnvironmentShape, Material, ShadeOptions};
    let size = 8;
    for &c in RADIANCE.iter().filter(|&&c| c <= 1e6) {
        let cube = constant_cube(size, c);
        let shape = EnvironmentShape {
            specular_size: size,
            specular_levels: cube.layout.levels,
            mapping: RoughnessMapping::Geometric as u32,
            irradiance_size: size,
            lut_size: 4,
            source_size: size,
            irradiance_levels: 1,
            sheen_size: size,
            sheen_levels: cube.layout.levels,
            sheen_mapping: RoughnessMapping::Linear as u32,
            sheen_table_size: splitsum::table::SHEEN_TABLE_SIZE,
            excess_entries: 0,
        };
        for n in hard_directions().into_iter().filter(|n| n.length() > 0.5) {
            let (t, _) = sampling::orthonormal_basis(n);
            for &nv in &N_DOT_V {
                let v = (n * nv + t * (1.0 - nv * nv).sqrt()).normalize();
                for &r in &ROUGHNESS {
                    for metallic in [0.0f32, 1.0] {
                        let m = Material {
                            base_color: Vec3::new(0.9, 0.5, 0.2),
                            metallic,
                            roughness: r,
                            occlusion: 1.0,
                            emissive: Vec3::ZERO,
                            sheen_color: Vec3::ZERO,
                            sheen_roughness: 0.0,
                        };
                        for fetches in [2, 4, 8, 16] {
                            let opts = ShadeOptions::DEFAULT.with_fetches(fetches);
                            assert_eq!(opts.fetches(), fetches);
                            let got = shade::lobe_radiance(shape, &cube.texels, opts, &m, n, v);
                            let e = (got - Vec3::splat(c)).abs().max_element();
                            let bound = if c < f32::MIN_POSITIVE { 1e-2 * c } else { 1e-5 * c };
                            assert!(got.is_finite() && e <= bound, "K {fetches} n {n} n·v {nv} r {r} L {c:e}: {got}");
                        }
                    }
                }
            }
        }
    }
}

/// An environment holding f32::MAX, +∞ (sanitised) and subnormals, baked end to end on
/// both backends at minimum roughness and a 2²⁴+1-sample LUT cell: clamped on reading to
/// 10²⁰, every product finite, and the GPU's frame finite too.
#[test]
fn extreme_environment_bakes_and_renders_finite() {
    use splitsum::bake;
    use splitsum::environment::{self, Environment};
    use splitsum::settings::{Products, Settings};
    let (w, h) = (64u32, 32u32);
    let mut texels: Vec<Vec4> = (0..w * h).map(|i| Vec4::splat(1.0 + (i % 7) as f32)).collect();
    texels[5] = Vec4::new(f32::MAX, f32::MAX, f32::MAX, 1.0);
    texels[70] = Vec4::new(f32::INFINITY, 1.0, 1.0, 1.0);
    texels[200] = Vec4::splat(1e-40);
    texels[300] = Vec4::splat(1e6);
    let report = environment::clean(std::path::Path::new("extreme"), &mut texels, true).unwrap();
    assert_eq!(report.clamped, 2, "f32::MAX and +∞ (made the channel's largest finite value) are clamped");
    assert!(texels.iter().all(|t| t.max_element() <= MAX_RADIANCE));
    let env = Environment::Equirect(splitsum::texture::Equirect { width: w, height: h, texels });
    let settings = Settings {
        size: 8,
        source_size: Some(16),
        mips: Some(4),
        samples: 64,
        irradiance_size: 4,
        irradiance_source: Some(8),
        sh_source: Some(8),
        lut_size: 8,
        lut_samples: 16,
        ..Settings::default()
    };
    for b in backends() {
        let baked = bake::bake(b, &env, &settings, Products::ALL).unwrap();
        let all = baked
            .cube(Product::SourceCube)
            .unwrap()
            .texels
            .iter()
            .chain(&baked.cube(Product::Specular).unwrap().texels)
            .chain(&baked.cube(Product::Irradiance).unwrap().texels)
            .chain(&baked.cube(Product::Sheen).expect("Products::ALL bakes sheen").texels);
        for t in all {
            assert!(t.is_finite(), "{}: {t}", b.describe());
        }
        assert!(baked.sh9().unwrap().radiance.iter().flatten().all(|v| v.is_finite()));
        assert!(baked.table(Product::BrdfTable).unwrap().texels.iter().all(|t| t.is_finite()));
    }
    // Rendered on the GPU in linear radiance, with lights of 10⁶ and mirror spheres.
    let baked = splitsum::reading::bake_for_display(&Backend::Cpu, &env, &settings).unwrap();
    let Backend::Gpu(gpu) = support::gpu() else { unreachable!() };
    let scene = splitsum_display::render::GpuScene::new(gpu, &baked);
    let mut view = splitsum_display::render::ViewState::default();
    for l in &mut view.lights {
        l.radiance = Vec4::new(1e6, 1e6, 1e6, 0.0);
    }
    let mut frame = view.frame(scene.shape, 64, 40, true);
    frame.flags |= splitsum_shaders::scene::Frame::LINEAR;
    let g = scene.render_offscreen(gpu, &frame, None).unwrap();
    assert!(g.iter().all(|p| p.is_finite()), "non-finite pixel on the GPU");
    let c = splitsum_display::render::render_cpu(&baked, &frame);
    assert!(c.iter().all(|p| p.is_finite()), "non-finite pixel on the CPU");
}

/// Sums longer than a driver lets one shader invocation loop (Mesa's lavapipe stops every
/// loop of an invocation after 65 535 iterations in total, counting each loop entered)
/// run in chunks: the GPU agrees with the CPU far past that point.
#[test]
fn long_sums_survive_the_gpu_loop_budget() {
    let probes = vec![Vec4::new(0.5, 0.5, 0.0, 0.0), Vec4::new(0.01, 0.1, 0.0, 0.0), Vec4::new(0.9, 0.05, 0.0, 0.0)];
    let n = 1 << 20;
    let g = support::gpu().probe(params(ProbeMode::Lut as u32, n), None, &probes).unwrap();
    let c = Backend::Cpu.probe(params(ProbeMode::Lut as u32, n), None, &probes).unwrap();
    let lut = support::max_diffs(g.iter().flat_map(|v| [v.x, v.y]), c.iter().flat_map(|v| [v.x, v.y])).0;
    let src = support::source_cube("city", 32);
    let dirs: Vec<Vec4> = (0..16).map(|i| splitsum_shaders::equirect::uv_to_dir(splitsum_shaders::sampling::hammersley(i, 16)).extend(0.6)).collect();
    let g = support::gpu().probe(params(ProbeMode::Prefilter as u32, 40_000), Some(&src), &dirs).unwrap();
    let c = Backend::Cpu.probe(params(ProbeMode::Prefilter as u32, 40_000), Some(&src), &dirs).unwrap();
    let pre = support::max_relative(&g, &c, 1e-3);
    println!("gpu vs cpu: BRDF table at 2^20 samples max |Δ| {lut:.2e}; prefilter at 40 000 samples max relative {pre:.2e}");
    assert!(lut < 1e-5 && pre < 1e-5, "{lut:e} {pre:e}");
}
