//! Output folders written as a unit ([`OutputDir`]): staged beside the target, swapped in
//! whole, the old folder's entries removed only as `manifest` allows.

use super::manifest::{Verified, check_replaceable, manifest_of};
use super::{Error, OUTPUT_MANIFEST, PENDING, Result, parent_dir, write_atomic};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Makes SIGINT, SIGTERM and SIGHUP remove every uncommitted staging folder (and the
/// folders made for it) and exit with 130. A process-wide signal handler: the command line
/// installs it; an application with its own handling leaves it out (its interrupted runs
/// may then leave a hidden `.NAME.splitsum-PID` folder beside the output).
pub fn remove_staging_on_interrupt() {
    #[cfg(not(target_arch = "wasm32"))]
    static ONCE: std::sync::Once = std::sync::Once::new();
    #[cfg(not(target_arch = "wasm32"))]
    ONCE.call_once(|| {
        // ctrlc runs this on its own thread, so it may take locks and touch files.
        let _ = ctrlc::set_handler(|| {
            let pending = PENDING.lock().unwrap_or_else(|e| e.into_inner());
            for (staging, created) in pending.iter() {
                let _ = std::fs::remove_dir_all(staging);
                for d in created.iter().rev() {
                    let _ = std::fs::remove_dir(d);
                }
            }
            eprintln!("interrupted: the output folder is as it was");
            std::process::exit(130);
        });
    });
}

/// An output folder written as a unit: every file goes into a hidden staging folder beside
/// it, and [`OutputDir::commit`] lists them in the folder's [`OUTPUT_MANIFEST`], checks the
/// old folder again, swaps the staging folder and the old folder in one
/// `renameat2(RENAME_EXCHANGE)` (Linux; elsewhere two renames), then removes from the old
/// folder what that check saw and nothing else ([`check_replaceable`]). A reader sees the
/// whole old set of files or the whole new set, never a mix; a failure before the commit
/// leaves the old folder as it was, no staging folder and no folder this run created, and
/// so does an interruption once [`remove_staging_on_interrupt`] is on. A folder holding
/// anything splitsum did not write, or a manifest splitsum could not have written, is
/// never replaced.
pub struct OutputDir {
    target: PathBuf,
    called: String,
    staging: PathBuf,
    created: Vec<PathBuf>,
    committed: bool,
}

impl OutputDir {
    /// Starts writing the folder `target`; `called` is what the caller calls it (a flag, a
    /// field), for messages. Refuses the root of the file system, a path that names no
    /// folder (`.`, `..`), a file or a symbolic link, and a folder holding anything
    /// splitsum did not write there ([`check_replaceable`]): it would be replaced whole.
    pub fn begin(target: &Path, called: &str) -> Result<Self> {
        let shown = target.display();
        if target.has_root() && target.parent().is_none() {
            return Err(Error::Invalid(format!(
                "{called} {shown} is the root of the file system; splitsum replaces its output folder as a whole: give a folder of its own, such as {called} out"
            )));
        }
        let name = target.file_name().filter(|n| *n != "." && *n != "..").ok_or_else(|| {
            Error::Invalid(format!("{called} {shown} names no folder (the output folder is replaced as a whole; give one such as {called} out)"))
        })?;
        match std::fs::symlink_metadata(target) {
            Ok(m) if m.file_type().is_symlink() => {
                return Err(Error::Invalid(format!("{called} {shown} is a symbolic link; give the folder itself (the output folder is replaced as a whole)")));
            }
            Ok(m) if !m.is_dir() => return Err(Error::Invalid(format!("{called} {shown} is an existing file; give a folder (it is created if missing)"))),
            Ok(_) => drop(check_replaceable(target, called)?),
            Err(_) => {}
        }
        let parent = parent_dir(target);
        // The folders above the output that this run creates (removed again on failure).
        let mut created = Vec::new();
        let mut up = parent.clone();
        while !up.exists() {
            created.push(up.clone());
            match up.parent() {
                Some(p) if !p.as_os_str().is_empty() => up = p.to_path_buf(),
                _ => break,
            }
        }
        created.reverse();
        let staging = parent.join(format!(".{}.splitsum-{}", name.to_string_lossy(), std::process::id()));
        {
            let mut pending = PENDING.lock().unwrap_or_else(|e| e.into_inner());
            let made = std::fs::create_dir_all(&parent).and_then(|_| std::fs::create_dir(&staging));
            if let Err(e) = made {
                for d in created.iter().rev() {
                    let _ = std::fs::remove_dir(d);
                }
                let why = match e.kind() {
                    std::io::ErrorKind::AlreadyExists => {
                        format!("{} is in the way (a staging folder of another run with this process id?); remove it", staging.display())
                    }
                    std::io::ErrorKind::PermissionDenied => {
                        format!("the folder it goes in, {}, takes no new entries from this user (permission denied)", parent.display())
                    }
                    _ => e.to_string(),
                };
                return Err(Error::file(target, format!("cannot create the output folder: {why}")));
            }
            pending.push((staging.clone(), created.clone()));
        }
        Ok(Self { target: target.to_path_buf(), called: called.to_string(), staging, created, committed: false })
    }

    /// The folder to write into (the staging folder).
    pub fn path(&self) -> &Path {
        &self.staging
    }

    /// The folder the files end up in.
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// Makes the staged files the output folder, replacing the old one whole: the staged
    /// entries are listed in the manifest, the old folder is checked again (it may have
    /// changed while the run worked), the two are swapped, and what that check saw is
    /// removed from the old folder. Should anything else be in the old folder by then (an
    /// entry that appeared, or a file that changed, between the check and the swap), that
    /// folder is kept beside the new one and a note says where.
    pub fn commit(mut self) -> Result<()> {
        let manifest = manifest_of(&self.staging).map_err(|e| Error::file_caused(&self.target, "cannot list the output files", e))?;
        write_atomic(&self.staging.join(OUTPUT_MANIFEST), |w| w.write_all(&manifest.to_json()))?;
        let pending = PENDING.lock().unwrap_or_else(|e| e.into_inner());
        let old: Option<Verified> = match std::fs::symlink_metadata(&self.target) {
            Ok(m) if m.is_dir() && !m.file_type().is_symlink() => Some(check_replaceable(&self.target, &self.called)?),
            Ok(_) => return Err(Error::Invalid(format!("{} {} is no longer a folder; nothing was replaced", self.called, self.target.display()))),
            Err(_) => None,
        };
        sync_dir(&self.staging);
        let swapped = if old.is_some() { exchange(&self.staging, &self.target) } else { std::fs::rename(&self.staging, &self.target) };
        swapped.map_err(|e| Error::file_caused(&self.target, "could not replace the output folder", e))?;
        sync_dir(&parent_dir(&self.target));
        self.committed = true;
        // The staging path now holds the old folder, which `old`'s handle follows.
        if let Some(old) = old {
            let emptied = old.remove();
            drop(old);
            if !(emptied && std::fs::remove_dir(&self.staging).is_ok()) {
                let kept = self.staging.with_file_name(format!(
                    "{}.kept",
                    self.staging.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default()
                ));
                let at = if std::fs::rename(&self.staging, &kept).is_ok() { kept } else { self.staging.clone() };
                crate::progress::note(&format!(
                    "note: entries appeared or changed in {} {} while this run worked: the old folder, with them, is kept at {}",
                    self.called,
                    self.target.display(),
                    at.display()
                ));
            }
        }
        drop(pending);
        PENDING.lock().unwrap_or_else(|e| e.into_inner()).retain(|(s, _)| *s != self.staging);
        Ok(())
    }
}

impl Drop for OutputDir {
    fn drop(&mut self) {
        if self.committed {
            return;
        }
        let mut pending = PENDING.lock().unwrap_or_else(|e| e.into_inner());
        let _ = std::fs::remove_dir_all(&self.staging);
        for d in self.created.iter().rev() {
            let _ = std::fs::remove_dir(d);
        }
        pending.retain(|(s, _)| *s != self.staging);
    }
}

fn sync_dir(dir: &Path) {
    if let Ok(f) = std::fs::File::open(dir) {
        let _ = f.sync_all();
    }
}

/// Swaps the folders `a` and `b` atomically.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn exchange(a: &Path, b: &Path) -> std::io::Result<()> {
    use std::os::unix::ffi::OsStrExt;
    let c = |p: &Path| std::ffi::CString::new(p.as_os_str().as_bytes()).map_err(std::io::Error::other);
    let (ca, cb) = (c(a)?, c(b)?);
    // SAFETY: two valid NUL-terminated paths, relative to the current directory.
    let r = unsafe { libc::renameat2(libc::AT_FDCWD, ca.as_ptr(), libc::AT_FDCWD, cb.as_ptr(), libc::RENAME_EXCHANGE) };
    if r == 0 { Ok(()) } else { Err(std::io::Error::last_os_error()) }
}

/// Swaps the folders `a` and `b` with two renames (no atomic exchange on this system: for
/// a moment `b` does not exist, but it never holds a mix).
#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
#[allow(dead_code)]
fn exchange(a: &Path, b: &Path) -> std::io::Result<()> {
    let aside = a.with_extension("old");
    std::fs::rename(b, &aside)?;
    std::fs::rename(a, b)?;
    std::fs::rename(&aside, a)
}
