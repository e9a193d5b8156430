//! Where the items of a stage run: threads of this process (`local`) or the tasks of one Slurm job
//! array per stage (`slurm`). The `[executor]` table of a pipeline file, overridden by
//! `drapelab run --executor`.

use drapelab_core::error::InputError;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Which executor runs the items.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ExecutorKind {
    /// Threads of this process (rayon; `--jobs`). Default.
    #[default]
    Local,
    /// One `sbatch --array` job per stage; its tasks run `drapelab worker` for their items.
    Slurm,
}

/// The `[executor]` table of a pipeline file. Only `slurm` reads the keys past `kind`.
#[allow(non_snake_case)]
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExecutorSettings {
    /// "local" (default) or "slurm".
    #[serde(default)]
    pub kind: ExecutorKind,
    /// Slurm partition (`sbatch --partition`); checked against `sinfo`. Default: the cluster's default.
    #[serde(default)]
    pub partition: Option<String>,
    /// Slurm account (`sbatch --account`). Default: none.
    #[serde(default)]
    pub account: Option<String>,
    /// Time limit of one array task, minutes (`sbatch --time`). Default 60.
    #[serde(default = "default_time")]
    pub time_limit_min: u32,
    /// Memory of one array task, MB (`sbatch --mem`). Default: the partition's default.
    #[serde(default)]
    pub memory_MB_per_task: Option<u64>,
    /// CPUs of one array task (`sbatch --cpus-per-task`; its items' threads). Default 1.
    #[serde(default = "default_one")]
    pub cpus_per_task: u32,
    /// Array tasks running at once (`--array=…%N`). Default: no limit.
    #[serde(default)]
    pub max_concurrent_tasks: Option<u32>,
    /// Items per array task (a chunk). Default 1.
    #[serde(default = "default_one")]
    pub items_per_task: u32,
    /// Submissions of a stage's missing items after the first (failed, cancelled or timed-out
    /// tasks). Default 2.
    #[serde(default = "default_resubmit")]
    pub max_resubmissions: u32,
    /// Seconds between two looks at `squeue`. Default 2.
    #[serde(default = "default_poll")]
    pub poll_interval_s: f64,
    /// More `sbatch` options, each one argument, e.g. ["--qos=short", "--constraint=avx2"].
    #[serde(default)]
    pub sbatch_options: Vec<String>,
}

fn default_time() -> u32 {
    60
}
fn default_one() -> u32 {
    1
}
fn default_resubmit() -> u32 {
    2
}
fn default_poll() -> f64 {
    2.0
}

impl Default for ExecutorSettings {
    fn default() -> Self {
        Self {
            kind: ExecutorKind::Local,
            partition: None,
            account: None,
            time_limit_min: default_time(),
            memory_MB_per_task: None,
            cpus_per_task: default_one(),
            max_concurrent_tasks: None,
            items_per_task: default_one(),
            max_resubmissions: default_resubmit(),
            poll_interval_s: default_poll(),
            sbatch_options: Vec::new(),
        }
    }
}

impl ExecutorSettings {
    /// Checks the values (not the cluster): an [`InputError`] naming `file` and `executor.KEY`.
    pub fn check(&self, file: &Path) -> Result<(), InputError> {
        let bad = |key: &str, msg: &str| {
            Err(InputError::new(
                file,
                format!("executor.{key}"),
                msg.to_string(),
            ))
        };
        if self.time_limit_min == 0 {
            return bad(
                "time_limit_min",
                "must be ≥ 1 minute: give the time one array task may run",
            );
        }
        if self.items_per_task == 0 {
            return bad("items_per_task", "must be ≥ 1");
        }
        if self.cpus_per_task == 0 {
            return bad("cpus_per_task", "must be ≥ 1");
        }
        if self.max_concurrent_tasks == Some(0) {
            return bad(
                "max_concurrent_tasks",
                "must be ≥ 1 (leave it out for no limit)",
            );
        }
        if self.memory_MB_per_task == Some(0) {
            return bad(
                "memory_MB_per_task",
                "must be ≥ 1 (leave it out for the partition's default)",
            );
        }
        if !(self.poll_interval_s.is_finite() && self.poll_interval_s > 0.0) {
            return bad("poll_interval_s", "must be a positive number of seconds");
        }
        Ok(())
    }
}
