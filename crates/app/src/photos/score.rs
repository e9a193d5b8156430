//! `score`: measured edges (a fit-edges table) against simulated ones (`edges_truth.parquet` files, one
//! per sample folder), per sample and edge: seed 000 Eq. 5 and the curve distance, into `score.parquet`.

use crate::job::Job;
use anyhow::{Context, Result, bail};
use drapelab_core::edges::{ScoreRow, score_edges};
use drapelab_record::{read_edges, write_table};
use serde::{Deserialize, Serialize};

/// Parameters of a score stage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScoreParams {
    /// Side of the samples, cm (normalises Eq. 5). Default 50.
    #[serde(default = "crate::defaults::side_cm")]
    pub side_cm: f64,
}

/// The inputs of a score stage.
pub struct ScoreInputs {
    /// The measured edges (a fit-edges table).
    pub measured: std::path::PathBuf,
    /// edges_truth.parquet files, one per sample folder (the folder names the sample).
    pub simulated: Vec<std::path::PathBuf>,
}

/// Scores simulated edges against the photos' fitted edges, one row per photo.
pub fn run(ctx: &Job<'_, ScoreInputs>, p: &ScoreParams) -> Result<Vec<ScoreRow>> {
    let measured_path = &ctx.inputs.measured;
    let measured = read_edges(measured_path)
        .with_context(|| format!("measured edges {}", measured_path.display()))?;
    let truths = &ctx.inputs.simulated;
    if truths.is_empty() {
        bail!("input `simulated` matched no file");
    }
    ctx.started(truths.len());
    let mut rows = Vec::new();
    for t in truths {
        let dir = t.parent().unwrap_or(std::path::Path::new("."));
        let sample = dir
            .strip_prefix(&ctx.root)
            .unwrap_or(dir)
            .to_string_lossy()
            .replace('\\', "/");
        let sim: Vec<_> = read_edges(t)?
            .into_iter()
            .map(|(_, e)| (sample.clone(), e))
            .collect();
        let real: Vec<_> = measured
            .iter()
            .filter(|(s, _)| *s == sample)
            .cloned()
            .collect();
        rows.extend(score_edges(&real, &sim, p.side_cm));
        ctx.item_done();
    }
    write_table(ctx.output("score")?, &rows)?;
    Ok(rows)
}
