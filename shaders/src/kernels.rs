//! Compute-kernel entry points: thin wrappers that turn an invocation id into a texel and
//! call the function the CPU path and the tests call natively.
//!
//! Binding scheme, the same for every kernel: set 0, binding 0 the parameters (uniform),
//! binding 1 the input texels (read-only storage), binding 2 the output (storage).
//! Texel kernels run 8×8 invocations per workgroup with `z` the cube face.
//!
//! Long sums (BRDF table, prefilter, irradiance) run one chunk of at most `math::CHUNK`
//! terms per dispatch, carrying compensated partial sums in the output buffer;
//! [`resolve_means`] and [`resolve_lut`] resolve them on the device with the same functions
//! the CPU backend uses.

use crate::brdf::microfacet::Masking;
use crate::cubemap::{self, CubeLayout};
use crate::math::MeanPartial;
use crate::prefilter::Lobe;
use crate::{calibrate, equirect, half, irradiance, lut, prefilter};
use bytemuck::{Pod, Zeroable};
use spirv_std::glam::{UVec3, Vec3, Vec4};
use spirv_std::spirv;

/// Parameters of [`brdf_lut`].
#[derive(Copy, Clone, Debug, Pod, Zeroable)]
#[repr(C)]
pub struct LutParams {
    /// Table width and height.
    pub size: u32,
    /// Hammersley points per texel, in all.
    pub samples: u32,
    /// First row of this dispatch.
    pub row_offset: u32,
    /// First sample of this dispatch's chunk.
    pub start: u32,
    /// Samples in this chunk (at most `math::CHUNK`).
    pub count: u32,
}

/// One chunk of one texel of the split-sum BRDF table: adds samples `start..start+count`
/// to the compensated partial sums `accum[y·size + x]` (`lut::accumulate`); [`resolve_lut`]
/// resolves them (`lut::resolve`) once every chunk has run.
#[spirv(compute(threads(8, 8)))]
pub fn brdf_lut(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(uniform, descriptor_set = 0, binding = 0)] p: &LutParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] accum: &mut [Vec4],
) {
    let y = id.y + p.row_offset;
    if id.x < p.size && y < p.size {
        let i = (y * p.size + id.x) as usize;
        let c = lut::texel_coords(id.x, y, p.size);
        accum[i] = lut::accumulate(c.x, c.y, p.samples, p.start, p.count, accum[i]);
    }
}

/// Parameters of [`brdf_table`].
#[derive(Copy, Clone, Debug, Pod, Zeroable)]
#[repr(C)]
pub struct TableParams {
    /// Table width and height.
    pub size: u32,
    /// `microfacet::Masking` code.
    pub masking: u32,
    /// First row of this dispatch.
    pub row_offset: u32,
}

/// One texel of the split-sum BRDF table by deterministic quadrature
/// (`lut::integrate_brdf_quadrature`): `(A, B)` in `out[y·size + x].xy`.
#[spirv(compute(threads(8, 8)))]
pub fn brdf_table(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(uniform, descriptor_set = 0, binding = 0)] p: &TableParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] out: &mut [Vec4],
) {
    let y = id.y + p.row_offset;
    if id.x < p.size && y < p.size {
        let t = lut::texel_quadrature(id.x, y, p.size, Masking::from_u32(p.masking));
        out[(y * p.size + id.x) as usize] = Vec4::new(t.x, t.y, 0.0, 0.0);
    }
}

/// Parameters of [`equirect_pyramid`] and [`equirect_to_cube`].
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
    /// Levels of the row pyramid.
    pub levels: u32,
    /// The pyramid level written (by [`equirect_pyramid`]).
    pub level: u32,
    /// Which way the image centre faces in the cube (`equirect::Facing` code).
    pub facing: u32,
}

