//! How a stage ended and why a stage must run, as data: the runner, the manifests, `drapelab status`
//! and the progress display all read these enums, never a sentence.

use serde::{Deserialize, Serialize};
use std::fmt;

/// Why a stage failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FailureCause {
    /// The stage returned an error (a solver status it treats as failure, I/O, …).
    Error,
    /// The stage panicked: a bug in drapelab.
    Panic,
    /// The stage returned without writing one of its outputs.
    MissingOutput,
    /// A stage it depends on failed, so it did not run.
    Upstream,
}

/// How a stage ended; kept in its manifest (`status`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "outcome")]
pub enum StageOutcome {
    /// Every output written.
    Ok,
    /// It failed; `message` says what happened and, where possible, what to do.
    Failed {
        /// What kind of failure.
        cause: FailureCause,
        /// One line.
        message: String,
    },
}

impl StageOutcome {
    /// A failure of `cause`.
    pub fn failed(cause: FailureCause, message: impl Into<String>) -> Self {
        Self::Failed {
            cause,
            message: message.into().replace('\n', " "),
        }
    }
    /// Whether the stage succeeded.
    pub fn is_ok(&self) -> bool {
        matches!(self, Self::Ok)
    }
}

impl fmt::Display for StageOutcome {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Ok => write!(f, "ok"),
            Self::Failed { message, .. } => write!(f, "failed: {message}"),
        }
    }
}

/// Why a stage is not up to date.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "reason", content = "detail")]
pub enum StaleReason {
    /// `--force` named it or a stage above it.
    Forced,
    /// A stage it reads from will run first.
    UpstreamWillRun(String),
    /// It never completed (no manifest).
    NeverRun,
    /// Its last run failed.
    LastRunFailed(String),
    /// Another drapelab version wrote the manifest.
    VersionChanged {
        /// The manifest's version.
        from: String,
        /// This version.
        to: String,
    },
    /// These parameters changed.
    ParamsChanged(Vec<String>),
    /// An input file is missing.
    InputMissing(String),
    /// A new input file matched its patterns.
    InputAdded(String),
    /// An input file's content changed.
    InputChanged(String),
    /// An input file is no longer matched.
    InputRemoved(String),
    /// An output is missing or not the size the manifest recorded.
    OutputAltered(String),
    /// The manifest's key does not match its recorded inputs.
    KeyMismatch,
    /// drapelab was rebuilt since.
    Rebuilt {
        /// The manifest's build.
        from: String,
        /// This build.
        to: String,
    },
}

impl fmt::Display for StaleReason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Forced => write!(f, "forced"),
            Self::UpstreamWillRun(d) => write!(f, "upstream stage `{d}` will run"),
            Self::NeverRun => write!(f, "never completed (no manifest)"),
            Self::LastRunFailed(m) => write!(f, "last run failed: {m}"),
            Self::VersionChanged { from, to } => {
                write!(f, "drapelab version changed ({from} → {to})")
            }
            Self::ParamsChanged(k) => write!(f, "parameter changed: {}", k.join(", ")),
            Self::InputMissing(p) => write!(f, "input `{p}` is missing"),
            Self::InputAdded(p) => write!(f, "new input `{p}`"),
            Self::InputChanged(p) => write!(f, "input `{p}` changed"),
            Self::InputRemoved(p) => write!(f, "input `{p}` removed"),
            Self::OutputAltered(p) => write!(f, "output `{p}` missing or altered"),
            Self::KeyMismatch => write!(f, "manifest key mismatch"),
            Self::Rebuilt { from, to } => write!(f, "drapelab was rebuilt (build {from} → {to})"),
        }
    }
}
