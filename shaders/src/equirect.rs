//! Equirectangular (latitude–longitude) environments and their resampling to a cube map.
//!
//! **Mapping** (the convention of Blender, three.js and most HDRI sites): the image centre
//! looks down `−Z`, `+X` is a quarter turn to the right, the top row is `+Y`:
//! `u = ½ + atan2(x, −z)/(2π)`, `v = atan2(√(x²+z²), y)/π` (polar angle from `+Y`).
//!
//! **Area-correct resampling**: a cube texel is the solid-angle-weighted mean of the
//! environment over the texel: `L = Σ L(ωⱼ) J(ωⱼ) / Σ J(ωⱼ)` over an `n×n` grid of points in
//! the texel, with the cube-face Jacobian `J = (1 + a² + b²)^(−3/2)`. Each point reads the
//! mean of the environment over its own footprint in longitude (which near a pole spans
//! `1/sin θ` times more texels) and interpolates linearly between rows. The host picks `n`
//! so that the points are at least as dense as the source texels (see [`supersampling`]);
//! a small bright source therefore lands in the cube with its power, whatever its
//! position, instead of aliasing to whichever texel a single point sample hits. The
//! weights are normalised, so a constant environment gives exactly that constant.
//!
//! **Row pyramid**: footprints are averaged from a pyramid that halves each row while its
//! width stays even (level k texel = mean of 2ᵏ source texels), at the level where the
//! footprint spans at most 16 texels — a bounded loop, whatever the footprint (a driver may
//! bound a shader's loop iterations, see `math::CHUNK`).

use crate::cubemap;
use crate::math;
use spirv_std::glam::{Vec2, Vec3, Vec4};

/// Which way the image centre faces in the cube: the equirect's orientation, a turn of
/// the whole environment about `+Y` (up stays up, handedness is kept). Each engine's own
/// baker fixes one (measured and cited in the README):
///
/// - `NegZ`, splitsum's ([`dir_to_uv`]): the centre looks down `−Z`;
/// - `PosX`, the Khronos glTF-IBL-Sampler's (`filter.frag`, `dirToUV`
///   `u = ½ + atan2(z, x)/2π` with its `direction.y = −direction.y`): the centre looks
///   down `+X`; splitsum's `(x, y, z)` is its `(−z, y, x)`;
/// - `PosZ`, Filament cmgen's (`CubemapUtils::equirectangularToCubemap`,
///   `u = ½ + atan2(x, z)/2π`, then `mirrorCubemap`, `x → −x`, which cmgen applies by
///   default): the centre looks down `+Z`; splitsum's `(x, y, z)` is its `(−x, y, −z)`.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
#[repr(u32)]
pub enum Facing {
    /// Centre at `−Z` (splitsum).
    NegZ = 0,
    /// Centre at `+X` (glTF-IBL-Sampler, so the glTF Sample Viewer and Bevy).
    PosX = 1,
    /// Centre at `+Z` (Filament's cmgen).
    PosZ = 2,
    /// Centre at `−X`.
    NegX = 3,
}

impl Facing {
    /// The direction, in splitsum's image convention ([`dir_to_uv`]), that a cube with
    /// this facing shows at cube direction `d`: the inverse turn about `+Y`.
    #[inline]
    pub fn image_direction(self, d: Vec3) -> Vec3 {
        match self {
            Self::NegZ => d,
            // Cube (x, y, z) = (−z', y', x') of the image direction (x', y', z').
            Self::PosX => Vec3::new(d.z, d.y, -d.x),
            Self::PosZ => Vec3::new(-d.x, d.y, -d.z),
            Self::NegX => Vec3::new(-d.z, d.y, d.x),
        }
    }

    /// The cube direction at which a cube with this facing shows image direction `d`
    /// (the inverse of [`Facing::image_direction`]).
    #[inline]
    pub fn cube_direction(self, d: Vec3) -> Vec3 {
        match self {
            Self::NegZ => d,
            Self::PosX => Vec3::new(-d.z, d.y, d.x),
            Self::PosZ => Vec3::new(-d.x, d.y, -d.z),
            Self::NegX => Vec3::new(d.z, d.y, -d.x),
        }
    }
}