/// One texel of level `level` of the equirect's row pyramid, from level `level − 1` of the
/// same buffer.
#[spirv(compute(threads(8, 8)))]
pub fn equirect_pyramid(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(uniform, descriptor_set = 0, binding = 0)] p: &EquirectParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] pyramid: &mut [Vec4],
) {
    let w = p.width >> p.level;
    if id.x < w && id.y < p.height {
        let v = equirect::pyramid_texel(pyramid, p.width, p.height, p.level, id.x, id.y);
        pyramid[(equirect::pyramid_offset(p.level, p.width, p.height) + id.y * w + id.x) as usize] = v;
    }
}

/// One texel of level 0 of the source cube, resampled from the equirect's row pyramid.
#[spirv(compute(threads(8, 8)))]
pub fn equirect_to_cube(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(uniform, descriptor_set = 0, binding = 0)] p: &EquirectParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] pyramid: &[Vec4],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] out: &mut [Vec4],
) {
    let s = p.face_size;
    if let Some(i) = face_texel(id, s, 0) {
        out[i] = equirect::cube_texel(pyramid, p.width, p.height, p.levels, equirect::Facing::from_u32(p.facing), id.z, id.x, id.y, s, p.supersample);
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
    /// GGX samples per texel, in all.
    pub samples: u32,
    /// Perceptual roughness of the level written.
    pub roughness: f32,
    /// Bias added to the source level of each sample.
    pub lod_bias: f32,
    /// Index in the output layout of the first texel of the level written.
    pub dst_offset: u32,
    /// First sample of this dispatch's chunk.
    pub start: u32,
    /// Samples in this chunk (at most `math::CHUNK`), or source texels for an exact sum.
    pub count: u32,
    /// The source level summed exactly (`prefilter::exact_accumulate`), or
    /// `prefilter::SAMPLED`.
    pub exact_level: u32,
    /// The distribution (`prefilter::Lobe`): GGX for the specular cube, Charlie for sheen.
    pub lobe: u32,
}

/// Reads the three `Vec4` of a [`MeanPartial`] at `accum[3i..]`.
#[inline]
fn load_partial(accum: &[Vec4], i: usize) -> MeanPartial {
    MeanPartial { sum: accum[3 * i], carry: accum[3 * i + 1], weight: accum[3 * i + 2] }
}

/// Writes a [`MeanPartial`] at `accum[3i..]`.
#[inline]
fn store_partial(accum: &mut [Vec4], i: usize, p: MeanPartial) {
    accum[3 * i] = p.sum;
    accum[3 * i + 1] = p.carry;
    accum[3 * i + 2] = p.weight;
}

/// One chunk of samples of one texel of one level of a prefiltered cube (specular: GGX;
/// sheen: Charlie, by `lobe`):
/// adds them to the texel's partial sums in `accum` (three `Vec4` per texel);
/// [`resolve_means`] resolves the means once every chunk has run
/// (`prefilter::accumulate`, `MeanPartial::resolve`). The exact sums are a kernel of their
/// own ([`prefilter_exact`]), not a branch here: a compiler that runs lanes under masks
/// (llvmpipe) would run both loops.
#[spirv(compute(threads(8, 8)))]
pub fn prefilter_specular(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(uniform, descriptor_set = 0, binding = 0)] p: &PrefilterParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] src: &[Vec4],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] accum: &mut [Vec4],
) {
    if let Some((layout, i, n)) = prefilter_invocation(id, p) {
        let partial = load_partial(accum, i);
        store_partial(accum, i, prefilter::accumulate(Lobe::from_u32(p.lobe), src, layout, n, p.roughness, p.samples, p.start, p.count, p.lod_bias, partial));
    }
}

/// One chunk of source texels of the exact sum (`prefilter::exact_accumulate` over level
/// `exact_level`) of one texel of one level of the prefiltered specular cube, as
/// [`prefilter_specular`] does for samples.
#[spirv(compute(threads(8, 8)))]
pub fn prefilter_exact(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(uniform, descriptor_set = 0, binding = 0)] p: &PrefilterParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] src: &[Vec4],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] accum: &mut [Vec4],
) {
    if let Some((layout, i, n)) = prefilter_invocation(id, p) {
        let partial = load_partial(accum, i);
        store_partial(accum, i, prefilter::exact_accumulate(Lobe::from_u32(p.lobe), src, layout, p.exact_level, cubemap::INLINE_GEOMETRY, n, p.roughness, p.start, p.count, partial));
    }
}

