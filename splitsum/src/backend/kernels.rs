//! The operations a bake is made of ([`Kernels`]), which each backend implements.

use super::split::Split;
use crate::error::Result;
use crate::texture::{Equirect, Sh9};
use splitsum_shaders::brdf::microfacet::Masking;
use splitsum_shaders::calibrate::Rate;
use splitsum_shaders::cubemap::CubeLayout;
use splitsum_shaders::equirect::Facing;
use splitsum_shaders::glam::Vec4;
use splitsum_shaders::kernels::ProbeParams;
use splitsum_shaders::prefilter::Lobe;
use splitsum_shaders::math::CHUNK;

/// The chunks `(start, count)` a sum of `n` terms is split into (see `math::CHUNK`).
pub fn chunks(n: u32) -> impl Iterator<Item = (u32, u32)> {
    let n = n.max(1);
    (0..n.div_ceil(CHUNK)).map(move |k| (k * CHUNK, CHUNK.min(n - k * CHUNK)))
}

/// What a prefilter computes: level `m` of `layout` filtered with `lobe` (GGX: the
/// specular cube; Charlie: the sheen cube) for `roughness[m]` from `samples[m]` samples, or summed exactly over source level `exact[m]` unless that is
/// `prefilter::SAMPLED`; only `levels` are baked (the others stay zero: a plan leaves out
/// what nothing reads).
#[derive(Clone, Debug)]
pub struct Prefilter<'a> {
    /// What the cube is, for progress and labels: the product's name (`specular`, `sheen`).
    pub what: &'static str,
    /// The distribution.
    pub lobe: Lobe,
    /// Layout of the cube.
    pub layout: CubeLayout,
    /// Roughness of each level.
    pub roughness: &'a [f32],
    /// The levels baked.
    pub levels: &'a [u32],
    /// Samples of each level.
    pub samples: &'a [u32],
    /// Source level summed exactly for each level, or `prefilter::SAMPLED`.
    pub exact: &'a [u32],
    /// Added to the source level of each sample.
    pub lod_bias: f32,
}

/// The operations a bake is made of, on one backend. Cubes are texels in `CubeLayout`
/// order; tables are rows of `(A, B, 0, 0)`.
pub trait Kernels {
    /// Where this backend keeps texels.
    type Texels;

    /// The largest buffer the backend binds as one storage buffer, in bytes (`None`: no
    /// limit, the CPU): what `crate::placement` places each step by.
    fn max_binding(&self) -> Option<u64> {
        None
    }
    /// Waits until the work submitted so far has run (the GPU's queue; nothing on the CPU),
    /// so that a step's wall time is its own.
    fn finish(&self) -> Result<()>;
    /// Texels from host memory.
    fn upload(&self, what: &str, texels: &[Vec4]) -> Result<Self::Texels>;
    /// Texels back in host memory.
    fn read(&self, texels: &Self::Texels) -> Result<Vec<Vec4>>;
    /// `count` texels of `texels` from index `start`.
    fn slice(&self, texels: &Self::Texels, start: u32, count: u32) -> Result<Self::Texels>;
    /// Level 0 of a cube with faces of `size` resampled from `env` with `supersample`²
    /// points per texel, the image centre facing `facing`, and its full mip chain.
    fn equirect_to_cube(&self, env: &Equirect, size: u32, supersample: u32, facing: Facing) -> Result<Self::Texels>;
    /// Fills levels 1.. of `cube` from its level 0.
    fn build_mips(&self, cube: &mut Self::Texels, layout: CubeLayout) -> Result<()>;
    /// The prefiltered cube of `job` (specular or sheen) from `src`, the levels that split
    /// (`bright::splits`) from `split` (made by `split::prefilter`, which callers call).
    fn prefilter(&self, src: &Self::Texels, src_layout: CubeLayout, job: &Prefilter<'_>, split: Option<&Split<Self::Texels>>) -> Result<Self::Texels>;
    /// The irradiance cube (`E/π`) of faces of `size` from level `level` of `src`.
    fn irradiance(&self, src: &Self::Texels, src_layout: CubeLayout, level: u32, size: u32) -> Result<Self::Texels>;
    /// The per-row SH9 partial sums of level `level` of `src` (see `irradiance::sh9_row`).
    fn sh9(&self, src: &Self::Texels, src_layout: CubeLayout, level: u32) -> Result<Sh9>;
    /// The `size`² BRDF table from `samples` Hammersley points per texel.
    fn brdf_lut(&self, size: u32, samples: u32) -> Result<Self::Texels>;
    /// The `size`² BRDF table by deterministic quadrature with `masking`.
    fn brdf_table(&self, size: u32, masking: Masking) -> Result<Self::Texels>;
    /// A calibration run (`calibrate::texel`): `count` steps of work `rate` per texel of a
    /// `size`² cube, over `src` (a cube of `src_layout`); for the cost model.
    fn calibrate(&self, src: &Self::Texels, src_layout: CubeLayout, rate: Rate, size: u32, count: u32) -> Result<Self::Texels>;
    /// `probes` evaluated with `params` over `cube` (see `kernels::probe_chunk`): raw
    /// results, three `Vec4` per probe.
    fn probe_raw(&self, params: ProbeParams, texels: &[Vec4], probes: &[Vec4], terms: u32) -> Result<Vec<Vec4>>;
}
