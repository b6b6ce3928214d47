//! The manifest of an output folder, and the one rule for what splitsum removes from a
//! folder it replaces (`docs/SECURITY.md`).
//!
//! A folder given as an output may come from anyone (a zip, a repository, a forged
//! manifest), so nothing read from it is trusted:
//! - the manifest's names must be plain relative names below the folder (no `..`, no root
//!   or prefix, no empty component), or the folder is refused whole;
//! - every entry below the folder must be listed there, a file with the size and BLAKE3
//!   hash it has now, or the folder is refused at the first that is not (in name order,
//!   depth first: a folder of the user's is refused at its first top-level entry, unread);
//! - what is removed after the swap is only what that check saw, each file hashed again,
//!   and every name is resolved beneath a handle to the folder (`cap_std::fs::Dir`), so
//!   that no `..`, absolute path or symbolic link reaches outside it.

use super::{Error, Result};
use std::path::Path;

#[cfg(not(target_arch = "wasm32"))]
use cap_std::fs::Dir;
#[cfg(target_arch = "wasm32")]
use wasm::Dir;

/// The manifest in every output folder splitsum writes as a unit (`OutputDir`): every
/// entry it wrote there, files with their size and BLAKE3 hash. A folder may be replaced
/// only when everything in it is listed there, unchanged ([`check_replaceable`]).
pub const OUTPUT_MANIFEST: &str = ".splitsum-manifest.json";

/// Format of [`OUTPUT_MANIFEST`].
const MANIFEST_FORMAT: &str = "splitsum-output-1";

/// The largest manifest read (a folder of 10⁵ entries); a larger file is not one of ours.
const MAX_MANIFEST_BYTES: u64 = 16 << 20;

/// The most entries a manifest lists (splitsum writes a few dozen).
const MAX_ENTRIES: usize = 100_000;

#[derive(serde::Serialize, serde::Deserialize)]
pub(super) struct Manifest {
    format: String,
    /// Every entry below the folder, `/`-separated, in the order of a depth-first walk by
    /// name.
    entries: Vec<Entry>,
}

#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
struct Entry {
    path: String,
    /// `None` for a folder.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    file: Option<Stamp>,
}

#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
struct Stamp {
    bytes: u64,
    blake3: String,
}

/// Why a manifest is not one splitsum could have written: the whole folder is refused.
#[derive(Debug)]
enum Forged {
    /// A link, a folder, a device.
    NotAFile,
    /// Larger than [`MAX_MANIFEST_BYTES`].
    TooLarge(u64),
    /// Not readable.
    Unreadable(std::io::Error),
    /// Not JSON of the manifest's shape.
    NotJson(serde_json::Error),
    /// Another format.
    Format(String),
    /// More than [`MAX_ENTRIES`] entries.
    TooMany(usize),
    /// An entry's name that is not a plain relative name below the folder.
    Unsafe { path: String, why: UnsafeName },
    /// An entry listed twice.
    Duplicate(String),
    /// A hash that is not 64 hexadecimal digits.
    BadHash(String),
}

/// What makes a name in a manifest unsafe to resolve below the folder.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub(super) enum UnsafeName {
    /// The empty name, or an empty component (`a//b`, a trailing `/`).
    Empty,
    /// Starts at the root (`/etc/passwd`).
    Absolute,
    /// A `..` component (leaves the folder) or a `.` component.
    Dots,
    /// A backslash, a drive prefix or a NUL: not a name splitsum writes on any system.
    Foreign,
    /// The manifest's own name.
    Manifest,
}

impl UnsafeName {
    fn describe(self) -> &'static str {
        match self {
            UnsafeName::Empty => "an empty name or component",
            UnsafeName::Absolute => "an absolute path, outside the folder",
            UnsafeName::Dots => "a '..' or '.' component, which leaves the folder or names it again",
            UnsafeName::Foreign => "a backslash, drive prefix or NUL, which no name splitsum writes has",
            UnsafeName::Manifest => "the manifest itself",
        }
    }
}

/// Whether `path` is a plain relative name below a folder: `/`-separated components, none
/// empty, `.`, `..`, a root, a drive prefix, or holding a backslash or NUL.
pub(super) fn check_name(path: &str) -> std::result::Result<(), UnsafeName> {
    if path.starts_with('/') {
        return Err(UnsafeName::Absolute);
    }
    if path == OUTPUT_MANIFEST {
        return Err(UnsafeName::Manifest);
    }
    for c in path.split('/') {
        match c {
            "" => return Err(UnsafeName::Empty),
            "." | ".." => return Err(UnsafeName::Dots),
            _ if c.contains(['\\', '\0', ':']) => return Err(UnsafeName::Foreign),
            _ => {}
        }
    }
    Ok(())
}

