//! A content-addressed cache of bakes: the key is a BLAKE3 hash of the environment's bytes,
//! every setting of the plan, the backend (and its adapter) and the compiled shaders, so an
//! unchanged bake is never redone and any change — a byte of the input, a sample count, a
//! shader edit — makes a new entry.
//!
//! An entry is a folder named by its key: `manifest.json` (the key again, and each file's
//! size and BLAKE3 hash) and one raw little-endian f32 file per product. An entry whose
//! manifest does not name its own key (foreign), or whose files are missing, short or do
//! not hash to the manifest (corrupt), is never used: it is removed and rebuilt. Entries
//! are written to a temporary folder and renamed into place.

use crate::reading::BakedEnvironment;
use crate::error::{Error, Result};
use crate::product::{Product, Shape};
use crate::texture::{Cube, Lut};
use serde::{Deserialize, Serialize};
use splitsum_shaders::cubemap::CubeLayout;
use splitsum_shaders::glam::{Vec2, Vec4};
use splitsum_shaders::prefilter::RoughnessMapping;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Version of the entry format (part of every key).
pub const FORMAT: &str = "splitsum-cache-5";

/// The cache folder: `$SPLITSUM_CACHE`, else `$XDG_CACHE_HOME/splitsum`, else
/// `~/.cache/splitsum`, else `.splitsum-cache`.
pub fn default_dir() -> PathBuf {
    if let Some(d) = std::env::var_os("SPLITSUM_CACHE") {
        return PathBuf::from(d);
    }
    if let Some(d) = std::env::var_os("XDG_CACHE_HOME") {
        return PathBuf::from(d).join("splitsum");
    }
    if let Some(h) = std::env::var_os("HOME") {
        return PathBuf::from(h).join(".cache").join("splitsum");
    }
    PathBuf::from(".splitsum-cache")
}

/// The key of a bake: BLAKE3 of the format, the environment's identity (the hash of its
/// bytes, `environment::identity`), the plan (as JSON), the backend and the SPIR-V modules.
pub fn key(environment: &[u8], plan_json: &str, backend: &str) -> String {
    let mut h = blake3::Hasher::new();
    let modules = splitsum_spirv::ENTRY_POINTS.iter().map(|e| e.bytes());
    for part in [FORMAT.as_bytes(), environment, plan_json.as_bytes(), backend.as_bytes()].into_iter().chain(modules) {
        h.update(&(part.len() as u64).to_le_bytes());
        h.update(part);
    }
    h.finalize().to_hex().to_string()
}

#[derive(Serialize, Deserialize)]
struct FileEntry {
    bytes: u64,
    blake3: String,
}

#[derive(Serialize, Deserialize)]
struct Manifest {
    format: String,
    key: String,
    mapping: u32,
    files: BTreeMap<String, FileEntry>,
}

/// Whether `name` is a file [`Cache::put`] writes: the only names the cache removes
/// (`manifest.json`, `Product::cache_file` of each product, and the excess list's file). Native systems only: a
/// browser has no cache folder.
#[cfg(not(target_arch = "wasm32"))]
fn entry_file(name: &str) -> bool {
    name == "manifest.json" || name == EXCESS_FILE || Product::ALL.iter().any(|p| p.cache_file() == name)
}

/// The largest entry manifest read (a real one is under a kilobyte).
const MAX_MANIFEST_BYTES: u64 = 1 << 20;

/// Removes the entry folder `dir`, only if it is a folder (not a link to one) holding
/// nothing but the files the cache writes (`ENTRY_FILES`, each a regular file); otherwise
/// it is left as it is, and the error names what the cache did not write. The files are
/// removed through a handle to the entry, never through a link.
fn remove_entry(dir: &Path) -> Result<()> {
    let foreign = |what: &str| {
        Error::file(
            dir,
            format!("this cache entry {what}, which splitsum did not write; the cache removes only its own files: move it away, or use another cache folder"),
        )
    };
    match std::fs::symlink_metadata(dir) {
        Ok(m) if m.file_type().is_symlink() => return Err(foreign("is a symbolic link")),
        Ok(m) if !m.is_dir() => return Err(foreign("is not a folder")),
        Ok(_) => {}
        Err(e) => return Err(Error::file_caused(dir, "cannot read the cache entry", e)),
    }
    #[cfg(not(target_arch = "wasm32"))]
    {
        let entry = cap_std::fs::Dir::open_ambient_dir(dir, cap_std::ambient_authority()).map_err(|e| Error::file_caused(dir, "cannot read the cache entry", e))?;
        let mut names = Vec::new();
        for e in entry.entries().map_err(|e| Error::file_caused(dir, "cannot read the cache entry", e))? {
            let e = e.map_err(|e| Error::file_caused(dir, "cannot read the cache entry", e))?;
            let name = e.file_name().to_string_lossy().into_owned();
            let is_file = e.file_type().is_ok_and(|t| t.is_file());
            if !is_file || !entry_file(&name) {
                return Err(foreign(&format!("holds {name}")));
            }
            names.push(name);
        }
        for name in names {
            entry.remove_file(&name).map_err(|err| Error::file_caused(&dir.join(&name), "cannot remove the stale cache file", err))?;
        }
    }
    std::fs::remove_dir(dir).map_err(|e| Error::file_caused(dir, "cannot remove the stale cache entry", e))
}

