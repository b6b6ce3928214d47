//! A sun just below a surface's horizon: what each rung of the shading ladder lets back in.
//!
//! A normal that sees a bright sun a few degrees below its horizon receives nothing from
//! it (`n·l ≤ 0`), but a filter read near the horizon reaches under the surface. Here a
//! generated sky's sun sits `δ` = 1–15° below the horizon of rough metals seen at grazing
//! views whose mirror direction leans towards the sun. Each rung's shaded colour is
//! compared with the full integral of the glTF BRDF over the same cube
//! (`splitsum_reference::Environment::shade`), with the sun and, as the baseline, with
//! the sun's texels set to the sky around them. What the sun adds is the difference.

use crate::measurement::{arr, rel};
use crate::skies;
use rayon::prelude::*;
use splitsum::Product;
use splitsum::backend::Backend;
use splitsum::reading;
use splitsum::error::Result;
use splitsum::settings::Settings;
use splitsum_reference as reference;
use splitsum_shaders::glam::Vec3;
use splitsum_shaders::sampling;
use splitsum_shaders::shade::{self, Material, ShadeOptions};

/// Degrees below the horizon the sun is put at.
pub const DEPTHS: [f32; 6] = [1.0, 3.0, 5.0, 7.5, 10.0, 15.0];
/// The views' `n·v`.
pub const VIEWS: [f32; 3] = [0.1, 0.25, 0.5];
/// The metals' roughness.
pub const ROUGHNESS: [f32; 3] = [0.4, 0.7, 1.0];

/// One rung's errors over the points.
#[derive(Clone, Debug)]
pub struct Row {
    /// Fetches per pixel.
    pub fetches: u32,
    /// Mean relative luminance error with the sun below the horizon.
    pub with_sun: f64,
    /// The same without the sun (the sky alone).
    pub without_sun: f64,
    /// The largest increase of one point's error that the sun causes.
    pub worst_added: f64,
}

/// Shading points: a normal with the sun `δ` below its horizon and a view at `n·v` whose
/// mirror direction points towards the sun's side of the horizon, `n·r = n·v` above it.
fn points(sun: Vec3) -> Vec<(Vec3, Vec3, f32)> {
    let mut out = Vec::new();
    let up = Vec3::Y;
    for depth in DEPTHS {
        let d = depth.to_radians();
        // Tilt the normal away from the sun until the sun is δ below its horizon.
        let side = (up - sun * sun.dot(up)).normalize();
        let n = (sun * -d.sin() + side * d.cos()).normalize();
        let towards = (sun - n * n.dot(sun)).normalize();
        for nv in VIEWS {
            let r = (towards * (1.0 - nv * nv).sqrt() + n * nv).normalize();
            let v = sampling::reflect(r, n);
            for roughness in ROUGHNESS {
                out.push((n, v, roughness));
            }
        }
    }
    out
}

/// Each rung's errors under a generated sky `width` wide whose sun of `radiance` stands
/// at 25°, baked on `backend` at the default settings with a `size`² source.
pub fn measure(backend: &Backend, width: u32, radiance: f32, size: u32) -> Result<Vec<Row>> {
    let settings = Settings { size, source_size: Some(size), ..Settings::default() };
    let elevation = 25.0;
    let sun = skies::sun_direction(elevation);
    let lit = skies::sunny(width, radiance, elevation);
    let dark = skies::sunny(width, 0.0, elevation);
    let pts = points(sun);
    let base = Vec3::splat(0.95);
    let mut rows = Vec::new();
    let mut scenes = Vec::new();
    for env in [&lit, &dark] {
        let baked = reading::bake_for_display(backend, env, &settings)?;
        let source = baked.cube(Product::SourceCube);
        let refenv = reference::Environment::new(source.level(0), source.layout.size);
        let truth: Vec<[f64; 3]> =
            pts.par_iter().map(|&(n, v, r)| refenv.shade(arr(n), arr(v), arr(base), 1.0, r as f64, reference::Smith::Correlated)).collect();
        scenes.push((baked, truth));
    }
    for rung in 0..shade::LADDER_RUNGS {
        let opts = ShadeOptions::DEFAULT.with_fetches(1 << rung);
        let errors = |(baked, truth): &(reading::BakedEnvironment, Vec<[f64; 3]>)| -> Vec<f64> {
            let (spec, irr, table, shape) = (baked.specular_buffer(), baked.cube(Product::Irradiance), baked.table(Product::BrdfTable), baked.shape());
            pts.iter()
                .zip(truth)
                .map(|(&(n, v, r), t)| {
                    let m = Material {
                        base_color: base,
                        metallic: 1.0,
                        roughness: r,
                        occlusion: 1.0,
                        emissive: Vec3::ZERO,
                        sheen_color: Vec3::ZERO,
                        sheen_roughness: 0.0,
                    };
                    let s = shade::ibl_sample(shape, &spec, &irr.texels, &table.texels, opts, &m, n, v);
                    let got = shade::ibl(opts, &m, n, v, s);
                    rel(got, *t)
                })
                .collect()
        };
        let (with, without) = (errors(&scenes[0]), errors(&scenes[1]));
        let mean = |e: &[f64]| e.iter().sum::<f64>() / e.len() as f64;
        let worst_added = with.iter().zip(&without).map(|(a, b)| a - b).fold(f64::MIN, f64::max);
        rows.push(Row { fetches: 1 << rung, with_sun: mean(&with), without_sun: mean(&without), worst_added });
    }
    Ok(rows)
}
