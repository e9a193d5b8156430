//! The stage kind over [`drapelab_app::peers`]: its slots and parameters checked when the plan loads,
//! and a call of the workflow with the stage's files.

use anyhow::Result;
pub use drapelab_app::peers::*;
use drapelab_pipeline::{Slot, StageContext, StageKind};

/// The `peers` stage kind.
pub struct Peers;

impl StageKind for Peers {
    type Params = PeersParams;
    const KIND: &'static str = "peers";
    const SUMMARY: &'static str = "scipy, CHOLMOD and numpy peers run beside drapelab";
    const INPUTS: &'static [Slot] = &[
        Slot::one("scene", "the hang4 scene"),
        Slot::one("scipy_newton", "benches/peers/scipy_newton.py"),
        Slot::one("numpy_explicit", "benches/peers/numpy_explicit.py"),
        Slot::optional(
            "cholmod_newton",
            "benches/peers/cholmod_newton.py (runs when given)",
        ),
        Slot::optional_many("support", "modules the scripts import (model.py)"),
    ];
    const OUTPUTS: &'static [Slot] = &[Slot::one("table", "peers.parquet")];
    fn run(ctx: &StageContext<'_>, p: &PeersParams) -> Result<()> {
        let ctx = &crate::job(ctx);
        run(ctx, p)
    }
}
