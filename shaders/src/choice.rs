//! The one idiom for a closed set of choices that crosses between host and shader: a
//! `#[repr(u32)]` enum defined here, whose `code` goes into parameter blocks (decoded with
//! its `from_u32`, which maps unknown codes to a stated default) and whose [`Choice::name`]
//! is what scene files, manifests and command-line flags spell. The host has no mirror
//! types: it parses and prints these through [`Choice`].

/// A closed set of named choices.
pub trait Choice: Copy + PartialEq + 'static {
    /// Every choice, in code order.
    const ALL: &'static [Self];

    /// The name files and flags spell.
    fn name(self) -> &'static str;

    /// The choice called `name`, if any.
    fn from_name(name: &str) -> Option<Self> {
        Self::ALL.iter().copied().find(|c| c.name() == name)
    }
}

use crate::brdf::microfacet::Masking;
use crate::prefilter::RoughnessMapping;
use crate::tonemap::Tonemapper;

impl Choice for RoughnessMapping {
    const ALL: &'static [Self] = &[Self::Linear, Self::Quadratic, Self::Geometric];
    fn name(self) -> &'static str {
        match self {
            Self::Linear => "linear",
            Self::Quadratic => "quadratic",
            Self::Geometric => "geometric",
        }
    }
}

impl Choice for Masking {
    const ALL: &'static [Self] = &[Self::SmithSchlick, Self::SmithCorrelated];
    fn name(self) -> &'static str {
        match self {
            Self::SmithSchlick => "schlick",
            Self::SmithCorrelated => "correlated",
        }
    }
}

impl Choice for Tonemapper {
    const ALL: &'static [Self] = &[Self::Aces, Self::Reinhard, Self::Clamp];
    fn name(self) -> &'static str {
        match self {
            Self::Aces => "aces",
            Self::Reinhard => "reinhard",
            Self::Clamp => "clamp",
        }
    }
}
