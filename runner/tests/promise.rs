//! The data-safety promise as a property (issues 19 and 31): random sequences of `bake`,
//! `bake --scene`, `report` and interruptions, run as a user runs them, into folders that
//! start missing, empty or holding the user's files, while the user adds files and an
//! attacker forges the folders: manifests naming `..`, absolute paths, folders outside,
//! wrong hashes, malformed or huge JSON, a manifest that is a link, entries that are links
//! out of the folder, hard links to files outside. Nothing outside `--out` may change.

mod common;

use common::{runner, scratch, snapshot, snapshot_or_none};
use std::path::{Path, PathBuf};

/// One step of the property test.
#[derive(Clone, Debug)]
enum Op {
    /// `bake` into folder `folder` for target `target` (splitsum, khronos, filament).
    Bake { folder: usize, target: usize, size: u32 },
    /// `bake --scene` into `folder`.
    Scene { folder: usize },
    /// `report --quick` into `folder`.
    Report { folder: usize },
    /// The user writes a file into `folder` (which may be an output folder by then).
    UserWrites { folder: usize, name: String, bytes: Vec<u8> },
    /// Someone tampers with `folder` (made if missing).
    Tamper { folder: usize, how: Tampering },
    /// `op`, interrupted by `signal` after `after_ms`.
    Interrupted { op: Box<Op>, after_ms: u64, signal: i32 },
}

/// How a folder is tampered with. Every kind but `HardLink` makes a folder splitsum must
/// refuse whole; `HardLink` lists a hard link to a file outside, with its true hash: the
/// folder may be replaced, and the file outside must keep its contents.
#[derive(Copy, Clone, Debug)]
enum Tampering {
    /// The manifest lists `../victim.txt` (the victim's true size and hash).
    DotDot,
    /// The manifest lists the victim by its absolute path.
    Absolute,
    /// The manifest lists the folder `../outside` and the file in it.
    OutsideFolder,
    /// A listed file's hash becomes `x`.
    WrongHash,
    /// A listed file is listed again as a folder.
    FileAsFolder,
    /// The manifest is cut in half.
    Malformed,
    /// The manifest grows past 16 MiB (a sparse file).
    Huge,
    /// The manifest is a link to a manifest outside that lists the victim.
    LinkedManifest,
    /// A link in the folder to the victim, listed with the victim's hash.
    LinkToFile,
    /// A link in the folder to `../outside`, listed as a folder with its file.
    LinkToFolder,
    /// A hard link in the folder to the victim, listed with its true hash.
    HardLink,
}

const TAMPERINGS: [Tampering; 11] = [
    Tampering::DotDot,
    Tampering::Absolute,
    Tampering::OutsideFolder,
    Tampering::WrongHash,
    Tampering::FileAsFolder,
    Tampering::Malformed,
    Tampering::Huge,
    Tampering::LinkedManifest,
    Tampering::LinkToFile,
    Tampering::LinkToFolder,
    Tampering::HardLink,
];

const MANIFEST: &str = ".splitsum-manifest.json";

fn stamp(bytes: &[u8]) -> serde_json::Value {
    serde_json::json!({ "bytes": bytes.len(), "blake3": blake3::hash(bytes).to_hex().as_str() })
}

/// The folder's manifest as JSON (a new, empty one where it has none or an unreadable one).
fn manifest_json(folder: &Path) -> serde_json::Value {
    std::fs::read(folder.join(MANIFEST))
        .ok()
        .and_then(|b| serde_json::from_slice(&b).ok())
        .unwrap_or_else(|| serde_json::json!({ "format": "splitsum-output-1", "entries": [] }))
}

/// Adds `entries` to the folder's manifest. A manifest that is there but unreadable (cut,
/// huge) stays as it is: rewriting it whole would mend the folder, and the model (a forged
/// folder stays refused) would no longer hold.
fn add_entries(folder: &Path, entries: Vec<serde_json::Value>) {
    let p = folder.join(MANIFEST);
    if std::fs::read(&p).is_ok_and(|b| serde_json::from_slice::<serde_json::Value>(&b).is_err()) {
        return;
    }
    let mut m = manifest_json(folder);
    m["entries"].as_array_mut().unwrap().extend(entries);
    let _ = std::fs::remove_file(&p);
    std::fs::write(p, serde_json::to_vec(&m).unwrap()).unwrap();
}

