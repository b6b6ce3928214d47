//! Cube maps stored in a plain buffer, with software filtering that the CPU reproduces
//! bit for bit.
//!
//! **Faces and orientation** follow Vulkan/OpenGL (OpenGL 4.6 §8.13, Table 8.19) and KTX2:
//! faces `+X, −X, +Y, −Y, +Z, −Z`; for a direction with major axis `m`, the face
//! coordinates are `u = (s_c/|m| + 1)/2`, `v = (t_c/|m| + 1)/2`, and row 0 of a face is
//! `v = 0`.
//!
//! **Storage**: RGBA f32 texels (`Vec4`), mip levels one after the other, each level six
//! faces of `sᵢ × sᵢ` texels in row-major order, `sᵢ = max(1, s₀ >> i)` ([`CubeLayout`]).
//!
//! **Filtering**: bilinear within a face; taps that fall off the face are re-projected onto
//! the neighbouring face (the texel whose centre the extrapolated texel centre projects
//! into), and the missing fourth tap at a cube corner is dropped with the weights
//! renormalised, i.e. the corner value is the weighted mean of the three texels that meet
//! there (the "seamless" filtering of ARB_seamless_cube_map and of AMD CubeMapGen).
//! Trilinear filtering blends two such levels.
//!
//! **Solid angle** of a texel: the exact area of its spherical quad, as two spherical
//! triangles by Van Oosterom & Strackee's formula
//! `tan(Ω/2) = |a·(b×c)| / (|a||b||c| + (a·b)|c| + (a·c)|b| + (b·c)|a|)` (IEEE Trans.
//! Biomed. Eng. 30(2), 1983). On the face plane `z = 1` the triple product of a texel
//! triangle is exactly `Δ²` (`Δ = 2/s`), so the formula has no cancellation even for tiny
//! texels.

use crate::math::{self, CompensatedSum, CompensatedSum4, MeanPartial};
use crate::tonemap;
use spirv_std::glam::{Vec2, Vec3, Vec4};

/// Number of faces of a cube map.
pub const FACES: u32 = 6;

/// Size and mip count of a cube map stored level after level in a buffer. Face sizes are
/// powers of two (the readers and the bake settings check it).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct CubeLayout {
    /// Face size of level 0, in texels.
    pub size: u32,
    /// Number of mip levels stored.
    pub levels: u32,
}

impl CubeLayout {
    /// A layout of `levels` mips starting at `size`×`size` faces.
    pub const fn new(size: u32, levels: u32) -> Self {
        Self { size, levels }
    }

    /// The number of levels of a full mip chain down to 1×1 for face size `size`.
    pub fn full_chain(size: u32) -> u32 {
        32 - size.max(1).leading_zeros()
    }

    /// Face size of level `level`: `max(1, size >> level)`.
    #[inline]
    pub fn level_size(&self, level: u32) -> u32 {
        let s = self.size >> level;
        if s == 0 { 1 } else { s }
    }

    /// Index of the first texel of level `level`, in closed form for the power-of-two face
    /// sizes every cube here has: `6·Σ_{k<L} (s/2ᵏ)² = 8(s² − (s/2ᴸ)²)` for `L ≤ log₂ s`,
    /// then 6 more per 1×1 level. No loop: some drivers charge every loop entered, even an
    /// empty one, against a shader's iteration budget (see `math::CHUNK`), and this runs
    /// for every texel tap.
    #[inline]
    pub fn level_offset(&self, level: u32) -> u32 {
        let s = self.size;
        // log₂ s from the f32 exponent (`leading_zeros` may be lowered to a loop).
        let p = ((s as f32).to_bits() >> 23) - 127; // level p is 1×1
        if level <= p {
            let t = s >> level;
            8 * (s * s - t * t)
        } else {
            8 * s * s - 2 + FACES * (level - p - 1)
        }
    }

    /// The first level whose faces are at most `face` wide (the level of that size in a
    /// power-of-two chain), or the last level if none is.
    #[inline]
    pub fn level_of_size(&self, face: u32) -> u32 {
        let mut level = 0;
        while level + 1 < self.levels && self.level_size(level) > face {
            level += 1;
        }
        level
    }

    /// Number of texels in all levels.
    #[inline]
    pub fn texel_count(&self) -> u32 {
        self.level_offset(self.levels)
    }

