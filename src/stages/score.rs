//! `score`: measured edges (a fit-edges table) against simulated ones (`edges_truth.parquet` files, one
//! per sample folder), per sample and edge: seed 000 Eq. 5 and the curve distance, into `score.parquet`.

use super::StageContext;
use crate::cli::edges::score_edges;
use crate::edges::read_edges;
use crate::io::write_parquet;
use anyhow::{Context, Result, bail};
use arrow::array::{Float64Array, RecordBatch, StringArray};
use arrow::datatypes::{DataType, Field, Schema};
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// Parameters of a score stage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScoreParams {
    /// The measured edges table (one of the inputs), e.g. "{run}/fit4/edges.parquet".
    pub measured: String,
    /// Side of the samples, cm (normalises Eq. 5). Default 50.
    #[serde(default = "default_side")]
    pub side_cm: f64,
}

fn default_side() -> f64 {
    50.0
}

/// Runs the stage: inputs named `edges_truth.parquet` are the simulated edges of their folder.
pub fn run(ctx: &StageContext<'_>, p: &ScoreParams) -> Result<()> {
    let run_rel = format!("runs/{}", ctx.plan.name);
    let measured_path = ctx.plan.root.join(p.measured.replace("{run}", &run_rel));
    let measured = read_edges(&measured_path)
        .with_context(|| format!("measured edges {}", measured_path.display()))?;
    let truths: Vec<_> = ctx
        .inputs
        .iter()
        .filter(|f| f.file_name().is_some_and(|n| n == "edges_truth.parquet"))
        .collect();
    if truths.is_empty() {
        bail!("no edges_truth.parquet among the inputs");
    }
    ctx.progress
        .stage_started(&ctx.stage.name, truths.len() as u64);
    let mut rows = Vec::new();
    for t in truths {
        let dir = t.parent().unwrap_or(std::path::Path::new("."));
        let sample = dir
            .strip_prefix(&ctx.plan.root)
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
        ctx.progress.item_done(&ctx.stage.name);
    }
    let schema = Arc::new(Schema::new(vec![
        Field::new("sample", DataType::Utf8, false),
        Field::new("edge", DataType::Utf8, false),
        Field::new("objective_pct", DataType::Float64, false),
        Field::new("objective_uncentred_pct", DataType::Float64, false),
        Field::new("curve_distance_pct", DataType::Float64, false),
    ]));
    let batch = RecordBatch::try_new(
        schema.clone(),
        vec![
            Arc::new(StringArray::from_iter_values(
                rows.iter().map(|r| r.sample.clone()),
            )),
            Arc::new(StringArray::from_iter_values(
                rows.iter().map(|r| r.edge.clone()),
            )),
            Arc::new(Float64Array::from_iter_values(
                rows.iter().map(|r| r.objective_pct),
            )),
            Arc::new(Float64Array::from_iter_values(
                rows.iter().map(|r| r.objective_uncentred_pct),
            )),
            Arc::new(Float64Array::from_iter_values(
                rows.iter().map(|r| r.curve_distance_pct),
            )),
        ],
    )?;
    write_parquet(&ctx.outputs[0], &batch, None)?;
    Ok(())
}