impl Manifest {
    /// Every rule a manifest splitsum wrote keeps (see [`Forged`]).
    fn validate(&self) -> std::result::Result<(), Forged> {
        if self.format != MANIFEST_FORMAT {
            return Err(Forged::Format(self.format.clone()));
        }
        if self.entries.len() > MAX_ENTRIES {
            return Err(Forged::TooMany(self.entries.len()));
        }
        let mut seen = std::collections::HashSet::new();
        for e in &self.entries {
            check_name(&e.path).map_err(|why| Forged::Unsafe { path: e.path.clone(), why })?;
            if !seen.insert(e.path.as_str()) {
                return Err(Forged::Duplicate(e.path.clone()));
            }
            if let Some(s) = &e.file
                && !(s.blake3.len() == 64 && s.blake3.bytes().all(|b| b.is_ascii_digit() || (b'a'..=b'f').contains(&b)))
            {
                return Err(Forged::BadHash(e.path.clone()));
            }
        }
        Ok(())
    }

    /// The manifest as JSON.
    pub(super) fn to_json(&self) -> Vec<u8> {
        serde_json::to_vec_pretty(self).expect("serialisable")
    }
}

/// An entry found below a folder, by its kind.
enum Kind {
    Folder,
    File(u64),
    /// A symbolic link, device, socket…: never something splitsum writes.
    Other,
}

/// The entries of `dir` in name order, the root's manifest left out where `root`; names
/// that are not UTF-8 kept as they print (no manifest can list them).
fn entries(dir: &Dir, root: bool) -> std::io::Result<Vec<(String, Kind)>> {
    let mut out = Vec::new();
    for e in dir.entries()? {
        let e = e?;
        let name = e.file_name().to_string_lossy().into_owned();
        if root && name == OUTPUT_MANIFEST {
            continue;
        }
        let t = e.file_type()?;
        let kind = if t.is_dir() {
            Kind::Folder
        } else if t.is_file() {
            Kind::File(e.metadata()?.len())
        } else {
            Kind::Other
        };
        out.push((name, kind));
    }
    out.sort_by(|a, b| a.0.cmp(&b.0));
    Ok(out)
}

/// The size and BLAKE3 hash of the file `rel` below `dir`.
fn hash(dir: &Dir, rel: &str) -> std::io::Result<Seal> {
    let file = dir.open(rel)?.into_std();
    let bytes = file.metadata()?.len();
    let mut h = blake3::Hasher::new();
    h.update_reader(&file)?;
    Ok((bytes, h.finalize().to_hex().to_string()))
}

/// The manifest of everything below `dir` (a staging folder, all of it written by this
/// run), in the order [`check_replaceable`] walks.
pub(super) fn manifest_of(dir: &Path) -> std::io::Result<Manifest> {
    fn visit(dir: &Dir, prefix: &str, out: &mut Vec<Entry>) -> std::io::Result<()> {
        for (name, kind) in entries(dir, prefix.is_empty())? {
            let rel = format!("{prefix}{name}");
            match kind {
                Kind::Folder => {
                    out.push(Entry { path: rel.clone(), file: None });
                    visit(&dir.open_dir(&name)?, &format!("{rel}/"), out)?;
                }
                Kind::File(_) => {
                    let (bytes, blake3) = hash(dir, &name)?;
                    out.push(Entry { path: rel, file: Some(Stamp { bytes, blake3 }) });
                }
                Kind::Other => return Err(std::io::Error::other(format!("{rel} is neither a file nor a folder"))),
            }
        }
        Ok(())
    }
    let mut entries = Vec::new();
    visit(&open(dir)?, "", &mut entries)?;
    Ok(Manifest { format: MANIFEST_FORMAT.into(), entries })
}

fn open(dir: &Path) -> std::io::Result<Dir> {
    #[cfg(not(target_arch = "wasm32"))]
    return Dir::open_ambient_dir(dir, cap_std::ambient_authority());
    #[cfg(target_arch = "wasm32")]
    return Dir::open_ambient_dir(dir);
}

/// Why a folder may not be replaced, in the terms of what it holds.
enum Refusal {
    /// An entry no manifest lists (the folder has none, or its manifest lacks it).
    Unlisted { entry: String, folder: bool, manifest: bool },
    /// A listed file whose size or hash differs, or a listed folder that is now a file (or
    /// the other way round).
    Changed(String),
    /// A link, device or socket.
    NotFileOrFolder(String),
    /// An entry that could not be read.
    Unreadable { entry: String, error: std::io::Error },
    /// A manifest splitsum could not have written.
    Forged(Forged),
}