/// Equirect coordinates `(u, v)` ∈ [0, 1]² of direction `d` (need not be unit).
#[inline]
pub fn dir_to_uv(d: Vec3) -> Vec2 {
    Vec2::new(dir_to_u(d), polar_to_v(axis_distance(d), d.y))
}

/// The equirect's `u` of direction `d`: its longitude, from its `x` and `z` alone.
#[inline]
pub fn dir_to_u(d: Vec3) -> f32 {
    0.5 + math::atan2(d.x, -d.z) * (0.5 * math::FRAC_1_PI)
}

/// `√(x² + z²)` of `d`: its distance from the `y` axis.
#[inline]
pub fn axis_distance(d: Vec3) -> f32 {
    math::sqrt(d.x * d.x + d.z * d.z)
}

/// The equirect's `v` of a direction at distance `rho` from the `y` axis and height `y`:
/// its polar angle from `+Y`, over π.
#[inline]
pub fn polar_to_v(rho: f32, y: f32) -> f32 {
    math::atan2(rho, y) * math::FRAC_1_PI
}

/// The unit direction at equirect coordinates `(u, v)`.
#[inline]
pub fn uv_to_dir(uv: Vec2) -> Vec3 {
    let (sin_phi, cos_phi) = math::sin_cos_turns(uv.x - 0.5);
    let (sin_theta, cos_theta) = math::sin_cos_turns(0.5 * uv.y);
    Vec3::new(sin_theta * sin_phi, cos_theta, -sin_theta * cos_phi)
}

/// Levels of the row pyramid of a `width`-wide image: each halves the one above while the
/// width is even (1024 → 11 levels, down to 1).
pub fn pyramid_levels(width: u32) -> u32 {
    // The number of trailing zero bits, plus the image itself.
    let tz = width.trailing_zeros();
    let tz = if tz > 15 { 15 } else { tz };
    tz + 1
}

/// Index of the first texel of pyramid level `level` (all levels `height` rows high):
/// `height·Σ_{k<L} width/2ᵏ = height·(2·width − 2·(width ≫ L))`.
#[inline]
pub fn pyramid_offset(level: u32, width: u32, height: u32) -> u32 {
    height * (2 * width - 2 * (width >> level))
}

/// Number of texels in all levels of the pyramid.
#[inline]
pub fn pyramid_len(width: u32, height: u32) -> u32 {
    let last = pyramid_levels(width) - 1;
    pyramid_offset(last, width, height) + height * (width >> last)
}

/// Texel `(x, y)` of pyramid level `level ≥ 1`: the mean of the two texels below it.
#[inline]
pub fn pyramid_texel(pyramid: &[Vec4], width: u32, height: u32, level: u32, x: u32, y: u32) -> Vec4 {
    let w = width >> (level - 1);
    let base = pyramid_offset(level - 1, width, height) + y * w + 2 * x;
    pyramid[base as usize] * 0.5 + pyramid[(base + 1) as usize] * 0.5
}

