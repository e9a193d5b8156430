//! The stage kind over [`drapelab_app::cusick::fabric`]: its slots and parameters checked when the plan loads,
//! and a call of the workflow with the stage's files.

use anyhow::Result;
pub use drapelab_app::cusick::fabric::*;
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
    const OUTPUTS: &'static [Slot] = &[
        Slot::optional(
            "fabric",
            "with params.fabric: its fabric file (bending calibrated with 2σ intervals, tensile and shear stated defaults)",
        ),
        Slot::optional(
            "fabrics",
            "without params.fabric: an index TOML, every fabric's file written beside it as fabric_NN.toml",
        ),
    ];
    /// `params.fabric` with `outputs.fabric`, or neither with `outputs.fabrics`.
    fn precheck(ctx: &StageContext<'_>, p: &CusickFabricParams) -> Result<()> {
        let one = ctx.outputs.contains_key("fabric");
        let all = ctx.outputs.contains_key("fabrics");
        let ok = match p.fabric {
            Some(_) => one && !all,
            None => all && !one,
        };
        if !ok {
            anyhow::bail!(drapelab_core::error::InputError::new(
                &ctx.pipeline_file,
                format!("stages.{}.outputs", ctx.stage),
                "give params.fabric with outputs.fabric (one fabric), or outputs.fabrics alone (every fabric beside an index)",
            ));
        }
        Ok(())
    }
    fn run(ctx: &StageContext<'_>, p: &CusickFabricParams) -> Result<()> {
        let inputs = CusickFabricInputs {
            predictions: ctx.file(&PREDICTIONS)?,
            index: ctx.file(&crate::CUSICK_INDEX_SLOT)?,
        };
        run(&crate::job(ctx, inputs), p).map(drop)
    }
}
