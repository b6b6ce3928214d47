//! The two ways to bake: on a GPU through wgpu ([`gpu`]), or natively on the CPU
//! ([`cpu`]). Both implement [`Kernels`] with the same `splitsum_shaders` functions, and
//! keep what they make where they made it (`Kernels::Texels`: host memory, or device
//! buffers), so one bake sequence (`crate::bake`) runs on either and nothing comes back
//! from the GPU unless asked.
//!
//! On the GPU, long sums run one chunk of at most `math::CHUNK` terms per dispatch and
//! carry compensated partial sums from dispatch to dispatch; the means are resolved with
//! the same shared functions the CPU backend ends with (`MeanPartial::resolve`,
//! `lut::resolve`), so both backends do the same arithmetic in the same order.

pub mod cpu;
pub mod gpu;
pub mod kernels;

use crate::error::{Error, Result};
use crate::texture::{Cube, Equirect, Lut, Sh9};
use splitsum_shaders::brdf::microfacet::Masking;
use splitsum_shaders::cubemap::CubeLayout;
use splitsum_shaders::equirect::Facing;
use splitsum_shaders::glam::Vec4;
use splitsum_shaders::kernels::ProbeParams;

pub use cpu::Cpu;
pub use gpu::Gpu;
pub use kernels::{Kernels, Prefilter, chunks};

/// Which backend to bake with.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum BackendKind {
    /// wgpu on a Vulkan adapter (a real GPU, or Mesa's lavapipe on the CPU).
    Gpu,
    /// The shader functions compiled natively, multi-threaded with rayon.
    Cpu,
}

splitsum_shaders::choice!(BackendKind: Gpu => "gpu", Cpu => "cpu");

/// An open backend.
pub enum Backend {
    /// The GPU, with its device and pipelines.
    Gpu(Box<Gpu>),
    /// The CPU.
    Cpu,
}

/// Runs `$body` with `$k` bound to the backend's [`Kernels`].
macro_rules! with_kernels {
    ($backend:expr, $k:ident => $body:expr) => {
        match $backend {
            Backend::Gpu(g) => {
                let $k: &$crate::backend::Gpu = g;
                $body
            }
            Backend::Cpu => {
                let $k: &$crate::backend::Cpu = &$crate::backend::Cpu;
                $body
            }
        }
    };
}
pub(crate) use with_kernels;

/// The BRDF table's arguments through the one validation, `Settings::validate`.
fn check_lut_args(size: u32, samples: u32) -> Result<()> {
    crate::settings::Settings { lut_size: size, lut_samples: samples, ..Default::default() }.validate()
}

impl Backend {
    /// Opens `kind` (for the GPU: adapter, device and pipelines, outside any timing).
    pub fn open(kind: BackendKind) -> Result<Self> {
        Ok(match kind {
            BackendKind::Gpu => Backend::Gpu(Box::new(Gpu::new()?)),
            BackendKind::Cpu => Backend::Cpu,
        })
    }

    /// A one-line description.
    pub fn describe(&self) -> String {
        match self {
            Backend::Gpu(g) => format!("gpu: {}", g.describe()),
            Backend::Cpu => format!("cpu: {} threads", rayon::current_num_threads()),
        }
    }

    /// What the backend's results depend on, for cache keys: the adapter and driver, or
    /// `cpu` (results on the CPU do not depend on the number of threads).
    pub fn identity(&self) -> String {
        match self {
            Backend::Gpu(g) => format!("gpu: {}", g.describe()),
            Backend::Cpu => "cpu".into(),
        }
    }

    /// Whether this is the GPU backend.
    pub fn is_gpu(&self) -> bool {
        matches!(self, Backend::Gpu(_))
    }

    /// The `size`×`size` BRDF table from `samples` points per texel.
    pub fn brdf_lut(&self, size: u32, samples: u32) -> Result<Lut> {
        check_lut_args(size, samples)?;
        with_kernels!(self, k => Ok(Lut::from_texels(size, &k.read(&k.brdf_lut(size, samples)?)?)))
    }

    /// The `size`×`size` BRDF table by deterministic quadrature with `masking`
    /// (`lut::integrate_brdf_quadrature`).
    pub fn brdf_table(&self, size: u32, masking: Masking) -> Result<Lut> {
        check_lut_args(size, 1)?;
        with_kernels!(self, k => Ok(Lut::from_texels(size, &k.read(&k.brdf_table(size, masking)?)?)))
    }

    /// The source cube: `env` resampled to faces of `size` with `supersample`² points per
    /// texel, the image centre facing `facing`, and its full mip chain.
    pub fn equirect_to_cube(&self, env: &Equirect, size: u32, supersample: u32, facing: Facing) -> Result<Cube> {
        let layout = CubeLayout::new(size, CubeLayout::full_chain(size));
        with_kernels!(self, k => Ok(Cube { layout, texels: k.read(&k.equirect_to_cube(env, size, supersample, facing)?)? }))
    }

