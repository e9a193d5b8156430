//! The stage kind over [`drapelab_app::calibration::validate`]: its slots and parameters checked when the plan loads,
//! and a call of the workflow with the stage's files.

use anyhow::Result;
pub use drapelab_app::calibration::validate::*;
use drapelab_pipeline::{Slot, StageContext, StageKind};

/// The calibrated parameters.
const CALIBRATION: Slot = Slot::one("calibration", "a calibrate stage's results.parquet");
/// The 2-corner edges.
const EDGES: Slot = Slot::one(
    "edges",
    "measured 2-corner edges of every sample (a fit-edges table)",
);
/// The 2-corner hang.
const SCENE: Slot = Slot::one("scene", "the 2-corner hang scene");

/// The workflow's inputs from the stage's files.
fn inputs(ctx: &StageContext<'_>) -> Result<ValidateInputs> {
    Ok(ValidateInputs {
        samples: crate::sample_inputs(ctx, [&EDGES, &crate::SAMPLES_SLOT, &SCENE])?,
        calibration: ctx.file(&CALIBRATION)?,
    })
}

/// The `validate` stage kind.
pub struct Validate;

impl StageKind for Validate {
    type Params = ValidateParams;
    const KIND: &'static str = "validate";
    const SUMMARY: &'static str =
        "Calibrated parameters on the 2-corner hang against its measured edges (seed 000 Table 6)";
    const INPUTS: &'static [Slot] = &[CALIBRATION, EDGES, crate::SAMPLES_SLOT, SCENE];
    const OUTPUTS: &'static [Slot] = &[Slot::one(
        "validation",
        "validation.parquet: one row per sample",
    )];
    fn run(ctx: &StageContext<'_>, p: &ValidateParams) -> Result<()> {
        let ctx = &crate::job(ctx, inputs(ctx)?);
        run(ctx, p).map(drop)
    }
}
