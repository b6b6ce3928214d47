//! [`Job`]: a bake resolved once from the settings, the target and the environment's
//! shape, which the bake, its cost, the backends, the textures and the files read.

use super::*;
use crate::adjustment::Adjustment;
use crate::error::{Error, Result};
use crate::texture::Format;
use serde::Serialize;
use splitsum_shaders::brdf::microfacet::Masking;
use splitsum_shaders::choice::Choice;
use splitsum_shaders::cubemap::CubeLayout;
use splitsum_shaders::equirect::Facing;
use crate::product::{Layout, Product};
use splitsum_shaders::prefilter::{self, Lobe, RoughnessMapping};
use std::collections::BTreeMap;

/// The values [`Settings::resolve`] derives.
pub(super) struct JobValues {
    pub(super) source_size: u32,
    pub(super) mips: u32,
    pub(super) mapping: RoughnessMapping,
    pub(super) irradiance_source: u32,
    pub(super) sh_source: u32,
    pub(super) lut_masking: Masking,
}

/// A bake, resolved once from [`Settings`], the target and the environment's shape
/// ([`Settings::resolve`]): every value concrete, and what every step needs worked out (the
/// roughness, samples and exact-sum level of each mip, the source levels, the layouts, the
/// supersampling). The bake, its cost, the backends' jobs, the textures and the files all
/// read it; nothing downstream derives a setting again.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Job {
    /// The settings as given.
    #[serde(skip)]
    pub given: Settings,
    /// Whose conventions the files follow.
    #[serde(with = "named")]
    pub target: Target,
    /// Which way the equirect's centre faces in the cube (the target's).
    #[serde(with = "named")]
    pub facing: Facing,
    /// Whether six-face input is mirrored in x (the target's: cmgen's).
    pub mirror_faces: bool,
    /// The products baked.
    pub products: Products,
    /// The environment's shape.
    pub input: InputShape,
    /// Face size of mip 0 of the specular cube.
    pub size: u32,
    /// Face size of the source cube.
    pub source_size: u32,
    /// Specular mips.
    pub mips: u32,
    /// Roughness of each mip.
    #[serde(with = "named")]
    pub mapping: RoughnessMapping,
    /// GGX samples per texel of specular mip 1.
    pub samples: u32,
    /// Growth of the sample count per mip after mip 1.
    pub sample_growth: u32,
    /// Rough mips summed exactly where cheaper.
    pub exact_sums: bool,
    /// Source-level bias of the prefilter samples.
    pub lod_bias: f32,
    /// Supersampling density of the equirect resampling.
    pub supersample_density: f32,
    /// Face size of the irradiance cube.
    pub irradiance_size: u32,
    /// Face size of the irradiance convolution's source level.
    pub irradiance_source: u32,
    /// Face size of the SH9 projection's source level.
    pub sh_source: u32,
    /// Width and height of the BRDF table.
    pub lut_size: u32,
    /// Samples per texel of a sampled table.
    pub lut_samples: u32,
    /// How the table is integrated.
    #[serde(with = "named")]
    pub lut_method: TableMethod,
    /// The table's masking term.
    #[serde(with = "named")]
    pub lut_masking: Masking,
    /// KTX2 texel format.
    #[serde(with = "named")]
    pub format: Format,
    /// Each prefiltered cube (`Product::lobe`: the specular cube, the sheen cube), baked or
    /// not: its roughness per mip, the mips baked, the exact sums. Both have the specular
    /// cube's size and mips.
    pub prefiltered: BTreeMap<Product, Prefiltered>,
    /// Samples per texel of each mip of a prefiltered cube (capped at 2²⁰).
    pub samples_per_mip: Vec<u32>,
    /// Equirect → cube supersamples per texel side (1 for a cube input).
    pub supersample: u32,
}

impl Job {
    pub(super) fn new(given: Settings, v: JobValues, input: InputShape, products: Products) -> Self {
        let fixed = given.target.fixed();
        let mut job = Self {
            target: given.target,
            facing: fixed.facing,
            mirror_faces: fixed.mirror_faces,
            products,
            input,
            size: given.size,
            source_size: v.source_size,
            mips: v.mips,
            mapping: v.mapping,
            samples: given.samples,
            sample_growth: given.sample_growth,
            exact_sums: given.exact_sums,
            lod_bias: given.lod_bias,
            supersample_density: given.supersample_density,
            irradiance_size: given.irradiance_size,
            irradiance_source: v.irradiance_source,
            sh_source: v.sh_source,
            lut_size: given.lut_size,
            lut_samples: given.lut_samples,
            lut_method: given.lut_method,
            lut_masking: v.lut_masking,
            format: given.format,
            prefiltered: BTreeMap::new(),
            samples_per_mip: Vec::new(),
            supersample: match input {
                InputShape::Equirect { width, .. } => splitsum_shaders::equirect::supersampling(v.source_size, width, given.supersample_density),
                _ => 1,
            },
            given,
        };
        job.samples_per_mip = job.asked_samples_per_mip().into_iter().map(|n| n.min(MAX_SAMPLES as u64) as u32).collect();
        for p in Product::ALL {
            let Some(lobe) = p.lobe() else { continue };
            let mapping = p.mapping(job.mapping);
            let roughness_per_mip: Vec<f32> = (0..job.mips).map(|m| mapping.roughness(m, job.mips)).collect();
            let exact_levels = exact_levels(lobe, &roughness_per_mip, &job.samples_per_mip, job.exact_sums, job.source_layout());
            job.prefiltered.insert(p, Prefiltered { mapping, roughness_per_mip, levels: (0..job.mips).collect(), exact_levels });
        }
        job
    }

