//! The CPU reference renderer's rasteriser for glTF meshes: the same coverage and
//! interpolation rules as a Vulkan rasteriser (pixel centres at half-integers, top-left
//! fill rule, perspective-correct attributes, depth affine in screen space), software
//! texture filtering (bilinear, repeat, mip 0; sRGB decoded before filtering), then the
//! same `surface::material` and `scene::shade_point` the fragment shader runs.

use crate::model::{Model, Texture};
use rayon::prelude::*;
use splitsum::Product;
use splitsum::reading::BakedEnvironment;
use splitsum_shaders::glam::{Vec2, Vec3, Vec4};
use splitsum_shaders::scene::{self, Frame};
use splitsum_shaders::surface::{self, Texels};
use splitsum_shaders::tonemap::srgb_to_linear;

/// A texture with its mip chain, as uploaded to the GPU.
pub struct MipTexture {
    levels: Vec<(u32, u32, Vec<u8>)>,
    srgb: bool,
}

impl MipTexture {
    /// The chain of `t` (`texture::mip_chain_rgba8`, the same the GPU receives).
    pub fn new(t: &Texture) -> Self {
        Self { levels: splitsum::texture::mip_chain_rgba8(t.width, t.height, &t.rgba, t.srgb), srgb: t.srgb }
    }

    /// Trilinear lookup at `uv` with the UV differences `dx`, `dy` to the neighbouring
    /// pixels: `λ = log₂ max(|dx·size|, |dy·size|)`, clamped to the chain.
    pub fn sample(&self, uv: Vec2, dx: Vec2, dy: Vec2) -> Vec4 {
        let (w, h, _) = self.levels[0];
        let size = Vec2::new(w as f32, h as f32);
        let rho = (dx * size).length().max((dy * size).length());
        let lambda = if rho > 0.0 { rho.log2() } else { 0.0 };
        let top = (self.levels.len() - 1) as f32;
        let l = lambda.clamp(0.0, top);
        let l0 = l.floor();
        let t = l - l0;
        let a = self.bilinear(l0 as usize, uv);
        if t > 0.0 { a * (1.0 - t) + self.bilinear(l0 as usize + 1, uv) * t } else { a }
    }

    fn bilinear(&self, level: usize, uv: Vec2) -> Vec4 {
        let (w, h, ref rgba) = self.levels[level];
        bilinear(w, h, rgba, self.srgb, uv)
    }
}

/// Bilinear lookup at `uv` with repeat addressing, in linear values.
pub fn bilinear(width: u32, height: u32, rgba: &[u8], srgb: bool, uv: Vec2) -> Vec4 {
    let fx = uv.x * width as f32 - 0.5;
    let fy = uv.y * height as f32 - 0.5;
    let (x0, y0) = (fx.floor(), fy.floor());
    let (tx, ty) = (fx - x0, fy - y0);
    let wrap = |v: i64, n: u32| v.rem_euclid(n as i64) as usize;
    let texel = |x: i64, y: i64| -> Vec4 {
        let i = 4 * (wrap(y, height) * width as usize + wrap(x, width));
        let c = |k: usize| rgba[i + k] as f32 / 255.0;
        if srgb { Vec4::new(srgb_to_linear(c(0)), srgb_to_linear(c(1)), srgb_to_linear(c(2)), c(3)) } else { Vec4::new(c(0), c(1), c(2), c(3)) }
    };
    let (x0, y0) = (x0 as i64, y0 as i64);
    let a = texel(x0, y0) * (1.0 - tx) + texel(x0 + 1, y0) * tx;
    let b = texel(x0, y0 + 1) * (1.0 - tx) + texel(x0 + 1, y0 + 1) * tx;
    a * (1.0 - ty) + b * ty
}

struct Fragment {
    depth: f32,
    prim: usize,
    tri: usize,
    bary: Vec3,
    /// Perspective-correct barycentrics at the quad's top-left pixel and its right and
    /// lower neighbours (coarse derivatives).
    quad: [Vec3; 3],
}

