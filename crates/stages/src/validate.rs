//! The stage kind over [`drapelab_app::validate`]: its slots and parameters checked when the plan loads,
//! and a call of the workflow with the stage's files.

use anyhow::Result;
pub use drapelab_app::validate::*;
use drapelab_pipeline::{Slot, StageContext, StageKind};

/// The `validate` stage kind.
pub struct Validate;

impl StageKind for Validate {
    type Params = ValidateParams;
    const KIND: &'static str = "validate";
    const SUMMARY: &'static str =
        "Calibrated parameters on the 2-corner hang against its measured edges (seed 000 Table 6)";
    const INPUTS: &'static [Slot] = &[
        Slot::one("calibration", "a calibrate stage's results.parquet"),
        Slot::one(
            "edges",
            "measured 2-corner edges of every sample (a fit-edges table)",
        ),
        Slot::one("samples", "Table 2's densities (knitted_samples.csv)"),
        Slot::one("scene", "the 2-corner hang scene"),
    ];
    const OUTPUTS: &'static [Slot] = &[Slot::one(
        "validation",
        "validation.parquet: one row per sample",
    )];
    fn run(ctx: &StageContext<'_>, p: &ValidateParams) -> Result<()> {
        let ctx = &crate::job(ctx);
        run(ctx, p).map(drop)
    }
}