/// One chunk of the excess list of a split source (`bright::accumulate`, entries
/// `start .. start + count` of `list`) added to the sums of one texel of one level of the
/// sheen cube, after its samples of the residual ([`prefilter_specular`] over it).
#[spirv(compute(threads(8, 8)))]
pub fn prefilter_bright(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(uniform, descriptor_set = 0, binding = 0)] p: &PrefilterParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] list: &[Vec4],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] accum: &mut [Vec4],
) {
    if let Some((_, i, n)) = prefilter_invocation(id, p) {
        let partial = load_partial(accum, i);
        store_partial(accum, i, crate::bright::accumulate(list, n, Lobe::from_u32(p.lobe).alpha(p.roughness), p.start, p.count, partial));
    }
}

/// One texel of a split sheen level traced at the split level's size, the ring (sheen
/// roughness 0) among them (`bright::traced_texel`): `buf` holds the residual's mean, a
/// `src_size`² cube, then from index `start` the `count` entries of the excess list and the
/// level's density table, if it has one (`bright::density_table`), or for the ring a header per tile
/// (`bright::ring_tile`: the index of its first entry from `start`, and their count, as the
/// bits of `x` and `y`) and the tiles' entries; written at `dst_offset` on.
#[spirv(compute(threads(8, 8)))]
pub fn prefilter_traced(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(uniform, descriptor_set = 0, binding = 0)] p: &PrefilterParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] buf: &[Vec4],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] out: &mut [Vec4],
) {
    if let Some((_, i, n)) = prefilter_invocation(id, p) {
        let alpha = Lobe::from_u32(p.lobe).alpha(p.roughness);
        let ring = p.roughness <= 0.0;
        let (list, count) = if ring {
            let h = buf[(p.start + crate::bright::ring_tile(id.z, id.x, id.y, p.dst_size)) as usize];
            (p.start + h.x.to_bits(), h.y.to_bits())
        } else {
            (p.start, p.count)
        };
        out[i] = crate::bright::traced_texel(buf, p.src_size, list, count, n, alpha, ring);
    }
}

/// The index of the cube texel an invocation `id` of a `size`² × 6 dispatch works on
/// (face `id.z`, column `id.x`, row `id.y`), `offset` texels into its buffer; nothing for
/// the invocations past the faces' edges.
#[inline]
fn face_texel(id: UVec3, size: u32, offset: u32) -> Option<usize> {
    if id.x < size && id.y < size && id.z < cubemap::FACES { Some((offset + (id.z * size + id.y) * size + id.x) as usize) } else { None }
}

/// The texel a prefilter kernel's invocation `id` works on: the source cube's layout, the
/// texel's index in the output's sums and its direction; nothing outside the level.
#[inline]
fn prefilter_invocation(id: UVec3, p: &PrefilterParams) -> Option<(CubeLayout, usize, Vec3)> {
    let s = p.dst_size;
    let i = face_texel(id, s, p.dst_offset)?;
    Some((CubeLayout::new(p.src_size, p.src_levels), i, cubemap::texel_dir(id.z, id.x, id.y, s)))
}

/// Parameters of [`irradiance_cube`] and [`irradiance_sh9_project`].
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
    /// First source texel of this dispatch's chunk.
    pub start: u32,
    /// Source texels in this chunk (at most `math::CHUNK`).
    pub count: u32,
    /// Index in `src` of the summed level's geometry table (`cubemap::level_geometry`),
    /// placed after the texels, or `cubemap::INLINE_GEOMETRY`.
    pub geometry: u32,
}

