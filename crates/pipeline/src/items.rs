//! Stages that run by items: each item's result is a part, `{run}/parts/<stage>/part-00017.parquet`
//! (written atomically by the stage kind), the parts folder is kept while the stage's key (inputs,
//! parameters, version, build) holds, so a rerun after a kill computes only the missing parts, and
//! the outputs are the gather of every part. The local executor runs the missing items on this
//! process's threads ([`Local`]); the Slurm executor runs them as array tasks. The runner chooses
//! the [`Executor`].

use crate::files::remove_partials;
use crate::stage::{Stage, StageContext};
use anyhow::{Context, Result};
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// The parts folder of stage `stage`: `{run}/parts/<stage>`.
pub fn parts_dir(run_dir: &Path, stage: &str) -> PathBuf {
    run_dir.join("parts").join(stage)
}

/// The part of item `item` in `dir`: `part-00017.parquet`.
pub fn part_path(dir: &Path, item: usize) -> PathBuf {
    dir.join(format!("part-{item:05}.parquet"))
}

/// The file in a parts folder holding the key its parts were computed under.
fn key_file(dir: &Path) -> PathBuf {
    dir.join("key.txt")
}

/// Makes `dir` the parts folder of `key`: parts computed under another key (other inputs,
/// parameters or build) are removed, so that only parts of this very stage are kept.
pub fn prepare_parts(dir: &Path, key: &str) -> Result<()> {
    let old = std::fs::read_to_string(key_file(dir)).unwrap_or_default();
    if old.trim() != key {
        if dir.exists() {
            std::fs::remove_dir_all(dir)
                .with_context(|| format!("cannot clear the parts folder {}", dir.display()))?;
        }
        std::fs::create_dir_all(dir)?;
        drapelab_core::atomic::write_text(&key_file(dir), &format!("{key}\n"))?;
    }
    Ok(())
}

/// Whether `dir` holds parts computed under `key`.
pub fn parts_match(dir: &Path, key: &str) -> bool {
    std::fs::read_to_string(key_file(dir)).is_ok_and(|k| k.trim() == key)
}

/// The items of `items` without a part in `dir`, in order.
pub fn without_part(dir: &Path, items: impl IntoIterator<Item = usize>) -> Vec<usize> {
    items
        .into_iter()
        .filter(|&i| !part_path(dir, i).exists())
        .collect()
}

/// Where the missing items of a stage are computed.
pub trait Executor: Sync {
    /// Computes `items` of stage kind `kind` (context `ctx`), one part each in `dir`; returns once
    /// every item has a part or has failed.
    fn compute(
        &self,
        kind: &dyn Stage,
        ctx: &StageContext<'_>,
        items: &[usize],
        dir: &Path,
    ) -> Result<()>;
}

/// The local executor: the items on this process's threads (the current rayon pool).
pub struct Local;

impl Executor for Local {
    /// Every item is tried; the first failure (by item) is returned after the others finished, so
    /// that their parts are kept.
    fn compute(
        &self,
        kind: &dyn Stage,
        ctx: &StageContext<'_>,
        items: &[usize],
        dir: &Path,
    ) -> Result<()> {
        let mut failures: Vec<(usize, anyhow::Error)> = items
            .par_iter()
            .filter_map(|&i| {
                let r = kind.compute_item(ctx, i, &part_path(dir, i));
                ctx.item_done();
                r.err().map(|e| (i, e))
            })
            .collect();
        failures.sort_by_key(|(i, _)| *i);
        match failures.into_iter().next() {
            Some((i, e)) => Err(e.context(format!("item {i}"))),
            None => Ok(()),
        }
    }
}

/// Runs stage kind `kind` of `n` items under `key`: the parts folder is prepared, the missing items
/// are computed by `executor`, and the parts are gathered into the outputs.
pub fn run_by_items(
    kind: &dyn Stage,
    ctx: &StageContext<'_>,
    n: usize,
    key: &str,
    executor: &dyn Executor,
) -> Result<()> {
    let dir = parts_dir(&ctx.run_dir, &ctx.stage);
    prepare_parts(&dir, key)?;
    remove_partials(&dir);
    let missing = without_part(&dir, 0..n);
    ctx.started(n);
    for _ in 0..n - missing.len() {
        ctx.item_done();
    }
    tracing::debug!(stage = %ctx.stage, items = n, missing = missing.len(), "parts");
    if !missing.is_empty() {
        executor.compute(kind, ctx, &missing, &dir)?;
    }
    let parts: Vec<PathBuf> = (0..n).map(|i| part_path(&dir, i)).collect();
    kind.gather(ctx, &parts)
}
