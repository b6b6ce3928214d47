//! Files in and out: KTX2 that a reader accepts, the half-float overflow rule, and clear
//! errors for missing, truncated, malformed, misshapen and non-finite inputs.

use splitsum::environment::{self, Environment};
use splitsum::ktx2::{self, Format};
use splitsum::texture::Cube;
use splitsum_shaders::cubemap::CubeLayout;
use splitsum_shaders::glam::Vec4;
use std::path::{Path, PathBuf};

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("splitsum-files-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn ramp_cube(size: u32, levels: u32, scale: f32) -> Cube {
    let layout = CubeLayout::new(size, levels);
    let texels = (0..layout.texel_count()).map(|i| Vec4::new(i as f32 * scale, 0.5, 1.0 + i as f32, 1.0)).collect();
    Cube { layout, texels }
}

/// The `ktx2` crate parses what we write: header, levels (smallest stored first, each
/// aligned), and a data format descriptor identical to the one it builds itself.
#[test]
fn ktx2_files_parse_and_round_trip() {
    for (format, vk, ty) in [(Format::Rgba16f, ktx2::VK_FORMAT_R16G16B16A16_SFLOAT, 2), (Format::Rgba32f, ktx2::VK_FORMAT_R32G32B32A32_SFLOAT, 4)] {
        let cube = ramp_cube(16, 5, 0.25);
        let (bytes, w) = ktx2::encode(&cube, format);
        assert_eq!(w.vk_format, vk);
        let r = ::ktx2::Reader::new(&bytes[..]).expect("a valid KTX2 file");
        let h = r.header();
        assert_eq!(h.format.map(|f| f.value()), Some(vk));
        assert_eq!((h.type_size, h.pixel_width, h.pixel_height, h.pixel_depth), (ty, 16, 16, 0));
        assert_eq!((h.layer_count, h.face_count, h.level_count), (0, 6, 5));
        assert!(h.supercompression_scheme.is_none());
        let want = ::ktx2::dfd::Basic::from_format(h.format.unwrap()).unwrap().0;
        assert_eq!(r.basic_dfd().expect("basic DFD"), &want);
        assert_eq!(r.writer().map(|s| s.starts_with("splitsum")), Some(true));
        for (level, l) in r.levels().enumerate() {
            let offset = l.data.as_ptr() as usize - bytes.as_ptr() as usize;
            assert_eq!(offset % (4 * ty as usize), 0, "level {level} misaligned");
            let texels = cube.level(level as u32);
            assert_eq!(l.data.len(), texels.len() * 4 * ty as usize);
            for (i, t) in texels.iter().enumerate() {
                let v = |k: usize| -> f32 {
                    let at = (4 * i + k) * ty as usize;
                    if ty == 2 {
                        half::f16::from_le_bytes([l.data[at], l.data[at + 1]]).to_f32()
                    } else {
                        f32::from_le_bytes(l.data[at..at + 4].try_into().unwrap())
                    }
                };
                let got = Vec4::new(v(0), v(1), v(2), v(3));
                // Half floats: 11 significant bits.
                let tol = if ty == 2 { t.abs() * (1.0 / 1024.0) } else { Vec4::ZERO };
                assert!(((got - *t).abs() - tol).max_element() <= 0.0, "level {level} texel {i}: {got} vs {t}");
            }
        }
    }
}

/// Values beyond the half-float range are never written as infinity: RGBA16F clamps them
/// to 65504 and counts them; `auto` switches to RGBA32F.
#[test]
fn half_float_overflow_rule() {
    let mut cube = ramp_cube(4, 1, 1.0);
    cube.texels[3] = Vec4::new(1e6, 70_000.0, f32::MAX, 1.0);
    let (bytes, w) = ktx2::encode(&cube, Format::Rgba16f);
    assert_eq!((w.vk_format, w.clamped), (ktx2::VK_FORMAT_R16G16B16A16_SFLOAT, 3));
    let r = ::ktx2::Reader::new(&bytes[..]).unwrap();
    let level = r.levels().next().unwrap();
    for c in level.data.chunks_exact(2) {
        assert!(half::f16::from_le_bytes([c[0], c[1]]).is_finite());
    }
    let (_, w) = ktx2::encode(&cube, Format::Auto);
    assert_eq!((w.vk_format, w.clamped), (ktx2::VK_FORMAT_R32G32B32A32_SFLOAT, 0));
    let (_, w) = ktx2::encode(&ramp_cube(4, 1, 1.0), Format::Auto);
    assert_eq!(w.vk_format, ktx2::VK_FORMAT_R16G16B16A16_SFLOAT);
}