    /// Index of texel `(x, y)` of `face` in `level`.
    #[inline]
    pub fn index(&self, level: u32, face: u32, x: u32, y: u32) -> u32 {
        let s = self.level_size(level);
        self.level_offset(level) + (face * s + y) * s + x
    }
}

/// The face of the major axis of `d` and the face coordinates `(u, v)` ∈ [0, 1]².
///
/// Ties (edges and corners) go to `x` before `y` before `z`, so every direction has one
/// face on every backend. The zero vector maps to the centre of face `+X`.
#[inline]
pub fn dir_to_face_uv(d: Vec3) -> (u32, Vec2) {
    let ax = math::abs(d.x);
    let ay = math::abs(d.y);
    let az = math::abs(d.z);
    let (face, ma, sc, tc) = if ax >= ay && ax >= az {
        if d.x >= 0.0 { (0, ax, -d.z, -d.y) } else { (1, ax, d.z, -d.y) }
    } else if ay >= az {
        if d.y >= 0.0 { (2, ay, d.x, d.z) } else { (3, ay, d.x, -d.z) }
    } else if d.z >= 0.0 {
        (4, az, d.x, -d.y)
    } else {
        (5, az, -d.x, -d.y)
    };
    if !(ma > 0.0) {
        return (0, Vec2::splat(0.5));
    }
    let inv = 0.5 / ma;
    (face, Vec2::new(sc * inv + 0.5, tc * inv + 0.5))
}

/// The point of face `face` at face coordinates `uv`, on the unit cube (not normalised).
#[inline]
pub fn face_uv_to_cube(face: u32, uv: Vec2) -> Vec3 {
    let a = 2.0 * uv.x - 1.0;
    let b = 2.0 * uv.y - 1.0;
    match face {
        0 => Vec3::new(1.0, -b, -a),
        1 => Vec3::new(-1.0, -b, a),
        2 => Vec3::new(a, 1.0, b),
        3 => Vec3::new(a, -1.0, -b),
        4 => Vec3::new(a, -b, 1.0),
        _ => Vec3::new(-a, -b, -1.0),
    }
}

/// The unit direction through face coordinates `uv` of `face`.
#[inline]
pub fn face_uv_to_dir(face: u32, uv: Vec2) -> Vec3 {
    let p = face_uv_to_cube(face, uv);
    p * (1.0 / math::sqrt(p.dot(p)))
}

/// The unit direction through the centre of texel `(x, y)` of a `size`×`size` face.
#[inline]
pub fn texel_dir(face: u32, x: u32, y: u32, size: u32) -> Vec3 {
    let s = size as f32;
    face_uv_to_dir(face, Vec2::new((x as f32 + 0.5) / s, (y as f32 + 0.5) / s))
}

/// The texel `(face, x, y)` of a `size`² cube that holds direction `(−x, y, z)` of texel
/// `(face, x, y)`: the cube mirrored in `x`, which Filament's cmgen applies to every input
/// by default (`CubemapUtils::mirrorCubemap`, undone by `--no-mirror`). An exact texel
/// permutation: `+X` and `−X` swap and every face's columns reverse (the `sc` of the
/// OpenGL face table changes sign with `x` on every face).
#[inline]
pub fn mirrored_x_texel(face: u32, x: u32, y: u32, size: u32) -> (u32, u32, u32) {
    let f = if face == 0 {
        1
    } else if face == 1 {
        0
    } else {
        face
    };
    (f, size - 1 - x, y)
}

/// Solid angle subtended at the origin by triangle `a, b, c` on the plane `z = 1`, whose
/// triple product `a·(b×c)` is `triple` (Van Oosterom & Strackee 1983).
#[inline]
fn plane_triangle_solid_angle(a: Vec3, b: Vec3, c: Vec3, triple: f32) -> f32 {
    let la = math::sqrt(a.dot(a));
    let lb = math::sqrt(b.dot(b));
    let lc = math::sqrt(c.dot(c));
    let den = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
    2.0 * math::atan2(triple, den)
}

