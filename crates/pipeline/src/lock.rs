//! One run at a time in a run folder: `drapelab run` holds an exclusive lock on
//! `runs/<pipeline>/.lock` (the OS file lock of `std::fs::File::lock`, released by the kernel when
//! the process ends, killed or not) and writes who holds it into the file. A second run is refused
//! with an [`InputError`] naming the holder (exit 2), or waits for it (`--wait`). A lock file that
//! still names a holder when the lock is free was left by a killed run; it is taken over, and said.

use drapelab_core::error::InputError;
use serde::{Deserialize, Serialize};
use std::fs::{File, TryLockError};
use std::io::{Read, Seek, Write};
use std::path::{Path, PathBuf};

/// Who holds a run folder's lock, as written in the lock file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Holder {
    /// Process id.
    pub pid: u32,
    /// Host name ([`drapelab_core::provenance::host`]).
    pub host: String,
    /// When it took the lock, Unix time in s.
    pub started_unix_s: u64,
    /// Its command line.
    pub command_line: Vec<String>,
}

impl Holder {
    fn this_process() -> Self {
        Self {
            pid: std::process::id(),
            host: drapelab_core::provenance::host(),
            started_unix_s: drapelab_core::provenance::unix_now_s(),
            command_line: std::env::args().collect(),
        }
    }
    fn describe(&self) -> String {
        use drapelab_core::provenance::{age, utc};
        format!(
            "process {} on {} (`{}`), running since {} ({} ago)",
            self.pid,
            self.host,
            self.command_line.join(" "),
            utc(self.started_unix_s),
            age(self.started_unix_s)
        )
    }
}

/// Whether to wait for a run folder held by another run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LockWait {
    /// Refuse at once (exit 2, naming the holder). Default.
    #[default]
    No,
    /// Block until the holder finishes.
    Yes,
}

/// The held lock of a run folder; released (and its holder record cleared) when dropped.
#[derive(Debug)]
pub struct RunLock {
    file: File,
    path: PathBuf,
    /// The holder recorded by a run that ended without releasing the lock (killed), if any.
    pub taken_over: Option<Holder>,
}

impl RunLock {
    /// Takes the lock of `run_dir` (created if missing).
    pub fn acquire(run_dir: &Path, wait: LockWait) -> Result<Self, InputError> {
        let path = run_dir.join(".lock");
        let io = |e: std::io::Error| InputError::new(&path, "", format!("cannot lock: {e}"));
        std::fs::create_dir_all(run_dir).map_err(io)?;
        let mut file = File::options()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(&path)
            .map_err(io)?;
        match file.try_lock() {
            Ok(()) => {}
            Err(TryLockError::WouldBlock) => {
                let holder = read_holder(&mut file)
                    .map_or_else(|| "another process".into(), |h| h.describe());
                if wait == LockWait::No {
                    return Err(InputError::new(
                        &path,
                        "",
                        format!(
                            "the run folder is in use by {holder}; wait for it to finish or pass --wait"
                        ),
                    ));
                }
                tracing::info!("waiting for the run folder, held by {holder}");
                file.lock().map_err(io)?;
            }
            Err(TryLockError::Error(e)) => return Err(io(e)),
        }
        let taken_over = read_holder(&mut file);
        if let Some(h) = &taken_over {
            tracing::warn!(
                "taking over the lock of {} left by {} (it ended without releasing it)",
                run_dir.display(),
                h.describe()
            );
        }
        let json = serde_json::to_string(&Holder::this_process()).unwrap_or_default();
        file.set_len(0).map_err(io)?;
        file.rewind().map_err(io)?;
        file.write_all(json.as_bytes()).map_err(io)?;
        file.flush().map_err(io)?;
        Ok(Self {
            file,
            path,
            taken_over,
        })
    }
    /// The lock file.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

impl Drop for RunLock {
    fn drop(&mut self) {
        // An empty file means "released cleanly"; the kernel drops the lock with the descriptor.
        self.file.set_len(0).ok();
        // A run that wrote nothing (refused as bad input before its first stage) leaves no folder:
        // the lock file goes, then the folder if it is empty. (A run waiting on this lock then
        // holds a removed file; a third run arriving in that instant would make a new one.)
        if let Some(dir) = self.path.parent()
            && std::fs::read_dir(dir).is_ok_and(|d| d.count() == 1)
        {
            std::fs::remove_file(&self.path).ok();
            std::fs::remove_dir(dir).ok();
        }
        self.file.unlock().ok();
    }
}

/// The holder recorded in a lock file, if any.
fn read_holder(file: &mut File) -> Option<Holder> {
    let mut s = String::new();
    file.rewind().ok()?;
    file.read_to_string(&mut s).ok()?;
    serde_json::from_str(&s).ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_second_lock_is_refused_naming_the_holder_and_a_left_record_is_taken_over() {
        let tmp = tempfile::tempdir().unwrap();
        let run = tmp.path().join("runs/t");
        let first = RunLock::acquire(&run, LockWait::No).unwrap();
        assert!(first.taken_over.is_none());
        let err = RunLock::acquire(&run, LockWait::No).unwrap_err();
        assert!(
            err.message
                .contains(&format!("process {}", std::process::id())),
            "{err}"
        );
        drop(first);
        // A run that wrote nothing leaves no folder behind.
        assert!(!run.exists());
        // A record without a holder (as a killed run leaves it) is taken over.
        let stale = Holder {
            pid: 4_000_000,
            host: "h".into(),
            started_unix_s: 1,
            command_line: vec!["drapelab".into(), "run".into()],
        };
        std::fs::create_dir_all(&run).unwrap();
        std::fs::write(run.join(".lock"), serde_json::to_string(&stale).unwrap()).unwrap();
        let again = RunLock::acquire(&run, LockWait::No).unwrap();
        assert_eq!(again.taken_over, Some(stale));
    }
}
