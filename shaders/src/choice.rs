//! The one idiom for a closed set of choices that crosses between host and shader: a
//! `#[repr(u32)]` enum defined once, whose [`Choice::code`] goes into parameter blocks
//! (the shaders compare codes with `Enum::Variant as u32`) and whose [`Choice::name`] is
//! what scene files, manifests and command-line flags spell. The host has no mirror types:
//! it parses, prints and decodes these through [`Choice`].

use crate::brdf::microfacet::Masking;
use crate::equirect::Facing;
use crate::prefilter::{Lobe, RoughnessMapping};
use crate::shade::{DiffuseModel, FresnelForm, SpecularModel};
use crate::tonemap::Tonemapper;

/// A closed set of named choices.
pub trait Choice: Copy + PartialEq + 'static {
    /// Every choice, in code order.
    const ALL: &'static [Self];

    /// The name files and flags spell.
    fn name(self) -> &'static str;

    /// The code parameter blocks carry.
    fn code(self) -> u32;

    /// The choice called `name`, if any.
    fn from_name(name: &str) -> Option<Self> {
        Self::ALL.iter().copied().find(|c| c.name() == name)
    }

    /// The choice whose code is `code`; unknown codes give the first choice, as the
    /// shaders read them.
    fn from_code(code: u32) -> Self {
        Self::ALL.iter().copied().find(|c| c.code() == code).unwrap_or(Self::ALL[0])
    }
}

/// Implements [`Choice`] for a fieldless `#[repr(u32)]` enum: its variants in code order,
/// each with its name; and `from_u32`, the decoder the shaders read parameter blocks with
/// (unknown codes give the first variant), which [`Choice::from_code`] is too.
#[macro_export]
macro_rules! choice {
    ($t:ty: $first:ident => $first_name:literal $(, $v:ident => $n:literal)* $(,)?) => {
        impl $t {
            /// The choice whose `u32` code is `code`, as parameter blocks carry it;
            /// unknown codes give the first choice. (A chain of comparisons, which
            /// rust-gpu compiles: no table, no early return.)
            #[inline]
            pub fn from_u32(code: u32) -> Self {
                #[allow(unused_mut)]
                let mut choice = <$t>::$first;
                $(
                    if code == <$t>::$v as u32 {
                        choice = <$t>::$v;
                    }
                )*
                choice
            }
        }
        impl $crate::choice::Choice for $t {
            const ALL: &'static [Self] = &[<$t>::$first $(, <$t>::$v)*];
            fn name(self) -> &'static str {
                match self {
                    <$t>::$first => $first_name,
                    $(<$t>::$v => $n,)*
                }
            }
            fn code(self) -> u32 {
                self as u32
            }
            fn from_code(code: u32) -> Self {
                <$t>::from_u32(code)
            }
        }
    };
}

choice!(RoughnessMapping: Linear => "linear", Quadratic => "quadratic", Geometric => "geometric", Filament => "filament");
choice!(Lobe: Ggx => "ggx", Charlie => "charlie");
choice!(Masking: SmithSchlick => "schlick", SmithCorrelated => "correlated");
choice!(Facing: NegZ => "-z", PosX => "+x", PosZ => "+z", NegX => "-x");
choice!(Tonemapper: Aces => "aces", Reinhard => "reinhard", Clamp => "clamp");
choice!(DiffuseModel: Lambert => "lambert", OrenNayar => "oren-nayar", FresnelWeighted => "fresnel-weighted");
choice!(SpecularModel: CookTorrance => "cook-torrance", Phong => "phong", BlinnPhong => "blinn-phong", None => "none");
choice!(FresnelForm: Schlick => "schlick", SphericalGaussian => "spherical-gaussian");

/// Declares a set of one-bit flags on a `u32` field of a parameter block, the other idiom
/// that crosses between host and shader: each flag an associated constant `1 << bit` of
/// the type, with its doc, and `FLAGS`, every flag's constant in bit order. Two flags on one
/// bit, or a flag on a bit of the `reserved` mask (bits another field of the same word
/// holds, as the shading ladder's fetch count), fail to compile.
///
/// ```
/// # struct Options;
/// splitsum_shaders::flags!(Options, reserved (0b1100) {
///     /// First.
///     FIRST = 0,
///     /// Second.
///     SECOND = 1,
/// });
/// assert_eq!((Options::FIRST, Options::SECOND), (1, 2));
/// assert_eq!(Options::FLAGS, [1, 2]);
/// ```
///
/// Two flags on one bit do not compile:
///
/// ```compile_fail
/// # struct Options;
/// splitsum_shaders::flags!(Options { A = 0, B = 0 });
/// ```
///
/// Nor does a flag on a reserved bit:
///
/// ```compile_fail
/// # struct Options;
/// splitsum_shaders::flags!(Options, reserved (0b100) { A = 2 });
/// ```
#[macro_export]
macro_rules! flags {
    ($t:ty $(, reserved ($reserved:expr))? { $($(#[$meta:meta])* $name:ident = $bit:expr),* $(,)? }) => {
        impl $t {
            $(
                $(#[$meta])*
                pub const $name: u32 = 1 << $bit;
            )*
            /// Every flag of this set, in bit order.
            pub const FLAGS: [u32; [$($bit),*].len()] = [$(1 << $bit),*];
        }
        const _: () = {
            let flags: [u32; [$($bit),*].len()] = [$(1 << $bit),*];
            let mut seen: u32 = 0 $(| $reserved)?;
            let mut i = 0;
            while i < flags.len() {
                assert!(seen & flags[i] == 0, "two flags share a bit, or a flag takes a reserved bit");
                seen |= flags[i];
                i += 1;
            }
        };
    };
}
