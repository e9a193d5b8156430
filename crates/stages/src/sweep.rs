//! The stage kind over [`drapelab_app::sweeps::sweep`]: its slots and parameters checked when the plan loads,
//! and a call of the workflow with the stage's files.

use anyhow::Result;
pub use drapelab_app::sweeps::sweep::*;
use drapelab_pipeline::{ItemKind, KeyError, Slot, StageContext, StageKind};
use std::path::{Path, PathBuf};

/// The scenes swept.
const SCENES: Slot = Slot::many("scenes", "scene TOMLs, each solved at every point");

/// The workflow's input from the stage's files.
fn inputs(ctx: &StageContext<'_>) -> SweepInputs {
    SweepInputs {
        scenes: ctx.files(&SCENES),
    }
}

/// The `sweep` stage kind.
pub struct Sweep;

impl StageKind for Sweep {
    type Params = SweepParams;
    const KIND: &'static str = "sweep";
    const SUMMARY: &'static str = "Solve scenes over a grid or Latin hypercube of scene keys";
    const INPUTS: &'static [Slot] = &[SCENES];
    const OUTPUTS: &'static [Slot] = &[Slot::one(
        "table",
        "sweep.parquet: one row per scene and point",
    )];
    fn check(p: &SweepParams) -> Result<(), KeyError> {
        p.check()
    }
    /// Every scene loads at every point (a bad axis or `set` value is refused naming it).
    fn precheck(ctx: &StageContext<'_>, p: &SweepParams) -> Result<()> {
        count(&crate::job(ctx, inputs(ctx)), p).map(drop)
    }
}

/// Items: every scene at every design point (scene-major), one row each.
impl ItemKind for Sweep {
    /// Every item's scene is loaded once here, so that a bad value is refused before any work.
    fn count(ctx: &StageContext<'_>, p: &SweepParams) -> Result<usize> {
        let ctx = &crate::job(ctx, inputs(ctx));
        count(ctx, p)
    }
    fn compute(ctx: &StageContext<'_>, p: &SweepParams, item: usize, part: &Path) -> Result<()> {
        let ctx = &crate::job(ctx, inputs(ctx));
        compute(ctx, p, item, part)
    }
    fn gather(ctx: &StageContext<'_>, _p: &SweepParams, parts: &[PathBuf]) -> Result<()> {
        let ctx = &crate::job(ctx, ());
        drapelab_record::gather_parquet(parts, ctx.output("table")?)
    }
}
