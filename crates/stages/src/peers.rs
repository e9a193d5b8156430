//! The stage kind over [`drapelab_app::sweeps::peers`]: its slots and parameters checked when the plan loads,
//! and a call of the workflow with the stage's files.

use anyhow::Result;
pub use drapelab_app::sweeps::peers::*;
use drapelab_pipeline::{Slot, StageContext, StageKind};

/// The scene the peers solve.
const SCENE: Slot = Slot::one("scene", "the hang4 scene");
/// scipy's Newton peer.
const SCIPY_NEWTON: Slot = Slot::one("scipy_newton", "benches/peers/scipy_newton.py");
/// numpy's explicit peer.
const NUMPY_EXPLICIT: Slot = Slot::one("numpy_explicit", "benches/peers/numpy_explicit.py");
/// CHOLMOD's Newton peer.
const CHOLMOD_NEWTON: Slot = Slot::optional(
    "cholmod_newton",
    "benches/peers/cholmod_newton.py (runs when given)",
);

/// The `peers` stage kind.
pub struct Peers;

impl StageKind for Peers {
    type Params = PeersParams;
    const KIND: &'static str = "peers";
    const SUMMARY: &'static str = "scipy, CHOLMOD and numpy peers run beside drapelab";
    const INPUTS: &'static [Slot] = &[
        SCENE,
        SCIPY_NEWTON,
        NUMPY_EXPLICIT,
        CHOLMOD_NEWTON,
        Slot::optional_many("support", "modules the scripts import (model.py)"),
    ];
    const OUTPUTS: &'static [Slot] = &[Slot::one("table", "peers.parquet")];
    fn run(ctx: &StageContext<'_>, p: &PeersParams) -> Result<()> {
        let inputs = PeersInputs {
            scene: ctx.file(&SCENE)?,
            scipy_newton: ctx.file(&SCIPY_NEWTON)?,
            numpy_explicit: ctx.file(&NUMPY_EXPLICIT)?,
            cholmod_newton: ctx.optional_file(&CHOLMOD_NEWTON)?,
        };
        let ctx = &crate::job(ctx, inputs);
        run(ctx, p)
    }
}
