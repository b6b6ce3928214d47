//! Display transforms for previews and the viewer: exposure, tone curves and the sRGB
//! encoding.
//!
//! - ACES filmic, Narkowicz's fit (K. Narkowicz 2015, "ACES Filmic Tone Mapping Curve"):
//!   `f(x) = x(2.51x + 0.03) / (x(2.43x + 0.59) + 0.14)`.
//! - Reinhard (Reinhard et al. 2002, "Photographic Tone Reproduction", eq. 3): `x/(1+x)`.
//! - Exposure from the log-average luminance with key 0.18 (Reinhard et al. 2002, eq. 1–2).
//! - sRGB transfer function (IEC 61966-2-1).

use crate::math;
use spirv_std::glam::Vec3;

/// Which tone curve to apply.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
#[repr(u32)]
pub enum Tonemapper {
    /// Narkowicz's ACES fit.
    #[default]
    Aces = 0,
    /// Reinhard's `x/(1+x)`.
    Reinhard = 1,
    /// Clamp to [0, 1].
    Clamp = 2,
}


/// Rec. 709 relative luminance.
#[inline]
pub fn luminance(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

/// Narkowicz's ACES filmic curve on one channel, clamped to [0, 1].
#[inline]
pub fn aces(x: f32) -> f32 {
    // Above 10⁴ the curve is 1 to f32 precision; the cut also keeps x² finite (and ∞/∞
    // away) for any input. NaN maps to 0.
    if x > 1e4 {
        return 1.0;
    }
    let x = math::max(x, 0.0);
    math::saturate(x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14))
}

/// Reinhard's curve on one channel.
#[inline]
pub fn reinhard(x: f32) -> f32 {
    if x > 1e30 {
        return 1.0;
    }
    let x = math::max(x, 0.0);
    x / (1.0 + x)
}

/// The sRGB encoding of a linear value in [0, 1].
#[inline]
pub fn linear_to_srgb(x: f32) -> f32 {
    let x = math::saturate(x);
    if x <= 0.003_130_8 { 12.92 * x } else { 1.055 * math::pow(x, 1.0 / 2.4) - 0.055 }
}

/// The linear value of an sRGB-encoded value in [0, 1].
#[inline]
pub fn srgb_to_linear(x: f32) -> f32 {
    let x = math::saturate(x);
    if x <= 0.040_45 { x / 12.92 } else { math::pow((x + 0.055) / 1.055, 2.4) }
}

/// Exposure that maps log-average luminance `log_average` to middle grey (key 0.18).
#[inline]
pub fn key_exposure(log_average: f32) -> f32 {
    if log_average > 0.0 { 0.18 / log_average } else { 1.0 }
}

/// Linear radiance to linear display values in [0, 1]: exposure and tone curve.
#[cfg_attr(target_arch = "spirv", inline(never))]
#[cfg_attr(not(target_arch = "spirv"), inline)]
pub fn tone(c: Vec3, exposure: f32, curve: Tonemapper) -> Vec3 {
    let e = c * exposure;
    match curve {
        Tonemapper::Aces => Vec3::new(aces(e.x), aces(e.y), aces(e.z)),
        Tonemapper::Reinhard => Vec3::new(reinhard(e.x), reinhard(e.y), reinhard(e.z)),
        Tonemapper::Clamp => Vec3::new(math::saturate(e.x), math::saturate(e.y), math::saturate(e.z)),
    }
}

/// Linear radiance to display sRGB in [0, 1]: exposure, tone curve, encoding.
#[inline]
pub fn display(c: Vec3, exposure: f32, curve: Tonemapper) -> Vec3 {
    let t = tone(c, exposure, curve);
    Vec3::new(linear_to_srgb(t.x), linear_to_srgb(t.y), linear_to_srgb(t.z))
}
