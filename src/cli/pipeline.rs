//! `drapelab run`, `drapelab status` and the hidden `drapelab worker`: pipelines run make-style,
//! their staleness, and one Slurm array task's items.

use super::ExecutorArg;
use crate::error::{EXIT_FAILED, EXIT_OK, InputError};
use anyhow::Result;
use std::path::{Path, PathBuf};

/// The flags of `drapelab run`.
#[derive(Debug, clap::Args)]
pub struct RunArgs {
    /// The pipeline file, e.g. pipelines/main.toml.
    pub pipeline: PathBuf,
    /// Run only this stage and the stages it depends on.
    #[arg(long, value_name = "STAGE")]
    pub until: Option<String>,
    /// Rerun this stage and everything downstream of it even if up to date. Repeatable.
    #[arg(long, value_name = "STAGE")]
    pub force: Vec<String>,
    /// Threads for the items of a stage (0 = all cores).
    #[arg(long, default_value_t = 0)]
    pub jobs: usize,
    /// Print what would run and why; run nothing.
    #[arg(long)]
    pub dry_run: bool,
    /// Where the items of sweep and calibrate stages run, overriding the pipeline's [executor]
    /// kind: local (this process's threads) or slurm (one `sbatch --array` job per stage; needs
    /// a filesystem shared with the nodes; docs/src/guide/slurm.md).
    #[arg(long, value_enum)]
    pub executor: Option<ExecutorArg>,
    /// When another `drapelab run` holds this pipeline's run folder, wait for it to finish
    /// instead of exiting with 2.
    #[arg(long)]
    pub wait: bool,
}

/// The flags of `drapelab worker` (one Slurm array task).
#[derive(Debug, clap::Args)]
pub struct WorkerArgs {
    /// The pipeline file.
    pub pipeline: PathBuf,
    /// The stage whose items to compute.
    #[arg(long)]
    pub stage: String,
    /// The task list (one line of item numbers per task).
    #[arg(long)]
    pub tasks: PathBuf,
    /// The task (line) to run, 0-based: $SLURM_ARRAY_TASK_ID.
    #[arg(long)]
    pub task: usize,
}

/// The flags of `drapelab status`.
#[derive(Debug, clap::Args)]
pub struct StatusArgs {
    /// The pipeline file.
    pub pipeline: PathBuf,
    /// Exit with 1 when a stage is stale (for scripts and CI).
    #[arg(long)]
    pub check: bool,
}

/// `drapelab run`: the flags into run options, then the pipeline.
pub fn run(a: RunArgs, quiet: bool) -> Result<i32> {
    run_pipeline_command(
        &a.pipeline,
        quiet,
        crate::pipeline::RunOptions {
            until: a.until,
            force: a.force,
            jobs: a.jobs,
            dry_run: a.dry_run,
            executor: a.executor.map(Into::into),
            wait: if a.wait {
                crate::pipeline::LockWait::Yes
            } else {
                crate::pipeline::LockWait::No
            },
        },
    )
}

/// `drapelab run`: runs a pipeline make-style with a progress display; returns the exit code.
/// With `quiet` (`-q`), only errors: no summary line.
pub(super) fn run_pipeline_command(
    pipeline: &Path,
    quiet: bool,
    opts: crate::pipeline::RunOptions,
) -> Result<i32> {
    run_pipeline_quietly(pipeline, opts, &crate::stages::registry(), quiet)
}

/// Runs a pipeline with the stage kinds of `registry` (drapelab's own, or those plus a program's
/// own kinds); 0 when every stage ran or was up to date, 1 when one failed (an error, a panic or a
/// missing output: the run goes on as far as the graph allows), bad input an error.
pub fn run_pipeline_with(
    pipeline: &Path,
    opts: crate::pipeline::RunOptions,
    registry: &crate::pipeline::Registry,
) -> Result<i32> {
    run_pipeline_quietly(pipeline, opts, registry, false)
}

/// [`run_pipeline_with`]; with `quiet`, the summary line is left out (failures are still said).
pub fn run_pipeline_quietly(
    pipeline: &Path,
    opts: crate::pipeline::RunOptions,
    registry: &crate::pipeline::Registry,
    quiet: bool,
) -> Result<i32> {
    let plan = crate::pipeline::load_checked_plan(pipeline, registry)?;
    let progress = crate::pipeline::progress_for_terminal();
    let summary = crate::pipeline::run_pipeline(&plan, &opts, progress.as_ref())?;
    for (name, why) in &summary.would_run {
        println!("would run {name}: {why}");
    }
    if !quiet {
        eprintln!(
            "{}: {} ran, {} up to date, {} failed{}",
            plan.name,
            summary.ran.len(),
            summary.skipped.len(),
            summary.failed.len(),
            if opts.dry_run { " (dry run)" } else { "" }
        );
    }
    for (name, why) in &summary.failed {
        eprintln!("  {name}: {why}");
    }
    Ok(if summary.failed.is_empty() {
        EXIT_OK
    } else {
        EXIT_FAILED
    })
}

/// `drapelab worker`: the items of line `task` of the task list, computed into their parts.
pub(super) fn worker(pipeline: &Path, stage: &str, tasks: &Path, task: usize) -> Result<i32> {
    let plan = crate::pipeline::load_plan(pipeline, &crate::stages::registry())?;
    let text = std::fs::read_to_string(tasks)
        .map_err(|e| InputError::new(tasks, "", format!("cannot read the task list: {e}")))?;
    let line = text.lines().nth(task).ok_or_else(|| {
        InputError::new(
            "--task",
            "",
            format!("{} has no line {task}", tasks.display()),
        )
    })?;
    let items = line
        .split_whitespace()
        .map(|w| w.parse::<usize>())
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| InputError::new(tasks, format!("line {task}"), e.to_string()))?;
    crate::pipeline::run_worker(&plan, stage, &items)?;
    Ok(EXIT_OK)
}

/// `drapelab status`: 1 with `--check` when a stage is stale.
pub(super) fn status(pipeline: &Path, check: bool) -> Result<i32> {
    let plan = crate::pipeline::load_checked_plan(pipeline, &crate::stages::registry())?;
    let mut stale = 0;
    for (name, state) in crate::pipeline::stage_states(&plan) {
        let last = crate::pipeline::Manifest::read(&crate::pipeline::manifest_path(&plan, &name))
            .map(|m| format!(" [last run {:.1} s]", m.wall_time_s))
            .unwrap_or_default();
        match state {
            crate::pipeline::StageState::UpToDate => println!("{name}: up to date{last}"),
            crate::pipeline::StageState::Stale(why) => {
                stale += 1;
                println!("{name}: stale ({why}){last}")
            }
        }
    }
    Ok(if check && stale > 0 {
        EXIT_FAILED
    } else {
        EXIT_OK
    })
}
