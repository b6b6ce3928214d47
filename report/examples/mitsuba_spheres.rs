//! splitsum's side of the comparison with Mitsuba 3 (`scripts/mitsuba.sh`): single spheres
//! of white metal (F₀ = 1) and of a coloured dielectric under the sunny environments of both
//! sets, which Mitsuba renders with the glTF BRDF (`scripts/mitsuba_gltf.py`).
//!
//! - `envs DIR [NAME...]`: writes each sunny environment of the two sets (or those named)
//!   as `DIR/<slug>.exr` (32-bit float, the radiance splitsum reads), and `DIR/envs.txt`
//!   (slug, set).
//! - `shade DIR`: for every `DIR/<slug>_points.f32` that the script's Mitsuba run wrote
//!   (per pixel: the normal and the view, six f32), bakes `<slug>.exr` with the defaults
//!   and writes `DIR/<slug>_<material>_r<r>_k<K>.f32`: per pixel the RGB that splitsum's
//!   shading gives the material ([`MATERIALS`]) at roughness `r` with `K` fetches (the one
//!   fetch is the default), and at every [`STRIDE`]-th pixel the exact reflectance integral
//!   of the glTF BRDF over the baked source cube (`splitsum_reference::Environment::shade`,
//!   height-correlated masking: `<slug>_<material>_r<r>_exact.f32`), which checks the
//!   Mitsuba renders before they are compared with.
use splitsum::Product;
use splitsum::backend::{Backend, BackendKind};
use splitsum::settings::Settings;
use splitsum_report::measurement::Set;
use splitsum_report::sets::{MEMBERS, Source};
use splitsum_shaders::glam::Vec3;
use splitsum_shaders::shade::{self, Material, ShadeOptions};
use rayon::prelude::*;
use splitsum_reference as reference;
use std::path::Path;

/// The roughnesses rendered (r 0.3–1), of each material.
const ROUGHNESS: [f32; 5] = [0.3, 0.5, 0.65, 0.8, 1.0];
/// The ladder's rungs compared.
const FETCHES: [u32; 3] = [1, 4, 16];
/// Every how many pixels the exact integrals are computed (each a sum over the source cube).
const STRIDE: usize = 16;
/// The materials (`scripts/mitsuba_spheres.py`'s `MATERIALS`, the same): name, metallic,
/// base colour.
const MATERIALS: [(&str, f32, [f32; 3]); 2] = [("metal", 1.0, [1.0; 3]), ("dielectric", 0.0, [0.9, 0.6, 0.3])];

fn slug(name: &str) -> String {
    name.chars().map(|c| if c.is_ascii_alphanumeric() { c.to_ascii_lowercase() } else { '_' }).collect()
}

fn sunny(source: Source, name: &str) -> bool {
    matches!(source, Source::Sunny { .. }) || ["city", "sunrise", "sunset"].contains(&name)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let (mode, dir) = (args.get(1).map(String::as_str), Path::new(args.get(2).map(String::as_str).unwrap_or(".")));
    let envs = Path::new("target/environments");
    match mode {
        Some("envs") => {
            let mut list = String::new();
            let named = &args[3..];
            for m in MEMBERS.iter().filter(|m| sunny(m.source, m.name) && (named.is_empty() || named.iter().any(|n| n == m.name))) {
                let env = splitsum_report::sets::load(m, envs, 1024)?;
                let splitsum::environment::Environment::Equirect(e) = &env else { return Err(format!("{} is not an equirect", m.name).into()) };
                let s = slug(m.name);
                splitsum::files::write_rgb_exr(&dir.join(format!("{s}.exr")), e.width, e.height, &e.texels, m.name)?;
                list += &format!("{s}\t{}\t{}\n", if m.set == Set::Tuning { "tuning" } else { "held-out" }, m.name);
            }
            std::fs::write(dir.join("envs.txt"), list)?;
        }
        Some("shade") => {
            let backend = Backend::open(BackendKind::Gpu)?;
            for line in std::fs::read_to_string(dir.join("envs.txt"))?.lines() {
                let s = line.split('\t').next().unwrap_or_default();
                let points = dir.join(format!("{s}_points.f32"));
                if !points.exists() {
                    continue;
                }
                let env = splitsum::environment::load(&dir.join(format!("{s}.exr")), false)?.0;
                let baked = splitsum::reading::bake_for_display(&backend, &env, &Settings::default())?;
                let raw: Vec<f32> = std::fs::read(&points)?.chunks_exact(4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect();
                let source = baked.cube(Product::SourceCube);
                let exact = reference::Environment::new(source.level(0), source.layout.size);
                let shape = baked.shape();
                let specular = baked.specular_buffer();
                let (irradiance, table) = (&baked.cube(Product::Irradiance).texels, &baked.table(Product::BrdfTable).texels);
                for ((material, metallic, base), &r) in MATERIALS.iter().flat_map(|m| ROUGHNESS.iter().map(move |r| (*m, r))) {
                    let m = Material {
                        base_color: Vec3::from_array(base),
                        metallic,
                        roughness: r,
                        occlusion: 1.0,
                        emissive: Vec3::ZERO,
                        sheen_color: Vec3::ZERO,
                        sheen_roughness: 0.0,
                    };
                    for &k in &FETCHES {
                        let opts = ShadeOptions { flags: ShadeOptions::DEFAULT.flags & !ShadeOptions::DIRECT, ..ShadeOptions::DEFAULT }.with_fetches(k);
                        let mut out = Vec::with_capacity(raw.len() / 2);
                        for p in raw.chunks_exact(6) {
                            let (n, v) = (Vec3::new(p[0], p[1], p[2]), Vec3::new(p[3], p[4], p[5]));
                            let sample = shade::ibl_sample(shape, &specular, irradiance, table, opts, &m, n, v);
                            let c = shade::ibl(opts, &m, n, v, sample);
                            out.extend([c.x, c.y, c.z]);
                        }
                        let bytes: Vec<u8> = out.iter().flat_map(|x| x.to_le_bytes()).collect();
                        std::fs::write(dir.join(format!("{s}_{material}_r{r}_k{k}.f32")), bytes)?;
                    }
                    let picked: Vec<&[f32]> = raw.chunks_exact(6).step_by(STRIDE).collect();
                    let out: Vec<f32> = picked
                        .par_iter()
                        .flat_map_iter(|p| {
                            let (n, v) = ([p[0] as f64, p[1] as f64, p[2] as f64], [p[3] as f64, p[4] as f64, p[5] as f64]);
                            exact.shade(n, v, base.map(f64::from), metallic as f64, r as f64, reference::Smith::Correlated).map(|c| c as f32)
                        })
                        .collect();
                    let bytes: Vec<u8> = out.iter().flat_map(|x| x.to_le_bytes()).collect();
                    std::fs::write(dir.join(format!("{s}_{material}_r{r}_exact.f32")), bytes)?;
                }
                eprintln!("shaded {s}");
            }
        }
        _ => return Err("usage: mitsuba_spheres envs|shade DIR".into()),
    }
    Ok(())
}
