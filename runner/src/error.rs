//! Errors of the runner library. Every message names what went wrong and, for files, which
//! file; the binary adds context with `anyhow` at its edge.

use std::path::{Path, PathBuf};
use thiserror::Error;

/// Something the runner could not do.
#[derive(Debug, Error)]
pub enum Error {
    /// No Vulkan adapter: the GPU backend cannot run here.
    #[error(
        "no Vulkan GPU adapter found{detail}.\n  \
         Run on the CPU instead with `--backend cpu`, or install a Vulkan driver; on Debian \
         or Ubuntu the CPU driver lavapipe works: `sudo apt-get install -y mesa-vulkan-drivers libvulkan1`"
    )]
    NoAdapter {
        /// What wgpu said, if anything.
        detail: String,
    },
    /// The GPU device refused something (a pipeline, a buffer, a limit).
    #[error("GPU: {0}")]
    Gpu(String),
    /// A file that could not be read, written or understood.
    #[error("{}: {problem}", path.display())]
    File {
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        problem: String,
    },
    /// An argument out of its range.
    #[error("{0}")]
    Invalid(String),
}

impl Error {
    /// A problem with the file at `path`.
    pub fn file(path: &Path, problem: impl Into<String>) -> Self {
        Self::File { path: path.to_path_buf(), problem: problem.into() }
    }
}

/// The runner's result type.
pub type Result<T, E = Error> = std::result::Result<T, E>;