/// Exact solid angle (steradians) of texel `(x, y)` of a `size`×`size` cube face.
/// Summed over the six faces it is 4π to f32 rounding.
#[inline]
pub fn texel_solid_angle(x: u32, y: u32, size: u32) -> f32 {
    let d = 2.0 / size as f32;
    let x0 = x as f32 * d - 1.0;
    let y0 = y as f32 * d - 1.0;
    let x1 = x0 + d;
    let y1 = y0 + d;
    let p00 = Vec3::new(x0, y0, 1.0);
    let p10 = Vec3::new(x1, y0, 1.0);
    let p11 = Vec3::new(x1, y1, 1.0);
    let p01 = Vec3::new(x0, y1, 1.0);
    let t = d * d; // a·(b×c) of both triangles, exactly
    plane_triangle_solid_angle(p00, p10, p11, t) + plane_triangle_solid_angle(p00, p11, p01, t)
}

/// The texel of level `level` whose face square contains direction `d` (nearest texel).
#[inline]
pub fn texel_of_dir(layout: CubeLayout, level: u32, d: Vec3) -> u32 {
    let s = layout.level_size(level);
    let (face, uv) = dir_to_face_uv(d);
    let sf = s as f32;
    let x = math::clamp(math::floor(uv.x * sf), 0.0, sf - 1.0) as u32;
    let y = math::clamp(math::floor(uv.y * sf), 0.0, sf - 1.0) as u32;
    layout.index(level, face, x, y)
}

/// Index of the texel that tap `(x, y)` of `face` reads, where `x` or `y` may be one texel
/// off the face: such a tap is re-projected onto the neighbouring face.
#[inline(always)]
fn tap_index(layout: CubeLayout, level: u32, face: u32, x: i32, y: i32, s: u32) -> u32 {
    let si = s as i32;
    let inside = x >= 0 && x < si && y >= 0 && y < si;
    // Natively, most taps are inside and skip the wrap. On the GPU there is no branch on
    // the way: llvmpipe runs both sides of a branch whenever any lane takes either, and
    // the geometric wrap this table replaced cost a third of the prefilter there.
    #[cfg(not(target_arch = "spirv"))]
    if inside {
        return layout.index(level, face, x as u32, y as u32);
    }
    // Off the face in one axis: the edge crossed and the coordinate along it.
    let edge = if x < 0 { 0 } else if x >= si { 1 } else if y < 0 { 2 } else { 3 };
    let t = (if edge < 2 { y } else { x }) as u32;
    let (f, ex, ey) = edge_texel(face, edge, t, s);
    if inside { layout.index(level, face, x as u32, y as u32) } else { layout.index(level, f, ex, ey) }
}

/// Where the texel one step across edge `edge` (0: x = −1, 1: x = s, 2: y = −1, 3: y = s) of
/// `face`, at coordinate `t` along that edge, lies on the neighbouring face of an `s`-wide
/// level: `(face, x, y)`. This is the texel whose square holds the direction through that
/// texel's centre on the extended face plane, which is what a seamless lookup reads
/// (`texel_of_dir(face_uv_to_cube(face, uv))`): projected onto the neighbour, its
/// along-edge coordinate `(t + 1)/(s + 1)` of the face lies strictly inside texel `t` (or
/// `s − 1 − t`), and its across-edge one inside the edge texel, so the wrap is a
/// permutation of texels, tabulated here per face as four 7-bit entries (neighbour face;
/// x and y as 0: 0, 1: s − 1, 2: t, 3: s − 1 − t). `shaders/tests/cubemap.rs` checks every
/// entry against the geometric lookup at every size up to 1024.
#[inline]
pub fn edge_texel(face: u32, edge: u32, t: u32, s: u32) -> (u32, u32, u32) {
    let word: u32 = match face {
        0 => 0x097a_a2cc,
        1 => 0x0c70_a24d,
        2 => 0x0287_4c11,
        3 => 0x07ad_1839,
        4 => 0x026c_a049,
        _ => 0x0766_a0c8,
    };
    let entry = (word >> (7 * edge)) & 127;
    let last = s.wrapping_sub(1);
    let pick = |code: u32| if code == 0 { 0 } else if code == 1 { last } else if code == 2 { t } else { last.wrapping_sub(t) };
    (entry & 7, pick((entry >> 3) & 3), pick((entry >> 5) & 3))
}

/// [`tap_texel`] of a tap that is dropped.
pub const NO_TAP: u32 = u32::MAX;

