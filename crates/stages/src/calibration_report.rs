//! The stage kind over [`drapelab_reports::calibration_report`]: its slots and parameters checked when the plan loads,
//! and a call of the workflow with the stage's files.

use anyhow::Result;
use drapelab_pipeline::{Slot, StageContext, StageKind};
pub use drapelab_reports::calibration_report::*;

/// The calibrated parameters.
const RESULTS: Slot = Slot::one("results", "a calibrate stage's results.parquet");
/// The 2-corner validation.
const VALIDATION: Slot = Slot::one("validation", "a validate stage's validation.parquet");
/// ICA's evaluations.
const EVALUATIONS: Slot = Slot::one("evaluations", "a calibrate stage's evaluations.parquet");
/// ICA against CMA-ES.
const COMPARISON: Slot = Slot::one("comparison", "a calibrate stage's comparison.parquet");
/// The tuning's main effects.
const MAIN_EFFECTS: Slot = Slot::one("main_effects", "a tune stage's main_effects.parquet");
/// The seed's optima.
const SEED_OPTIMUM: Slot = Slot::one(
    "seed_optimum",
    "seed 000's 4-corner optima (ica_optimum_4corner.csv)",
);
/// The seed's validation errors.
const SEED_VALIDATION: Slot = Slot::one(
    "seed_validation",
    "seed 000's 2-corner errors (ica_validation_2corner.csv)",
);

/// The `calibration-report` stage kind.
pub struct CalibrationReport;

impl StageKind for CalibrationReport {
    type Params = CalibrationReportParams;
    const KIND: &'static str = "calibration-report";
    const SUMMARY: &'static str =
        "The Markdown report of a calibration (seed 000 Tables 4 and 6, Figs 10 and 13)";
    const INPUTS: &'static [Slot] = &[
        RESULTS,
        VALIDATION,
        EVALUATIONS,
        COMPARISON,
        MAIN_EFFECTS,
        SEED_OPTIMUM,
        SEED_VALIDATION,
    ];
    const OUTPUTS: &'static [Slot] = &[
        Slot::one("markdown", "the report, .md"),
        Slot::optional("convergence_plot", "ICA's convergence, .svg"),
        Slot::optional("main_effects_plot", "the main effects of the tuning, .svg"),
    ];
    fn run(ctx: &StageContext<'_>, p: &CalibrationReportParams) -> Result<()> {
        let inputs = CalibrationReportInputs {
            results: ctx.file(&RESULTS)?,
            validation: ctx.file(&VALIDATION)?,
            evaluations: ctx.file(&EVALUATIONS)?,
            comparison: ctx.file(&COMPARISON)?,
            main_effects: ctx.file(&MAIN_EFFECTS)?,
            seed_optimum: ctx.file(&SEED_OPTIMUM)?,
            seed_validation: ctx.file(&SEED_VALIDATION)?,
        };
        let ctx = &crate::job(ctx, inputs);
        run(ctx, p)
    }
}
