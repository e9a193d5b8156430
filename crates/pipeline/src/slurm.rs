//! The Slurm executor: a stage's missing items become the tasks of one `sbatch --array` job (chunks
//! of `items_per_task`), each task runs `drapelab worker` for its items, the runner polls `squeue`
//! (counting finished parts for the progress bar) until the job has left the queue, resubmits the
//! items still missing (failed, cancelled, timed-out tasks) up to `max_resubmissions` times, and the
//! stage gathers the parts. Needs only a filesystem that the nodes share with this process.

use crate::executor::ExecutorSettings;
use crate::items::{Executor, without_part};
use crate::stage::{Stage, StageContext};
use anyhow::{Context, Result, bail};
use drapelab_core::error::InputError;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

/// Output of `program args`, or why it could not run.
fn output(program: &str, args: &[&str]) -> Result<std::process::Output> {
    Command::new(program)
        .args(args)
        .output()
        .with_context(|| format!("cannot run `{program}`"))
}

/// Checks, before any stage runs, that Slurm can take the work: `sbatch`, `squeue` and `sinfo` on
/// PATH and the partition known to `sinfo`. A bad setting is an [`InputError`] naming `file` (the
/// pipeline) and the key.
pub fn preflight(settings: &ExecutorSettings, file: &Path) -> Result<(), InputError> {
    for tool in ["sbatch", "squeue", "sinfo"] {
        if output(tool, &["--version"]).is_err() {
            return Err(InputError::new(
                "--executor slurm",
                "executor.kind",
                format!(
                    "`{tool}` is not on PATH: run on a Slurm login node (or tests/slurm/up.sh \
                     for a one-machine cluster), or use --executor local"
                ),
            ));
        }
    }
    if let Some(part) = &settings.partition {
        let listed = output("sinfo", &["-h", "-o", "%P"])
            .map(|o| String::from_utf8_lossy(&o.stdout).to_string())
            .unwrap_or_default();
        let names: Vec<&str> = listed
            .split_whitespace()
            .map(|p| p.trim_end_matches('*'))
            .collect();
        if !names.contains(&part.as_str()) {
            return Err(InputError::new(
                file,
                "executor.partition",
                format!(
                    "no partition `{part}` in this cluster (sinfo lists: {}); name one of them or \
                     leave the key out",
                    names.join(", ")
                ),
            ));
        }
    }
    Ok(())
}

/// The batch script of one array job: `#SBATCH` lines from the settings, then the worker.
fn script(
    ctx: &StageContext<'_>,
    s: &ExecutorSettings,
    tasks: &Path,
    n_tasks: usize,
    logs: &Path,
) -> Result<String> {
    let exe = std::env::current_exe().context("cannot locate the drapelab executable")?;
    let pipeline = std::fs::canonicalize(ctx.root.join(&ctx.pipeline_file))?;
    let mut lines = vec![
        "#!/bin/bash".to_string(),
        format!("#SBATCH --job-name=drapelab-{}-{}", ctx.pipeline, ctx.stage),
        format!(
            "#SBATCH --array=0-{}{}",
            n_tasks - 1,
            s.max_concurrent_tasks
                .map(|m| format!("%{m}"))
                .unwrap_or_default()
        ),
        format!("#SBATCH --time={}", s.time_limit_min),
        format!("#SBATCH --cpus-per-task={}", s.cpus_per_task),
        format!("#SBATCH --output={}/task-%A_%a.log", logs.display()),
    ];
    if let Some(p) = &s.partition {
        lines.push(format!("#SBATCH --partition={p}"));
    }
    if let Some(a) = &s.account {
        lines.push(format!("#SBATCH --account={a}"));
    }
    if let Some(m) = s.memory_MB_per_task {
        lines.push(format!("#SBATCH --mem={m}M"));
    }
    lines.extend(s.sbatch_options.iter().map(|o| format!("#SBATCH {o}")));
    lines.push(format!("export RAYON_NUM_THREADS={}", s.cpus_per_task));
    lines.push(format!(
        "cd '{}'",
        std::fs::canonicalize(&ctx.root)?.display()
    ));
    lines.push(format!(
        "exec '{}' -q worker '{}' --stage '{}' --tasks '{}' --task \"$SLURM_ARRAY_TASK_ID\"",
        exe.display(),
        pipeline.display(),
        ctx.stage,
        tasks.display()
    ));
    Ok(lines.join("\n") + "\n")
}

