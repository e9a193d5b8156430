//! The stage kind over [`drapelab_reports::calibration_report`]: its slots and parameters checked when the plan loads,
//! and a call of the workflow with the stage's files.

use anyhow::Result;
use drapelab_pipeline::{Slot, StageContext, StageKind};
pub use drapelab_reports::calibration_report::*;

/// The `calibration-report` stage kind.
pub struct CalibrationReport;

impl StageKind for CalibrationReport {
    type Params = CalibrationReportParams;
    const KIND: &'static str = "calibration-report";
    const SUMMARY: &'static str =
        "The Markdown report of a calibration (seed 000 Tables 4 and 6, Figs 10 and 13)";
    const INPUTS: &'static [Slot] = &[
        Slot::one("results", "a calibrate stage's results.parquet"),
        Slot::one("validation", "a validate stage's validation.parquet"),
        Slot::one("evaluations", "a calibrate stage's evaluations.parquet"),
        Slot::one("comparison", "a calibrate stage's comparison.parquet"),
        Slot::one("main_effects", "a tune stage's main_effects.parquet"),
        Slot::one(
            "seed_optimum",
            "seed 000's 4-corner optima (ica_optimum_4corner.csv)",
        ),
        Slot::one(
            "seed_validation",
            "seed 000's 2-corner errors (ica_validation_2corner.csv)",
        ),
    ];
    const OUTPUTS: &'static [Slot] = &[
        Slot::one("markdown", "the report, .md"),
        Slot::optional("convergence_plot", "ICA's convergence, .svg"),
        Slot::optional("main_effects_plot", "the main effects of the tuning, .svg"),
    ];
    fn run(ctx: &StageContext<'_>, p: &CalibrationReportParams) -> Result<()> {
        let ctx = &crate::job(ctx);
        run(ctx, p)
    }
}
