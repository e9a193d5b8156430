//! The stage kind over [`drapelab_app::cusick_predict`]: its slots and parameters checked when the plan loads,
//! and a call of the workflow with the stage's files.

use anyhow::Result;
pub use drapelab_app::cusick_predict::*;
use drapelab_pipeline::{Slot, StageContext, StageKind};

/// The `cusick-predict` stage kind.
pub struct CusickPredict;

impl StageKind for CusickPredict {
    type Params = CusickPredictParams;
    const KIND: &'static str = "cusick-predict";
    const SUMMARY: &'static str =
        "Calibrate each Cusick fabric's bending length on one specimen, predict the others";
    const INPUTS: &'static [Slot] = &[
        Slot::one(
            "index",
            "captures_index.csv of a Cusick dataset (its folder holds the rest)",
        ),
        Slot::one("shadows", "a cusick-measure stage's shadows.parquet"),
        Slot::one(
            "photo_outlines",
            "a cusick-measure stage's outlines.parquet (the photos' outlines r(θ))",
        ),
    ];
    const OUTPUTS: &'static [Slot] = &[
        Slot::one("predictions", "predictions.parquet: one row per fabric"),
        Slot::one(
            "by_capture",
            "predictions_by_capture.parquet: one row per predicted capture, its face's DC with a 90 % interval",
        ),
        Slot::one(
            "outlines",
            "outlines.parquet: the simulated drapes' shadow outlines r(θ)",
        ),
        Slot::one(
            "profiles",
            "profiles.parquet: measured and simulated height profiles z(r)",
        ),
        Slot::one(
            "recording",
            "drapes.rrd: registered meshes and simulated drapes overlaid, per fabric",
        ),
    ];
    fn run(ctx: &StageContext<'_>, p: &CusickPredictParams) -> Result<()> {
        let ctx = &crate::job(ctx);
        run(ctx, p).map(drop)
    }
}
