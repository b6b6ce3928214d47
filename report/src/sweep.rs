//! What a report measures: the sweeps of every knob ([`Sweep`], full or quick) and the
//! sets of environments ([`Sets`]).

use crate::measurement::Method;
use splitsum::settings::{Settings, Target};
use splitsum_shaders::brdf::microfacet::Masking;
use splitsum_shaders::shade::{self, ShadeOptions};

/// The sweeps of a report.
#[derive(Clone, Debug)]
pub struct Sweep {
    /// Face size of the source cube everything is filtered from (and the references sum).
    pub source_size: u32,
    /// The bake whose specular levels the prefilter sweeps measure: the defaults at the
    /// report's size (face size, mips, roughness per mip, each mip's sample count, the
    /// exact sums where they are cheaper), so that the sweeps sit around what a user bakes.
    pub levels: Settings,
    /// Width of the BRDF table whose texel centres are compared.
    pub lut_size: u32,
    /// Sample counts swept for the table and the prefilter.
    pub samples: Vec<u32>,
    /// Table sizes swept (bilinear lookups compared at scattered points).
    pub lut_sizes: Vec<u32>,
    /// Source-mip biases swept, at each of `bias_samples` sample counts.
    pub biases: Vec<f32>,
    /// Sample counts of the bias sweep.
    pub bias_samples: Vec<u32>,
    /// Face sizes of the roughness-⅓ level swept (cube size).
    pub cube_sizes: Vec<u32>,
    /// Source levels (face sizes) swept for the irradiance convolution.
    pub irradiance_sources: Vec<u32>,
    /// Face size of the irradiance cube.
    pub irradiance_size: u32,
    /// Source levels swept for SH9.
    pub sh_sources: Vec<u32>,
    /// Quality levels of the shaded colour.
    pub qualities: Vec<Settings>,
    /// Probe directions per comparison.
    pub directions: u32,
    /// Largest face size of the source cube of the end-to-end measure (`accuracy`): the
    /// environment's own resolution up to this.
    pub accuracy_source: u32,
    /// Shading points and prefiltered lookups of the end-to-end measure.
    pub accuracy_points: (u32, u32),
}

impl Sweep {
    /// The full report: a few minutes on lavapipe and 2 CPU cores. Its shaded colour also
    /// measures the default bake settings (`Settings::default()`).
    pub fn full() -> Self {
        let mut sweep = Self::with(
            256,
            Settings::default().size,
            32,
            vec![16, 64, 256, 1024, 4096],
            vec![8, 16, 32, 64, 128],
            vec![256, 1024],
            vec![8, 16, 32, 64],
            vec![4, 8, 16, 32, 64],
            vec![8, 16, 32, 64, 128],
            32,
        );
        sweep.qualities.push(Settings::default());
        sweep
    }

    /// A quick report for CI: the same sweeps, smaller and shorter.
    pub fn quick() -> Self {
        let mut sweep = Self::with(16, 8, 8, vec![4, 16, 64], vec![4, 8, 16], vec![16], vec![4, 8], vec![4, 8, 16], vec![4, 8, 16], 8);
        // Down to 1² faces: an 8² cube at the defaults would be the mirror alone.
        sweep.levels.mips = Some(4);
        for q in &mut sweep.qualities {
            q.mips = Some(4);
        }
        sweep.accuracy_source = 16;
        sweep.accuracy_points = (48, 48);
        sweep
    }

