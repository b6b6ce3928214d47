//! Vertex and fragment entry points of the viewer and the offscreen renderer: thin wrappers
//! around [`crate::scene`], which the CPU reference renderer calls per pixel too.
//!
//! Bindings (set 1, so they never meet the compute kernels' set 0): 0 the [`Frame`]
//! uniform, 1 the specular cube, 2 the irradiance cube, 3 the BRDF table, 4 the source
//! cube, 5 the sheen cube, 6 the sheen tables (read-only storage buffers, filtered in
//! software by `cubemap` and `lut`). Meshes add set 2: their [`MeshMaterial`], seven
//! textures and a sampler.

use crate::sampling;
use crate::scene::{self, Frame};
use crate::surface::{self, MeshMaterial, Texels};
use spirv_std::glam::{Vec2, Vec3, Vec4};
use spirv_std::{Image, Sampler, spirv};

/// A triangle covering the screen: vertices (−1,−1), (3,−1), (−1,3).
#[spirv(vertex)]
pub fn fullscreen_vs(#[spirv(vertex_index)] index: i32, #[spirv(position)] position: &mut Vec4) {
    let x = ((index << 1) & 2) as f32;
    let y = (index & 2) as f32;
    *position = Vec4::new(2.0 * x - 1.0, 2.0 * y - 1.0, 0.0, 1.0);
}

/// One pixel of the sphere grid and sky, with the depth of what it shows (so that meshes
/// drawn after it are hidden by nearer spheres).
#[spirv(fragment(depth_replacing))]
pub fn scene_fs(
    #[spirv(frag_coord)] coord: Vec4,
    #[spirv(uniform, descriptor_set = 1, binding = 0)] frame: &Frame,
    #[spirv(storage_buffer, descriptor_set = 1, binding = 1)] specular: &[Vec4],
    #[spirv(storage_buffer, descriptor_set = 1, binding = 2)] irradiance: &[Vec4],
    #[spirv(storage_buffer, descriptor_set = 1, binding = 3)] table: &[Vec2],
    #[spirv(storage_buffer, descriptor_set = 1, binding = 4)] source: &[Vec4],
    #[spirv(storage_buffer, descriptor_set = 1, binding = 5)] sheen: &[Vec4],
    #[spirv(storage_buffer, descriptor_set = 1, binding = 6)] sheen_tables: &[Vec2],
    output: &mut Vec4,
    #[spirv(frag_depth)] depth: &mut f32,
) {
    let (c, d) = scene::radiance_depth(frame, source, specular, irradiance, table, sheen, sheen_tables, Vec2::new(coord.x, coord.y));
    *output = scene::to_display(frame, c);
    *depth = d;
}

/// A mesh vertex, already in world space: position, normal, tangent and texture
/// coordinates to the fragment shader.
#[spirv(vertex)]
pub fn mesh_vs(
    position: Vec3,
    normal: Vec3,
    tangent: Vec4,
    uv: Vec2,
    #[spirv(uniform, descriptor_set = 1, binding = 0)] frame: &Frame,
    #[spirv(position)] clip_position: &mut Vec4,
    out_position: &mut Vec3,
    out_normal: &mut Vec3,
    out_tangent: &mut Vec4,
    out_uv: &mut Vec2,
) {
    *clip_position = surface::clip(&frame.view_proj, position);
    *out_position = position;
    *out_normal = normal;
    *out_tangent = tangent;
    *out_uv = uv;
}

/// One pixel of a glTF mesh: its five textures read by the hardware sampler, then the same
/// shading as the spheres.
#[spirv(fragment)]
pub fn mesh_fs(
    position: Vec3,
    normal: Vec3,
    tangent: Vec4,
    uv: Vec2,
    #[spirv(uniform, descriptor_set = 1, binding = 0)] frame: &Frame,
    #[spirv(storage_buffer, descriptor_set = 1, binding = 1)] specular: &[Vec4],
    #[spirv(storage_buffer, descriptor_set = 1, binding = 2)] irradiance: &[Vec4],
    #[spirv(storage_buffer, descriptor_set = 1, binding = 3)] table: &[Vec2],
    #[spirv(storage_buffer, descriptor_set = 1, binding = 5)] sheen: &[Vec4],
    #[spirv(storage_buffer, descriptor_set = 1, binding = 6)] sheen_tables: &[Vec2],
    #[spirv(uniform, descriptor_set = 2, binding = 0)] material: &MeshMaterial,
    #[spirv(descriptor_set = 2, binding = 1)] base_color: &Image!(2D, type = f32, sampled),
    #[spirv(descriptor_set = 2, binding = 2)] metallic_roughness: &Image!(2D, type = f32, sampled),
    #[spirv(descriptor_set = 2, binding = 3)] normal_map: &Image!(2D, type = f32, sampled),
    #[spirv(descriptor_set = 2, binding = 4)] occlusion: &Image!(2D, type = f32, sampled),
    #[spirv(descriptor_set = 2, binding = 5)] emissive: &Image!(2D, type = f32, sampled),
    #[spirv(descriptor_set = 2, binding = 6)] sheen_color: &Image!(2D, type = f32, sampled),
    #[spirv(descriptor_set = 2, binding = 7)] sheen_roughness: &Image!(2D, type = f32, sampled),
    #[spirv(descriptor_set = 2, binding = 8)] sampler: &Sampler,
    output: &mut Vec4,
) {
    let texels = Texels {
        base_color: base_color.sample(*sampler, uv),
        metallic_roughness: metallic_roughness.sample(*sampler, uv),
        normal: normal_map.sample(*sampler, uv),
        occlusion: occlusion.sample(*sampler, uv),
        emissive: emissive.sample(*sampler, uv),
        sheen_color: sheen_color.sample(*sampler, uv),
        sheen_roughness: sheen_roughness.sample(*sampler, uv),
    };
    let (m, n) = surface::material(material, &texels, normal, tangent);
    let v = sampling::normalize_or(frame.eye.truncate() - position, n);
    let c = scene::shade_point(frame, material.options, specular, irradiance, table, sheen, sheen_tables, &m, position, n, v);
    *output = scene::to_display(frame, c);
}
