//! Where a bake's files go: a folder on disk ([`Folder`], each file written atomically)
//! or memory ([`Memory`], what the web page zips). `output` writes through a [`Sink`], so
//! both receive the same bytes.

use crate::error::Result;
use std::path::Path;
use std::sync::Mutex;

/// Files by name (`/`-separated inside the folder), with their bytes.
pub type Files = Vec<(String, Vec<u8>)>;

/// Receives the files of an output folder, by name.
pub trait Sink: Sync {
    /// Stores `bytes` as `name`: a relative, `/`-separated path that splitsum chose (its
    /// folders are made as needed).
    fn put(&self, name: &str, bytes: &[u8]) -> Result<()>;
}

/// A folder on disk: each file written atomically beneath it (`files::write_atomic`).
pub struct Folder<'a>(pub &'a Path);

impl Sink for Folder<'_> {
    fn put(&self, name: &str, bytes: &[u8]) -> Result<()> {
        super::write_atomic(&self.0.join(name), |w| std::io::Write::write_all(w, bytes))
    }
}

/// Files held in memory.
#[derive(Default)]
pub struct Memory(Mutex<Vec<(String, Vec<u8>)>>);

impl Sink for Memory {
    fn put(&self, name: &str, bytes: &[u8]) -> Result<()> {
        self.0.lock().unwrap_or_else(|e| e.into_inner()).push((name.to_string(), bytes.to_vec()));
        Ok(())
    }
}

impl Memory {
    /// The files stored, by name (files written at once arrive in any order).
    pub fn into_files(self) -> Files {
        let mut files = self.0.into_inner().unwrap_or_else(|e| e.into_inner());
        files.sort_by(|a, b| a.0.cmp(&b.0));
        files
    }
}
