//! Declarative make-style pipelines (n2's habit): stages read from `pipelines/*.toml`, a graph from
//! declared inputs and outputs, and a stage is up to date when the hash of its input files' content,
//! its resolved parameters and the drapelab version matches the one in its manifest.
//!
//! Paths in a pipeline are relative to the project root (the folder above `pipelines/`); `{run}`
//! stands for `runs/<pipeline>`. An input equal to (or a glob matching) another stage's output makes
//! that stage a dependency.

#![warn(missing_docs)]
mod executor;
mod files;
mod items;
mod lock;
mod manifest;
mod outcome;
mod plan;
mod progress;
mod runner;
mod slurm;
mod stage;
mod stale;

pub use executor::{ExecutorKind, ExecutorSettings};
pub use items::{Executor, Local, part_path, parts_dir};
pub use lock::{Holder, LockWait, RunLock};
pub use manifest::{Manifest, hash_file};
pub use outcome::{FailureCause, StageOutcome, StaleReason};
pub use plan::{Paths, Plan, PlannedStage, StageSpec, load_plan};
pub use progress::{LogProgress, MultiBarProgress, Progress, progress_for_terminal};
pub use runner::{RunOptions, RunSummary, load_checked_plan, run_pipeline, run_worker};
pub use stage::{ItemKind, KeyError, Registry, Slot, Stage, StageContext, StageKind, typed_params};
pub use stale::{StageState, manifest_path, stage_states};