    /// This job baking only `levels` of the prefiltered cube `cube` (the others stay zero):
    /// what a scene's plan keeps. Refuses a level the cube does not have.
    pub fn with_levels(mut self, cube: Product, levels: Vec<u32>) -> Result<Self> {
        if let Some(&m) = levels.iter().find(|&&m| m >= self.mips) {
            return Err(Error::setting(Field::Mips, format!("has no {cube} mip {m} to bake (there are {})", self.mips)));
        }
        self.prefiltered.get_mut(&cube).expect("a prefiltered cube").levels = levels;
        Ok(self)
    }

    internal! {
        /// Where product `p`'s texels lie: a prefiltered cube (any lobe) has the specular cube's
        /// layout.
        pub fn layout(&self, p: Product) -> Layout {
            match p {
                Product::SourceCube => Layout::Cube(self.source_layout()),
                p if p.lobe().is_some() => Layout::Cube(self.specular_layout()),
                Product::Irradiance => Layout::Cube(self.irradiance_layout()),
                Product::BrdfTable => Layout::Table(self.lut_size),
                Product::SheenTables => Layout::Table(crate::product::SHEEN_TABLE_SIZE),
                Product::Sh9 => Layout::Coefficients,
                _ => unreachable!("{p} is a prefiltered cube, matched above"),
            }
        }
    }

    /// Roughness of each mip of the specular cube.
    pub fn roughness_per_mip(&self) -> &[f32] {
        &self.prefiltered[&Product::Specular].roughness_per_mip
    }

    /// `samples × sample_growth^(m−1)` per mip, before the cap.
    fn asked_samples_per_mip(&self) -> Vec<u64> {
        (0..self.mips).map(|m| (self.samples as u64).saturating_mul((self.sample_growth as u64).saturating_pow(m.saturating_sub(1)))).collect()
    }

    /// Layout of the source cube, with its full mip chain.
    pub fn source_layout(&self) -> CubeLayout {
        CubeLayout::new(self.source_size, CubeLayout::full_chain(self.source_size))
    }

    /// Layout of the specular cube.
    pub fn specular_layout(&self) -> CubeLayout {
        CubeLayout::new(self.size, self.mips)
    }

    /// Layout of the irradiance cube.
    pub fn irradiance_layout(&self) -> CubeLayout {
        CubeLayout::new(self.irradiance_size, 1)
    }

    /// The source level the irradiance convolution sums over.
    pub fn irradiance_level(&self) -> u32 {
        self.source_layout().level_of_size(self.irradiance_source)
    }

    /// The source level projected onto SH9.
    pub fn sh_level(&self) -> u32 {
        self.source_layout().level_of_size(self.sh_source)
    }

    /// The BRDF table this job bakes, in words: `256² by quadrature (correlated)` or
    /// `256² × 1024 samples`.
    pub fn table_description(&self) -> String {
        match self.lut_method {
            TableMethod::Quadrature => format!("{}² by quadrature ({})", self.lut_size, self.lut_masking.name()),
            TableMethod::Sampled => format!("{}² × {} samples", self.lut_size, self.lut_samples),
        }
    }

    /// What this bake changes from what its settings ask: a mip's sample count capped at 2²⁰ (`MAX_SAMPLES`),
    /// a source cube finer than the environment resolves.
    pub fn adjustments(&self) -> Vec<Adjustment> {
        let mut out = Vec::new();
        let specular = &self.prefiltered[&Product::Specular];
        for (mip, asked) in self.asked_samples_per_mip().into_iter().enumerate() {
            // The mirror and a mip summed exactly take no samples.
            let sampled = specular.roughness_per_mip[mip] > 0.0 && specular.exact_levels[mip] == prefilter::SAMPLED;
            if sampled && self.products.has(Product::Specular) && asked > self.samples_per_mip[mip] as u64 {
                out.push(Adjustment::SamplesCapped { mip: mip as u32, asked, used: self.samples_per_mip[mip] });
            }
        }
        if let InputShape::Equirect { width, height } = self.input {
            let resolves = (width / 4).max(8).next_power_of_two();
            if self.source_size > resolves {
                out.push(Adjustment::Upsampled { width, height, resolves, source_size: self.source_size });
            }
        }
        out
    }
}

/// The source level each level of a `lobe` cube is summed over exactly, or
/// `prefilter::SAMPLED`: with `exact`, wherever that costs less than its samples
/// (`prefilter::exact_level`).
pub fn exact_levels(lobe: Lobe, roughness: &[f32], samples: &[u32], exact: bool, src: CubeLayout) -> Vec<u32> {
    roughness.iter().zip(samples).map(|(&r, &n)| if exact { prefilter::exact_level(lobe, r, n, src) } else { prefilter::SAMPLED }).collect()
}

/// One prefiltered cube of a job (the specular cube, the sheen cube): which roughness each
/// mip holds and how each is made. Every lobe of [`Product::ALL`] has one in
/// `Job::prefiltered`, baked or not.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Prefiltered {
    /// The roughness each mip holds.
    #[serde(with = "named")]
    pub mapping: RoughnessMapping,
    /// Roughness of each mip.
    pub roughness_per_mip: Vec<f32>,
    /// The mips baked (all, unless a plan keeps fewer; the others stay zero).
    pub levels: Vec<u32>,
    /// The source level each mip is summed over exactly, or `prefilter::SAMPLED`.
    pub exact_levels: Vec<u32>,
}