/// One chunk of source texels for one texel of the irradiance cube: adds them to its
/// partial sums in `accum` (three `Vec4` per texel; `irradiance::accumulate`).
#[spirv(compute(threads(8, 8)))]
pub fn irradiance_cube(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(uniform, descriptor_set = 0, binding = 0)] p: &IrradianceParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] src: &[Vec4],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] accum: &mut [Vec4],
) {
    let s = p.dst_size;
    if let Some(i) = face_texel(id, s, 0) {
        let layout = CubeLayout::new(p.src_size, p.src_levels);
        let n = cubemap::texel_dir(id.z, id.x, id.y, s);
        let partial = load_partial(accum, i);
        store_partial(accum, i, irradiance::accumulate(src, layout, p.src_level, p.geometry, n, p.start, p.count, partial));
    }
}

/// The SH9 partial sums of one row (`id.x`) of one face (`id.z`) of the source level:
/// ten `Vec4` per row (see [`irradiance::sh9_row`]).
#[spirv(compute(threads(64)))]
pub fn irradiance_sh9_project(
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

/// What [`probe`] evaluates (its code goes into [`ProbeParams::mode`]).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
#[repr(u32)]
pub enum ProbeMode {
    /// `lut::accumulate(n·v = q.x, roughness = q.y)`: the partial sums in `out[3i]`.
    Lut = 0,
    /// `prefilter::accumulate(dir = q.xyz, roughness = q.w)`: a `MeanPartial` in `out[3i..]`.
    Prefilter = 1,
    /// `irradiance::accumulate(normal = q.xyz)` over level `src_level`: a `MeanPartial`.
    Irradiance = 2,
    /// `cubemap::sample_lod(dir = q.xyz, lod = q.w)` in `out[3i]`.
    Sample = 3,
}

crate::choice!(ProbeMode: Lut => "lut", Prefilter => "prefilter", Irradiance => "irradiance", Sample => "sample");

/// Parameters of [`probe`].
#[derive(Copy, Clone, Debug, Pod, Zeroable)]
#[repr(C)]
pub struct ProbeParams {
    /// A [`ProbeMode`] code.
    pub mode: u32,
    /// Number of probes.
    pub count: u32,
    /// Index in the input of the first probe (the cube's texels come first).
    pub probe_offset: u32,
    /// Samples in all (LUT, prefilter).
    pub samples: u32,
    /// Level-0 face size of the cube.
    pub src_size: u32,
    /// Levels of the cube.
    pub src_levels: u32,
    /// Level summed over (irradiance).
    pub src_level: u32,
    /// Source-level bias (prefilter).
    pub lod_bias: f32,
    /// First sample (or source texel) of this chunk.
    pub start: u32,
    /// Samples (or texels) in this chunk.
    pub chunk: u32,
}

/// One chunk of probe `q`: the math at an arbitrary input, so that tests run the same
/// inputs (poles, corners, zero vectors, extreme values) natively and on the GPU. Writes
/// (or continues) three `Vec4` at `out[3i..]`.
pub fn probe_chunk(p: &ProbeParams, input: &[Vec4], q: Vec4, out: &mut [Vec4], i: usize) {
    let layout = CubeLayout::new(p.src_size, p.src_levels);
    if p.mode == ProbeMode::Lut as u32 {
        out[3 * i] = lut::accumulate(q.x, q.y, p.samples, p.start, p.chunk, out[3 * i]);
    } else if p.mode == ProbeMode::Prefilter as u32 {
        let partial = load_partial(out, i);
        store_partial(out, i, prefilter::accumulate(Lobe::Ggx, input, layout, q.truncate(), q.w, p.samples, p.start, p.chunk, p.lod_bias, partial));
    } else if p.mode == ProbeMode::Irradiance as u32 {
        let partial = load_partial(out, i);
        store_partial(out, i, irradiance::accumulate(input, layout, p.src_level, cubemap::INLINE_GEOMETRY, q.truncate(), p.start, p.chunk, partial));
    } else {
        out[3 * i] = cubemap::sample_lod(input, layout, q.truncate(), q.w);
    }
}

/// Evaluates one chunk of probe `id.x` (see [`probe_chunk`]).
#[spirv(compute(threads(64)))]
pub fn probe(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(uniform, descriptor_set = 0, binding = 0)] p: &ProbeParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] input: &[Vec4],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] out: &mut [Vec4],
) {
    if id.x < p.count {
        let q = input[(p.probe_offset + id.x) as usize];
        probe_chunk(p, input, q, out, id.x as usize);
    }
}

