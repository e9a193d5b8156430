//! The stage kind over [`drapelab_app::photos::score`]: its slots and parameters checked when the plan loads,
//! and a call of the workflow with the stage's files.

use anyhow::Result;
pub use drapelab_app::photos::score::*;
use drapelab_pipeline::{Slot, StageContext, StageKind};

/// The edges measured.
const MEASURED: Slot = Slot::one("measured", "the measured edges (a fit-edges table)");
/// The edges simulated.
const SIMULATED: Slot = Slot::many(
    "simulated",
    "edges_truth.parquet files, one per sample folder (the folder names the sample)",
);

/// The `score` stage kind.
pub struct Score;

impl StageKind for Score {
    type Params = ScoreParams;
    const KIND: &'static str = "score";
    const SUMMARY: &'static str =
        "Seed 000 Eq. 5 and curve distance of measured against simulated edges";
    const INPUTS: &'static [Slot] = &[MEASURED, SIMULATED];
    const OUTPUTS: &'static [Slot] = &[Slot::one("score", "score.parquet")];
    fn run(ctx: &StageContext<'_>, p: &ScoreParams) -> Result<()> {
        let inputs = ScoreInputs {
            measured: ctx.file(&MEASURED)?,
            simulated: ctx.files(&SIMULATED),
        };
        let ctx = &crate::job(ctx, inputs);
        run(ctx, p).map(drop)
    }
}
