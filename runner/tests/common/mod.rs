//! What the whole-process tests share: the binary, scratch folders, snapshots.

#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::Command;

/// The `runner` binary, with a runtime folder (Mesa's device-selection layer wants one).
pub fn runner() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_runner"));
    c.env("XDG_RUNTIME_DIR", std::env::temp_dir());
    c
}

/// A new empty folder for one test, under the system's temporary folder.
pub fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("splitsum-process-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The CC0 courtyard the library embeds, as a file.
pub fn courtyard() -> String {
    format!("{}/../splitsum/assets/courtyard.exr", env!("CARGO_MANIFEST_DIR"))
}

/// Every entry below `dir` with its bytes, in sorted order: a folder with none, a file
/// with its contents, a symbolic link (never followed) with `->` and where it points.
pub fn snapshot(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            let t = std::fs::symlink_metadata(&p).unwrap().file_type();
            if t.is_symlink() {
                let to = std::fs::read_link(&p).unwrap();
                out.push((p, [b"->".as_slice(), to.as_os_str().as_encoded_bytes()].concat()));
            } else if t.is_dir() {
                out.push((p.clone(), Vec::new()));
                stack.push(p);
            } else {
                out.push((p.clone(), std::fs::read(&p).unwrap()));
            }
        }
    }
    out.sort();
    out
}

/// [`snapshot`] of `dir`, or `None` where it does not exist.
pub fn snapshot_or_none(dir: &Path) -> Option<Vec<(PathBuf, Vec<u8>)>> {
    dir.is_dir().then(|| snapshot(dir))
}