/// Parameters of [`resolve_means`] and [`resolve_lut`].
#[derive(Copy, Clone, Debug, Pod, Zeroable)]
#[repr(C)]
pub struct ResolveParams {
    /// Texels resolved.
    pub count: u32,
    /// Index of the first texel's partial sums in the input (in texels).
    pub src_offset: u32,
    /// Index of the first texel written.
    pub dst_offset: u32,
    /// Samples per texel, in all (for [`resolve_lut`]).
    pub samples: u32,
}

/// The mean of texel `id.x` from its partial sums (`MeanPartial::resolve`, the function
/// the CPU backend ends with), so that the products stay on the GPU.
#[spirv(compute(threads(64)))]
pub fn resolve_means(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(uniform, descriptor_set = 0, binding = 0)] p: &ResolveParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] accum: &[Vec4],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] out: &mut [Vec4],
) {
    if id.x < p.count {
        out[(p.dst_offset + id.x) as usize] = load_partial(accum, (p.src_offset + id.x) as usize).resolve();
    }
}

/// Texel `id.x` of the sampled BRDF table from its sums (`lut::resolve`): `(A, B)` in `xy`.
#[spirv(compute(threads(64)))]
pub fn resolve_lut(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(uniform, descriptor_set = 0, binding = 0)] p: &ResolveParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] accum: &[Vec4],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] out: &mut [Vec4],
) {
    if id.x < p.count {
        let t = lut::resolve(accum[(p.src_offset + id.x) as usize], p.samples);
        out[(p.dst_offset + id.x) as usize] = Vec4::new(t.x, t.y, 0.0, 0.0);
    }
}

/// One texel of a mirror level (roughness 0) of the specular cube: the source read along
/// the texel's direction (`prefilter::mirror_texel`, no sum), written at `dst_offset`.
#[spirv(compute(threads(8, 8)))]
pub fn prefilter_mirror(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(uniform, descriptor_set = 0, binding = 0)] p: &PrefilterParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] src: &[Vec4],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] out: &mut [Vec4],
) {
    let s = p.dst_size;
    if let Some(i) = face_texel(id, s, p.dst_offset) {
        out[i] = prefilter::mirror_texel(src, CubeLayout::new(p.src_size, p.src_levels), id.z, id.x, id.y, s);
    }
}

/// Parameters of [`pack_half`] and [`unpack_rows`]: a block of `rows` rows of `width`
/// texels, dense on the `Vec4` side and `row_words` 32-bit words apart on the packed side
/// (rows of a texture copy are 256-byte aligned).
#[derive(Copy, Clone, Debug, Pod, Zeroable)]
#[repr(C)]
pub struct RowsParams {
    /// Texels per row.
    pub width: u32,
    /// Rows.
    pub rows: u32,
    /// Index of the first `Vec4` texel.
    pub texel_offset: u32,
    /// Words from one packed row to the next.
    pub row_words: u32,
    /// Index of the first packed word.
    pub word_offset: u32,
    /// Channels per packed texel: 4 (RGBA) or 2 (RG).
    pub channels: u32,
    /// Packed texels are halves (1) or f32 (0) (for [`unpack_rows`]).
    pub half: u32,
}