/// Renders the scene with `model` in it: the ray-cast spheres and sky, then every triangle
/// depth-tested against them. Returns display values, row 0 at the top.
pub fn render(env: &BakedEnvironment, frame: &Frame, model: &Model) -> Vec<Vec4> {
    let specular = env.specular_buffer();
    let (w, h) = (frame.width as usize, frame.height as usize);
    let mut colour = vec![Vec3::ZERO; w * h];
    let mut depth = vec![1.0f32; w * h];
    colour.par_chunks_mut(w).zip(depth.par_chunks_mut(w)).enumerate().for_each(|(y, (crow, drow))| {
        for x in 0..w {
            let px = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            let (c, d) = scene::radiance_depth(
                frame,
                env.cube(Product::SourceCube).level(0),
                &specular,
                &env.cube(Product::Irradiance).texels,
                &env.table(Product::BrdfTable).texels,
                &env.cube(Product::Sheen).texels,
                &env.table(Product::SheenTables).texels,
                px,
            );
            crow[x] = c;
            drow[x] = d;
        }
    });
    // Visibility: the nearest fragment of any triangle per pixel.
    let mut nearest: Vec<Option<Fragment>> = (0..w * h).map(|_| None).collect();
    for (pi, prim) in model.primitives.iter().enumerate() {
        let clip: Vec<Vec4> = prim.vertices.iter().map(|v| surface::clip(&frame.view_proj, Vec3::from(v.position))).collect();
        for (ti, tri) in prim.indices.chunks_exact(3).enumerate() {
            let c = [clip[tri[0] as usize], clip[tri[1] as usize], clip[tri[2] as usize]];
            if c.iter().any(|v| v.w <= frame.near) {
                continue; // behind the near plane: not drawn by either renderer in our scenes
            }
            let ndc = c.map(|v| v.truncate() / v.w);
            // Counter-clockwise in NDC (y up) is the front face.
            let area = (ndc[1].x - ndc[0].x) * (ndc[2].y - ndc[0].y) - (ndc[2].x - ndc[0].x) * (ndc[1].y - ndc[0].y);
            if area == 0.0 || (area < 0.0 && !prim.double_sided) {
                continue;
            }
            let s = ndc.map(|p| Vec2::new((p.x * 0.5 + 0.5) * w as f32, (0.5 - p.y * 0.5) * h as f32));
            let (lo, hi) = (s[0].min(s[1]).min(s[2]), s[0].max(s[1]).max(s[2]));
            // Pixel centres inside the bounding box.
            let x0 = ((lo.x - 0.5).ceil() as i64).max(0);
            let x1 = ((hi.x - 0.5).floor() as i64).min(w as i64 - 1);
            let y0 = ((lo.y - 0.5).ceil() as i64).max(0);
            let y1 = ((hi.y - 0.5).floor() as i64).min(h as i64 - 1);
            // Edge functions in screen space; the sign of the area orients them.
            let edge = |a: Vec2, b: Vec2, p: Vec2| (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
            let total = edge(s[0], s[1], s[2]);
            // Top-left rule: a pixel centre exactly on an edge belongs to the triangle only
            // for top or left edges (Vulkan spec, "Polygon Rasterization").
            let top_left = |a: Vec2, b: Vec2| {
                let d = if total > 0.0 { b - a } else { a - b };
                (d.y == 0.0 && d.x < 0.0) || d.y > 0.0
            };
            let owns = [top_left(s[1], s[2]), top_left(s[2], s[0]), top_left(s[0], s[1])];
            for y in y0..=y1 {
                for x in x0..=x1 {
                    let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                    let e = [edge(s[1], s[2], p), edge(s[2], s[0], p), edge(s[0], s[1], p)];
                    let inside = (0..3).all(|k| {
                        let v = e[k] * total.signum();
                        v > 0.0 || (v == 0.0 && owns[k])
                    });
                    if !inside {
                        continue;
                    }
                    let l = Vec3::new(e[0], e[1], e[2]) / total;
                    let z = l.x * ndc[0].z + l.y * ndc[1].z + l.z * ndc[2].z;
                    let i = y as usize * w + x as usize;
                    if z < depth[i] && nearest[i].as_ref().is_none_or(|f| z < f.depth) {
                        // Perspective-correct barycentrics at a pixel centre.
                        let at = |q: Vec2| {
                            let e = Vec3::new(edge(s[1], s[2], q), edge(s[2], s[0], q), edge(s[0], s[1], q)) / total;
                            let pc = Vec3::new(e.x / c[0].w, e.y / c[1].w, e.z / c[2].w);
                            pc / (pc.x + pc.y + pc.z)
                        };
                        let q = Vec2::new((x & !1) as f32 + 0.5, (y & !1) as f32 + 0.5);
                        let quad = [at(q), at(q + Vec2::X), at(q + Vec2::Y)];
                        nearest[i] = Some(Fragment { depth: z, prim: pi, tri: ti, bary: at(p), quad });
                    }
                }
            }
        }
    }
    // Shading of the visible fragments.
    let textures: Vec<Vec<Option<MipTexture>>> =
        model.primitives.iter().map(|p| p.textures.iter().map(|t| t.as_ref().map(MipTexture::new)).collect()).collect();
    colour.par_iter_mut().zip(nearest.par_iter()).for_each(|(c, f)| {
        let Some(f) = f else { return };
        let prim = &model.primitives[f.prim];
        let t = &prim.indices[3 * f.tri..3 * f.tri + 3];
        let v = |k: usize| &prim.vertices[t[k] as usize];
        let mix3 = |g: &dyn Fn(usize) -> Vec3| g(0) * f.bary.x + g(1) * f.bary.y + g(2) * f.bary.z;
        let position = mix3(&|k| Vec3::from(v(k).position));
        let normal = mix3(&|k| Vec3::from(v(k).normal));
        let tangent = Vec4::from(v(0).tangent) * f.bary.x + Vec4::from(v(1).tangent) * f.bary.y + Vec4::from(v(2).tangent) * f.bary.z;
        let uv_at = |b: Vec3| Vec2::from(v(0).uv) * b.x + Vec2::from(v(1).uv) * b.y + Vec2::from(v(2).uv) * b.z;
        let uv = uv_at(f.bary);
        let (dx, dy) = (uv_at(f.quad[1]) - uv_at(f.quad[0]), uv_at(f.quad[2]) - uv_at(f.quad[0]));
        let read = |k: usize| textures[f.prim][k].as_ref().map_or(Vec4::ONE, |tex| tex.sample(uv, dx, dy));
        let texels = Texels {
            base_color: read(0),
            metallic_roughness: read(1),
            normal: read(2),
            occlusion: read(3),
            emissive: read(4),
            sheen_color: read(5),
            sheen_roughness: read(6),
        };
        let (m, n) = surface::material(&prim.material, &texels, normal, tangent);
        let view = splitsum_shaders::sampling::normalize_or(frame.eye.truncate() - position, n);
        *c = scene::shade_point(
            frame,
            prim.material.options,
            &specular,
            &env.cube(Product::Irradiance).texels,
            &env.table(Product::BrdfTable).texels,
            &env.cube(Product::Sheen).texels,
            &env.table(Product::SheenTables).texels,
            &m,
            position,
            n,
            view,
        );
    });
    colour.into_iter().map(|c| scene::to_display(frame, c)).collect()
}