impl Refusal {
    /// The refusal in the user's terms: `called` is what they call the folder.
    fn into_error(self, called: &str, dir: &Path) -> Error {
        let shown = dir.display();
        let (entry, why) = match self {
            Refusal::Unlisted { entry, folder, manifest } => {
                let what = if folder { "a folder splitsum did not write" } else { "which splitsum did not write" };
                let why = if manifest { what.to_string() } else { format!("{what} (the folder has no {OUTPUT_MANIFEST})") };
                (entry, why)
            }
            Refusal::Changed(entry) => (entry, "which has changed since splitsum wrote it".into()),
            Refusal::NotFileOrFolder(entry) => (entry, "which is neither a file nor a folder splitsum wrote (a link, device or socket)".into()),
            Refusal::Unreadable { entry, error } => (entry, format!("which cannot be read ({error})")),
            Refusal::Forged(f) => {
                let why = match f {
                    Forged::NotAFile => "which is not a regular file".to_string(),
                    Forged::TooLarge(n) => format!("of {n} bytes, more than any manifest splitsum writes ({MAX_MANIFEST_BYTES})"),
                    Forged::Unreadable(e) => format!("which cannot be read ({e})"),
                    Forged::NotJson(e) => format!("which is not a manifest splitsum wrote ({e})"),
                    Forged::Format(f) => format!("of format {f:?}, not {MANIFEST_FORMAT:?}"),
                    Forged::TooMany(n) => format!("listing {n} entries, more than splitsum writes ({MAX_ENTRIES})"),
                    Forged::Unsafe { path, why } => format!("whose entry {path:?} is {}", why.describe()),
                    Forged::Duplicate(p) => format!("which lists {p:?} twice"),
                    Forged::BadHash(p) => format!("whose hash of {p:?} is not a BLAKE3 hash"),
                };
                (OUTPUT_MANIFEST.to_string(), format!("{why}: splitsum trusts no manifest it could not have written"))
            }
        };
        Error::Invalid(format!(
            "{called} {shown} holds {entry}, {why}; splitsum replaces an output folder only when everything in it is what splitsum wrote there (listed, unchanged, in its {OUTPUT_MANIFEST}): move {entry} away, or give a new or empty folder"
        ))
    }
}

/// What [`check_replaceable`] saw in a folder it passed, and a handle to that folder: the
/// only entries an output folder's commit may remove from it.
pub struct Verified {
    dir: Dir,
    /// Files, with the size and hash they had.
    files: Vec<(String, Stamp)>,
    /// Folders, in walk order (parents first).
    folders: Vec<String>,
    /// The manifest's own size and hash, if the folder held a valid one.
    manifest: Option<Seal>,
}

/// A file's size and BLAKE3 hash (hex).
type Seal = (u64, String);

/// Reads and checks the manifest of `dir`, with its own seal: `None` if there is none.
fn read_manifest(dir: &Dir) -> std::result::Result<Option<(Manifest, Seal)>, Forged> {
    let meta = match dir.symlink_metadata(OUTPUT_MANIFEST) {
        Ok(m) => m,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(Forged::Unreadable(e)),
    };
    if !meta.is_file() {
        return Err(Forged::NotAFile);
    }
    if meta.len() > MAX_MANIFEST_BYTES {
        return Err(Forged::TooLarge(meta.len()));
    }
    let bytes = {
        use std::io::Read;
        let mut bytes = Vec::new();
        dir.open(OUTPUT_MANIFEST).and_then(|f| f.into_std().take(MAX_MANIFEST_BYTES + 1).read_to_end(&mut bytes)).map_err(Forged::Unreadable)?;
        bytes
    };
    if bytes.len() as u64 > MAX_MANIFEST_BYTES {
        return Err(Forged::TooLarge(bytes.len() as u64));
    }
    let manifest: Manifest = serde_json::from_slice(&bytes).map_err(Forged::NotJson)?;
    manifest.validate()?;
    Ok(Some((manifest, (bytes.len() as u64, blake3::hash(&bytes).to_hex().to_string()))))
}