fn write_exr(path: &Path, w: usize, h: usize, f: impl Fn(usize, usize) -> f32 + Sync) {
    use exr::prelude::*;
    let img = Image::from_channels(
        (w, h),
        SpecificChannels::rgb(|p: Vec2<usize>| {
            let v = f(p.x(), p.y());
            (v, v, v)
        }),
    );
    img.write().to_file(path).unwrap();
}

fn load_err(path: &Path) -> String {
    match environment::load(path, false) {
        Ok(_) => panic!("{} should not load", path.display()),
        Err(e) => e.to_string(),
    }
}

#[test]
fn the_vendored_dwab_environments_load() {
    for name in ["city", "courtyard", "studio"] {
        let e = support::environment(name);
        assert_eq!((e.width, e.height), (1024, 512), "{name}");
        assert!(e.texels.iter().all(|t| t.is_finite() && t.min_element() >= 0.0));
    }
}

#[test]
fn bad_inputs_get_errors_that_name_the_file_and_the_problem() {
    let d = scratch("bad");
    let missing = d.join("missing.exr");
    let e = load_err(&missing);
    assert!(e.contains("missing.exr") && e.contains("cannot read"), "{e}");

    let empty = d.join("empty.hdr");
    std::fs::write(&empty, b"").unwrap();
    assert!(load_err(&empty).contains("empty"));

    let junk = d.join("junk.exr");
    std::fs::write(&junk, b"this is not an image at all").unwrap();
    let e = load_err(&junk);
    assert!(e.contains("junk.exr") && e.contains("neither"), "{e}");

    let good = d.join("good.exr");
    write_exr(&good, 64, 32, |x, _| x as f32);
    let bytes = std::fs::read(&good).unwrap();
    let truncated = d.join("truncated.exr");
    std::fs::write(&truncated, &bytes[..bytes.len() / 2]).unwrap();
    let e = load_err(&truncated);
    assert!(e.contains("truncated.exr") && e.contains("OpenEXR"), "{e}");

    let hdr_bad = d.join("bad.hdr");
    std::fs::write(&hdr_bad, b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 4 +X 8\n\x02\x02").unwrap();
    let e = load_err(&hdr_bad);
    assert!(e.contains("bad.hdr") && e.contains("Radiance"), "{e}");

    let square = d.join("square.exr");
    write_exr(&square, 32, 32, |_, _| 1.0);
    let e = load_err(&square);
    assert!(e.contains("square.exr") && e.contains("twice as wide"), "{e}");

    let tiny = d.join("tiny.exr");
    write_exr(&tiny, 4, 2, |_, _| 1.0);
    assert!(load_err(&tiny).contains("too small"));
}

#[test]
fn non_finite_texels_are_refused_unless_sanitised() {
    let d = scratch("nan");
    let p = d.join("nan.exr");
    write_exr(&p, 16, 8, |x, y| match (x, y) {
        (1, 1) => f32::NAN,
        (2, 2) | (3, 3) => f32::INFINITY,
        (4, 4) => f32::NEG_INFINITY,
        (5, 5) => 7.0,
        (6, 6) => -2.0,
        _ => 1.0,
    });
    let e = load_err(&p);
    assert!(e.contains("nan.exr") && e.contains("1 texels with NaN") && e.contains("3 with an infinite") && e.contains("sanitising"), "{e}");
    let (env, report) = environment::load(&p, true).unwrap();
    assert_eq!((report.nan, report.infinite, report.negative), (1, 3, 1));
    let Environment::Equirect(e) = env else { panic!() };
    assert_eq!(e.texels[16 + 1].x, 0.0); // NaN → 0
    assert_eq!(e.texels[2 * 16 + 2].x, 7.0); // +inf → largest finite value
    assert_eq!(e.texels[4 * 16 + 4].x, 0.0); // −inf → 0
    assert_eq!(e.texels[6 * 16 + 6].x, 0.0); // negative → 0
}

#[test]
fn radiance_hdr_files_load() {
    let d = scratch("hdr");
    let p = d.join("sky.hdr");
    let (w, h) = (32u32, 16u32);
    let pixels: Vec<image::Rgb<f32>> = (0..w * h).map(|i| image::Rgb([i as f32 / 10.0, 1.0, 2.0])).collect();
    let f = std::fs::File::create(&p).unwrap();
    image::codecs::hdr::HdrEncoder::new(f).encode(&pixels, w as usize, h as usize).unwrap();
    let (env, _) = environment::load(&p, false).unwrap();
    let Environment::Equirect(e) = env else { panic!() };
    assert_eq!((e.width, e.height), (w, h));
    // RGBE keeps 8 bits of mantissa.
    assert!((e.texels[100].x - 10.0).abs() < 10.0 / 128.0, "{}", e.texels[100]);
}

/// A file held in memory (what a web page is given) reads as the same file read from disk:
/// the same texels, the same report, the same errors.
#[test]
fn files_in_memory_read_as_files_on_disk() {
    let d = scratch("bytes");
    let hdr = d.join("sky.hdr");
    let (w, h) = (64u32, 32u32);
    let pixels: Vec<image::Rgb<f32>> = (0..w * h).map(|i| image::Rgb([i as f32 / 10.0, 1.0, 2.0])).collect();
    image::codecs::hdr::HdrEncoder::new(std::fs::File::create(&hdr).unwrap()).encode(&pixels, w as usize, h as usize).unwrap();
    let exr = Path::new(env!("CARGO_MANIFEST_DIR")).join("../splitsum/assets/courtyard.exr");
    for p in [hdr, exr] {
        let (disk, disk_report) = environment::load(&p, false).unwrap();
        let (memory, memory_report) = environment::read_bytes("dropped", &std::fs::read(&p).unwrap(), false).unwrap();
        let (Environment::Equirect(a), Environment::Equirect(b)) = (disk, memory) else { panic!("equirects") };
        assert_eq!((a.width, a.height), (b.width, b.height), "{}", p.display());
        assert!(a.texels == b.texels, "{}: texels differ", p.display());
        assert_eq!(format!("{disk_report:?}"), format!("{memory_report:?}"));
    }
    let e = environment::read_bytes("sky.png", b"\x89PNG....", false).unwrap_err().to_string();
    assert!(e.contains("sky.png") && e.contains("neither an OpenEXR nor a Radiance HDR"), "{e}");
}

#[test]
fn six_face_folders_load_and_are_checked() {
    let d = scratch("faces");
    for (i, name) in environment::FACE_NAMES.iter().enumerate() {
        write_exr(&d.join(format!("{name}.exr")), 8, 8, move |_, _| i as f32);
    }
    let (env, _) = environment::load(&d, false).unwrap();
    let Environment::Cube(c) = env else { panic!() };
    assert_eq!(c.layout.size, 8);
    assert_eq!(c.texels[2 * 64].x, 2.0); // +Y is the third face
    // A face of another size, and a missing face.
    write_exr(&d.join("pz.exr"), 4, 4, |_, _| 0.0);
    let e = load_err(&d);
    assert!(e.contains("pz.exr") && e.contains("first face"), "{e}");
    std::fs::remove_file(d.join("pz.exr")).unwrap();
    let e = load_err(&d);
    assert!(e.contains("pz"), "{e}");
}

/// splitsum's streaming RGBE reader gives what the `image` crate's whole-image decoder
/// gives, bit for bit: run-length coded scanlines (widths 8..32767, as `image`'s encoder
/// writes them, with runs and literals), flat scanlines (width 4) and old-style repeat
/// markers (written by hand), over values from 10⁻³ to 10⁴.
#[test]
fn radiance_scanlines_decode_as_the_image_crate_decodes_them() {
    use image::ImageDecoder;
    let d = scratch("rgbe");
    let decode_with_image = |p: &std::path::Path| -> Vec<f32> {
        let dec = image::codecs::hdr::HdrDecoder::new(std::io::BufReader::new(std::fs::File::open(p).unwrap())).unwrap();
        let mut buf = vec![0u8; dec.total_bytes() as usize];
        dec.read_image(&mut buf).unwrap();
        bytemuck::pod_collect_to_vec(&buf)
    };
    let ours = |p: &std::path::Path| -> Vec<f32> {
        let (e, _) = environment::read_reduced(p, false, 1).unwrap();
        e.texels.iter().flat_map(|t| [t.x, t.y, t.z]).collect()
    };
    for (w, h) in [(64u32, 32u32), (4, 2), (1024, 512)] {
        let p = d.join(format!("sky{w}.hdr"));
        // Runs (constant stretches) and literals (noise), across seven decades.
        let pixels: Vec<image::Rgb<f32>> = (0..w * h)
            .map(|i| {
                let x = i % w;
                let v = if (x / 16) % 2 == 0 { 1.5 } else { 1e-3 * 10f32.powf(((i * 2_654_435_761) % 7000) as f32 / 1000.0) };
                image::Rgb([v, 0.5 * v, 2.0 * v])
            })
            .collect();
        image::codecs::hdr::HdrEncoder::new(std::fs::File::create(&p).unwrap()).encode(&pixels, w as usize, h as usize).unwrap();
        let (a, b) = (ours(&p), decode_with_image(&p));
        assert_eq!(a.len(), b.len());
        assert!(a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits()), "{w}×{h}: differs from image's decoder");
    }
    // Old-style run-length coding: `1 1 1 n` repeats the previous pixel n times, and a
    // second marker in a row multiplies by 256.
    let p = d.join("old.hdr");
    let mut bytes = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 301\n".to_vec();
    for _ in 0..2 {
        bytes.extend_from_slice(&[200, 100, 50, 129]);
        bytes.extend_from_slice(&[1, 1, 1, 43]); // 43 repeats
        bytes.extend_from_slice(&[1, 1, 1, 1]); // then 256 more
        bytes.extend_from_slice(&[10, 20, 30, 140]);
    }
    std::fs::write(&p, &bytes).unwrap();
    let (a, b) = (ours(&p), decode_with_image(&p));
    assert!(a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits()) && a.len() == 2 * 301 * 3);
    // 1 pixel, 43 repeats, then 1 << 8 = 256 more: pixel 300 is the last one written,
    // its mantissas times 2^(140−136).
    assert_eq!(&a[3 * 300..3 * 301], &[10.0 * 16.0, 20.0 * 16.0, 30.0 * 16.0]);
    assert_eq!(&a[3 * 299..3 * 300], &a[0..3]);
}