/// The means of rows `y0` and `y1` of pyramid level `level` over `[a, a + len)` in that
/// level's texel units (wrapping in `u`), `1 ≤ len ≤ width`: each texel weighs in by its
/// overlap, the same weights for both rows, computed once.
#[allow(clippy::too_many_arguments)]
fn row_means(pyramid: &[Vec4], width: u32, height: u32, level: u32, y0: u32, y1: u32, a: f32, len: f32) -> (Vec4, Vec4) {
    let end = a + len;
    let k0 = math::floor(a) as i32;
    let k1 = math::floor(end) as i32;
    let w = (width >> level) as i32;
    let base = pyramid_offset(level, width, height);
    let (row0, row1) = (base + y0 * w as u32, base + y1 * w as u32);
    let mut acc0 = Vec4::ZERO;
    let mut acc1 = Vec4::ZERO;
    let mut k = k0;
    while k <= k1 {
        let lo = math::max(k as f32, a);
        let hi = math::min(k as f32 + 1.0, end);
        if hi > lo {
            // k mod w without a division (no vector integer division on a CPU driver):
            // a ∈ [−w/2, w) and len ≤ w put k in [−w, 2w).
            let mut x = k;
            if x < 0 {
                x += w;
            }
            if x >= w {
                x -= w;
            }
            // Weights normalised as they go: the mean never exceeds the largest texel.
            let weight = (hi - lo) / len;
            acc0 += pyramid[(row0 + x as u32) as usize] * weight;
            acc1 += pyramid[(row1 + x as u32) as usize] * weight;
        }
        k += 1;
    }
    (math::finite4(acc0), math::finite4(acc1))
}

/// Area lookup at `(u, v)` in the row pyramid of a `width`×`height` image: the mean over a
/// window `window` level-0 texels wide in `u` (at least one texel, at most the whole row;
/// wrapping), interpolated linearly between rows in `v` (clamped). A one-texel window is
/// exactly bilinear interpolation; wider windows integrate every texel they cover, which
/// is what keeps narrow features near the poles — where texels shrink in `u` — from being
/// missed. Windows wider than 16 texels are read from the pyramid level where they span
/// 8 to 16 texels.
pub fn sample_area(pyramid: &[Vec4], width: u32, height: u32, levels: u32, uv: Vec2, window: f32) -> Vec4 {
    let fy = math::clamp(uv.y * height as f32 - 0.5, 0.0, (height - 1) as f32);
    let y0f = math::floor(fy);
    let ty = fy - y0f;
    let y0 = y0f as u32;
    let y1 = if y0 + 1 < height { y0 + 1 } else { y0 };
    let win = math::clamp(window, 1.0, width as f32);
    let level = if win > 16.0 { math::min(math::floor(math::log2(win * 0.0625)) + 1.0, (levels - 1) as f32) as u32 } else { 0 };
    let scale = 1.0 / (1u32 << level) as f32;
    let w = (width >> level) as f32;
    let len = math::clamp(win * scale, 1.0, w);
    let a = uv.x * w - 0.5 * len;
    let (r0, r1) = row_means(pyramid, width, height, level, y0, y1, a, len);
    math::finite4(r0 * (1.0 - ty) + r1 * ty)
}

/// Points per axis, per cube texel, so that the supersampling grid is `density` times as
/// fine as the equirect's texels at the equator (where they are largest), clamped to
/// [1, 16] (a cube smaller than its source by more than that is better made from the
/// source's mip chain). A cube texel at the face centre spans `2/size` radians; an
/// equirect texel spans `2π/width`.
pub fn supersampling(face_size: u32, width: u32, density: f32) -> u32 {
    let cube_texel = 2.0 / face_size as f32;
    let src_texel = math::TAU / width as f32;
    let n = math::floor(density * cube_texel / src_texel + 0.999);
    math::clamp(n, 1.0, 16.0) as u32
}

/// Solid angle of row `y` of a `height`-row equirect image per unit of longitude (radians):
/// `cos θ₀ − cos θ₁` over the row's polar span `[πy/h, π(y+1)/h]`, written as
/// `2·sin(π(y+½)/h)·sin(π/(2h))` so that rows at the poles keep their precision (the
/// difference of cosines cancels there).
#[inline]
pub fn row_solid_angle(y: u32, height: u32) -> f32 {
    let h = height as f32;
    let (s_mid, _) = math::sin_cos_turns(0.5 * (y as f32 + 0.5) / h);
    let (s_half, _) = math::sin_cos_turns(0.25 / h);
    2.0 * s_mid * s_half
}

