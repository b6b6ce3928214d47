//! Equirectangular (latitude–longitude) environments and their resampling to a cube map.
//!
//! **Mapping** (the convention of Blender, three.js and most HDRI sites): the image centre
//! looks down `−Z`, `+X` is a quarter turn to the right, the top row is `+Y`:
//! `u = ½ + atan2(x, −z)/(2π)`, `v = atan2(√(x²+z²), y)/π` (polar angle from `+Y`).
//!
//! **Area-correct resampling**: a cube texel is the solid-angle-weighted mean of the
//! environment over the texel: `L = Σ L(ωⱼ) J(ωⱼ) / Σ J(ωⱼ)` over an `n×n` grid of points in
//! the texel, with the cube-face Jacobian `J = (1 + a² + b²)^(−3/2)` and a bilinear
//! reconstruction of the environment. The host picks `n` so that the points are at least
//! as dense as the source texels (see [`supersampling`]); a small bright source therefore
//! lands in the cube with its power, whatever its position, instead of aliasing to
//! whichever texel a single point sample hits. The weights are normalised, so a constant
//! environment gives exactly that constant.

use crate::cubemap;
use crate::math;
use spirv_std::glam::{Vec2, Vec3, Vec4};

/// Equirect coordinates `(u, v)` ∈ [0, 1]² of direction `d` (need not be unit).
#[inline]
pub fn dir_to_uv(d: Vec3) -> Vec2 {
    let u = 0.5 + math::atan2(d.x, -d.z) * (0.5 * math::FRAC_1_PI);
    let v = math::atan2(math::sqrt(d.x * d.x + d.z * d.z), d.y) * math::FRAC_1_PI;
    Vec2::new(u, v)
}

/// The unit direction at equirect coordinates `(u, v)`.
#[inline]
pub fn uv_to_dir(uv: Vec2) -> Vec3 {
    let (sin_phi, cos_phi) = math::sin_cos_turns(uv.x - 0.5);
    let (sin_theta, cos_theta) = math::sin_cos_turns(0.5 * uv.y);
    Vec3::new(sin_theta * sin_phi, cos_theta, -sin_theta * cos_phi)
}

/// Bilinear lookup in a `width`×`height` RGBA image at `(u, v)`: wraps in `u`, clamps in `v`.
pub fn sample_bilinear(texels: &[Vec4], width: u32, height: u32, uv: Vec2) -> Vec4 {
    let fx = uv.x * width as f32 - 0.5;
    let fy = math::clamp(uv.y * height as f32 - 0.5, 0.0, (height - 1) as f32);
    let x0f = math::floor(fx);
    let y0f = math::floor(fy);
    let tx = fx - x0f;
    let ty = fy - y0f;
    let w = width as i32;
    let mut x0 = (x0f as i32) % w;
    if x0 < 0 {
        x0 += w;
    }
    let x1 = if x0 + 1 == w { 0 } else { x0 + 1 };
    let y0 = y0f as u32;
    let y1 = if y0 + 1 < height { y0 + 1 } else { y0 };
    let r0 = y0 * width;
    let r1 = y1 * width;
    let a = texels[(r0 + x0 as u32) as usize] * (1.0 - tx) + texels[(r0 + x1 as u32) as usize] * tx;
    let b = texels[(r1 + x0 as u32) as usize] * (1.0 - tx) + texels[(r1 + x1 as u32) as usize] * tx;
    a * (1.0 - ty) + b * ty
}

/// Points per axis, per cube texel, so that the supersampling grid is `density` times as
/// fine as the equirect's texels at the equator (where they are largest), clamped to
/// [1, 32]. A cube texel at the face centre spans `2/size` radians; an equirect texel spans
/// `2π/width`.
pub fn supersampling(face_size: u32, width: u32, density: f32) -> u32 {
    let cube_texel = 2.0 / face_size as f32;
    let src_texel = math::TAU / width as f32;
    let n = math::floor(density * cube_texel / src_texel + 0.999);
    math::clamp(n, 1.0, 32.0) as u32
}

/// Cube texel `(x, y)` of `face` (face size `size`) resampled from the equirect image with
/// an `n×n` grid of solid-angle-weighted bilinear samples.
pub fn cube_texel(texels: &[Vec4], width: u32, height: u32, face: u32, x: u32, y: u32, size: u32, n: u32) -> Vec4 {
    let s = size as f32;
    let nf = n as f32;
    let mut acc = Vec4::ZERO;
    let mut wsum = 0.0;
    let mut j = 0;
    while j < n {
        let mut i = 0;
        while i < n {
            let uv = Vec2::new(
                (x as f32 + (i as f32 + 0.5) / nf) / s,
                (y as f32 + (j as f32 + 0.5) / nf) / s,
            );
            let p = cubemap::face_uv_to_cube(face, uv);
            let r2 = p.dot(p);
            let w = 1.0 / (r2 * math::sqrt(r2)); // (1 + a² + b²)^(−3/2)
            acc += sample_bilinear(texels, width, height, dir_to_uv(p)) * w;
            wsum += w;
            i += 1;
        }
        j += 1;
    }
    acc * (1.0 / wsum)
}
