//! What a bake did with its input and settings other than take them as given: an input
//! reduced, upsampled or cleaned as it was read, a sample count capped. Nothing is changed
//! silently: each is returned to the caller ([`crate::environment::InputReport::adjustments`],
//! [`crate::settings::Job::adjustments`]), which states it in its own terms
//! ([`Adjustment::describe`]: the command line names its flags) and records it
//! (`bake.json`'s `adjustments`).

use crate::field::Field;
use serde::Serialize;

/// One change from what was given.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Adjustment {
    /// An equirect read at a lower resolution (area-weighted, as it was decoded): the
    /// source cube resolves no more.
    Reduced {
        /// Width and height of the file.
        from: (u32, u32),
        /// Width and height read.
        to: (u32, u32),
        /// The source cube's face size.
        source_size: u32,
    },
    /// Cube faces read at a lower resolution (the cube's own mip filter).
    FacesReduced {
        /// Face size of the files.
        from: u32,
        /// Face size read.
        to: u32,
    },
    /// The source cube is finer than the equirect resolves: it is interpolated, adding
    /// time and no detail.
    Upsampled {
        /// Width and height of the equirect as read.
        width: u32,
        /// Height.
        height: u32,
        /// The cube face size the equirect resolves (a quarter of its width).
        resolves: u32,
        /// The source cube's face size.
        source_size: u32,
    },
    /// A mip's GGX sample count, `samples × sample_growth^(m−1)`, held at the most a mip
    /// takes.
    SamplesCapped {
        /// The mip.
        mip: u32,
        /// What the settings ask for.
        asked: u64,
        /// What the mip takes.
        used: u32,
    },
    /// Texels with a negative channel (lossy-compression ringing), set to 0.
    NegativeTexels {
        /// How many.
        count: u64,
    },
    /// Texels brighter than the headroom every sum is built for, clamped to it.
    ClampedTexels {
        /// How many.
        count: u64,
        /// The value they were clamped to.
        max: f32,
    },
    /// NaN and infinite texels replaced (sanitising): NaN and −∞ by 0, +∞ by the channel's
    /// largest finite value.
    Sanitized {
        /// Texels with a NaN channel.
        nan: u64,
        /// Texels with an infinite channel.
        infinite: u64,
    },
}

impl Adjustment {
    /// The adjustment in words, naming each setting through `term` (a field name of
    /// `Settings` → what the caller calls it: a flag, a scene field).
    pub fn describe(&self, term: &dyn Fn(Field) -> String) -> String {
        match *self {
            Adjustment::Reduced { from, to, source_size } => format!(
                "{}×{} read as {}×{} (area-weighted): a cube of {source_size}² faces resolves no more ({})",
                from.0,
                from.1,
                to.0,
                to.1,
                term(Field::SourceSize)
            ),
            Adjustment::FacesReduced { from, to } => {
                format!("faces of {from}² read as {to}² (the cube's own mip filter): the bake uses no more ({})", term(Field::SourceSize))
            }
            Adjustment::Upsampled { width, height, resolves, source_size } => format!(
                "{width}×{height} resolves about {resolves}² per cube face; the {source_size}² source cube ({}) interpolates it {}×, which adds time and no detail",
                term(Field::SourceSize),
                source_size / resolves.max(1)
            ),
            Adjustment::SamplesCapped { mip, asked, used } => format!(
                "mip {mip} takes {used} GGX samples per texel, not the {asked} that {} × {}^{} asks for (the most a mip takes)",
                term(Field::Samples),
                term(Field::SampleGrowth),
                mip.saturating_sub(1)
            ),
            Adjustment::NegativeTexels { count } => format!("{count} texels had negative values, set to 0"),
            Adjustment::ClampedTexels { count, max } => format!("{count} texels were brighter than {max:e} and were clamped to it"),
            Adjustment::Sanitized { nan, infinite } => format!("replaced {nan} NaN and {infinite} infinite texels, as sanitising asks"),
        }
    }
}

impl std::fmt::Display for Adjustment {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.describe(&|field| format!("`{}`", field.name())))
    }
}