/// Tampers with `folder` as `how` says; `root` holds the victims. Returns whether the folder
/// must be refused from now on.
fn tamper(folder: &Path, root: &Path, how: Tampering) -> bool {
    std::fs::create_dir_all(folder).unwrap();
    let victim = root.join("victim.txt");
    let victim_bytes = std::fs::read(&victim).unwrap();
    let outside_file = root.join("outside/v.txt");
    let outside_bytes = std::fs::read(&outside_file).unwrap();
    let rel_to_root = if folder.parent() == Some(root) { "..".to_string() } else { "../..".to_string() };
    let m = manifest_json(folder);
    // The first listed file that is there: a listed entry that is not there (the bogus one
    // below) guards nothing, and listed again as a folder it would mend the folder.
    let first_file = m["entries"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|e| e.get("file").is_some())
        .filter_map(|e| e["path"].as_str())
        .find(|p| !p.starts_with('/') && !p.contains("..") && folder.join(p).is_file())
        .map(str::to_string);
    let free = |stem: &str| (0..).map(|k| format!("{stem}{k}")).find(|n| std::fs::symlink_metadata(folder.join(n)).is_err()).unwrap();
    match how {
        Tampering::DotDot => add_entries(folder, vec![serde_json::json!({ "path": format!("{rel_to_root}/victim.txt"), "file": stamp(&victim_bytes) })]),
        Tampering::Absolute => add_entries(folder, vec![serde_json::json!({ "path": victim.to_str().unwrap(), "file": stamp(&victim_bytes) })]),
        Tampering::OutsideFolder => add_entries(
            folder,
            vec![
                serde_json::json!({ "path": format!("{rel_to_root}/outside") }),
                serde_json::json!({ "path": format!("{rel_to_root}/outside/v.txt"), "file": stamp(&outside_bytes) }),
            ],
        ),
        Tampering::WrongHash | Tampering::FileAsFolder => {
            let Some(first) = first_file else {
                // Nothing listed to corrupt: list a file that is not there, wrongly.
                add_entries(folder, vec![serde_json::json!({ "path": "absent.ktx2", "file": { "bytes": 1, "blake3": "x" } })]);
                return true;
            };
            let mut m = m;
            for e in m["entries"].as_array_mut().unwrap() {
                if e["path"] == first.as_str() {
                    match how {
                        Tampering::WrongHash => e["file"]["blake3"] = "x".into(),
                        _ => {
                            e.as_object_mut().unwrap().remove("file");
                        }
                    }
                }
            }
            std::fs::write(folder.join(MANIFEST), serde_json::to_vec(&m).unwrap()).unwrap();
        }
        Tampering::Malformed => {
            let bytes = serde_json::to_vec(&m).unwrap();
            let _ = std::fs::remove_file(folder.join(MANIFEST));
            std::fs::write(folder.join(MANIFEST), &bytes[..bytes.len() / 2]).unwrap();
        }
        Tampering::Huge => {
            let _ = std::fs::remove_file(folder.join(MANIFEST));
            let f = std::fs::File::create(folder.join(MANIFEST)).unwrap();
            std::io::Write::write_all(&mut &f, &serde_json::to_vec(&m).unwrap()).unwrap();
            f.set_len(17 << 20).unwrap();
        }
        Tampering::LinkedManifest => {
            let elsewhere = root.join(format!("{}-manifest.json", folder.file_name().unwrap().to_string_lossy()));
            let mut m = m;
            m["entries"].as_array_mut().unwrap().push(serde_json::json!({ "path": format!("{rel_to_root}/victim.txt"), "file": stamp(&victim_bytes) }));
            std::fs::write(&elsewhere, serde_json::to_vec(&m).unwrap()).unwrap();
            let _ = std::fs::remove_file(folder.join(MANIFEST));
            std::os::unix::fs::symlink(&elsewhere, folder.join(MANIFEST)).unwrap();
        }
        Tampering::LinkToFile => {
            let name = free("link");
            std::os::unix::fs::symlink(&victim, folder.join(&name)).unwrap();
            add_entries(folder, vec![serde_json::json!({ "path": name, "file": stamp(&victim_bytes) })]);
        }
        Tampering::LinkToFolder => {
            let name = free("dir");
            std::os::unix::fs::symlink(root.join("outside"), folder.join(&name)).unwrap();
            add_entries(
                folder,
                vec![serde_json::json!({ "path": name.clone() }), serde_json::json!({ "path": format!("{name}/v.txt"), "file": stamp(&outside_bytes) })],
            );
        }
        Tampering::HardLink => {
            let name = free("hard");
            std::fs::hard_link(&victim, folder.join(&name)).unwrap();
            add_entries(folder, vec![serde_json::json!({ "path": name, "file": stamp(&victim_bytes) })]);
            return false;
        }
    }
    true
}

