//! The stage kind over [`drapelab_app::cusick::predict`]: its slots and parameters checked when the plan loads,
//! and a call of the workflow with the stage's files.

use anyhow::Result;
pub use drapelab_app::cusick::predict::*;
use drapelab_pipeline::{Slot, StageContext, StageKind};

/// The captures measured.
const SHADOWS: Slot = Slot::one("shadows", "a cusick-measure stage's shadows.parquet");
/// The photos' outlines.
const PHOTO_OUTLINES: Slot = Slot::one(
    "photo_outlines",
    "a cusick-measure stage's outlines.parquet (the photos' outlines r(θ))",
);

/// The `cusick-predict` stage kind.
pub struct CusickPredict;

impl StageKind for CusickPredict {
    type Params = CusickPredictParams;
    const KIND: &'static str = "cusick-predict";
    const SUMMARY: &'static str =
        "Calibrate each Cusick fabric's bending length on one specimen, predict the others";
    const INPUTS: &'static [Slot] = &[crate::CUSICK_INDEX_SLOT, SHADOWS, PHOTO_OUTLINES];
    const OUTPUTS: &'static [Slot] = &[
        Slot::one("predictions", "predictions.parquet: one row per fabric"),
        Slot::one(
            "by_capture",
            "predictions_by_capture.parquet: one row per predicted capture, its face's DC with a 90 % interval and its node count (the model's, corrected by the node line)",
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
        let inputs = CusickPredictInputs {
            index: ctx.file(&crate::CUSICK_INDEX_SLOT)?,
            shadows: ctx.file(&SHADOWS)?,
            photo_outlines: ctx.file(&PHOTO_OUTLINES)?,
        };
        let ctx = &crate::job(ctx, inputs);
        run(ctx, p).map(drop)
    }
}
