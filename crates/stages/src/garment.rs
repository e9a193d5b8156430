//! The stage kind over [`drapelab_app::garment`]: its slots and parameters checked when the plan loads,
//! and a call of the workflow with the stage's files.

use anyhow::Result;
pub use drapelab_app::garment::*;
use drapelab_pipeline::{Slot, StageContext, StageKind};

/// The garment scene.
const SCENE: Slot = Slot::one(
    "scene",
    "the garment scene TOML (a mesh sheet with the group to measure)",
);
/// The fabric it is draped in.
const FABRIC: Slot = Slot::one(
    "fabric",
    "a fabric file (TOML), e.g. a cusick-fabric stage's",
);

/// The workflow's inputs from the stage's files.
fn inputs(ctx: &StageContext<'_>) -> Result<GarmentInputs> {
    Ok(GarmentInputs {
        scene: ctx.file(&SCENE)?,
        fabric: ctx.file(&FABRIC)?,
    })
}

/// The `garment` stage kind.
pub struct Garment;

impl StageKind for Garment {
    type Params = GarmentParams;
    const KIND: &'static str = "garment";
    const SUMMARY: &'static str = "Drape a garment scene in a fabric file: the drape recorded, the hem's flare with the interval of the fabric's calibrated bending";
    const INPUTS: &'static [Slot] = &[SCENE, FABRIC];
    const OUTPUTS: &'static [Slot] = &[
        Slot::one("particles", "particles.parquet, the converged drape"),
        Slot::one("run", "run.json, the solve report (in the same folder)"),
        Slot::optional("recording", "drape.rrd, the drape as a rerun recording"),
        Slot::one(
            "measure",
            "garment.parquet: the hem's flare and its interval (one row)",
        ),
    ];
    fn run(ctx: &StageContext<'_>, p: &GarmentParams) -> Result<()> {
        let ctx = &crate::job(ctx, inputs(ctx)?);
        run(ctx, p).map(drop)
    }
}