/// Checks that the existing folder `dir` may be replaced whole: every entry below it is
/// listed in its [`OUTPUT_MANIFEST`] (a manifest whose every name is a plain relative name
/// below the folder) and every file there is as splitsum wrote it (size and BLAKE3 hash).
/// Otherwise the error names the first entry splitsum did not write, the first it wrote
/// that has changed since, or the manifest and what is wrong with it; `called` is what the
/// caller calls the folder (a flag, a field). The walk goes by name, depth first, and
/// stops at the first refusal: a folder without a manifest is refused at its first entry.
/// An empty folder may be replaced. Returns what was seen: what a commit may remove.
pub fn check_replaceable(dir: &Path, called: &str) -> Result<Verified> {
    let handle = open(dir).map_err(|e| unreadable(dir, called, &e))?;
    let top = entries(&handle, true).map_err(|e| unreadable(dir, called, &e))?;
    let manifest = read_manifest(&handle).map_err(|f| Refusal::Forged(f).into_error(called, dir))?;
    let (listed, manifest_stamp) = match manifest {
        Some((m, stamp)) => (Some(m.entries.into_iter().map(|e| (e.path, e.file)).collect::<std::collections::HashMap<_, _>>()), Some(stamp)),
        None => (None, None),
    };
    let mut v = Verified { dir: handle, files: Vec::new(), folders: Vec::new(), manifest: manifest_stamp };
    fn visit(
        dir: &Dir,
        found: Vec<(String, Kind)>,
        prefix: &str,
        listed: Option<&std::collections::HashMap<String, Option<Stamp>>>,
        v: &mut Verified,
    ) -> std::result::Result<(), Refusal> {
        for (name, kind) in found {
            let rel = format!("{prefix}{name}");
            let entry = listed.and_then(|l| l.get(&rel));
            match (kind, entry) {
                (Kind::Other, _) => return Err(Refusal::NotFileOrFolder(rel)),
                (Kind::Folder, Some(None)) => {
                    let sub = dir.open_dir(&name).map_err(|error| Refusal::Unreadable { entry: rel.clone(), error })?;
                    let inner = entries(&sub, false).map_err(|error| Refusal::Unreadable { entry: rel.clone(), error })?;
                    v.folders.push(rel.clone());
                    visit(&sub, inner, &format!("{rel}/"), listed, v)?;
                }
                (Kind::File(bytes), Some(Some(stamp))) => {
                    if stamp.bytes != bytes {
                        return Err(Refusal::Changed(rel));
                    }
                    match hash(dir, &name) {
                        Ok((b, h)) if b == stamp.bytes && h == stamp.blake3 => v.files.push((rel, stamp.clone())),
                        Ok(_) => return Err(Refusal::Changed(rel)),
                        Err(error) => return Err(Refusal::Unreadable { entry: rel, error }),
                    }
                }
                (Kind::Folder | Kind::File(_), Some(_)) => return Err(Refusal::Changed(rel)),
                (kind, None) => return Err(Refusal::Unlisted { entry: rel, folder: matches!(kind, Kind::Folder), manifest: listed.is_some() }),
            }
        }
        Ok(())
    }
    let dir_handle = v.dir.try_clone().map_err(|e| unreadable(dir, called, &e))?;
    visit(&dir_handle, top, "", listed.as_ref(), &mut v).map_err(|r| r.into_error(called, dir))?;
    Ok(v)
}

/// The message for a folder that cannot be listed.
fn unreadable(dir: &Path, called: &str, e: &std::io::Error) -> Error {
    let why = match e.kind() {
        std::io::ErrorKind::PermissionDenied => "permission denied".to_string(),
        _ => e.to_string(),
    };
    Error::Invalid(format!(
        "{called} {} cannot be read ({why}): splitsum lists what a folder holds before it replaces it; give a folder you may read and write, or a new one",
        dir.display()
    ))
}

impl Verified {
    /// Removes, from the folder checked (wherever it is now: the handle follows it), what
    /// the check saw and nothing else: each file only if it still has the size and hash it
    /// had then, folders from the deepest only once empty, the manifest only if unchanged.
    /// Every name is resolved beneath the folder's handle. Returns whether the folder is now
    /// empty.
    pub(super) fn remove(&self) -> bool {
        for (rel, stamp) in &self.files {
            let same = self.dir.symlink_metadata(rel).is_ok_and(|m| m.is_file() && m.len() == stamp.bytes)
                && hash(&self.dir, rel).is_ok_and(|(b, h)| b == stamp.bytes && h == stamp.blake3);
            if same {
                let _ = self.dir.remove_file(rel);
            }
        }
        for rel in self.folders.iter().rev() {
            let _ = self.dir.remove_dir(rel);
        }
        if let Some(stamp) = &self.manifest
            && self.dir.symlink_metadata(OUTPUT_MANIFEST).is_ok_and(|m| m.is_file())
            && hash(&self.dir, OUTPUT_MANIFEST).is_ok_and(|s| s == *stamp)
        {
            let _ = self.dir.remove_file(OUTPUT_MANIFEST);
        }
        self.dir.entries().is_ok_and(|mut e| e.next().is_none())
    }
}