/// The buffer index of bilinear tap `(x, y)` of `face` of an `s`-wide level `level`, where
/// `x` or `y` may be one texel off the face (`tap_index`); [`NO_TAP`] for a tap off the
/// face in both axes (a cube corner), which a lookup drops, weight and all.
///
/// It takes no buffer, so rust-gpu keeps it a function that every tap of every lookup
/// calls (a buffer argument forces inlining): with the face wrap inlined at each tap, the
/// display's fragment shader was 2.3 MB of WGSL, and a browser's compiler (Chromium's
/// SwiftShader) ran out of memory on any kernel that held two lookups in one loop.
#[cfg_attr(target_arch = "spirv", inline(never))]
#[cfg_attr(not(target_arch = "spirv"), inline)]
pub fn tap_texel(layout: CubeLayout, level: u32, face: u32, s: u32, x: i32, y: i32) -> u32 {
    let si = s as i32;
    let x_in = x >= 0 && x < si;
    let y_in = y >= 0 && y < si;
    if x_in || y_in { tap_index(layout, level, face, x, y, s) } else { NO_TAP }
}

/// Seamless bilinear lookup of level `level` in direction `d` (need not be unit length).
///
/// The four taps run as a loop around one [`tap_texel`] call, so that the face wrap is
/// emitted once per lookup. The sums start at −0, the identity of IEEE addition, so they
/// equal the unrolled `a + b + c + d` bit for bit.
#[inline]
pub fn sample_bilinear(texels: &[Vec4], layout: CubeLayout, level: u32, d: Vec3) -> Vec4 {
    let (face, uv) = dir_to_face_uv(d);
    bilinear_at(texels, layout, level, face, uv)
}

/// [`sample_bilinear`] at face coordinates `uv` of `face` ([`dir_to_face_uv`]), which a
/// trilinear lookup finds once for both its levels.
#[cfg_attr(not(target_arch = "spirv"), inline(always))]
fn bilinear_at(texels: &[Vec4], layout: CubeLayout, level: u32, face: u32, uv: Vec2) -> Vec4 {
    let s = layout.level_size(level);
    let sf = s as f32;
    let fx = uv.x * sf - 0.5;
    let fy = uv.y * sf - 0.5;
    let x0f = math::floor(fx);
    let y0f = math::floor(fy);
    let tx = fx - x0f;
    let ty = fy - y0f;
    let x0 = x0f as i32;
    let y0 = y0f as i32;
    // Natively, the four taps of a lookup inside one face (nearly all of them) are read
    // as two pairs of neighbours without the wrap: the same weights, sums and order.
    #[cfg(not(target_arch = "spirv"))]
    if x0 >= 0 && y0 >= 0 && x0 + 1 < s as i32 && y0 + 1 < s as i32 {
        let i = layout.index(level, face, x0 as u32, y0 as u32) as usize;
        let row = s as usize;
        let quad = &texels[i..i + row + 2];
        let (w0, w1, w2, w3) = ((1.0 - tx) * (1.0 - ty), tx * (1.0 - ty), (1.0 - tx) * ty, tx * ty);
        let acc = Vec4::splat(-0.0) + quad[0] * w0 + quad[1] * w1 + quad[row] * w2 + quad[row + 1] * w3;
        let wsum = -0.0 + w0 + w1 + w2 + w3;
        return math::finite4(acc * (1.0 / wsum));
    }
    let mut acc = Vec4::splat(-0.0);
    let mut wsum = -0.0;
    let mut k = 0u32;
    while k < 4 {
        let (dx, dy) = ((k & 1) as i32, (k >> 1) as i32);
        let w = (if dx == 1 { tx } else { 1.0 - tx }) * (if dy == 1 { ty } else { 1.0 - ty });
        let i = tap_texel(layout, level, face, s, x0 + dx, y0 + dy);
        // A dropped tap is not read: an infinite texel times a zero weight would be NaN.
        let (v, w) = if i != NO_TAP { (texels[i as usize] * w, w) } else { (Vec4::ZERO, 0.0) };
        acc += v;
        wsum += w;
        k += 1;
    }
    math::finite4(acc * (1.0 / wsum))
}

/// Seamless trilinear lookup at fractional level `lod`, clamped to the stored levels.
pub fn sample_lod(texels: &[Vec4], layout: CubeLayout, d: Vec3, lod: f32) -> Vec4 {
    sample_levels(texels, layout, d, lod, false)
}

