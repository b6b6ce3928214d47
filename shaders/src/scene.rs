//! The viewer's scene, evaluated per pixel the same way by the fragment shader and by the
//! CPU reference renderer: a pinhole camera, an analytic grid of spheres (rows of rising
//! metalness, columns of rising roughness) ray-cast exactly, direct lights, and the sky
//! drawn from the specular cube at a chosen blur.
//!
//! Ray–sphere intersection with the half-`b` form `t = −b − √(b² − c)`,
//! `b = (o−c)·d`, `c = |o−c|² − R²` (Pharr, Jakob & Humphreys, *PBRT* 4e §6.2.2).

use crate::cubemap::{self, CubeLayout};
use crate::prefilter::RoughnessMapping;
use crate::shade::{self, EnvironmentShape, Material, ShadeOptions};
use crate::{math, sampling, tonemap};
use bytemuck::{Pod, Zeroable};
use spirv_std::glam::{Mat4, Vec2, Vec3, Vec4};

/// Most direct lights in a frame.
pub const MAX_LIGHTS: usize = 4;

/// A direct light.
#[derive(Copy, Clone, Debug, PartialEq, Pod, Zeroable)]
#[repr(C)]
pub struct Light {
    /// `w = 0`: unit direction towards a distant light; `w = 1`: position of a point light.
    pub position: Vec4,
    /// RGB radiance arriving from a distant light, or a point light's intensity (the
    /// radiance it delivers at distance 1; it falls off as 1/d²).
    pub radiance: Vec4,
}

/// Everything a frame needs besides the baked buffers: a uniform block whose layout is the
/// same in Rust and in std140 without padding fields. Vectors are `Vec4` (std140 aligns a
/// three-vector to 16 bytes, glam's host `Vec3` to 4), their `w` unused; scalars come in
/// named groups of four.
#[derive(Copy, Clone, Debug, PartialEq, Pod, Zeroable)]
#[repr(C)]
pub struct Frame {
    /// Camera position (`xyz`).
    pub eye: Vec4,
    /// Unit view direction (`xyz`).
    pub forward: Vec4,
    /// Unit right vector (`xyz`).
    pub right: Vec4,
    /// Unit up vector (`xyz`).
    pub up: Vec4,
    /// Width of the target in pixels.
    pub width: f32,
    /// Height of the target in pixels.
    pub height: f32,
    /// Exposure (a factor on radiance).
    pub exposure: f32,
    /// Blur of the sky: a specular mip, fractional.
    pub sky_blur: f32,
    /// Rows of the sphere grid: metalness, then one sheen row where `sheen_color` is not
    /// black ([`grid_material`]).
    pub rows: u32,
    /// Columns of the sphere grid (roughness).
    pub columns: u32,
    /// The tone curve (a `Tonemapper` code).
    pub tonemapper: u32,
    /// Direct lights used, the first of `lights`.
    pub light_count: u32,
    /// Bit 0: encode sRGB in the shader; bit 1: draw the sphere grid; bit 2: output linear
    /// radiance (no exposure, tone curve or encoding; for tests).
    pub flags: u32,
    /// Near plane of the projection.
    pub near: f32,
    /// Far plane of the projection.
    pub far: f32,
    /// `tan` of half the vertical field of view.
    pub tan_half_fov: f32,
    /// Shading models and lights.
    pub options: ShadeOptions,
    /// Shapes of the baked buffers.
    pub shape: EnvironmentShape,
    /// Base colour of the spheres (linear RGB).
    pub base_color: Vec4,
    /// Direct lights; the first `light_count` are used.
    pub lights: [Light; MAX_LIGHTS],
    /// World to clip space of the camera (for rasterised meshes and the depth of ray hits).
    pub view_proj: Mat4,
    /// The grid's metalness from the top row to the bottom (`x`, `y`) and roughness from
    /// the left column to the right (`z`, `w`).
    pub grid_ranges: Vec4,
    /// Sheen colour of the grid's sheen row (`xyz`, linear; black: no sheen row).
    pub sheen_color: Vec4,
    /// The grid's sheen roughness from the left column to the right (`x`, `y`; `z`, `w`
    /// unused).
    pub sheen_ranges: Vec4,
}

crate::flags!(Frame {
    /// Encode sRGB in the shader (the target is a UNORM format).
    ENCODE_SRGB = 0,
    /// Draw the sphere grid.
    SPHERES = 1,
    /// Output linear radiance.
    LINEAR = 2,
});

/// Spacing of the sphere grid's centres.
pub const GRID_SPACING: f32 = 1.0;
/// Radius of the grid's spheres.
pub const SPHERE_RADIUS: f32 = 0.42;

/// The unit ray through pixel position `px` (pixel centres at half-integers, y down).
#[inline]
pub fn camera_ray(frame: &Frame, px: Vec2) -> Vec3 {
    let tan = frame.tan_half_fov;
    let aspect = frame.width / frame.height;
    let x = (2.0 * px.x / frame.width - 1.0) * tan * aspect;
    let y = (1.0 - 2.0 * px.y / frame.height) * tan;
    let d = frame.forward.truncate() + frame.right.truncate() * x + frame.up.truncate() * y;
    sampling::normalize_or(d, frame.forward.truncate())
}

