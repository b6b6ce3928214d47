//! Vertex and fragment entry points of the viewer and the offscreen renderer: thin wrappers
//! around [`crate::scene`], which the CPU reference renderer calls per pixel too.
//!
//! Bindings (set 1, so they never meet the compute kernels' set 0): 0 the [`Frame`]
//! uniform, 1 the specular cube, 2 the irradiance cube, 3 the BRDF table, 4 the source
//! cube (read-only storage buffers, filtered in software by `cubemap` and `lut`).

use crate::scene::{self, Frame};
use spirv_std::glam::{Vec2, Vec4};
use spirv_std::spirv;

/// A triangle covering the screen: vertices (−1,−1), (3,−1), (−1,3).
#[spirv(vertex)]
pub fn fullscreen_vs(#[spirv(vertex_index)] index: i32, #[spirv(position)] position: &mut Vec4) {
    let x = ((index << 1) & 2) as f32;
    let y = (index & 2) as f32;
    *position = Vec4::new(2.0 * x - 1.0, 2.0 * y - 1.0, 0.0, 1.0);
}

/// One pixel of the sphere grid and sky.
#[spirv(fragment)]
pub fn scene_fs(
    #[spirv(frag_coord)] coord: Vec4,
    #[spirv(uniform, descriptor_set = 1, binding = 0)] frame: &Frame,
    #[spirv(storage_buffer, descriptor_set = 1, binding = 1)] specular: &[Vec4],
    #[spirv(storage_buffer, descriptor_set = 1, binding = 2)] irradiance: &[Vec4],
    #[spirv(storage_buffer, descriptor_set = 1, binding = 3)] table: &[Vec2],
    #[spirv(storage_buffer, descriptor_set = 1, binding = 4)] source: &[Vec4],
    output: &mut Vec4,
) {
    *output = scene::pixel(frame, source, specular, irradiance, table, Vec2::new(coord.x, coord.y));
}