/// [`sample_lod`] with the two levels blended in log luminance: the linear blend's
/// colour, scaled so that its luminance is `L₀^(1−t)·L₁^t`, the geometric blend of the two
/// levels' luminances. Near a bright source, prefiltered radiance changes by a factor from
/// one roughness level to the next rather than by an amount, so a linear blend between
/// mips overshoots towards the brighter level; the geometric one follows the factor.
/// (Luminances below `1e-12` are taken as `1e-12`; a constant environment is returned as it
/// is.)
#[inline]
pub fn sample_lod_log(texels: &[Vec4], layout: CubeLayout, d: Vec3, lod: f32) -> Vec4 {
    sample_levels(texels, layout, d, lod, true)
}

/// The bilinear samples of the two levels around `lod` (clamped to the stored levels),
/// blended linearly ([`sample_lod`]), or in log luminance where `log` ([`sample_lod_log`]).
/// A caller that chooses at run time calls this once with the choice rather than both:
/// each call is a lookup the GPU compiler emits again.
#[inline]
pub fn sample_levels(texels: &[Vec4], layout: CubeLayout, d: Vec3, lod: f32, log: bool) -> Vec4 {
    let (m0, t) = lod_levels(lod, layout.levels);
    let (face, uv) = dir_to_face_uv(d);
    let a = bilinear_at(texels, layout, m0, face, uv);
    if t > 0.0 {
        let b = bilinear_at(texels, layout, m0 + 1, face, uv);
        let linear = a * (1.0 - t) + b * t;
        if log {
            let tiny = 1e-12;
            let la = math::max(tonemap::luminance(a.truncate()), tiny);
            let lb = math::max(tonemap::luminance(b.truncate()), tiny);
            let geometric = math::exp2(math::log2(la) * (1.0 - t) + math::log2(lb) * t);
            let scale = geometric / math::max(tonemap::luminance(linear.truncate()), tiny);
            math::finite4((linear.truncate() * scale).extend(linear.w))
        } else {
            math::finite4(linear)
        }
    } else {
        a
    }
}

/// The levels a lookup at `lod` blends on a cube of `levels` levels ([`sample_levels`]):
/// the lower one, `m0`, and the weight `t` of `m0 + 1`, 0 where `lod` is clamped to the
/// stored levels or falls on one (then only `m0` is read).
#[inline]
pub fn lod_levels(lod: f32, levels: u32) -> (u32, f32) {
    let l = math::clamp(lod, 0.0, (levels - 1) as f32);
    let l0 = math::floor(l);
    let m0 = l0 as u32;
    (m0, if m0 + 1 < levels { l - l0 } else { 0.0 })
}

/// Texels a [`sample_levels`] lookup at `lod` reads on a cube of `levels` levels: a
/// bilinear 2×2 at each level it blends ([`lod_levels`]). For the cost model.
#[inline]
pub fn lookup_texels(lod: f32, levels: u32) -> u32 {
    if lod_levels(lod, levels).1 > 0.0 { 8 } else { 4 }
}

/// Texel `(x, y)` of `face` in level `level + 1` from the 2×2 texels it covers in
/// `level`, each weighted by its solid angle (an area-correct box filter).
pub fn downsample_texel(texels: &[Vec4], layout: CubeLayout, level: u32, face: u32, x: u32, y: u32) -> Vec4 {
    let s = layout.level_size(level);
    if s == 1 {
        return texels[layout.index(level, face, 0, 0) as usize];
    }
    downsample_with(texels, layout, level, face, x, y, downsample_weights(x, y, s))
}

/// The weights [`downsample_texel`] gives the 2×2 texels of an `s`-wide level under texel
/// `(x, y)` of the level above, in the order `(2x, 2y)`, `(2x+1, 2y)`, `(2x, 2y+1)`,
/// `(2x+1, 2y+1)`: each texel's solid angle over the four's sum, normalised first so that
/// the filtered value never exceeds the largest input (no overflow even at f32::MAX). The
/// same on every face, so the CPU backend makes them once per level.
pub fn downsample_weights(x: u32, y: u32, s: u32) -> Vec4 {
    let w00 = texel_solid_angle(2 * x, 2 * y, s);
    let w10 = texel_solid_angle(2 * x + 1, 2 * y, s);
    let w01 = texel_solid_angle(2 * x, 2 * y + 1, s);
    let w11 = texel_solid_angle(2 * x + 1, 2 * y + 1, s);
    let wsum = w00 + w10 + w01 + w11;
    Vec4::new(w00 / wsum, w10 / wsum, w01 / wsum, w11 / wsum)
}

