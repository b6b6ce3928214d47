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

/// The mean of row `y` over the interval `[a, a + len)` in texel units (wrapping around in
/// `u`), `1 ≤ len ≤ width`, of the piecewise-constant image: each texel weighs in by its
/// overlap with the interval.
fn row_mean(texels: &[Vec4], width: u32, y: u32, a: f32, len: f32) -> Vec4 {
    let end = a + len;
    let k0 = math::floor(a) as i32;
    let k1 = math::floor(end) as i32;
    let w = width as i32;
    let row = y * width;
    let mut acc = Vec4::ZERO;
    let mut k = k0;
    while k <= k1 {
        let lo = math::max(k as f32, a);
        let hi = math::min(k as f32 + 1.0, end);
        if hi > lo {
            let mut x = k % w;
            if x < 0 {
                x += w;
            }
            acc += texels[(row + x as u32) as usize] * (hi - lo);
        }
        k += 1;
    }
    acc * (1.0 / len)
}

/// Area lookup in a `width`×`height` RGBA image at `(u, v)`: the mean over a window
/// `window` texels wide in `u` (at least one texel, at most the whole row; wrapping),
/// interpolated linearly between rows in `v` (clamped). A one-texel window is exactly
/// bilinear interpolation; wider windows integrate every texel they cover, which is what
/// keeps narrow features near the poles — where texels shrink in `u` — from being missed.
pub fn sample_area(texels: &[Vec4], width: u32, height: u32, uv: Vec2, window: f32) -> Vec4 {
    let w = width as f32;
    let fy = math::clamp(uv.y * height as f32 - 0.5, 0.0, (height - 1) as f32);
    let y0f = math::floor(fy);
    let ty = fy - y0f;
    let y0 = y0f as u32;
    let y1 = if y0 + 1 < height { y0 + 1 } else { y0 };
    let len = math::clamp(window, 1.0, w);
    let a = uv.x * w - 0.5 * len;
    let r0 = row_mean(texels, width, y0, a, len);
    let r1 = row_mean(texels, width, y1, a, len);
    r0 * (1.0 - ty) + r1 * ty
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
/// an `n×n` grid of solid-angle-weighted samples, each the mean over its own footprint in
/// `u` ([`sample_area`]): the grid spacing, `2/(size·n)` on the face plane, is about
/// `2/(size·n·|p|)` radians at point `p`, which near a pole spans `1/sin θ` times more
/// longitude.
pub fn cube_texel(texels: &[Vec4], width: u32, height: u32, face: u32, x: u32, y: u32, size: u32, n: u32) -> Vec4 {
    let s = size as f32;
    let nf = n as f32;
    let spacing = 2.0 / (s * nf);
    let texels_per_radian = width as f32 * (0.5 * math::FRAC_1_PI);
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
            let r = math::sqrt(r2);
            let w = 1.0 / (r2 * r); // (1 + a² + b²)^(−3/2)
            // Longitude spanned by one grid step: (spacing/r) / sin θ, sin θ = √(x²+z²)/r.
            let rho = math::sqrt(p.x * p.x + p.z * p.z);
            let window = if rho > 0.0 { spacing / rho * texels_per_radian } else { width as f32 };
            acc += sample_area(texels, width, height, dir_to_uv(p), window) * w;
            wsum += w;
            i += 1;
        }
        j += 1;
    }
    acc * (1.0 / wsum)
}