    /// The display methods the end-to-end measure compares, for an environment whose native
    /// face size is `native`: the seed method, today's defaults, and each shading option.
    pub fn methods(&self, native: u32) -> Vec<crate::accuracy::Method> {
        use crate::accuracy::{Method, seed_settings};
        use crate::measurement::Method as Kind;
        let src = native.min(self.accuracy_source).max(4);
        let default = Settings { size: src, source_size: Some(src), ..Settings::default() };
        let flags = ShadeOptions::DEFAULT.flags & !(ShadeOptions::IBL | ShadeOptions::DIRECT);
        let mut methods = Vec::new();
        // Each method's error against its bake time: the seed at three sample counts, the
        // defaults at three (mip 1's count; ×2 per mip after it).
        for n in [64, 256, 1024] {
            // The seed's shading: the mirror direction, the roughness-aware Fresnel weights.
            methods.push(Method { kind: Kind::Seed, settings: Settings { samples: n, ..seed_settings(src) }, flags: ShadeOptions::ROUGHNESS_FRESNEL });
        }
        for n in [16, 256] {
            methods.push(Method { kind: Kind::Defaults, settings: Settings { samples: n, ..default.clone() }, flags });
        }
        methods.extend(vec![
            Method { kind: Kind::Defaults, settings: default.clone(), flags },
            Method { kind: Kind::MirrorDirection, settings: default.clone(), flags: flags & !ShadeOptions::DOMINANT_DIRECTION },
            Method { kind: Kind::MultipleScattering, settings: default.clone(), flags: flags | ShadeOptions::MULTISCATTER },
            Method { kind: Kind::FilteredSampling, settings: default.clone(), flags: flags | ShadeOptions::FILTERED_SAMPLING },
            Method { kind: Kind::LinearMipBlend, settings: default.clone(), flags: flags & !ShadeOptions::LOG_MIP_BLEND },
            Method { kind: Kind::RoughnessFresnel, settings: default.clone(), flags: flags | ShadeOptions::ROUGHNESS_FRESNEL },
            Method { kind: Kind::NoHorizonLift, settings: default.clone(), flags: flags & !ShadeOptions::LIFT_ABOVE_HORIZON },
        ]);
        // The shading ladder: the defaults' bake read with 2, 4, 8 and 16 fetches.
        let base = ShadeOptions { flags, ..ShadeOptions::DEFAULT };
        for rung in 1..shade::LADDER_RUNGS {
            let flags = base.with_fetches(1 << rung).flags;
            methods.push(Method { kind: Kind::Ladder, settings: default.clone(), flags });
        }
        methods.push(Method { kind: Kind::SmithSchlickTable, settings: Settings { lut_masking: Some(Masking::SmithSchlick), ..default.clone() }, flags });
        // Each engine target's levels, read as its engine reads them (linear between mips).
        for (kind, target) in [(Kind::KhronosBevyLookup, Target::Khronos), (Kind::FilamentLookup, Target::Filament)] {
            let fixed = target.fixed();
            let settings = Settings { mapping: fixed.mapping, mips: fixed.mips.map(|m| m(src)), ..default.clone() };
            methods.push(Method { kind, settings, flags: flags & !(ShadeOptions::LOG_MIP_BLEND | ShadeOptions::LIFT_ABOVE_HORIZON) });
        }
        methods
    }

    /// The job of [`Sweep::levels`]: its roughness per mip, sample counts and exact levels.
    pub fn level_job(&self) -> splitsum::error::Result<splitsum::settings::Job> {
        self.levels.resolve(splitsum::settings::InputShape::Unknown, splitsum::Products::DISPLAY)
    }

    /// The methods the measure over sets compares: the seed at its 1024 samples, the
    /// defaults, and each shading option.
    pub fn set_methods(&self, native: u32) -> Vec<crate::accuracy::Method> {
        let n = Settings::default().samples;
        self.methods(native)
            .into_iter()
            .filter(|m| match m.kind {
                Method::Seed => m.settings.samples == 1024,
                _ => m.settings.samples == n,
            })
            .collect()
    }

    #[allow(clippy::too_many_arguments)]
    fn with(
        source_size: u32,
        specular_size: u32,
        lut_size: u32,
        samples: Vec<u32>,
        lut_sizes: Vec<u32>,
        bias_samples: Vec<u32>,
        cube_sizes: Vec<u32>,
        irradiance_sources: Vec<u32>,
        sh_sources: Vec<u32>,
        directions: u32,
    ) -> Self {
        let level = |n: u32, lut: u32, irr: u32| Settings {
            size: specular_size,
            source_size: Some(source_size),
            samples: n,
            irradiance_size: Settings::default().irradiance_size.min(specular_size / 2).max(4),
            irradiance_source: Some(irr.min(source_size)),
            sh_source: Some(source_size),
            lut_size: lut,
            lut_samples: n,
            ..Settings::default()
        };
        let q = &samples;
        let qualities = vec![
            level(q[0], lut_sizes[0], irradiance_sources[0]),
            level(q[q.len() / 2], lut_sizes[lut_sizes.len() / 2], irradiance_sources[irradiance_sources.len() / 2]),
            level(q[q.len() - 1], *lut_sizes.last().expect("sizes"), *irradiance_sources.last().expect("sizes")),
        ];
        Self {
            source_size,
            levels: Settings { size: specular_size, source_size: Some(source_size), ..Settings::default() },
            lut_size,
            samples,
            lut_sizes,
            biases: vec![-1.0, -0.5, 0.0, 0.5, 1.0, 1.5, 2.0],
            bias_samples,
            cube_sizes,
            irradiance_sources,
            irradiance_size: Settings::default().irradiance_size.min(specular_size / 2).max(4),
            sh_sources,
            qualities,
            directions,
            accuracy_source: 256,
            accuracy_points: (512, 512),
        }
    }
}

/// The measure over the tuning and held-out sets ([`crate::sets`]), when a report asks.
#[derive(Clone, Debug)]
pub struct Sets {
    /// The folder of Blender's studio lights.
    pub dir: std::path::PathBuf,
    /// Only the environments present (and the generated ones), for a quick report.
    pub present_only: bool,
    /// Only this set (to iterate on the tuning set without looking at the held-out one).
    pub only: Option<splitsum::measured::Set>,
}
