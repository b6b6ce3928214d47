//! Reflectance models, each in its own module with its formula and source:
//!
//! - [`microfacet`]: the GGX normal distribution and Smith–Schlick masking (Cook–Torrance).
//! - [`fresnel`]: Schlick's approximation, its roughness-aware variant, and UE4's
//!   spherical-Gaussian form.
//! - [`diffuse`]: Lambert, Oren–Nayar, and the Fresnel-weighted diffuse of Ashikhmin–Shirley.
//! - [`phong`]: normalised Phong and Blinn–Phong lobes, kept for comparison.
//! - [`sheen`]: the Charlie sheen lobe (Estevez & Kulla 2017) and its two visibility terms.
//!
//! Conventions: all vectors are unit and point away from the surface; `roughness` is the
//! artist ("perceptual") roughness `r` in [0, 1] and the GGX width is `α = r²`
//! (Burley 2012, "Physically-Based Shading at Disney", §5.4).

pub mod diffuse;
pub mod fresnel;
pub mod microfacet;
pub mod phong;
pub mod sheen;

/// GGX width `α = r²` from perceptual roughness (Burley 2012 §5.4).
#[inline]
pub fn alpha_from_roughness(roughness: f32) -> f32 {
    roughness * roughness
}
