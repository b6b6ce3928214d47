//! Compute-kernel entry points: thin wrappers that turn an invocation id into a texel and
//! call the function the CPU path and the tests call natively.
//!
//! Binding scheme, the same for every kernel: set 0, binding 0 the parameters (uniform),
//! binding 1 the input texels (read-only storage), binding 2 the output (storage).
//! Texel kernels run 8×8 invocations per workgroup with `z` the cube face.

use crate::cubemap::{self, CubeLayout};
use crate::{equirect, irradiance, lut, prefilter};
use bytemuck::{Pod, Zeroable};
use spirv_std::glam::{UVec3, Vec2, Vec4};
use spirv_std::spirv;

/// Workgroup width and height of the texel kernels.
pub const TILE: u32 = 8;

/// Parameters of [`brdf_lut`].
#[derive(Copy, Clone, Debug, Pod, Zeroable)]
#[repr(C)]
pub struct LutParams {
    /// Table width and height.
    pub size: u32,
    /// Hammersley points per texel.
    pub samples: u32,
    /// First row of this dispatch.
    pub row_offset: u32,
    /// Unused; keeps the block 16 bytes.
    pub pad: u32,
}

/// One texel of the split-sum BRDF table: `out[y·size + x] = (scale, bias)`.
#[spirv(compute(threads(8, 8)))]
pub fn brdf_lut(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(uniform, descriptor_set = 0, binding = 0)] p: &LutParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] out: &mut [Vec2],
) {
    let y = id.y + p.row_offset;
    if id.x < p.size && y < p.size {
        out[(y * p.size + id.x) as usize] = lut::texel(id.x, y, p.size, p.samples);
    }
}

/// Parameters of [`equirect_to_cube`].
#[derive(Copy, Clone, Debug, Pod, Zeroable)]
#[repr(C)]
pub struct EquirectParams {
    /// Source width.
    pub width: u32,
    /// Source height.
    pub height: u32,
    /// Cube face size.
    pub face_size: u32,
    /// Supersampling points per axis per cube texel.
    pub supersample: u32,
}

/// One texel of level 0 of the source cube, resampled from the equirect image.
#[spirv(compute(threads(8, 8)))]
pub fn equirect_to_cube(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(uniform, descriptor_set = 0, binding = 0)] p: &EquirectParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] src: &[Vec4],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] out: &mut [Vec4],
) {
    let s = p.face_size;
    if id.x < s && id.y < s && id.z < cubemap::FACES {
        let v = equirect::cube_texel(src, p.width, p.height, id.z, id.x, id.y, s, p.supersample);
        out[((id.z * s + id.y) * s + id.x) as usize] = v;
    }
}

/// Parameters of [`downsample`].
#[derive(Copy, Clone, Debug, Pod, Zeroable)]
#[repr(C)]
pub struct DownsampleParams {
    /// Level-0 face size of the cube.
    pub size: u32,
    /// Levels stored.
    pub levels: u32,
    /// The level read; `level + 1` is written.
    pub level: u32,
    /// Unused; keeps the block 16 bytes.
    pub pad: u32,
}

/// One texel of level `level + 1` of a cube, from level `level` of the same buffer.
#[spirv(compute(threads(8, 8)))]
pub fn downsample(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(uniform, descriptor_set = 0, binding = 0)] p: &DownsampleParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] cube: &mut [Vec4],
) {
    let layout = CubeLayout::new(p.size, p.levels);
    let s = layout.level_size(p.level + 1);
    if id.x < s && id.y < s && id.z < cubemap::FACES {
        let v = cubemap::downsample_texel(cube, layout, p.level, id.z, id.x, id.y);
        cube[layout.index(p.level + 1, id.z, id.x, id.y) as usize] = v;
    }
}

/// Parameters of [`prefilter_specular`].
#[derive(Copy, Clone, Debug, Pod, Zeroable)]
#[repr(C)]
pub struct PrefilterParams {
    /// Level-0 face size of the source cube.
    pub src_size: u32,
    /// Levels of the source cube.
    pub src_levels: u32,
    /// Face size of the level written.
    pub dst_size: u32,
    /// GGX samples per texel.
    pub samples: u32,
    /// Perceptual roughness of the level written.
    pub roughness: f32,
    /// Bias added to the source level of each sample.
    pub lod_bias: f32,
    /// Index in the output of the first texel of the level written.
    pub dst_offset: u32,
    /// Unused; keeps the block a multiple of 16 bytes.
    pub pad: u32,
}

/// One texel of one level of the prefiltered specular cube.
#[spirv(compute(threads(8, 8)))]
pub fn prefilter_specular(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(uniform, descriptor_set = 0, binding = 0)] p: &PrefilterParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] src: &[Vec4],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] out: &mut [Vec4],
) {
    let s = p.dst_size;
    if id.x < s && id.y < s && id.z < cubemap::FACES {
        let layout = CubeLayout::new(p.src_size, p.src_levels);
        let v = prefilter::prefilter_texel(src, layout, id.z, id.x, id.y, s, p.roughness, p.samples, p.lod_bias);
        out[(p.dst_offset + (id.z * s + id.y) * s + id.x) as usize] = v;
    }
}

/// Parameters of [`irradiance_cube`] and [`irradiance_sh9`].
#[derive(Copy, Clone, Debug, Pod, Zeroable)]
#[repr(C)]
pub struct IrradianceParams {
    /// Level-0 face size of the source cube.
    pub src_size: u32,
    /// Levels of the source cube.
    pub src_levels: u32,
    /// The source level summed over.
    pub src_level: u32,
    /// Face size of the irradiance cube written.
    pub dst_size: u32,
}

/// One texel of the irradiance cube (`E/π`).
#[spirv(compute(threads(8, 8)))]
pub fn irradiance_cube(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(uniform, descriptor_set = 0, binding = 0)] p: &IrradianceParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] src: &[Vec4],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] out: &mut [Vec4],
) {
    let s = p.dst_size;
    if id.x < s && id.y < s && id.z < cubemap::FACES {
        let layout = CubeLayout::new(p.src_size, p.src_levels);
        let n = cubemap::texel_dir(id.z, id.x, id.y, s);
        out[((id.z * s + id.y) * s + id.x) as usize] = irradiance::convolve_dir(src, layout, p.src_level, n);
    }
}

/// The SH9 partial sums of one row (`id.x`) of one face (`id.z`) of the source level:
/// ten `Vec4` per row (see [`irradiance::sh9_row`]).
#[spirv(compute(threads(64)))]
pub fn irradiance_sh9(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(uniform, descriptor_set = 0, binding = 0)] p: &IrradianceParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] src: &[Vec4],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] out: &mut [Vec4],
) {
    let layout = CubeLayout::new(p.src_size, p.src_levels);
    let s = layout.level_size(p.src_level);
    if id.x < s && id.z < cubemap::FACES {
        let row = irradiance::sh9_row(src, layout, p.src_level, id.z, id.x);
        let base = ((id.z * s + id.x) * (irradiance::SH9 as u32 + 1)) as usize;
        let mut k = 0;
        while k < irradiance::SH9 + 1 {
            out[base + k] = row[k];
            k += 1;
        }
    }
}
