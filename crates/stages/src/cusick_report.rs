//! The stage kind over [`drapelab_reports::cusick_report`]: its slots and parameters checked when the plan loads,
//! and a call of the workflow with the stage's files.

use anyhow::Result;
use drapelab_pipeline::{Slot, StageContext, StageKind};
pub use drapelab_reports::cusick_report::*;

/// The fabrics' predictions.
const PREDICTIONS: Slot = Slot::one(
    "predictions",
    "a cusick-predict stage's predictions.parquet",
);
/// The photos' outlines.
const PHOTO_OUTLINES: Slot = Slot::one(
    "photo_outlines",
    "a cusick-measure stage's outlines.parquet (the photos)",
);
/// The simulated drapes' outlines.
const MODEL_OUTLINES: Slot = Slot::one(
    "model_outlines",
    "a cusick-predict stage's outlines.parquet (the simulated drapes)",
);
/// The height profiles.
const PROFILES: Slot = Slot::one("profiles", "a cusick-predict stage's profiles.parquet");
/// The captures' predictions.
const BY_CAPTURE: Slot = Slot::one(
    "by_capture",
    "a cusick-predict stage's predictions_by_capture.parquet",
);

/// The `cusick-report` stage kind.
pub struct CusickReport;

impl StageKind for CusickReport {
    type Params = CusickReportParams;
    const KIND: &'static str = "cusick-report";
    const SUMMARY: &'static str =
        "Markdown and pictures of the Cusick predictions against the measurements";
    const INPUTS: &'static [Slot] = &[
        PREDICTIONS,
        PHOTO_OUTLINES,
        MODEL_OUTLINES,
        PROFILES,
        BY_CAPTURE,
    ];
    const OUTPUTS: &'static [Slot] = &[
        Slot::one("markdown", "the report, .md"),
        Slot::one("shadows", "the shadows picture, .svg"),
        Slot::one("profile_plot", "the height profiles picture, .svg"),
    ];
    fn run(ctx: &StageContext<'_>, p: &CusickReportParams) -> Result<()> {
        let inputs = CusickReportInputs {
            predictions: ctx.file(&PREDICTIONS)?,
            photo_outlines: ctx.file(&PHOTO_OUTLINES)?,
            model_outlines: ctx.file(&MODEL_OUTLINES)?,
            profiles: ctx.file(&PROFILES)?,
            by_capture: ctx.file(&BY_CAPTURE)?,
        };
        let ctx = &crate::job(ctx, inputs);
        run(ctx, p)
    }
}