    /// Fills levels 1.. of `cube` from its level 0.
    pub fn build_mips(&self, cube: &mut Cube) -> Result<()> {
        with_kernels!(self, k => {
            let mut t = k.upload("cube", &cube.texels)?;
            k.build_mips(&mut t, cube.layout)?;
            cube.texels = k.read(&t)?;
            Ok(())
        })
    }

    /// The prefiltered specular cube with layout `out`, level `m` filtered for
    /// `roughness[m]` with `samples` GGX samples and source-level bias `lod_bias`.
    pub fn prefilter(&self, src: &Cube, out: CubeLayout, roughness: &[f32], samples: u32, lod_bias: f32) -> Result<Cube> {
        let all: Vec<u32> = (0..out.levels).collect();
        self.prefilter_levels(src, out, roughness, &all, &vec![samples; out.levels as usize], false, lod_bias)
    }

    /// As [`Backend::prefilter`], baking only `levels`, level `m` from `samples[m]` GGX
    /// samples, or with `exact` summed exactly over a source level where that is cheaper
    /// (`prefilter::exact_level`).
    #[allow(clippy::too_many_arguments)]
    pub fn prefilter_levels(
        &self,
        src: &Cube,
        out: CubeLayout,
        roughness: &[f32],
        levels: &[u32],
        samples: &[u32],
        exact: bool,
        lod_bias: f32,
    ) -> Result<Cube> {
        if samples.contains(&0) {
            return Err(Error::setting("samples", "must be at least 1, not 0"));
        }
        let exact = crate::settings::exact_levels(roughness, samples, exact, src.layout);
        let job = Prefilter { layout: out, roughness, levels, samples, exact: &exact, lod_bias };
        with_kernels!(self, k => {
            let t = k.upload("source cube", &src.texels)?;
            Ok(Cube { layout: out, texels: k.read(&k.prefilter(&t, src.layout, &job)?)? })
        })
    }

    /// The irradiance cube (`E/π`) of face size `size` from level `level` of `src`.
    pub fn irradiance(&self, src: &Cube, level: u32, size: u32) -> Result<Cube> {
        with_kernels!(self, k => {
            let t = k.upload("source cube", &src.texels)?;
            Ok(Cube { layout: CubeLayout::new(size, 1), texels: k.read(&k.irradiance(&t, src.layout, level, size)?)? })
        })
    }

    /// The nine SH coefficients of radiance of level `level` of `src`.
    pub fn sh9(&self, src: &Cube, level: u32) -> Result<Sh9> {
        with_kernels!(self, k => k.sh9(&k.upload("source cube", &src.texels)?, src.layout, level))
    }

    /// Evaluates `probes` with `params` (see `kernels::probe_chunk`) over `cube`, if any:
    /// the BRDF table `(A, B)` in `xy`, a prefiltered or irradiance mean, or a cube lookup.
    pub fn probe(&self, params: ProbeParams, cube: Option<&Cube>, probes: &[Vec4]) -> Result<Vec<Vec4>> {
        use splitsum_shaders::choice::Choice;
        use splitsum_shaders::cubemap::FACES;
        use splitsum_shaders::kernels::ProbeMode;
        use splitsum_shaders::{lut, prefilter};
        let texels: &[Vec4] = cube.map_or(&[], |c| &c.texels);
        let p = ProbeParams {
            count: probes.len() as u32,
            probe_offset: texels.len() as u32,
            src_size: cube.map_or(1, |c| c.layout.size),
            src_levels: cube.map_or(1, |c| c.layout.levels),
            ..params
        };
        let layout = CubeLayout::new(p.src_size, p.src_levels);
        // Terms of the sum each probe runs, in chunks.
        let mode = ProbeMode::from_code(p.mode);
        let terms = match mode {
            ProbeMode::Lut | ProbeMode::Prefilter => p.samples.max(1),
            ProbeMode::Irradiance => FACES * layout.level_size(p.src_level).pow(2),
            _ => 1,
        };
        let raw = with_kernels!(self, k => k.probe_raw(p, texels, probes, terms))?;
        let partial = |i: usize| splitsum_shaders::math::MeanPartial { sum: raw[3 * i], carry: raw[3 * i + 1], weight: raw[3 * i + 2] };
        Ok(raw
            .chunks_exact(3)
            .zip(probes)
            .enumerate()
            .map(|(i, (c, q))| match mode {
                ProbeMode::Lut => lut::resolve(c[0], p.samples).extend(0.0).extend(0.0),
                // A mirror is no sum: the lookup itself.
                ProbeMode::Prefilter if splitsum_shaders::math::saturate(q.w) <= 0.0 => {
                    prefilter::prefilter_dir(texels, layout, q.truncate(), 0.0, p.samples, p.lod_bias)
                }
                ProbeMode::Prefilter | ProbeMode::Irradiance => partial(i).resolve(),
                _ => c[0],
            })
            .collect())
    }
}
