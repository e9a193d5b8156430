//! Errors that reach the user. Bad input is an [`InputError`] (exit code 2) naming the file and key.

use std::fmt;
use std::path::{Path, PathBuf};

/// Bad input: a malformed, unknown, missing, out-of-range or non-finite value in a file the user gave.
///
/// Displayed on one line as `FILE: KEY: MESSAGE`, so the user knows where to look and what to do.
#[derive(Debug, Clone, PartialEq)]
pub struct InputError {
    /// The file that holds the bad value (or the command line, for `--set`).
    pub file: PathBuf,
    /// The dotted key path of the bad value, empty when the whole file is at fault.
    pub key: String,
    /// What is wrong and, where possible, what to do about it.
    pub message: String,
}

impl InputError {
    /// A new input error for `file` at `key`.
    pub fn new(file: impl AsRef<Path>, key: impl Into<String>, message: impl Into<String>) -> Self {
        Self {
            file: file.as_ref().to_path_buf(),
            key: key.into(),
            message: message.into(),
        }
    }
}

impl fmt::Display for InputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let msg = self.message.replace('\n', " ");
        if self.key.is_empty() {
            write!(f, "{}: {}", self.file.display(), msg)
        } else {
            write!(f, "{}: key `{}`: {}", self.file.display(), self.key, msg)
        }
    }
}

impl std::error::Error for InputError {}

/// A bad key and what is wrong with it, before the file it is in is known: a stage parameter
/// (the key under `params.`, empty for the whole table), a scene section's key, a config case's.
/// [`InputError`] adds the file.
#[derive(Debug, Clone, PartialEq)]
pub struct KeyError {
    /// Dotted key, relative to the table checked.
    pub key: String,
    /// What is wrong.
    pub message: String,
}

impl KeyError {
    /// A new key error.
    pub fn new(key: impl Into<String>, message: impl Into<String>) -> Self {
        Self {
            key: key.into(),
            message: message.into(),
        }
    }
    /// Ok when `v` is a finite number > 0; else the error naming `key`.
    pub fn positive(key: &str, v: f64) -> Result<(), KeyError> {
        if !v.is_finite() || v <= 0.0 {
            return Err(Self::new(
                key,
                format!("must be a finite number > 0, got {v}"),
            ));
        }
        Ok(())
    }
    /// Ok when `v` is a finite number ≥ 0; else the error naming `key`.
    pub fn non_negative(key: &str, v: f64) -> Result<(), KeyError> {
        if !v.is_finite() || v < 0.0 {
            return Err(Self::new(
                key,
                format!("must be a finite number ≥ 0, got {v}"),
            ));
        }
        Ok(())
    }
    /// The same error under `prefix.` (a section's key seen from the file).
    pub fn under(self, prefix: &str) -> Self {
        Self::new(format!("{prefix}.{}", self.key), self.message)
    }
}

/// Exit code for success.
pub const EXIT_OK: i32 = 0;
/// Exit code when a run or stage failed (I/O, a solver status that the caller treats as failure).
pub const EXIT_FAILED: i32 = 1;
/// Exit code for bad input.
pub const EXIT_BAD_INPUT: i32 = 2;
/// Exit code of a run stopped by Ctrl-C (SIGINT), as shells report 128 + 2.
pub const EXIT_INTERRUPTED: i32 = 130;

/// Maps an error chain to the process exit code: 2 for bad input, 1 otherwise.
pub fn exit_code(err: &anyhow::Error) -> i32 {
    if err.chain().any(|e| e.is::<InputError>()) {
        EXIT_BAD_INPUT
    } else {
        EXIT_FAILED
    }
}