/// [`downsample_texel`] with its weights given ([`downsample_weights`]).
#[inline]
pub fn downsample_with(texels: &[Vec4], layout: CubeLayout, level: u32, face: u32, x: u32, y: u32, w: Vec4) -> Vec4 {
    let i00 = layout.index(level, face, 2 * x, 2 * y) as usize;
    let i01 = layout.index(level, face, 2 * x, 2 * y + 1) as usize;
    math::finite4(Vec4::ZERO + texels[i00] * w.x + texels[i00 + 1] * w.y + texels[i01] * w.z + texels[i01 + 1] * w.w)
}

/// The unit direction (`xyz`) and solid angle (`w`) of texel `t` of a level with faces
/// `s` wide, texels numbered face by face, row by row: what [`weighted_level_sum`] weighs
/// a texel by. Every output texel of an exact sum needs the same ones, so a sum over a
/// level reads them from a table of them made once ([`level_geometry`]) instead of
/// computing two triangles' solid angles per term again for every output texel.
#[inline]
pub fn texel_geometry(t: u32, s: u32) -> Vec4 {
    let face = t / (s * s);
    let y = (t / s) % s;
    let x = t % s;
    texel_dir(face, x, y, s).extend(texel_solid_angle(x, y, s))
}

/// [`texel_geometry`] of every texel of a level with faces `s` wide, in order.
#[cfg(not(target_arch = "spirv"))]
pub fn level_geometry(s: u32) -> impl Iterator<Item = Vec4> {
    (0..FACES * s * s).map(move |t| texel_geometry(t, s))
}

/// Where [`weighted_level_sum`] finds the geometry of the level's texels: computed per term
/// (no table).
pub const INLINE_GEOMETRY: u32 = u32::MAX;

/// Adds texels `start .. start + count` of `level` (numbered face by face, row by row) to
/// the weighted mean `p`, each weighted by `weight(direction, solid angle)` (zero or
/// negative weights skip the texel): the exact sums of the irradiance convolution and of the
/// exact prefilter, with compensated running sums carried from chunk to chunk. The texels'
/// geometry ([`texel_geometry`]) is read from `src[geometry + t]` (a table placed after the
/// texels), or computed per term when `geometry` is [`INLINE_GEOMETRY`]; both give the same
/// values, bit for bit, when the table was computed by the same compiler.
#[inline]
#[allow(clippy::too_many_arguments)]
pub fn weighted_level_sum(
    src: &[Vec4],
    layout: CubeLayout,
    level: u32,
    geometry: u32,
    start: u32,
    count: u32,
    p: MeanPartial,
    weight: impl Fn(Vec3, f32) -> f32,
) -> MeanPartial {
    let s = layout.level_size(level);
    let base = layout.level_offset(level);
    let mut acc = CompensatedSum4::resume(p.sum, p.carry);
    let mut wsum = CompensatedSum::resume(p.weight.x, p.weight.y);
    let mut t = start;
    let end = start + count;
    // Two loops, not a choice per term: a GPU compiler that runs lanes under masks would
    // otherwise compute the inline geometry for every term even when a table holds it.
    if geometry == INLINE_GEOMETRY {
        while t < end {
            let g = texel_geometry(t, s);
            let w = weight(g.truncate(), g.w);
            if w > 0.0 {
                acc.add(src[(base + t) as usize] * w);
                wsum.add(w);
            }
            t += 1;
        }
    } else {
        while t < end {
            let g = src[(geometry + t) as usize];
            let w = weight(g.truncate(), g.w);
            if w > 0.0 {
                acc.add(src[(base + t) as usize] * w);
                wsum.add(w);
            }
            t += 1;
        }
    }
    let (sum, carry) = acc.parts();
    let (w, wc) = wsum.parts();
    MeanPartial { sum, carry, weight: Vec4::new(w, wc, 0.0, 0.0) }
}
