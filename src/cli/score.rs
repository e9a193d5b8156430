//! `drapelab score`: simulated edges against measured ones (seed 000 Eq. 5).

use super::args;
use crate::error::EXIT_OK;
use anyhow::Result;
use std::path::{Path, PathBuf};

/// The flags of `drapelab score`.
#[derive(Debug, clap::Args)]
pub struct ScoreArgs {
    /// Measured edges.parquet.
    pub real: PathBuf,
    /// Simulated edges.parquet.
    pub sim: PathBuf,
    /// Side of the sample, cm.
    #[arg(long, default_value_t = 50.0, value_parser = args::positive)]
    pub side_cm: f64,
}

/// `drapelab score`.
pub fn run(a: ScoreArgs) -> Result<i32> {
    score(&a.real, &a.sim, a.side_cm)
}

/// `drapelab score`: Eq. 5 and the curve distance per edge, as a Markdown table.
fn score(real: &Path, sim: &Path, side_cm: f64) -> Result<i32> {
    let rows = crate::io::score_files(real, sim, side_cm)?;
    println!(
        "| edge | objective (Eq. 5) % | Eq. 5 uncentred % | curve distance % of side |\n|---|---|---|---|"
    );
    for r in &rows {
        println!(
            "| {} | {:.4} | {:.4} | {:.4} |",
            r.edge, r.objective_pct, r.objective_uncentred_pct, r.curve_distance_pct
        );
    }
    Ok(EXIT_OK)
}