/// The arguments of a command op.
fn op_args(op: &Op, env: &Path, scene: &Path, folders: &[PathBuf]) -> Vec<String> {
    let s = |v: &[&str]| v.iter().map(|a| a.to_string()).collect::<Vec<_>>();
    match op {
        Op::Bake { folder, target, size } => {
            let target = ["splitsum", "khronos", "filament"][*target];
            let mut a = s(&["bake", env.to_str().unwrap(), "--backend", "cpu", "--size", &size.to_string(), "--target", target]);
            if target != "filament" {
                a.extend(s(&["--lut-size", "8", "--irradiance-size", "4"]));
            }
            a.extend(s(&["--out", folders[*folder].to_str().unwrap()]));
            a
        }
        Op::Scene { folder } => s(&["bake", "--scene", scene.to_str().unwrap(), "--backend", "cpu", "--out", folders[*folder].to_str().unwrap()]),
        Op::Report { folder } => s(&["report", env.to_str().unwrap(), "--quick", "--backends", "cpu", "--out", folders[*folder].to_str().unwrap()]),
        Op::UserWrites { .. } | Op::Tamper { .. } | Op::Interrupted { .. } => unreachable!("not a command"),
    }
}

/// Whether `dir` is a whole set written by splitsum, read independently of the library:
/// its manifest lists every entry there, every listed entry is there, and every file has
/// the listed size and BLAKE3 hash.
fn whole_new_set(dir: &Path) -> Result<(), String> {
    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join(MANIFEST)).map_err(|e| format!("no manifest: {e}"))?).map_err(|e| format!("manifest: {e}"))?;
    let mut listed = std::collections::BTreeSet::new();
    for e in manifest["entries"].as_array().ok_or("no entries")? {
        let rel = e["path"].as_str().ok_or("entry without a path")?;
        listed.insert(dir.join(rel));
        let p = dir.join(rel);
        match e.get("file") {
            Some(f) => {
                let bytes = std::fs::read(&p).map_err(|err| format!("{rel}: {err}"))?;
                if bytes.len() as u64 != f["bytes"].as_u64().unwrap() || blake3::hash(&bytes).to_hex().as_str() != f["blake3"].as_str().unwrap() {
                    return Err(format!("{rel} differs from the manifest"));
                }
            }
            None if p.is_dir() => {}
            None => return Err(format!("{rel} is not a folder")),
        }
    }
    for (p, _) in snapshot(dir) {
        if p != dir.join(MANIFEST) && !listed.contains(&p) {
            return Err(format!("{} is not listed", p.display()));
        }
    }
    Ok(())
}

