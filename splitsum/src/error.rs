//! Errors of the splitsum library, in its own terms: a setting by its field name, a file by
//! its path. The command line maps them to the flags a user wrote (`runner`'s `cli`).
//!
//! A message says what splitsum could not do; what failed underneath (an I/O error, a
//! decoder's, wgpu's) is its [`source`](std::error::Error::source), not part of the
//! message, so that a caller printing the chain (`anyhow`'s `{:#}`) reads each cause once.

use std::path::{Path, PathBuf};
use thiserror::Error;

/// What failed underneath an [`Error`](enum@Error): an I/O error, a decoder's, wgpu's.
pub type Cause = Box<dyn std::error::Error + Send + Sync + 'static>;

/// Something splitsum could not do. New kinds may be added: match with a wildcard arm.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum Error {
    /// No GPU adapter: the GPU backend cannot run here.
    #[error(
        "no GPU adapter found{detail}.\n  \
         Bake on the CPU instead, or install a driver; on Debian or Ubuntu Mesa's CPU \
         drivers work: `sudo apt-get install -y mesa-vulkan-drivers libvulkan1` (Vulkan, \
         lavapipe) or `libegl1 libgles2 libgl1-mesa-dri` (GL, llvmpipe)"
    )]
    NoAdapter {
        /// What wgpu said, if anything.
        detail: String,
    },
    /// The GPU device refused something (a pipeline, a buffer, a limit).
    #[error("GPU: {problem}")]
    Gpu {
        /// What could not be done.
        problem: String,
        /// What wgpu (or the window system) said, if anything.
        #[source]
        cause: Option<Cause>,
    },
    /// A file that could not be read, written or understood.
    #[error("{}: {problem}", path.display())]
    File {
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        problem: String,
        /// What failed underneath (the I/O error, the decoder's), if anything.
        #[source]
        cause: Option<Cause>,
    },
    /// An environment with NaN or infinite texels, read without sanitising.
    #[error(
        "{}: has {nan} texels with NaN and {infinite} with an infinite value; sanitising replaces NaN and -inf by 0 and +inf by the channel's largest finite value",
        path.display()
    )]
    NonFinite {
        /// The file.
        path: PathBuf,
        /// Texels with a NaN channel.
        nan: u64,
        /// Texels with an infinite channel.
        infinite: u64,
    },
    /// A field of `Settings` out of its range.
    #[error("{field} {problem}")]
    Setting {
        /// The field of `Settings`.
        field: crate::field::Field,
        /// What is wrong with its value.
        problem: String,
    },
    /// A bake estimated to run longer than `bake::MAX_UNFORCED_SECONDS`, not forced.
    #[error("this bake is estimated to take {} ({} of it for the {step})", crate::progress::seconds(*seconds), crate::progress::seconds(*step_seconds))]
    TooLong {
        /// The estimate, in seconds.
        seconds: f64,
        /// Its longest step.
        step: crate::product::Product,
        /// That step's estimate.
        step_seconds: f64,
    },
    /// An argument out of its range.
    #[error("{0}")]
    Invalid(String),
}

impl Error {
    /// A problem with the file at `path`.
    pub fn file(path: &Path, problem: impl Into<String>) -> Self {
        Self::File { path: path.to_path_buf(), problem: problem.into(), cause: None }
    }

    /// A problem with the file at `path`, because of `cause`.
    pub fn file_caused(path: &Path, problem: impl Into<String>, cause: impl Into<Cause>) -> Self {
        Self::File { path: path.to_path_buf(), problem: problem.into(), cause: Some(cause.into()) }
    }

    /// Something the GPU device refused.
    pub fn gpu(problem: impl Into<String>) -> Self {
        Self::Gpu { problem: problem.into(), cause: None }
    }

    /// Something the GPU device refused, because of `cause`.
    pub fn gpu_caused(problem: impl Into<String>, cause: impl Into<Cause>) -> Self {
        Self::Gpu { problem: problem.into(), cause: Some(cause.into()) }
    }

    /// A problem with field `field` of `Settings`.
    pub fn setting(field: crate::field::Field, problem: impl Into<String>) -> Self {
        Self::Setting { field, problem: problem.into() }
    }
}

/// `e` and what failed underneath it, one cause after another (as `anyhow`'s `{:#}` prints
/// a chain): for messages that go on after an error, where no `anyhow` is at hand.
pub fn chain(e: &(dyn std::error::Error + 'static)) -> String {
    let mut text = e.to_string();
    let mut cause = e.source();
    while let Some(c) = cause {
        text += &format!(": {c}");
        cause = c.source();
    }
    text
}

/// splitsum's result type.
pub type Result<T, E = Error> = std::result::Result<T, E>;