/// Centre of the sphere in `row`, `col` of a `rows`×`cols` grid centred on the origin in the
/// plane `z = 0` (row 0 at the top).
#[inline]
pub fn sphere_centre(row: u32, col: u32, rows: u32, cols: u32) -> Vec3 {
    Vec3::new((col as f32 - 0.5 * (cols as f32 - 1.0)) * GRID_SPACING, (0.5 * (rows as f32 - 1.0) - row as f32) * GRID_SPACING, 0.0)
}

/// The nearest sphere hit along the ray: `(t, row, col)`, `t < 0` if none.
pub fn hit_grid(frame: &Frame, origin: Vec3, dir: Vec3) -> (f32, u32, u32) {
    let rows = frame.rows;
    let cols = frame.columns;
    let mut best = -1.0f32;
    let mut best_row = 0;
    let mut best_col = 0;
    let mut row = 0;
    while row < rows {
        let mut col = 0;
        while col < cols {
            // Haines et al., "Precision Improvements for Ray/Sphere Intersection" (Ray
            // Tracing Gems, 2019, ch. 7): the discriminant as `R² − |f − (f·d)d|²`, the
            // squared distance of the centre from the ray, instead of `b² − c`, whose two
            // terms (≈ |f|², the camera's distance squared) cancel. Without it, whether a
            // GPU fuses `b·b − c` into an FMA moved edge pixels by 1e-3 on an H100.
            let oc = origin - sphere_centre(row, col, rows, cols);
            let b = oc.dot(dir);
            let perp = oc - dir * b;
            let disc = SPHERE_RADIUS * SPHERE_RADIUS - perp.dot(perp);
            if disc >= 0.0 {
                let t = -b - math::sqrt(disc);
                if t > 0.0 && (best < 0.0 || t < best) {
                    best = t;
                    best_row = row;
                    best_col = col;
                }
            }
            col += 1;
        }
        row += 1;
    }
    (best, best_row, best_col)
}

/// The material of the sphere in `row`, `col`: metalness rises down the rows, roughness
/// along the columns, over the frame's `grid_ranges`. Where the frame has a sheen colour,
/// the last row is the sheen row: the top row's metalness, the same roughness per column,
/// and the sheen layer, its roughness rising along the columns over `sheen_ranges`; the
/// rows above it carry no sheen.
#[inline]
pub fn grid_material(frame: &Frame, row: u32, col: u32) -> Material {
    let r = frame.grid_ranges;
    let s = frame.sheen_ranges;
    let has_sheen_row = frame.sheen_color.x > 0.0 || frame.sheen_color.y > 0.0 || frame.sheen_color.z > 0.0;
    let sheen_row = has_sheen_row && row + 1 == frame.rows;
    let metal_rows = if has_sheen_row && frame.rows > 1 { frame.rows - 1 } else { frame.rows };
    Material {
        base_color: frame.base_color.truncate(),
        // Clamped so that rounding never steps outside the declared range (a plan bakes
        // only the mips that range reads).
        metallic: if sheen_row { r.x } else { math::clamp(r.x + (r.y - r.x) * step(row, metal_rows), r.x, r.y) },
        roughness: math::clamp(r.z + (r.w - r.z) * step(col, frame.columns), r.z, r.w),
        occlusion: 1.0,
        emissive: Vec3::ZERO,
        sheen_color: if sheen_row { frame.sheen_color.truncate() } else { Vec3::ZERO },
        sheen_roughness: math::clamp(s.x + (s.y - s.x) * step(col, frame.columns), s.x, s.y),
    }
}

/// `i/(n−1)`, or 0 for a single step.
#[inline]
fn step(i: u32, n: u32) -> f32 {
    if n > 1 { i as f32 / (n - 1) as f32 } else { 0.0 }
}

/// The baked buffers a frame reads: the specular, irradiance, sheen and source cubes and
/// the BRDF and sheen tables (storage buffers on the GPU; each a plain slice argument,
/// since a struct holding storage-buffer slices does not validate in a shader).
///
/// Radiance leaving point `p` (normal `n`) towards the eye along `v` under the models and
/// lights of `opts`: emission, the image-based light and every direct light of the frame,
/// each with the material's sheen layer on top (`shade::sheen_ibl`, `shade::sheen_direct`).
#[allow(clippy::too_many_arguments)]
pub fn shade_point(
    frame: &Frame,
    opts: ShadeOptions,
    specular: &[Vec4],
    irradiance: &[Vec4],
    table: &[Vec2],
    sheen: &[Vec4],
    sheen_tables: &[Vec2],
    m: &Material,
    p: Vec3,
    n: Vec3,
    v: Vec3,
) -> Vec3 {
    let mut color = m.emissive;
    if opts.flags & ShadeOptions::IBL != 0 {
        let s = shade::ibl_sample(frame.shape, specular, irradiance, table, opts, m, n, v);
        let (layer, keep) = shade::sheen_ibl(frame.shape, sheen, sheen_tables, m, n, v);
        color += shade::ibl(opts, m, n, v, s) * keep + layer * m.occlusion;
    }
    if opts.flags & ShadeOptions::DIRECT != 0 {
        let count = if (frame.light_count as usize) < MAX_LIGHTS { frame.light_count as usize } else { MAX_LIGHTS };
        let mut i = 0;
        while i < count {
            let light = frame.lights[i];
            let (l, radiance) = if light.position.w == 0.0 {
                (sampling::normalize_or(light.position.truncate(), n), light.radiance.truncate())
            } else {
                let to = light.position.truncate() - p;
                let d2 = math::max(to.dot(to), 1e-8);
                (to * (1.0 / math::sqrt(d2)), light.radiance.truncate() * (1.0 / d2))
            };
            let (layer, keep) = shade::sheen_direct(frame.shape, sheen_tables, m, n, v, l, radiance);
            color += shade::direct(opts, m, n, v, l, radiance) * keep + layer;
            i += 1;
        }
    }
    color
}

