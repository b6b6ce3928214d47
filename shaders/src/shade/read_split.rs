//! The share of a split source's excess in the shading (`crate::excess`): the brightest
//! texels of the source, taken out of the cubes the split sum reads, lit at each point by
//! the glTF BRDF itself.

use super::*;
use spirv_std::glam::{Vec2, Vec3, Vec4};

/// The excess list's share of the radiance the specular lobe of `m` averages at normal `n`
/// and view `v` (`crate::excess`; nothing without a list). For Cook–Torrance, each entry lit
/// by the glTF BRDF's specular term over its texel (`excess::reflected_weight`), whatever
/// the view, the entries below the horizon left out, then divided by the weight [`ibl`]
/// multiplies the lobe's radiance by (`F·A + B`, the table `brdf`), so that the shaded
/// colour holds the excess exactly; for the other models, the excess's prefiltered terms
/// along the read direction, those below the horizon left out.
#[allow(clippy::too_many_arguments)]
pub fn excess_lobe_radiance(shape: EnvironmentShape, specular: &[Vec4], opts: ShadeOptions, m: &Material, n: Vec3, v: Vec3, brdf: Vec2) -> Vec3 {
    let count = shape.excess_entries;
    if count == 0 {
        return Vec3::ZERO;
    }
    let base = shape.excess_start();
    if opts.specular != SpecularModel::CookTorrance as u32 {
        let dir = read_direction(opts.flags, n, v, m.roughness);
        return crate::excess::prefiltered_excess(specular, base, count, dir, m.roughness, n).truncate();
    }
    let n_dot_v = math::max(n.dot(v), MIN_N_DOT_V);
    let alpha = alpha_from_roughness(math::saturate(m.roughness));
    let f0 = m.f0();
    let mut acc = math::CompensatedSum4::new();
    let mut j = 0;
    while j < count {
        let at = base + crate::bright::ENTRY * j;
        let w = crate::excess::reflected_weight(n, v, n_dot_v, alpha, specular[at as usize]);
        if w.y > 0.0 {
            acc.add((specular[(at + 1) as usize].truncate() * fresnel(opts.fresnel, f0, w.x) * w.y).extend(0.0));
        }
        j += 1;
    }
    let albedo = ibl_fresnel(opts, f0, n_dot_v, m.roughness) * brdf.x + Vec3::splat(brdf.y);
    let reflected = acc.total().truncate();
    math::finite4((reflected / albedo.max(Vec3::splat(1e-12))).extend(0.0)).truncate()
}

/// The excess list's irradiance over π at normal `n` (`crate::excess::irradiance`; nothing
/// without a list), to add to the residual's irradiance read.
#[inline]
pub fn excess_irradiance(shape: EnvironmentShape, specular: &[Vec4], n: Vec3) -> Vec3 {
    if shape.excess_entries == 0 {
        return Vec3::ZERO;
    }
    crate::excess::irradiance(specular, shape.excess_start(), shape.excess_entries, n)
}
