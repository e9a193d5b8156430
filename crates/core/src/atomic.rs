//! Write-to-temporary-then-rename, and what an interrupted process removes: every temporary file
//! and staging folder it made, and the output folders it made that are still empty.

use anyhow::{Context, Result};
use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// What this process made and has not finished: removed by [`remove_unfinished`] when it is
/// interrupted (Ctrl-C), in the reverse order of making.
static UNFINISHED: Mutex<Vec<(PathBuf, Removal)>> = Mutex::new(Vec::new());

/// How an unfinished path goes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Removal {
    /// A temporary file or staging folder: removed with everything in it.
    Whole,
    /// An output folder this process made: removed only while empty.
    IfEmpty,
}

/// Notes `path` as unfinished: an interrupt removes it ([`remove_unfinished`]).
pub fn note_unfinished(path: &Path, how: Removal) {
    if let Ok(mut v) = UNFINISHED.lock() {
        v.push((path.to_path_buf(), how));
    }
}

/// Notes `path` as finished (published, or removed already): an interrupt leaves it.
pub fn note_finished(path: &Path) {
    if let Ok(mut v) = UNFINISHED.lock() {
        v.retain(|(p, _)| p != path);
    }
}

/// Removes everything noted unfinished, newest first: what a Ctrl-C handler calls before the
/// process exits, so that an interrupted run leaves nothing behind. Returns how many paths went.
pub fn remove_unfinished() -> usize {
    let list = match UNFINISHED.lock() {
        Ok(mut v) => std::mem::take(&mut *v),
        Err(_) => return 0,
    };
    let mut removed = 0;
    for (p, how) in list.iter().rev() {
        let gone = match how {
            Removal::Whole if p.is_dir() => std::fs::remove_dir_all(p).is_ok(),
            Removal::Whole => std::fs::remove_file(p).is_ok(),
            Removal::IfEmpty => std::fs::remove_dir(p).is_ok(),
        };
        removed += usize::from(gone);
    }
    removed
}

/// A file being written under a temporary name beside its final path.
pub struct Staged {
    tmp: tempfile::NamedTempFile,
    target: PathBuf,
}

impl Staged {
    /// Starts a staged file for `target` (its folder must exist).
    pub fn new(target: &Path) -> Result<Self> {
        let dir = target
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        let name = target
            .file_name()
            .map(|n| n.to_string_lossy().to_string())
            .unwrap_or_default();
        let tmp = tempfile::Builder::new()
            .prefix(&format!(".{name}."))
            .suffix(".partial")
            .tempfile_in(dir)
            .with_context(|| format!("cannot create a temporary file in {}", dir.display()))?;
        note_unfinished(tmp.path(), Removal::Whole);
        Ok(Self {
            tmp,
            target: target.to_path_buf(),
        })
    }
    /// The temporary path (for writers that open files themselves).
    pub fn path(&self) -> &Path {
        self.tmp.path()
    }
    /// The open temporary file.
    pub fn file(&mut self) -> &mut File {
        self.tmp.as_file_mut()
    }
    /// Flushes to disk, gives the file ordinary permissions (temporary files are private) and renames
    /// it to the final path.
    pub fn commit(self) -> Result<PathBuf> {
        self.tmp.as_file().sync_all().ok();
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            std::fs::set_permissions(self.tmp.path(), std::fs::Permissions::from_mode(0o644)).ok();
        }
        let target = self.target.clone();
        note_finished(self.tmp.path());
        self.tmp
            .persist(&target)
            .with_context(|| format!("cannot rename into {}", target.display()))?;
        Ok(target)
    }
}

/// Writes `path` atomically with the bytes `write` produces.
pub fn write_atomic(path: &Path, write: impl FnOnce(&mut File) -> Result<()>) -> Result<PathBuf> {
    let mut staged = Staged::new(path)?;
    write(staged.file())?;
    staged.file().flush()?;
    staged.commit()
}

/// Writes `text` to `path` atomically (see [`write_atomic`]).
pub fn write_text(path: &Path, text: &str) -> Result<PathBuf> {
    write_atomic(path, |f| {
        use std::io::Write;
        f.write_all(text.as_bytes())?;
        Ok(())
    })
}

/// Folders a command made for its outputs: the ones left empty are removed again when this drops
/// (innermost first), so that a command that fails after making them leaves nothing behind.
#[derive(Debug, Default)]
pub struct MadeDirs {
    made: Vec<PathBuf>,
}

impl MadeDirs {
    /// Makes `dir` and its missing parents, remembering which were missing.
    pub fn create(dir: &Path) -> std::io::Result<Self> {
        let made = dir
            .ancestors()
            .take_while(|d| !d.as_os_str().is_empty() && !d.exists())
            .map(Path::to_path_buf)
            .collect();
        let guard = Self { made };
        std::fs::create_dir_all(dir)?;
        for d in guard.made.iter().rev() {
            note_unfinished(d, Removal::IfEmpty);
        }
        Ok(guard)
    }
}

impl Drop for MadeDirs {
    fn drop(&mut self) {
        // `remove_dir` removes only an empty folder: one with an output in it stays, and so do its
        // parents.
        for d in &self.made {
            note_finished(d);
        }
        for d in &self.made {
            if std::fs::remove_dir(d).is_err() {
                break;
            }
        }
    }
}
