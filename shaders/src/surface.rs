//! Surfaces of glTF 2.0 meshes: from the material's factors and the texel values read at a
//! point (by the GPU's sampler, or by the CPU reference renderer's software filtering) to
//! a shading [`Material`] and normal.
//!
//! glTF 2.0 §3.9 (metallic–roughness material): base colour = factor × texture (sRGB
//! texture, decoded to linear before filtering); metalness = factor × texture.B,
//! roughness = factor × texture.G; occlusion `1 + strength·(texture.R − 1)`; emission =
//! factor × texture (sRGB). `KHR_materials_sheen`: sheen colour = factor × texture.RGB
//! (sRGB), sheen roughness = factor × texture.A. Normal texture: tangent-space `n = normalize((2t − 1)·(s, s, 1))`,
//! mapped by the tangent frame `(T, B = w·(N × T), N)` (§3.9.3; Mikkelsen 2008).

use crate::sampling;
use crate::shade::{Material, ShadeOptions};
use bytemuck::{Pod, Zeroable};
use spirv_std::glam::{Mat4, UVec4, Vec3, Vec4};

/// The per-primitive uniform block of a mesh.
#[derive(Copy, Clone, Debug, PartialEq, Pod, Zeroable)]
#[repr(C)]
pub struct MeshMaterial {
    /// Base colour factor (linear RGBA).
    pub base_color: Vec4,
    /// Emissive factor (xyz); `w` = normal texture scale.
    pub emissive: Vec4,
    /// Metallic factor, roughness factor, occlusion strength, unused.
    pub params: Vec4,
    /// Which textures are present: bit 0 base colour, 1 metallic–roughness, 2 normal,
    /// 3 occlusion, 4 emissive.
    pub textures: UVec4,
    /// Roughness clamped to `[x, y]`, metalness to `[z, w]` (a scene's declared ranges).
    pub ranges: Vec4,
    /// The shading models of this material.
    pub options: ShadeOptions,
    /// `KHR_materials_sheen`: sheen colour factor (`xyz`, linear) and sheen roughness
    /// factor (`w`).
    pub sheen: Vec4,
}

crate::flags!(MeshMaterial {
    /// Base colour texture present.
    BASE_COLOR = 0,
    /// Metallic–roughness texture present.
    METALLIC_ROUGHNESS = 1,
    /// Normal texture present.
    NORMAL = 2,
    /// Occlusion texture present.
    OCCLUSION = 3,
    /// Emissive texture present.
    EMISSIVE = 4,
    /// Sheen colour texture present (`sheenColorTexture`, sRGB).
    SHEEN_COLOR = 5,
    /// Sheen roughness texture present (`sheenRoughnessTexture`, alpha channel).
    SHEEN_ROUGHNESS = 6,
});

/// Texel values read at one point, one per texture slot (ignored where the slot is empty).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Texels {
    /// Base colour (linear, decoded from sRGB).
    pub base_color: Vec4,
    /// Metallic–roughness (B metal, G rough).
    pub metallic_roughness: Vec4,
    /// Tangent-space normal, encoded in [0, 1].
    pub normal: Vec4,
    /// Occlusion in R.
    pub occlusion: Vec4,
    /// Emission (linear, decoded from sRGB).
    pub emissive: Vec4,
    /// Sheen colour (linear, decoded from sRGB).
    pub sheen_color: Vec4,
    /// Sheen roughness in A.
    pub sheen_roughness: Vec4,
}

#[inline]
fn has(m: &MeshMaterial, bit: u32) -> bool {
    m.textures.x & bit != 0
}

/// The shading material and unit shading normal at a point with interpolated geometric
/// normal `normal` and tangent `tangent` (`w` = handedness).
pub fn material(m: &MeshMaterial, t: &Texels, normal: Vec3, tangent: Vec4) -> (Material, Vec3) {
    let base = if has(m, MeshMaterial::BASE_COLOR) { m.base_color * t.base_color } else { m.base_color };
    let (mut metallic, mut roughness) = (m.params.x, m.params.y);
    if has(m, MeshMaterial::METALLIC_ROUGHNESS) {
        metallic *= t.metallic_roughness.z;
        roughness *= t.metallic_roughness.y;
    }
    let occlusion = if has(m, MeshMaterial::OCCLUSION) { 1.0 + m.params.z * (t.occlusion.x - 1.0) } else { 1.0 };
    let emissive = if has(m, MeshMaterial::EMISSIVE) { m.emissive.truncate() * t.emissive.truncate() } else { m.emissive.truncate() };
    let sheen_color = if has(m, MeshMaterial::SHEEN_COLOR) { m.sheen.truncate() * t.sheen_color.truncate() } else { m.sheen.truncate() };
    let sheen_roughness = if has(m, MeshMaterial::SHEEN_ROUGHNESS) { m.sheen.w * t.sheen_roughness.w } else { m.sheen.w };
    let n = sampling::normalize_or(normal, Vec3::Z);
    let shading_normal = if has(m, MeshMaterial::NORMAL) {
        let s = m.emissive.w;
        let c = t.normal.truncate() * 2.0 - Vec3::ONE;
        let local = sampling::normalize_or(Vec3::new(c.x * s, c.y * s, c.z), Vec3::Z);
        // Gram–Schmidt: the interpolated tangent is no longer exactly perpendicular.
        let tt = tangent.truncate();
        let tan = sampling::normalize_or(tt - n * n.dot(tt), sampling::orthonormal_basis(n).0);
        let bitan = n.cross(tan) * if tangent.w < 0.0 { -1.0 } else { 1.0 };
        sampling::normalize_or(tan * local.x + bitan * local.y + n * local.z, n)
    } else {
        n
    };
    (
        Material {
            base_color: base.truncate(),
            metallic: crate::math::clamp(metallic, m.ranges.z, m.ranges.w),
            roughness: crate::math::clamp(roughness, m.ranges.x, m.ranges.y),
            occlusion,
            emissive,
            sheen_color,
            sheen_roughness: crate::math::saturate(sheen_roughness),
        },
        shading_normal,
    )
}

/// Depth in [0, 1] of a point at distance `d` along the view direction, for the
/// right-handed perspective projection with depth range [0, 1] (glam `perspective_rh`):
/// `far/(far − near)·(1 − near/d)`.
#[inline]
pub fn depth(d: f32, near: f32, far: f32) -> f32 {
    far / (far - near) * (1.0 - near / d)
}

/// Clip-space position of world point `p`.
#[inline]
pub fn clip(view_proj: &Mat4, p: Vec3) -> Vec4 {
    *view_proj * p.extend(1.0)
}
