//! The stage kind over [`drapelab_app::cusick_fabric`]: its slots and parameters checked when the plan loads,
//! and a call of the workflow with the stage's files.

use anyhow::Result;
pub use drapelab_app::cusick_fabric::*;
use drapelab_pipeline::{Slot, StageContext, StageKind};

/// The calibration's table.
const PREDICTIONS: Slot = Slot::one(
    "predictions",
    "a cusick-predict stage's predictions.parquet",
);

/// The `cusick-fabric` stage kind.
pub struct CusickFabric;

impl StageKind for CusickFabric {
    type Params = CusickFabricParams;
    const KIND: &'static str = "cusick-fabric";
    const SUMMARY: &'static str = "Write one calibrated Cusick fabric as a fabric file (TOML) that scenes take with [material] fabric";
    const INPUTS: &'static [Slot] = &[PREDICTIONS, crate::CUSICK_INDEX_SLOT];
    const OUTPUTS: &'static [Slot] = &[Slot::one(
        "fabric",
        "the fabric file: bending calibrated with 2σ intervals, tensile and shear stated defaults",
    )];
    fn run(ctx: &StageContext<'_>, p: &CusickFabricParams) -> Result<()> {
        let inputs = CusickFabricInputs {
            predictions: ctx.file(&PREDICTIONS)?,
            index: ctx.file(&crate::CUSICK_INDEX_SLOT)?,
        };
        run(&crate::job(ctx, inputs), p).map(drop)
    }
}
