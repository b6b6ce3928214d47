//! Host-data conveniences over the backends, for reports, tests and tools: each runs one
//! operation of [`Kernels`] on data in host memory and reads the result back, with its
//! arguments checked by the one validation (`Settings::resolve`), on the CPU where its
//! buffers are larger than the device binds (`crate::placement`).

use crate::backend::{Backend, Kernels, Prefilter, with_kernels};
use crate::error::{Error, Result};
use crate::placement::{self, texel_bytes};
use crate::settings::{Field, Settings};
use crate::texture::{Cube, Equirect, Lut, Sh9};
use splitsum_shaders::brdf::microfacet::Masking;
use splitsum_shaders::cubemap::CubeLayout;
use splitsum_shaders::equirect::Facing;
use splitsum_shaders::glam::Vec4;
use splitsum_shaders::kernels::ProbeParams;
use splitsum_shaders::prefilter::Lobe;

/// The BRDF table's arguments through the one validation, `Settings::validate`.
fn check_lut_args(size: u32, samples: u32) -> Result<()> {
    Settings { lut_size: size, lut_samples: samples, ..Default::default() }.validate()
}

impl Backend {
    /// Runs `f` on this backend, or on the CPU where an operation whose largest buffer is
    /// `needs` bytes does not fit one storage binding of this device (`crate::placement`).
    fn placed<T>(&self, what: &str, needs: u64, f: impl FnOnce(&Backend) -> T) -> T {
        let binds = match self {
            Backend::Cpu => None,
            Backend::Gpu(g) => Some(g.max_binding()),
        };
        let cpu = Backend::Cpu;
        f(placement::run(placement::place_buffer(needs, binds), || what.to_string(), || self, || &cpu))
    }

    internal! {
        /// The `size`×`size` BRDF table from `samples` points per texel.
        pub fn brdf_lut(&self, size: u32, samples: u32) -> Result<Lut> {
            check_lut_args(size, samples)?;
            self.placed("the BRDF table", texel_bytes((size as u64).pow(2)), |b| {
                with_kernels!(b, k => Ok(Lut::from_texels(size, &k.read(&k.brdf_lut(size, samples)?)?)))
            })
        }
    }

    internal! {
        /// The `size`×`size` BRDF table by deterministic quadrature with `masking`
        /// (`lut::integrate_brdf_quadrature`).
        pub fn brdf_table(&self, size: u32, masking: Masking) -> Result<Lut> {
            check_lut_args(size, 1)?;
            self.placed("the BRDF table", texel_bytes((size as u64).pow(2)), |b| {
                with_kernels!(b, k => Ok(Lut::from_texels(size, &k.read(&k.brdf_table(size, masking)?)?)))
            })
        }
    }

    internal! {
        /// The source cube: `env` resampled to faces of `size` with `supersample`² points per
        /// texel, the image centre facing `facing`, and its full mip chain.
        pub fn equirect_to_cube(&self, env: &Equirect, size: u32, supersample: u32, facing: Facing) -> Result<Cube> {
            let layout = CubeLayout::new(size, CubeLayout::full_chain(size));
            let needs = placement::resampling_buffer(env.width, env.height, layout);
            self.placed("resampling the equirect", needs, |b| {
                with_kernels!(b, k => Ok(Cube { layout, texels: k.read(&k.equirect_to_cube(env, size, supersample, facing)?)? }))
            })
        }
    }

    internal! {
        /// Fills levels 1.. of `cube` from its level 0.
        pub fn build_mips(&self, cube: &mut Cube) -> Result<()> {
            self.placed("the mips", texel_bytes(cube.texels.len() as u64), |b| {
                with_kernels!(b, k => {
                    let mut t = k.upload("cube", &cube.texels)?;
                    k.build_mips(&mut t, cube.layout)?;
                    cube.texels = k.read(&t)?;
                    Ok(())
                })
            })
        }
    }

    internal! {
        /// The prefiltered specular cube with layout `out`, level `m` filtered for
        /// `roughness[m]` with `samples` GGX samples and source-level bias `lod_bias`.
        pub fn prefilter(&self, src: &Cube, out: CubeLayout, roughness: &[f32], samples: u32, lod_bias: f32) -> Result<Cube> {
            let all: Vec<u32> = (0..out.levels).collect();
            self.prefilter_levels(Lobe::Ggx, src, out, roughness, &all, &vec![samples; out.levels as usize], false, lod_bias)
        }
    }

    internal! {
        /// As [`Backend::prefilter`] with the distribution `lobe` (GGX, or Charlie for the
        /// sheen cube), baking only `levels`, level `m` from `samples[m]` samples, or with
        /// `exact` summed exactly over a source level where that is cheaper
        /// (`prefilter::exact_level`).
        #[allow(clippy::too_many_arguments)]
        pub fn prefilter_levels(
            &self,
            lobe: Lobe,
            src: &Cube,
            out: CubeLayout,
            roughness: &[f32],
            levels: &[u32],
            samples: &[u32],
            exact: bool,
            lod_bias: f32,
        ) -> Result<Cube> {
            if samples.contains(&0) {
                return Err(Error::setting(Field::Samples, "must be at least 1, not 0"));
            }
            let exact = crate::settings::exact_levels(lobe, roughness, samples, exact, src.layout);
            let job = Prefilter { what: "prefiltered", lobe, layout: out, roughness, levels, samples, exact: &exact, lod_bias };
            let needs = placement::sums_buffer(src.texels.len() as u64, out);
            self.placed("the prefiltered cube", needs, |b| {
                with_kernels!(b, k => {
                    let t = k.upload("source cube", &src.texels)?;
                    Ok(Cube { layout: out, texels: k.read(&crate::backend::split::prefilter(k, &t, src.layout, &job)?)? })
                })
            })
        }
    }

    internal! {
        /// The irradiance cube (`E/π`) of face size `size` from level `level` of `src`.
        pub fn irradiance(&self, src: &Cube, level: u32, size: u32) -> Result<Cube> {
            let needs = placement::sums_buffer(src.texels.len() as u64, CubeLayout::new(size, 1));
            self.placed("the irradiance", needs, |b| {
                with_kernels!(b, k => {
                    let t = k.upload("source cube", &src.texels)?;
                    Ok(Cube { layout: CubeLayout::new(size, 1), texels: k.read(&k.irradiance(&t, src.layout, level, size)?)? })
                })
            })
        }
    }

    internal! {
        /// The nine SH coefficients of radiance of level `level` of `src`.
        pub fn sh9(&self, src: &Cube, level: u32) -> Result<Sh9> {
            self.placed("SH9", texel_bytes(src.texels.len() as u64), |b| with_kernels!(b, k => k.sh9(&k.upload("source cube", &src.texels)?, src.layout, level)))
        }
    }

    internal! {
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
            let needs = placement::probes_buffer(texels.len() as u64, probes.len() as u64);
            let raw = self.placed("the probes", needs, |b| with_kernels!(b, k => k.probe_raw(p, texels, probes, terms)))?;
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
}
