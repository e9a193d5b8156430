//! The stage kind over [`drapelab_app::calibration::knitted_fabric`]: its slots and parameters checked when the plan loads,
//! and a call of the workflow with the stage's files.

use anyhow::Result;
pub use drapelab_app::calibration::knitted_fabric::*;
use drapelab_pipeline::{Slot, StageContext, StageKind};

/// The calibration's results.
const RESULTS: Slot = Slot::one("results", "a calibrate stage's results.parquet");

/// The `knitted-fabric` stage kind.
pub struct KnittedFabric;

impl StageKind for KnittedFabric {
    type Params = KnittedFabricParams;
    const KIND: &'static str = "knitted-fabric";
    const SUMMARY: &'static str =
        "Write one calibrated knitted sample as a mass-spring fabric file (TOML)";
    const INPUTS: &'static [Slot] = &[RESULTS, crate::SAMPLES_SLOT];
    const OUTPUTS: &'static [Slot] = &[Slot::one(
        "fabric",
        "the fabric file: the calibrated mass-spring parameters with their intervals",
    )];
    fn run(ctx: &StageContext<'_>, p: &KnittedFabricParams) -> Result<()> {
        let inputs = KnittedFabricInputs {
            results: ctx.file(&RESULTS)?,
            samples: ctx.file(&crate::SAMPLES_SLOT)?,
        };
        run(&crate::job(ctx, inputs), p).map(drop)
    }
}