/// Texel `(id.x, id.y)` as halves (`half::pack_radiance`: NaN to 0, clamped to ±65504),
/// into rows laid out as `copy_buffer_to_texture` reads them.
#[spirv(compute(threads(8, 8)))]
pub fn pack_half(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(uniform, descriptor_set = 0, binding = 0)] p: &RowsParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] texels: &[Vec4],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] words: &mut [u32],
) {
    if id.x < p.width && id.y < p.rows {
        let v = texels[(p.texel_offset + id.y * p.width + id.x) as usize];
        let w = (p.word_offset + id.y * p.row_words + id.x * p.channels / 2) as usize;
        words[w] = half::pack_radiance(v.x, v.y);
        if p.channels == 4 {
            words[w + 1] = half::pack_radiance(v.z, v.w);
        }
    }
}

/// Texel `(id.x, id.y)` of RGBA rows copied out of a caller's texture (halves or f32),
/// cleaned (`half::clean_radiance`) into dense `Vec4` texels.
#[spirv(compute(threads(8, 8)))]
pub fn unpack_rows(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(uniform, descriptor_set = 0, binding = 0)] p: &RowsParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] words: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] texels: &mut [Vec4],
) {
    if id.x < p.width && id.y < p.rows {
        let row = (p.word_offset + id.y * p.row_words) as usize;
        let v = half::copied_texel(words, row, id.x as usize, p.half == 1);
        texels[(p.texel_offset + id.y * p.width + id.x) as usize] = half::clean_radiance(v);
    }
}

/// Parameters of [`read_cube`].
#[derive(Copy, Clone, Debug, Pod, Zeroable)]
#[repr(C)]
pub struct ReadCubeParams {
    /// Face size of the level read.
    pub size: u32,
    /// The mip level read.
    pub level: u32,
    /// Index of the output's first texel.
    pub texel_offset: u32,
}

/// Texel `(id.x, id.y)` of face `id.z` of mip `level` of a cube texture, cleaned
/// (`half::clean_radiance`), into dense `Vec4` texels (faces in order, rows top to bottom).
/// The cube is sampled at the texel's centre direction (`cubemap::texel_dir`) with a
/// nearest-texel sampler at that exact level, which returns the texel itself: for devices
/// that cannot copy a cube texture to a buffer (wgpu's GL backend reports "Not implemented
/// yet: cubemap texture copy to buffer" and copies nothing).
#[spirv(compute(threads(8, 8)))]
pub fn read_cube(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(uniform, descriptor_set = 0, binding = 0)] p: &ReadCubeParams,
    #[spirv(descriptor_set = 0, binding = 1)] cube: &spirv_std::Image!(cube, type = f32, sampled),
    #[spirv(descriptor_set = 0, binding = 3)] sampler: &spirv_std::Sampler,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] texels: &mut [Vec4],
) {
    if let Some(i) = face_texel(id, p.size, p.texel_offset) {
        let d = cubemap::texel_dir(id.z, id.x, id.y, p.size);
        let v: Vec4 = cube.sample_by_lod(*sampler, d, p.level as f32);
        texels[i] = half::clean_radiance(v);
    }
}

/// Parameters of [`calibrate()`].
#[derive(Copy, Clone, Debug, Pod, Zeroable)]
#[repr(C)]
pub struct CalibrateParams {
    /// The work measured (`calibrate::Rate` as `u32`).
    pub rate: u32,
    /// Face size of the output written (one texel per invocation).
    pub size: u32,
    /// Level-0 face size of the input cube.
    pub src_size: u32,
    /// Levels of the input cube.
    pub src_levels: u32,
    /// Steps of work per invocation.
    pub count: u32,
}

/// One texel of a calibration run (`calibrate::texel`).
#[spirv(compute(threads(8, 8)))]
pub fn calibrate(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(uniform, descriptor_set = 0, binding = 0)] p: &CalibrateParams,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] src: &[Vec4],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] out: &mut [Vec4],
) {
    let s = p.size;
    if let Some(i) = face_texel(id, s, 0) {
        let layout = CubeLayout::new(p.src_size, p.src_levels);
        out[i] = calibrate::texel(src, layout, calibrate::Rate::from_u32(p.rate), id.z, id.x, id.y, s, p.count);
    }
}