/// Linear radiance seen through pixel position `px` (a sphere of the grid, or the sky) and
/// its depth in [0, 1] (1 for the sky).
#[allow(clippy::too_many_arguments)]
pub fn radiance_depth(frame: &Frame, source: &[Vec4], specular: &[Vec4], irradiance: &[Vec4], table: &[Vec2], sheen: &[Vec4], sheen_tables: &[Vec2], px: Vec2) -> (Vec3, f32) {
    let origin = frame.eye.truncate();
    let dir = camera_ray(frame, px);
    if frame.flags & Frame::SPHERES != 0 {
        let (t, row, col) = hit_grid(frame, origin, dir);
        if t > 0.0 {
            let p = origin + dir * t;
            let n = sampling::normalize_or(p - sphere_centre(row, col, frame.rows, frame.columns), -dir);
            let m = grid_material(frame, row, col);
            let d = (p - origin).dot(frame.forward.truncate());
            let depth = crate::surface::depth(d, frame.near, frame.far);
            return (shade_point(frame, frame.options, specular, irradiance, table, sheen, sheen_tables, &m, p, n, -dir), depth);
        }
    }
    (sky(frame, source, specular, dir), 1.0)
}

/// Linear radiance seen through pixel position `px`.
#[allow(clippy::too_many_arguments)]
pub fn radiance(frame: &Frame, source: &[Vec4], specular: &[Vec4], irradiance: &[Vec4], table: &[Vec2], sheen: &[Vec4], sheen_tables: &[Vec2], px: Vec2) -> Vec3 {
    radiance_depth(frame, source, specular, irradiance, table, sheen, sheen_tables, px).0
}

/// The sky along `dir`: the source cube when the blur is 0, else the specular cube at the
/// blur level (a fractional mip, i.e. a roughness).
#[inline]
pub fn sky(frame: &Frame, source: &[Vec4], specular: &[Vec4], dir: Vec3) -> Vec3 {
    let blur = frame.sky_blur;
    if blur > 0.0 {
        let shape = frame.shape;
        let layout = CubeLayout::new(shape.specular_size, shape.specular_levels);
        let c = cubemap::sample_lod(specular, layout, dir, blur).truncate();
        if shape.excess_entries == 0 {
            return c;
        }
        // A cube baked from a split source: its excess at the roughness between the two
        // mips the blur reads.
        let top = (shape.specular_levels - 1) as f32;
        let at = math::clamp(blur, 0.0, top);
        let m0 = math::floor(at);
        let mapping = RoughnessMapping::from_u32(shape.mapping);
        let (r0, r1) = (mapping.roughness(m0 as u32, shape.specular_levels), mapping.roughness(math::min(m0 + 1.0, top) as u32, shape.specular_levels));
        let r = r0 + (r1 - r0) * (at - m0);
        c + crate::excess::prefiltered_excess(specular, layout.texel_count(), shape.excess_entries, dir, r, Vec3::ZERO).truncate()
    } else {
        cubemap::sample_bilinear(source, CubeLayout::new(frame.shape.source_size, 1), 0, dir).truncate()
    }
}

/// Display value of linear radiance `c` for this frame: exposure, tone curve, and the
/// sRGB encoding when the target does not encode itself.
#[inline]
pub fn to_display(frame: &Frame, c: Vec3) -> Vec4 {
    if frame.flags & Frame::LINEAR != 0 {
        return c.extend(1.0);
    }
    let curve = tonemap::Tonemapper::from_u32(frame.tonemapper);
    if frame.flags & Frame::ENCODE_SRGB != 0 {
        tonemap::display(c, frame.exposure, curve).extend(1.0)
    } else {
        tonemap::tone(c, frame.exposure, curve).extend(1.0)
    }
}

/// The value of pixel position `px`.
#[allow(clippy::too_many_arguments)]
pub fn pixel(frame: &Frame, source: &[Vec4], specular: &[Vec4], irradiance: &[Vec4], table: &[Vec2], sheen: &[Vec4], sheen_tables: &[Vec2], px: Vec2) -> Vec4 {
    to_display(frame, radiance(frame, source, specular, irradiance, table, sheen, sheen_tables, px))
}
