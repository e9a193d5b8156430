//! The stage kind over [`drapelab_app::simulate`]: its slots and parameters checked when the plan loads,
//! and a call of the workflow with the stage's files.

use anyhow::Result;
pub use drapelab_app::simulate::*;
use drapelab_pipeline::{Slot, StageContext, StageKind};

/// The scene solved.
const SCENE: Slot = Slot::one("scene", "the scene TOML");

/// The workflow's inputs from the stage's files.
fn inputs(ctx: &StageContext<'_>) -> Result<SimulateInputs> {
    Ok(SimulateInputs {
        scene: ctx.file(&SCENE)?,
    })
}

/// The `simulate` stage kind.
pub struct Simulate;

impl StageKind for Simulate {
    type Params = SimulateParams;
    const KIND: &'static str = "simulate";
    const SUMMARY: &'static str = "Solve one scene (with overrides) and record it";
    const INPUTS: &'static [Slot] = &[SCENE];
    const OUTPUTS: &'static [Slot] = &[
        Slot::one("particles", "particles.parquet, the converged drape"),
        Slot::one("run", "run.json, the solve report"),
        Slot::optional("timeline", "timeline.mcap, when record.timeline is set"),
        Slot::optional("recording", "drape.rrd, when record.rerun is set"),
    ];
    /// The scene loads with the overrides (a bad value is refused naming `params.set.KEY`).
    fn precheck(ctx: &StageContext<'_>, p: &SimulateParams) -> Result<()> {
        let ctx = &crate::job(ctx, inputs(ctx)?);
        let overrides: Vec<_> = p.set.iter().map(|(k, v)| (k.clone(), v.clone())).collect();
        ctx.load_scene(&ctx.inputs.scene, &overrides, |k| format!("set.{k}"))
            .map(drop)
    }
    fn run(ctx: &StageContext<'_>, p: &SimulateParams) -> Result<()> {
        let ctx = &crate::job(ctx, inputs(ctx)?);
        run(ctx, p).map(drop)
    }
}
