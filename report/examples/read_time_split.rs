//! A measurement for issue 34's fourth part, outside CI: how far the prefiltered lookup near
//! a sun gets if the sun is taken out of the cube and added back at read time, against the
//! defaults' one read.
//!
//! **The split read.** The source's level 0 is split as the sheen's source is
//! (`shaders/src/bright.rs`): `T` is the luminance of its `(K+1)`-th brightest texel; a
//! texel brighter keeps `L·T/lum(L)` (the residual) and gives the rest to an excess list of
//! at most `K` texels. The residual is baked with the defaults and read as the defaults
//! read; each excess texel adds `E·∫_texel D(h)(n·l) dl / ∫_sphere D(h)(n·l) dl` with
//! `n = v` = the lookup direction, the prefilter's own weight: the f64 reference's exact
//! prefilter (`reference::Environment::prefilter`) of a level that holds the excess alone.
//! The filter is linear, so this is the exact prefilter of the source wherever the
//! residual's read is.
//!
//! **f32 hazard, for a shader.** At `r ≤ 0.05` (`α ≤ 0.0025`) `n·h` differs from 1 by less
//! than f32's epsilon across the lobe; `D` must come from `1 − n·h = |n − h|²/2` or from
//! `n·l`, not from `n·h` squared, or the excess of a 10⁴ sun reads hundreds of percent off.
//!
//! `cargo run --release -p splitsum-report --example read_time_split -- near|anywhere
//! POINTS K [ENVIRONMENT...]`: `POINTS` lookups per roughness band and environment, within
//! three lobe widths of the brightest texel (`near`, as `runner report`'s near-sun
//! lookups) or anywhere; every member of both sets, or those named. Prints each
//! environment's mean relative luminance error per band (defaults → split), then each set's
//! mean.
use rayon::prelude::*;
use splitsum::Product;
use splitsum::backend::Backend;
use splitsum::environment::Environment;
use splitsum::measured::Set;
use splitsum::settings::Settings;
use splitsum::texture::Cube;
use splitsum_report::measurement::rel64;
use splitsum_report::sets::MEMBERS;
use splitsum_shaders::cubemap::CubeLayout;
use splitsum_shaders::glam::{Vec3, Vec4};
use splitsum_shaders::sampling;
use splitsum_shaders::shade::{self, ShadeOptions};

/// The roughness bands of `runner report`'s lookups.
const BANDS: [(f32, f32); 8] = [(0.02, 0.05), (0.05, 0.1), (0.1, 0.15), (0.15, 0.2), (0.2, 0.35), (0.35, 0.5), (0.5, 0.75), (0.75, 1.0)];

fn unit(v: Vec3) -> [f64; 3] {
    splitsum_reference::normalize([v.x as f64, v.y as f64, v.z as f64])
}

/// A set's sums over its environments: (defaults, split) per band, and how many.
type SetSums = (Set, usize, [(f64, f64); BANDS.len()]);

/// Splits level 0 at the `(K+1)`-th brightest texel: the residual level, the level that
/// holds the excess alone, and how many texels were split.
fn split(level: &[Vec4], keep: usize) -> (Vec<Vec4>, Vec<Vec4>, usize) {
    let lum = |t: &Vec4| 0.2126 * t.x + 0.7152 * t.y + 0.0722 * t.z;
    let mut sorted: Vec<f32> = level.iter().map(lum).collect();
    sorted.sort_by(|a, b| b.total_cmp(a));
    let threshold = sorted[keep.min(sorted.len() - 1)].max(1e-6);
    let (mut residual, mut excess, mut count) = (level.to_vec(), vec![Vec4::ZERO; level.len()], 0);
    for (i, t) in level.iter().enumerate() {
        let l = lum(t);
        if l > threshold {
            let kept = t.truncate() * (threshold / l);
            residual[i] = kept.extend(t.w);
            excess[i] = (t.truncate() - kept).extend(t.w);
            count += 1;
        }
    }
    (residual, excess, count)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let usage = "usage: read_time_split near|anywhere POINTS K [ENVIRONMENT...]";
    let near = match args.get(1).map(String::as_str) {
        Some("near") => true,
        Some("anywhere") => false,
        _ => return Err(usage.into()),
    };
    let points: u32 = args.get(2).and_then(|s| s.parse().ok()).ok_or(usage)?;
    let keep: usize = args.get(3).and_then(|s| s.parse().ok()).ok_or(usage)?;
    let named = &args[4.min(args.len())..];
    let envs = std::path::Path::new("target/environments");
    // Per set and band: (defaults, split) sums and counts over environments.
    let mut sets: Vec<SetSums> = vec![(Set::Tuning, 0, [(0.0, 0.0); BANDS.len()]), (Set::HeldOut, 0, [(0.0, 0.0); BANDS.len()])];
    for m in MEMBERS.iter().filter(|m| named.is_empty() || named.iter().any(|n| n == m.name)) {
        let env = splitsum_report::sets::load(m, envs, 1024)?;
        let baked = splitsum::bake::bake_for_display(&Backend::Cpu, &env, &Settings::default())?;
        let s = baked.shape().specular_size;
        let cube = splitsum::bake::host_source_cube(&Backend::Cpu, &env, &Settings { source_size: Some(s), size: s, ..Settings::default() })?;
        let (residual, excess, count) = split(cube.level(0), keep);
        let rest = Environment::Cube(Cube { layout: CubeLayout::new(s, 1), texels: residual });
        let rest = splitsum::bake::bake_for_display(&Backend::Cpu, &rest, &Settings::default())?;
        let reference = splitsum_reference::Environment::new(cube.level(0), s);
        let excess = splitsum_reference::Environment::new(&excess, s);
        let b = reference.brightest();
        let sun = Vec3::new(b[0] as f32, b[1] as f32, b[2] as f32).normalize();
        let (t, bt) = sampling::orthonormal_basis(sun);
        let read = |baked: &splitsum::bake::BakedEnvironment, d: Vec3, r: f32| {
            let v = shade::prefiltered(baked.shape(), &baked.cube(Product::Specular).texels, ShadeOptions::DEFAULT.flags, d, r);
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
                    let (rest, extra) = (read(&rest, d, r), excess.prefilter(unit(d), r as f64));
                    (rel64(read(&baked, d, r), exact), rel64([0, 1, 2].map(|c| rest[c] + extra[c]), exact))
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
