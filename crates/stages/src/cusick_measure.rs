//! The stage kind over [`drapelab_app::cusick::measure`]: its slots and parameters checked when the plan loads,
//! and a call of the workflow with the stage's files.

use anyhow::Result;
pub use drapelab_app::cusick::measure::*;
use drapelab_pipeline::{Slot, StageContext, StageKind};

/// The `cusick-measure` stage kind.
pub struct CusickMeasure;

impl StageKind for CusickMeasure {
    type Params = CusickMeasureParams;
    const KIND: &'static str = "cusick-measure";
    const SUMMARY: &'static str =
        "DC and node count of every Cusick capture, from its photo and from its 3D mesh";
    const INPUTS: &'static [Slot] = &[
        crate::CUSICK_INDEX_SLOT,
        Slot::many(
            "files",
            "every file of the dataset (for the up-to-date check), e.g. datasets/cusick/*.* and its silhouettes",
        ),
    ];
    const OUTPUTS: &'static [Slot] = &[
        Slot::one("table", "shadows.parquet: one row per capture"),
        Slot::one(
            "outlines",
            "outlines.parquet: each photo's smoothed shadow outline r(θ), 1° sectors",
        ),
    ];
    fn run(ctx: &StageContext<'_>, p: &CusickMeasureParams) -> Result<()> {
        let index = ctx.file(&crate::CUSICK_INDEX_SLOT)?;
        let ctx = &crate::job(ctx, CusickMeasureInputs { index });
        run(ctx, p).map(drop)
    }
}