fn ops() -> impl proptest::strategy::Strategy<Value = Vec<Op>> {
    use proptest::prelude::*;
    let command = prop_oneof![
        9 => (0usize..2, 0usize..3, prop_oneof![Just(8u32), Just(16)]).prop_map(|(folder, target, size)| Op::Bake { folder, target, size }),
        5 => (0usize..2).prop_map(|folder| Op::Scene { folder }),
        1 => (0usize..2).prop_map(|folder| Op::Report { folder }),
    ];
    let op = prop_oneof![
        10 => command.clone(),
        3 => (0usize..2, "[a-z]{1,8}(\\.txt|\\.json|\\.exr)?", prop::collection::vec(any::<u8>(), 0..64))
            .prop_map(|(folder, name, bytes)| Op::UserWrites { folder, name, bytes }),
        4 => (0usize..2, 0usize..TAMPERINGS.len()).prop_map(|(folder, k)| Op::Tamper { folder, how: TAMPERINGS[k] }),
        5 => (command, 0u64..150, prop_oneof![Just(libc::SIGINT), Just(libc::SIGTERM)])
            .prop_map(|(op, after_ms, signal)| Op::Interrupted { op: Box::new(op), after_ms, signal }),
    ];
    prop::collection::vec(op, 1..6)
}

