//! The stage kind over [`drapelab_reports::cusick_report`]: its slots and parameters checked when the plan loads,
//! and a call of the workflow with the stage's files.

use anyhow::Result;
use drapelab_pipeline::{Slot, StageContext, StageKind};
pub use drapelab_reports::cusick_report::*;

/// The `cusick-report` stage kind.
pub struct CusickReport;

impl StageKind for CusickReport {
    type Params = CusickReportParams;
    const KIND: &'static str = "cusick-report";
    const SUMMARY: &'static str =
        "Markdown and pictures of the Cusick predictions against the measurements";
    const INPUTS: &'static [Slot] = &[
        Slot::one(
            "predictions",
            "a cusick-predict stage's predictions.parquet",
        ),
        Slot::one(
            "photo_outlines",
            "a cusick-measure stage's outlines.parquet (the photos)",
        ),
        Slot::one(
            "model_outlines",
            "a cusick-predict stage's outlines.parquet (the simulated drapes)",
        ),
        Slot::one("profiles", "a cusick-predict stage's profiles.parquet"),
        Slot::one(
            "by_capture",
            "a cusick-predict stage's predictions_by_capture.parquet",
        ),
    ];
    const OUTPUTS: &'static [Slot] = &[
        Slot::one("markdown", "the report, .md"),
        Slot::one("shadows", "the shadows picture, .svg"),
        Slot::one("profile_plot", "the height profiles picture, .svg"),
    ];
    fn run(ctx: &StageContext<'_>, p: &CusickReportParams) -> Result<()> {
        let ctx = &crate::job(ctx);
        run(ctx, p)
    }
}
