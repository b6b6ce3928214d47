//! A measurement for issue 34's fourth part, outside CI: the prefiltered lookup near a sun
//! with the source split for reading (`splitsum::reading::for_display`: the sun taken out of
//! the cube and its exact terms added back per lookup, `splitsum_shaders::excess`) against
//! the whole cube read as before, both against the f64 reference's exact prefilter.
//!
//! `cargo run --release -p splitsum-report --example read_time_split -- near|anywhere
//! POINTS [ENVIRONMENT...]`: `POINTS` lookups per roughness band and environment, within
//! three lobe widths of the brightest texel (`near`, as `runner report`'s near-sun
//! lookups) or anywhere; every member of both sets, or those named. Prints each
//! environment's mean relative luminance error per band (whole → split), then each set's
//! mean.
use rayon::prelude::*;
use splitsum::backend::Backend;
use splitsum::bake;
use splitsum::measured::Set;
use splitsum::settings::{InputShape, Products, Settings};
use splitsum_report::measurement::rel64;
use splitsum_report::sets::MEMBERS;
use splitsum_shaders::glam::Vec3;
use splitsum_shaders::sampling;
use splitsum_shaders::shade::{self, ShadeOptions};

/// The roughness bands of `runner report`'s lookups.
const BANDS: [(f32, f32); 8] = [(0.02, 0.05), (0.05, 0.1), (0.1, 0.15), (0.15, 0.2), (0.2, 0.35), (0.35, 0.5), (0.5, 0.75), (0.75, 1.0)];

fn unit(v: Vec3) -> [f64; 3] {
    splitsum_reference::normalize([v.x as f64, v.y as f64, v.z as f64])
}

/// A set's sums over its environments: (whole, split) per band, and how many.
type SetSums = (Set, usize, [(f64, f64); BANDS.len()]);

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let usage = "usage: read_time_split near|anywhere POINTS [ENVIRONMENT...]";
    let near = match args.get(1).map(String::as_str) {
        Some("near") => true,
        Some("anywhere") => false,
        _ => return Err(usage.into()),
    };
    let points: u32 = args.get(2).and_then(|s| s.parse().ok()).ok_or(usage)?;
    let named = &args[3.min(args.len())..];
    let envs = std::path::Path::new("target/environments");
    // Per set and band: (whole, split) sums and counts over environments.
    let mut sets: Vec<SetSums> = vec![(Set::Tuning, 0, [(0.0, 0.0); BANDS.len()]), (Set::HeldOut, 0, [(0.0, 0.0); BANDS.len()])];
    for m in MEMBERS.iter().filter(|m| named.is_empty() || named.iter().any(|n| n == m.name)) {
        let env = splitsum_report::sets::load(m, envs, 1024)?;
        let job = Settings::default().resolve(InputShape::of(&env), Products::DISPLAY)?;
        let whole = bake::bake_job(&Backend::Cpu, &env, &job)?.into_display(job.mapping);
        let split = splitsum::reading::bake_for_display(&Backend::Cpu, &env, &Settings::default())?;
        let s = split.shape().specular_size;
        let cube = bake::host_source_cube(&Backend::Cpu, &env, &Settings { source_size: Some(s), size: s, ..Settings::default() })?;
        let count = split.excess.len() / splitsum_shaders::bright::ENTRY as usize;
        let reference = splitsum_reference::Environment::new(cube.level(0), s);
        let b = reference.brightest();
        let sun = Vec3::new(b[0] as f32, b[1] as f32, b[2] as f32).normalize();
        let (t, bt) = sampling::orthonormal_basis(sun);
        let read = |baked: &splitsum::reading::BakedEnvironment, d: Vec3, r: f32| {
            let v = shade::prefiltered(baked.shape(), &baked.specular_buffer(), ShadeOptions::DEFAULT.flags, d, r);
            [v.x as f64, v.y as f64, v.z as f64]
        };
        let set = sets.iter_mut().find(|x| x.0 == m.set).expect("both sets are listed");
        set.1 += 1;
        print!("{:<22} {count:>3} texels split |", m.name);
        for (band, &(lo, hi)) in BANDS.iter().enumerate() {
            let errors: Vec<(f64, f64)> = (0..points)
                .into_par_iter()
                .map(|i| {
                    let r = lo + (hi - lo) * ((i as f32 * 0.618_034 + 0.5).fract());
                    let width = (r * r).max(2.0 * std::f32::consts::FRAC_PI_2 / s as f32);
                    let angle = sampling::radical_inverse(i + 1) * if near { 3.0 * width } else { std::f32::consts::PI };
                    let turn = (i as f32 + 0.5) / points as f32 * std::f32::consts::TAU;
                    let d = (sun * angle.cos() + (t * turn.cos() + bt * turn.sin()) * angle.sin()).normalize();
                    let exact = reference.prefilter(unit(d), r as f64);
                    (rel64(read(&whole, d, r), exact), rel64(read(&split, d, r), exact))
                })
                .collect();
            let mean = |f: fn(&(f64, f64)) -> f64| 100.0 * errors.iter().map(f).sum::<f64>() / errors.len() as f64;
            let (one, split) = (mean(|e| e.0), mean(|e| e.1));
            set.2[band].0 += one;
            set.2[band].1 += split;
            print!(" {lo}–{hi}: {one:.1} → {split:.1} |");
        }
        println!();
    }
    for (set, count, bands) in sets.iter().filter(|s| s.1 > 0) {
        print!("{:<22} mean of {count:>2}         |", set.title());
        for (band, &(lo, hi)) in BANDS.iter().enumerate() {
            print!(" {lo}–{hi}: {:.1} → {:.1} |", bands[band].0 / *count as f64, bands[band].1 / *count as f64);
        }
        println!();
    }
    Ok(())
}