/// The factor (a power of two) by which a `width`×`height` equirect can be reduced, by
/// area-weighted box filtering, and still resolve a cube of faces `face_size` wide: halve
/// while both sides stay even and the reduced texel, `2π/width` radians, stays no wider
/// than a cube texel at its face centre, `2/face_size` (i.e. `width ≥ π·face_size`), times
/// two for margin: `width/2 ≥ 2π·face_size`. The resampling then still places at least
/// `2·density` supersampling points per cube texel and axis ([`supersampling`]); what a
/// finer source would add is below the cube's own resolution.
pub fn reduction_factor(width: u32, height: u32, face_size: u32) -> u32 {
    let need = math::TAU * face_size as f32;
    let mut f = 1;
    while (width / f).is_multiple_of(2) && (height / f).is_multiple_of(2) && (width / f / 2) as f32 >= need {
        f *= 2;
    }
    f
}

/// Cube texel `(x, y)` of `face` (face size `size`) resampled from the equirect image's row
/// pyramid (`levels` levels) with an `n×n` grid of solid-angle-weighted samples, each the
/// mean over its own footprint in `u` ([`sample_area`]): the grid spacing, `2/(size·n)` on
/// the face plane, is about `2/(size·n·|p|)` radians at point `p`, which near a pole spans
/// `1/sin θ` times more longitude. The cube faces `facing` (a turn about `+Y`, which
/// leaves that longitude span as it is).
#[allow(clippy::too_many_arguments)]
pub fn cube_texel(pyramid: &[Vec4], width: u32, height: u32, levels: u32, facing: Facing, face: u32, x: u32, y: u32, size: u32, n: u32) -> Vec4 {
    let s = size as f32;
    let nf = n as f32;
    let spacing = 2.0 / (s * nf);
    let texels_per_radian = width as f32 * (0.5 * math::FRAC_1_PI);
    // What a point's `x` and `z` alone give: its equirect `u`, its distance from the axis and
    // its window. On a side face (0, 1, 4, 5) those depend on the point's column alone, so
    // natively they are computed for the first row of points and read back for the others
    // (the same values, a third of the point's arithmetic).
    let column = |p: Vec3| {
        let d = facing.image_direction(p);
        // Longitude spanned by one grid step: (spacing/r) / sin θ, sin θ = √(x²+z²)/r
        // (a turn about +Y keeps √(x²+z²), bit for bit: squares and a sum in either order).
        let rho = axis_distance(p);
        let window = if rho > 0.0 { spacing / rho * texels_per_radian } else { width as f32 };
        Vec3::new(dir_to_u(d), axis_distance(d), window)
    };
    #[cfg(not(target_arch = "spirv"))]
    let mut columns = [Vec3::ZERO; 16];
    #[cfg(not(target_arch = "spirv"))]
    let side = face != 2 && face != 3 && n as usize <= columns.len();
    let mut acc = Vec4::ZERO;
    let mut wsum = 0.0;
    let mut j = 0;
    while j < n {
        let mut i = 0;
        while i < n {
            let uv = Vec2::new((x as f32 + (i as f32 + 0.5) / nf) / s, (y as f32 + (j as f32 + 0.5) / nf) / s);
            let p = cubemap::face_uv_to_cube(face, uv);
            let r2 = p.dot(p);
            let r = math::sqrt(r2);
            // (1 + a² + b²)^(−3/2) ≤ 1, divided by n² so the weights sum to at most 1 and
            // the weighted sum cannot overflow.
            let w = 1.0 / (r2 * r) / (nf * nf);
            #[cfg(not(target_arch = "spirv"))]
            let c = if side && j > 0 {
                columns[i as usize]
            } else {
                let c = column(p);
                if side {
                    columns[i as usize] = c;
                }
                c
            };
            #[cfg(target_arch = "spirv")]
            let c = column(p);
            let uv = Vec2::new(c.x, polar_to_v(c.y, p.y));
            acc += sample_area(pyramid, width, height, levels, uv, c.z) * w;
            wsum += w;
            i += 1;
        }
        j += 1;
    }
    math::finite4(acc * (1.0 / wsum))
}