/// Every target's files made in memory (the web page's zip) are the bytes `output::write`
/// puts on disk, under the same names, and nothing else.
#[test]
fn a_folder_in_memory_is_the_folder_on_disk() {
    use splitsum::{Backend, Choice, Settings, Target, output};
    let (env, _) = environment::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../splitsum/assets/courtyard.exr"), false).unwrap();
    for target in [Target::Splitsum, Target::Khronos, Target::Bevy, Target::Filament] {
        let job = Settings { size: 16, ..Settings::default() }.with_target(target).resolve(splitsum::InputShape::of(&env), target.products()).unwrap();
        let baked = splitsum::bake_job(&Backend::Cpu, &env, &job).unwrap();
        let dir = scratch(&format!("memory-{}", target.name())).join("sky");
        output::write(&dir, &baked, &job, output::About::default()).unwrap();
        let (_, files) = output::in_memory("sky", &baked, &job, output::About::default()).unwrap();
        let mut on_disk = Vec::new();
        let mut walk = vec![dir.clone()];
        while let Some(d) = walk.pop() {
            for e in std::fs::read_dir(&d).unwrap() {
                let p = e.unwrap().path();
                if p.is_dir() {
                    walk.push(p);
                } else {
                    on_disk.push(p.strip_prefix(&dir).unwrap().to_string_lossy().replace('\\', "/"));
                }
            }
        }
        // The folder's guard (files::OUTPUT_MANIFEST) is the folder's, not the bake's.
        on_disk.retain(|n| n != splitsum::files::OUTPUT_MANIFEST);
        on_disk.sort();
        assert_eq!(files.iter().map(|f| f.0.clone()).collect::<Vec<_>>(), on_disk, "{}", target.name());
        for (name, bytes) in &files {
            assert!(*bytes == std::fs::read(dir.join(name)).unwrap(), "{}: {name} differs", target.name());
        }
    }
}
