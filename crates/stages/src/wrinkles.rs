//! The stage kind over [`drapelab_app::wrinkles`]: its slots and parameters checked when the plan loads,
//! and a call of the workflow with the stage's files.

use anyhow::Result;
pub use drapelab_app::wrinkles::*;
use drapelab_pipeline::{Slot, StageContext, StageKind};

/// The `wrinkles` stage kind.
pub struct Wrinkles;

impl StageKind for Wrinkles {
    type Params = WrinklesParams;
    const KIND: &'static str = "wrinkles";
    const SUMMARY: &'static str = "Seed 002's tension-field wrinkles of every case of a config";
    const INPUTS: &'static [Slot] = &[crate::WRINKLE_CONFIG_SLOT];
    const OUTPUTS: &'static [Slot] = &[
        Slot::optional("table", "wrinkles.parquet: one row per case"),
        Slot::optional("mesh", "the deformed grids, Parquet"),
        Slot::optional("recording", "each grid as a rerun mesh, .rrd"),
        Slot::optional("markdown", "the report, .md"),
    ];
    fn run(ctx: &StageContext<'_>, p: &WrinklesParams) -> Result<()> {
        let config = ctx.file(&crate::WRINKLE_CONFIG_SLOT)?;
        let ctx = &crate::job(ctx, WrinklesInputs { config });
        run(ctx, p).map(drop)
    }
}
