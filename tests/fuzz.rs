//! A fuzzing budget for every loader: valid seeds mutated at random (bytes overwritten,
//! files cut short) and random inputs, fed to the EXR, HDR, face-folder, glTF, scene,
//! cache and KTX2 readers, and Draco-compressed glTF. Each must answer with a value or an error, never panic.
//! `PROPTEST_CASES` raises the budget (default 48 cases per loader, a few seconds here).

use proptest::prelude::*;
use splitsum::environment;
use std::path::{Path, PathBuf};

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("splitsum-fuzz-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn config() -> ProptestConfig {
    let cases = std::env::var("PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(48);
    ProptestConfig { cases, failure_persistence: None, ..ProptestConfig::default() }
}

/// `seed` with `edits` applied (position modulo the length, new byte) and cut to `keep`
/// of its length (in 1/256ths; 256 keeps it whole).
fn mutate(seed: &[u8], edits: &[(usize, u8)], keep: u16) -> Vec<u8> {
    let mut b = seed.to_vec();
    for &(i, v) in edits {
        let n = b.len();
        b[i % n] = v;
    }
    let len = (b.len() * keep.min(256) as usize) / 256;
    b.truncate(len.max(1));
    b
}

fn edits() -> impl Strategy<Value = (Vec<(usize, u8)>, u16)> {
    (prop::collection::vec((any::<usize>(), any::<u8>()), 0..12), prop_oneof![Just(256u16), 0u16..256])
}

fn exr_seed(w: usize, h: usize) -> Vec<u8> {
    use exr::prelude::*;
    let ch = SpecificChannels::rgb(|p: Vec2<usize>| (p.x() as f32, p.y() as f32, 1.0f32));
    let mut buf = std::io::Cursor::new(Vec::new());
    Image::from_channels((w, h), ch).write().to_buffered(&mut buf).unwrap();
    buf.into_inner()
}

fn hdr_seed() -> Vec<u8> {
    let mut b = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 8 +X 16\n".to_vec();
    for i in 0..16 * 8 {
        b.extend_from_slice(&[(i % 200) as u8, 100, 50, 128]);
    }
    b
}

fn load(path: &Path) {
    let _ = environment::load(path, true);
    let _ = environment::load(path, false);
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn exr_files(e in edits()) {
        let d = scratch("exr");
        let p = d.join("env.exr");
        std::fs::write(&p, mutate(&exr_seed(16, 8), &e.0, e.1)).unwrap();
        load(&p);
    }

    #[test]
    fn hdr_files(e in edits()) {
        let d = scratch("hdr");
        let p = d.join("env.hdr");
        std::fs::write(&p, mutate(&hdr_seed(), &e.0, e.1)).unwrap();
        load(&p);
    }

    #[test]
    fn face_folders(face in 0usize..6, e in edits()) {
        let d = scratch(&format!("faces-{face}"));
        let seed = exr_seed(8, 8);
        for (k, name) in environment::FACE_NAMES.iter().enumerate() {
            let bytes = if k == face { mutate(&seed, &e.0, e.1) } else { seed.clone() };
            std::fs::write(d.join(format!("{name}.exr")), bytes).unwrap();
        }
        load(&d);
    }

    #[test]
    fn gltf_models(e in edits()) {
        let d = scratch("gltf");
        let p = d.join("model.glb");
        std::fs::write(&p, mutate(splitsum_display::model::EMBEDDED_SAMPLE, &e.0, e.1)).unwrap();
        let _ = splitsum_display::model::load(&p);
    }

    #[test]
    fn draco_models(speed in prop_oneof![Just(0), Just(10)], e in edits()) {
        let d = scratch("draco");
        let p = d.join("model.glb");
        std::fs::write(&p, mutate(&support::model::draco_torus_glb(speed), &e.0, e.1)).unwrap();
        let _ = splitsum_display::model::load(&p);
    }

    #[test]
    fn scene_files(e in edits(), text in "[\\[\\]a-z_=\"0-9.,{} \n-]{0,200}") {
        let seed = std::fs::read(format!("{}/../scenes/brushed-metal.toml", env!("CARGO_MANIFEST_DIR"))).unwrap();
        let mutated = String::from_utf8_lossy(&mutate(&seed, &e.0, e.1)).into_owned();
        let _ = splitsum_display::scene::Scene::parse(&mutated);
        let _ = splitsum_display::scene::Scene::parse(&text);
    }

    #[test]
    fn cache_entries(file in 0usize..5, e in edits()) {
        let d = scratch(&format!("cache-{file}"));
        let cache = splitsum::cache::Cache::new(&d);
        let env = support::small_display_bake();
        cache.put("k", &env).unwrap();
        let mut entries: Vec<PathBuf> = std::fs::read_dir(cache.entry("k")).unwrap().map(|x| x.unwrap().path()).collect();
        entries.sort();
        let target = &entries[file % entries.len()];
        let bytes = std::fs::read(target).unwrap();
        std::fs::write(target, mutate(&bytes, &e.0, e.1)).unwrap();
        let _ = cache.get("k");
    }

    /// What splitsum writes as KTX2, from any values (NaN, ±∞, subnormals, beyond half
    /// floats), reads back with the `ktx2` crate: six faces per level, every level there.
    #[test]
    fn ktx2_read_back(size_log in 0u32..4, values in prop::collection::vec(any::<f32>(), 1..64), half in any::<bool>()) {
        use splitsum::ktx2::{self, Format};
        use splitsum_shaders::cubemap::CubeLayout;
        use splitsum_shaders::glam::Vec4;
        let size = 1u32 << size_log;
        let layout = CubeLayout::new(size, CubeLayout::full_chain(size));
        let texels = (0..layout.texel_count() as usize).map(|i| Vec4::new(values[i % values.len()], values[(i + 1) % values.len()], values[(i + 2) % values.len()], 1.0)).collect();
        let cube = splitsum::texture::Cube { layout, texels };
        let (bytes, _) = ktx2::encode(&cube, if half { Format::Rgba16f } else { Format::Auto });
        let reader = ::ktx2::Reader::new(&bytes[..]).expect("splitsum's KTX2 parses");
        prop_assert_eq!(reader.header().face_count, 6);
        prop_assert_eq!(reader.levels().count() as u32, layout.levels);
    }
}