/// The promise, as a property: random sequences of `bake` (three targets), `bake --scene`,
/// `report` and interruptions (SIGINT, SIGTERM) run into two folders that start missing,
/// empty or holding the user's files, while the user adds files into them (outputs
/// included) and someone tampers with them ([`Tampering`]). After every step every file of
/// the user's, inside the folders and outside them (the victims the forgeries name), is
/// there byte for byte; every output folder is either the whole old set or a whole new set
/// (read independently of the library); a folder holding the user's files or forged is
/// refused with exit code 2 and left as it was; no staging folder is left.
/// `PROPTEST_CASES` sets the number of sequences (200 by default; more by hand).
#[test]
fn the_users_files_survive_any_sequence_of_runs() {
    use proptest::prelude::*;
    use proptest::test_runner::{Config, TestRunner};
    let d = scratch("promise");
    let env = d.join("tiny.hdr");
    {
        use std::io::Write;
        let mut f = std::fs::File::create(&env).unwrap();
        write!(f, "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 32 +X 64\n").unwrap();
        for i in 0..64 * 32u32 {
            f.write_all(&[100 + (i % 64) as u8, 100, 100 + (i / 64) as u8, 128]).unwrap();
        }
    }
    let scene = d.join("tiny.toml");
    std::fs::write(
        &scene,
        "environment = \"tiny.hdr\"\n[quality]\nsize = 8\nlut_size = 8\n[[materials]]\nname = \"steel\"\nmetallic = 1.0\nroughness = [0.4, 0.7]\n[[objects]]\nkind = \"sphere-grid\"\nmaterial = \"steel\"\n",
    )
    .unwrap();
    let cases = std::env::var("PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(200);
    let mut runner_ = TestRunner::new(Config { cases, failure_persistence: None, ..Config::default() });
    let case = std::sync::atomic::AtomicUsize::new(0);
    let tampered = std::sync::atomic::AtomicUsize::new(0);
    let start = std::time::Instant::now();
    let starts = prop::collection::vec(0u8..3, 2);
    let seeds = prop::collection::vec(("[a-z]{1,6}\\.(tex|png|json)", prop::collection::vec(any::<u8>(), 1..32)), 0..3);
    let result = runner_.run(&(starts, seeds, ops()), |(starts, seeds, ops)| {
        let root = d.join(format!("case{}", case.fetch_add(1, std::sync::atomic::Ordering::Relaxed)));
        let folders = [root.join("out"), root.join("deep/report")];
        std::fs::create_dir_all(root.join("outside")).unwrap();
        // The user's files: beside the output folders always (the victims forged manifests
        // name among them), inside them where a folder starts so.
        let mut mine: std::collections::BTreeMap<PathBuf, Vec<u8>> = Default::default();
        for (p, bytes) in
            [(root.join("thesis.tex"), b"mine".to_vec()), (root.join("victim.txt"), b"precious".to_vec()), (root.join("outside/v.txt"), b"also mine".to_vec())]
        {
            std::fs::write(&p, &bytes).unwrap();
            mine.insert(p, bytes);
        }
        for (k, start) in starts.iter().enumerate() {
            match start {
                0 => {}
                1 => std::fs::create_dir_all(&folders[k]).unwrap(),
                _ => {
                    std::fs::create_dir_all(folders[k].join("figs")).unwrap();
                    for (name, bytes) in seeds.iter().chain([&("plan.json".to_string(), b"{}".to_vec())]) {
                        for p in [folders[k].join(name), folders[k].join("figs").join(name)] {
                            std::fs::write(&p, bytes).unwrap();
                            mine.insert(p, bytes.clone());
                        }
                    }
                }
            }
        }
        let mut forged = [false; 2];
        for op in &ops {
            let before: Vec<_> = folders.iter().map(|f| snapshot_or_none(f)).collect();
            let outside = snapshot(&root.join("outside"));
            let refused: Vec<bool> = folders.iter().enumerate().map(|(k, f)| forged[k] || mine.keys().any(|p| p.starts_with(f))).collect();
            let (command, signal) = match op {
                Op::UserWrites { folder, name, bytes } => {
                    let p = folders[*folder].join(name);
                    std::fs::create_dir_all(&folders[*folder]).unwrap();
                    if std::fs::symlink_metadata(&p).is_err() {
                        std::fs::write(&p, bytes).unwrap();
                        mine.insert(p, bytes.clone());
                    }
                    continue;
                }
                Op::Tamper { folder, how } => {
                    forged[*folder] |= tamper(&folders[*folder], &root, *how);
                    tampered.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    continue;
                }
                Op::Interrupted { op, after_ms, signal } => (op.as_ref(), Some((*after_ms, *signal))),
                op => (op, None),
            };
            let folder = match command {
                Op::Bake { folder, .. } | Op::Scene { folder } | Op::Report { folder } => *folder,
                _ => unreachable!(),
            };
            let args = op_args(command, &env, &scene, &folders);
            let child = runner().args(&args).stdout(std::process::Stdio::null()).stderr(std::process::Stdio::piped()).spawn().unwrap();
            if let Some((after, sig)) = signal {
                std::thread::sleep(std::time::Duration::from_millis(after));
                // SAFETY: signalling our own child (it may have exited already).
                unsafe { libc::kill(child.id() as i32, sig) };
            }
            let o = child.wait_with_output().unwrap();
            let said = String::from_utf8_lossy(&o.stderr).into_owned();
            let code = o.status.code();
            for (p, bytes) in &mine {
                let now = std::fs::read(p).ok();
                prop_assert_eq!(now.as_ref(), Some(bytes), "{:?} lost or changed by {:?}: {}", p, op, said);
            }
            prop_assert_eq!(&snapshot(&root.join("outside")), &outside, "{:?} changed the folder outside --out: {}", op, said);
            for (k, f) in folders.iter().enumerate() {
                let now = snapshot_or_none(f);
                if now != before[k] {
                    prop_assert!(k == folder && !refused[k], "{:?} changed folder {} holding the user's files or forged: {}", op, k, said);
                    let whole = whole_new_set(f);
                    prop_assert!(whole.is_ok(), "{:?} left folder {} neither old nor whole new: {:?}: {}", op, k, whole, said);
                }
            }
            if refused[folder] {
                prop_assert!(
                    code == Some(2) || (signal.is_some() && code.is_none()) || code == Some(130),
                    "{:?} into a folder of the user's or forged: {:?}: {}",
                    op,
                    code,
                    said
                );
            } else if signal.is_none() {
                prop_assert_eq!(code, Some(0), "{:?}: {}", op, said);
            }
            for dir in [root.clone(), root.join("deep")] {
                for e in std::fs::read_dir(&dir).into_iter().flatten() {
                    let name = e.unwrap().file_name().to_string_lossy().into_owned();
                    prop_assert!(!name.contains(".splitsum-") && !name.ends_with(".tmp"), "{:?} left {} in {}: {}", op, name, dir.display(), said);
                }
            }
        }
        let _ = std::fs::remove_dir_all(&root);
        Ok(())
    });
    eprintln!("{cases} sequences ({} tamperings) in {:.1} s", tampered.into_inner(), start.elapsed().as_secs_f64());
    if let Err(e) = result {
        panic!("{e}");
    }
    let _ = std::fs::remove_dir_all(&d);
}