/// The browser has no file system: every folder operation fails there.
#[cfg(target_arch = "wasm32")]
mod wasm {
    use std::io::{Error, ErrorKind, Result};
    use std::path::Path;

    fn none<T>() -> Result<T> {
        Err(Error::new(ErrorKind::Unsupported, "no file system here"))
    }

    pub struct Dir;
    pub struct Entry;
    pub struct Kind;
    pub struct Meta;

    impl Dir {
        pub fn open_ambient_dir(_: &Path) -> Result<Dir> {
            none()
        }
        pub fn entries(&self) -> Result<std::vec::IntoIter<Result<Entry>>> {
            none()
        }
        pub fn open_dir(&self, _: &str) -> Result<Dir> {
            none()
        }
        pub fn open(&self, _: &str) -> Result<std::fs::File> {
            none()
        }
        pub fn symlink_metadata(&self, _: &str) -> Result<Meta> {
            none()
        }
        pub fn remove_file(&self, _: &str) -> Result<()> {
            none()
        }
        pub fn remove_dir(&self, _: &str) -> Result<()> {
            none()
        }
        pub fn try_clone(&self) -> Result<Dir> {
            none()
        }
    }
    impl Entry {
        pub fn file_name(&self) -> std::ffi::OsString {
            Default::default()
        }
        pub fn file_type(&self) -> Result<Kind> {
            none()
        }
        pub fn metadata(&self) -> Result<Meta> {
            none()
        }
    }
    impl Kind {
        pub fn is_dir(&self) -> bool {
            false
        }
        pub fn is_file(&self) -> bool {
            false
        }
    }
    impl Meta {
        pub fn is_file(&self) -> bool {
            false
        }
        pub fn len(&self) -> u64 {
            0
        }
    }
    pub trait IntoStd {
        fn into_std(self) -> std::fs::File;
    }
    impl IntoStd for std::fs::File {
        fn into_std(self) -> std::fs::File {
            self
        }
    }
}
#[cfg(target_arch = "wasm32")]
use wasm::IntoStd;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_plain_relative_names_pass() {
        for ok in ["specular.ktx2", "charlie/sheen.ktx2", "a/b/c", ".hidden", "x..y"] {
            assert_eq!(check_name(ok), Ok(()), "{ok}");
        }
        for (bad, why) in [
            ("", UnsafeName::Empty),
            ("a//b", UnsafeName::Empty),
            ("a/", UnsafeName::Empty),
            ("/etc/passwd", UnsafeName::Absolute),
            ("..", UnsafeName::Dots),
            ("../victim", UnsafeName::Dots),
            ("a/../../victim", UnsafeName::Dots),
            ("./a", UnsafeName::Dots),
            ("a\\..\\b", UnsafeName::Foreign),
            ("C:/x", UnsafeName::Foreign),
            ("a\0b", UnsafeName::Foreign),
            (OUTPUT_MANIFEST, UnsafeName::Manifest),
        ] {
            assert_eq!(check_name(bad), Err(why), "{bad:?}");
        }
    }

    #[test]
    fn a_manifest_with_an_unsafe_name_a_duplicate_or_a_bad_hash_is_forged() {
        let hash = "0".repeat(64);
        let m = |entries: Vec<(&str, Option<&str>)>| Manifest {
            format: MANIFEST_FORMAT.into(),
            entries: entries.into_iter().map(|(p, h)| Entry { path: p.into(), file: h.map(|h| Stamp { bytes: 1, blake3: h.into() }) }).collect(),
        };
        assert!(m(vec![("a", Some(&hash)), ("d", None), ("d/b", Some(&hash))]).validate().is_ok());
        assert!(matches!(m(vec![("../v", Some(&hash))]).validate(), Err(Forged::Unsafe { why: UnsafeName::Dots, .. })));
        assert!(matches!(m(vec![("a", Some(&hash)), ("a", None)]).validate(), Err(Forged::Duplicate(_))));
        assert!(matches!(m(vec![("a", Some("x"))]).validate(), Err(Forged::BadHash(_))));
        assert!(matches!(m(vec![("a", Some(&"G".repeat(64)))]).validate(), Err(Forged::BadHash(_))));
        let mut other = m(vec![]);
        other.format = "splitsum-output-0".into();
        assert!(matches!(other.validate(), Err(Forged::Format(_))));
    }
}