/// Why a cache entry may not be used (rendered to words only where it is shown).
#[derive(Debug)]
pub enum Rejection {
    /// Its manifest cannot be read.
    NoManifest(Error),
    /// Its manifest is not JSON of the cache's form.
    MalformedManifest(serde_json::Error),
    /// Its manifest names another key or format: another bake's entry.
    Foreign {
        /// The key it names.
        key: String,
        /// The format it names.
        format: String,
    },
    /// The manifest lists no such file.
    Unlisted(&'static str),
    /// A file that cannot be read.
    Unreadable(&'static str, std::io::Error),
    /// A name that is not a regular file.
    NotAFile(&'static str),
    /// A file of another size than the manifest says.
    WrongSize {
        /// The file.
        name: &'static str,
        /// Its size.
        bytes: u64,
        /// The size the manifest lists.
        listed: u64,
    },
    /// A file whose BLAKE3 hash differs from the manifest's.
    WrongHash(&'static str),
    /// A file that changed while it was read.
    Changed(&'static str),
    /// A file that does not hold the cube its name says.
    NotACube(&'static str),
    /// A file that does not hold the table its name says.
    NotATable(&'static str),
    /// A file that does not hold an excess list of at most `split::TEXELS` entries.
    NotAList(&'static str),
}

impl std::fmt::Display for Rejection {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Rejection::NoManifest(e) => write!(f, "no readable manifest ({e})"),
            Rejection::MalformedManifest(e) => write!(f, "malformed manifest ({e})"),
            Rejection::Foreign { key, format } => write!(f, "a foreign entry (its manifest names key {key} in format {format})"),
            Rejection::Unlisted(name) => write!(f, "the manifest lists no {name}"),
            Rejection::Unreadable(name, e) => write!(f, "{name} unreadable ({e})"),
            Rejection::NotAFile(name) => write!(f, "{name} is not a regular file"),
            Rejection::WrongSize { name, bytes, listed } => write!(f, "{name} is corrupt (it holds {bytes} bytes, the manifest says {listed})"),
            Rejection::WrongHash(name) => write!(f, "{name} is corrupt (its BLAKE3 hash differs from the manifest)"),
            Rejection::Changed(name) => write!(f, "{name} changed while it was read"),
            Rejection::NotACube(name) => write!(f, "{name} does not hold a cube"),
            Rejection::NotATable(name) => write!(f, "{name} does not hold a table"),
            Rejection::NotAList(name) => write!(f, "{name} does not hold an excess list"),
        }
    }
}

/// What a lookup found.
pub enum Lookup {
    /// A valid entry.
    Hit(Box<BakedEnvironment>),
    /// No entry.
    Miss,
    /// An entry that may not be used, and why; it has been removed.
    Rejected(Rejection),
    /// An entry that may not be used and holds files the cache did not write: left as it
    /// is, and the error says what is in the way.
    Foreign(Error),
}

/// A cache folder.
pub struct Cache {
    dir: PathBuf,
}

fn cube_bytes(c: &Cube) -> Vec<u8> {
    let mut out = Vec::with_capacity(16 + c.texels.len() * 16);
    out.extend_from_slice(&c.layout.size.to_le_bytes());
    out.extend_from_slice(&c.layout.levels.to_le_bytes());
    out.extend_from_slice(bytemuck::cast_slice(&c.texels));
    out
}

/// The excess list's file in an entry (`BakedEnvironment::excess`), where it has one.
const EXCESS_FILE: &str = "excess.bin";

/// The excess list `bytes` hold (raw `Vec4`s, `bright::ENTRY` an entry), if they hold one
/// of at most `split::TEXELS` entries.
fn list_from(bytes: &[u8]) -> Option<Vec<Vec4>> {
    let entry = 16 * splitsum_shaders::bright::ENTRY as usize;
    let fits = !bytes.is_empty() && bytes.len().is_multiple_of(entry) && bytes.len() / entry <= crate::backend::split::TEXELS as usize;
    fits.then(|| bytemuck::pod_collect_to_vec::<u8, Vec4>(bytes))
}

fn cube_from(bytes: &[u8]) -> Option<Cube> {
    let size = u32::from_le_bytes(bytes.get(0..4)?.try_into().ok()?);
    let levels = u32::from_le_bytes(bytes.get(4..8)?.try_into().ok()?);
    if size == 0 || !size.is_power_of_two() || levels == 0 || levels > 16 {
        return None;
    }
    let layout = CubeLayout::new(size, levels);
    let data = bytes.get(8..)?;
    (data.len() == layout.texel_count() as usize * 16).then(|| Cube { layout, texels: bytemuck::pod_collect_to_vec::<u8, Vec4>(data) })
}

impl Cache {
    /// The cache in `dir` (created on first write).
    pub fn new(dir: impl Into<PathBuf>) -> Self {
        Self { dir: dir.into() }
    }

    /// Where entry `key` lives.
    pub fn entry(&self, key: &str) -> PathBuf {
        self.dir.join(key)
    }

    /// Takes the lock of entry `key` (a `.lock` file beside it, locked exclusively by the
    /// operating system, so a crashed holder releases it): concurrent runs that bake the
    /// same key take turns, and each after the first finds the entry the first stored. Says
    /// on stderr when it has to wait. Held until the returned file is dropped.
    pub fn lock(&self, key: &str) -> Result<std::fs::File> {
        std::fs::create_dir_all(&self.dir).map_err(|e| Error::file_caused(&self.dir, "cannot create the cache folder", e))?;
        let path = self.dir.join(format!("{key}.lock"));
        let mut options = std::fs::OpenOptions::new();
        options.create(true).truncate(false).write(true);
        // Never through a link: a planted `KEY.lock` link must not create or open a file
        // elsewhere.
        #[cfg(unix)]
        std::os::unix::fs::OpenOptionsExt::custom_flags(&mut options, libc::O_NOFOLLOW);
        let file = options
            .open(&path)
            .map_err(|e| Error::file_caused(&path, "cannot open the cache lock", e))?;
        match file.try_lock() {
            Ok(()) => {}
            Err(std::fs::TryLockError::WouldBlock) => {
                crate::progress::note(&format!("waiting for another run that bakes the same scene (cache lock {})", path.display()));
                file.lock().map_err(|e| Error::file_caused(&path, "cannot lock", e))?;
            }
            Err(std::fs::TryLockError::Error(e)) => return Err(Error::file_caused(&path, "cannot lock", e)),
        }
        Ok(file)
    }

    /// Looks up `key`, checking the manifest's key and every file's hash.
    pub fn get(&self, key: &str) -> Lookup {
        let dir = self.entry(key);
        if !dir.exists() {
            return Lookup::Miss;
        }
        match self.read(key, &dir) {
            Ok(env) => Lookup::Hit(Box::new(env)),
            Err(why) => match remove_entry(&dir) {
                Ok(()) => Lookup::Rejected(why),
                Err(e) => Lookup::Foreign(e),
            },
        }
    }

    fn read(&self, key: &str, dir: &Path) -> std::result::Result<BakedEnvironment, Rejection> {
        let manifest = dir.join("manifest.json");
        let text = crate::files::read_text(&manifest, MAX_MANIFEST_BYTES).map_err(Rejection::NoManifest)?;
        let m: Manifest = serde_json::from_str(&text).map_err(Rejection::MalformedManifest)?;
        if m.format != FORMAT || m.key != key {
            return Err(Rejection::Foreign { key: m.key, format: m.format });
        }
        let file = |name: &'static str| -> std::result::Result<Vec<u8>, Rejection> {
            let want = m.files.get(name).ok_or(Rejection::Unlisted(name))?;
            // The size first: a file longer than the manifest says is never read in.
            let meta = std::fs::metadata(dir.join(name)).map_err(|e| Rejection::Unreadable(name, e))?;
            if !meta.is_file() {
                return Err(Rejection::NotAFile(name));
            }
            let len = meta.len();
            if len != want.bytes {
                return Err(Rejection::WrongSize { name, bytes: len, listed: want.bytes });
            }
            // Then the hash, streamed: a file that is not what the manifest says is never held.
            let mut h = blake3::Hasher::new();
            let file = std::fs::File::open(dir.join(name)).map_err(|e| Rejection::Unreadable(name, e))?;
            h.update_reader(file).map_err(|e| Rejection::Unreadable(name, e))?;
            if h.finalize().to_hex().as_str() != want.blake3 {
                return Err(Rejection::WrongHash(name));
            }
            let bytes = std::fs::read(dir.join(name)).map_err(|e| Rejection::Unreadable(name, e))?;
            if bytes.len() as u64 != want.bytes {
                return Err(Rejection::Changed(name));
            }
            Ok(bytes)
        };
        let mut env = BakedEnvironment { cubes: BTreeMap::new(), tables: BTreeMap::new(), mapping: RoughnessMapping::from_u32(m.mapping), excess: Vec::new() };
        // Every product the entry lists, and only those (a plan leaves some out).
        for p in Product::ALL.into_iter().filter(|p| m.files.contains_key(p.cache_file())) {
            let name = p.cache_file();
            match p.shape() {
                Shape::Cube => {
                    env.cubes.insert(p, cube_from(&file(name)?).ok_or(Rejection::NotACube(name))?);
                }
                Shape::Table => {
                    env.tables.insert(p, table_from(&file(name)?).ok_or(Rejection::NotATable(name))?);
                }
                Shape::Coefficients => return Err(Rejection::Unlisted(name)),
            }
        }
        if !env.cubes.contains_key(&Product::SourceCube) {
            return Err(Rejection::Unlisted(Product::SourceCube.cache_file()));
        }
        if m.files.contains_key(EXCESS_FILE) {
            env.excess = list_from(&file(EXCESS_FILE)?).ok_or(Rejection::NotAList(EXCESS_FILE))?;
        }
        Ok(env)
    }

    /// Stores `env` under `key` (atomically: a temporary folder renamed into place).
    pub fn put(&self, key: &str, env: &BakedEnvironment) -> Result<()> {
        let fail = |e: std::io::Error| Error::file_caused(&self.dir, "cannot write the cache", e);
        std::fs::create_dir_all(&self.dir).map_err(fail)?;
        // A folder of a name nobody has (created new, never one found there): the files
        // below are written into this run's own folder.
        let tmp = (0..1000u32)
            .map(|k| self.dir.join(format!(".{key}.{}.{k}.tmp", std::process::id())))
            .find_map(|p| match std::fs::create_dir(&p) {
                Ok(()) => Some(Ok(p)),
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => None,
                Err(e) => Some(Err(e)),
            })
            .unwrap_or_else(|| Err(std::io::Error::other("no free temporary folder name")))
            .map_err(fail)?;
        let mut files = BTreeMap::new();
        // The source cube is its level 0 already (`Baked::into_display`).
        let cubes = env.cubes.iter().map(|(p, c)| (p.cache_file(), cube_bytes(c)));
        let tables = env.tables.iter().map(|(p, t)| (p.cache_file(), table_bytes(t)));
        let excess = (!env.excess.is_empty()).then(|| (EXCESS_FILE, bytemuck::cast_slice::<Vec4, u8>(&env.excess).to_vec()));
        for (name, bytes) in cubes.chain(tables).chain(excess) {
            std::fs::write(tmp.join(name), &bytes).map_err(fail)?;
            files.insert(name.to_string(), FileEntry { bytes: bytes.len() as u64, blake3: blake3::hash(&bytes).to_hex().to_string() });
        }
        let manifest = Manifest { format: FORMAT.into(), key: key.into(), mapping: env.mapping as u32, files };
        std::fs::write(tmp.join("manifest.json"), serde_json::to_string_pretty(&manifest).expect("serialisable")).map_err(fail)?;
        let dest = self.entry(key);
        if std::fs::symlink_metadata(&dest).is_ok()
            && let Err(e) = remove_entry(&dest) {
                let _ = std::fs::remove_dir_all(&tmp);
                return Err(e);
            }
        std::fs::rename(&tmp, &dest).map_err(|e| {
            let _ = std::fs::remove_dir_all(&tmp);
            fail(e)
        })
    }
}

/// A table as the cache stores it: its size (u32), then its texels.
fn table_bytes(t: &Lut) -> Vec<u8> {
    let mut out = t.size.to_le_bytes().to_vec();
    out.extend_from_slice(bytemuck::cast_slice(&t.texels));
    out
}

/// The table [`table_bytes`] wrote, if `bytes` hold one.
fn table_from(bytes: &[u8]) -> Option<Lut> {
    let size = u32::from_le_bytes(bytes.get(0..4)?.try_into().ok()?);
    let data = &bytes[4..];
    if size == 0 || data.len() != (size as usize).pow(2) * 8 {
        return None;
    }
    Some(Lut { size, texels: bytemuck::pod_collect_to_vec::<u8, Vec2>(data) })
}