/// Submits `items` as one array job (tasks of `items_per_task` items); returns the job id.
fn submit(
    ctx: &StageContext<'_>,
    s: &ExecutorSettings,
    items: &[usize],
    dir: &Path,
    attempt: u32,
) -> Result<String> {
    let work = dir.join("slurm");
    std::fs::create_dir_all(&work)?;
    let chunks: Vec<String> = items
        .chunks(s.items_per_task as usize)
        .map(|c| c.iter().map(usize::to_string).collect::<Vec<_>>().join(" "))
        .collect();
    let tasks = work.join(format!("tasks-{attempt}.txt"));
    drapelab_core::atomic::write_text(&tasks, &(chunks.join("\n") + "\n"))?;
    let batch = work.join(format!("array-{attempt}.sh"));
    drapelab_core::atomic::write_text(&batch, &script(ctx, s, &tasks, chunks.len(), &work)?)?;
    let out = output("sbatch", &["--parsable", &batch.to_string_lossy()])?;
    if !out.status.success() {
        bail!(
            "sbatch refused {}: {}",
            batch.display(),
            String::from_utf8_lossy(&out.stderr).trim()
        );
    }
    let id = String::from_utf8_lossy(&out.stdout)
        .trim()
        .split(';')
        .next()
        .unwrap_or_default()
        .to_string();
    tracing::info!(
        "[{}] submitted array job {id}: {} task(s) for {} item(s)",
        ctx.stage,
        chunks.len(),
        items.len()
    );
    Ok(id)
}

/// Whether job `id` still has tasks in the queue.
fn in_queue(id: &str) -> Result<bool> {
    let out = output("squeue", &["-h", "-j", id, "-o", "%i"])?;
    // squeue fails ("Invalid job id") once the job has left the controller's memory.
    Ok(out.status.success() && !String::from_utf8_lossy(&out.stdout).trim().is_empty())
}

/// The Slurm executor with its settings.
pub struct Slurm<'a>(pub &'a ExecutorSettings);

impl Executor for Slurm<'_> {
    /// The items as Slurm array tasks (each runs `drapelab worker`), resubmitting what is missing.
    fn compute(
        &self,
        _kind: &dyn Stage,
        ctx: &StageContext<'_>,
        items: &[usize],
        dir: &Path,
    ) -> Result<()> {
        compute_slurm(ctx, items, dir, self.0)
    }
}

/// Computes `items` of the stage in `ctx` as Slurm array tasks, resubmitting what is missing.
fn compute_slurm(
    ctx: &StageContext<'_>,
    items: &[usize],
    dir: &Path,
    s: &ExecutorSettings,
) -> Result<()> {
    let wanted = |dir: &Path| without_part(dir, items.iter().copied());
    let mut todo = items.to_vec();
    let mut reported = 0;
    for attempt in 0..=s.max_resubmissions {
        let id = submit(ctx, s, &todo, dir, attempt)?;
        loop {
            let left = wanted(dir).len();
            for _ in reported..items.len() - left {
                ctx.item_done();
            }
            reported = reported.max(items.len() - left);
            if !in_queue(&id)? {
                break;
            }
            std::thread::sleep(Duration::from_secs_f64(s.poll_interval_s));
        }
        todo = wanted(dir);
        if todo.is_empty() {
            return Ok(());
        }
        tracing::warn!(
            "[{}] array job {id} left {} item(s) without a part{}",
            ctx.stage,
            todo.len(),
            if attempt < s.max_resubmissions {
                "; resubmitting them"
            } else {
                ""
            }
        );
    }
    let logs: PathBuf = dir.join("slurm");
    bail!(
        "{} item(s) still without a part after {} submission(s) (first: item {}); the tasks' logs \
         are in {}",
        todo.len(),
        s.max_resubmissions + 1,
        todo[0],
        logs.display()
    )
}
