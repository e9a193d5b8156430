//! `skips`: each skip the engine makes, measured on and off in the same run; the workflow is
//! [`drapelab_app::sweeps::skips`], and the skip of an up-to-date stage is measured here, with the engine.

use anyhow::Result;
pub use drapelab_app::sweeps::skips::*;
use drapelab_core::benchmark::SkipRow;
use drapelab_pipeline::{Slot, StageContext, StageKind};
use std::path::Path;
use std::time::Instant;

/// The whole drape.
const FULL: Slot = Slot::one("full", "a drape on a table, whole (table_wool.toml)");
/// The quarter model of it.
const QUARTER: Slot = Slot::one(
    "quarter",
    "the same drape as a quarter model (table_wool_quarter.toml)",
);
/// The hang.
const HANG: Slot = Slot::one("hang", "a hang without obstacles (hang4.toml)");

/// The `skips` stage kind.
pub struct Skips;

impl StageKind for Skips {
    type Params = SkipsParams;
    const KIND: &'static str = "skips";
    const SUMMARY: &'static str = "Each skip the engine makes, measured on and off";
    const INPUTS: &'static [Slot] = &[FULL, QUARTER, HANG];
    const OUTPUTS: &'static [Slot] = &[Slot::one("table", "skips.parquet")];
    fn run(ctx: &StageContext<'_>, p: &SkipsParams) -> Result<()> {
        let inputs = SkipsInputs {
            full: ctx.file(&FULL)?,
            quarter: ctx.file(&QUARTER)?,
            hang: ctx.file(&HANG)?,
        };
        run(&crate::job(ctx, inputs), p, skip_up_to_date_stage)
    }
}

/// Up-to-date stages: a one-stage pipeline run from scratch, then again (nothing to do).
fn skip_up_to_date_stage(hang_file: &Path, name: &str) -> Result<SkipRow> {
    let proj = tempfile::tempdir()?;
    std::fs::create_dir_all(proj.path().join("pipelines"))?;
    std::fs::create_dir_all(proj.path().join("datasets/scenes"))?;
    std::fs::copy(hang_file, proj.path().join("datasets/scenes/hang4.toml"))?;
    let file = proj.path().join("pipelines/p.toml");
    std::fs::write(
        &file,
        "name = \"p\"\n[stages.h]\nkind = \"simulate\"\ninputs.scene = \"datasets/scenes/hang4.toml\"\n\
         outputs = { particles = \"{run}/h/particles.parquet\", run = \"{run}/h/run.json\" }\n\
         params.set = { \"cloth.nx\" = 41, \"cloth.ny\" = 41 }\n",
    )?;
    let plan = drapelab_pipeline::load_plan(&file, &crate::registry())?;
    let mut t = [0.0; 2];
    for t in &mut t {
        let start = Instant::now();
        drapelab_pipeline::run_pipeline(&plan, &Default::default(), &Silent)?;
        *t = start.elapsed().as_secs_f64();
    }
    Ok(SkipRow::new(
        "up-to-date stage skipped",
        format!("{name} 41×41"),
        t[1],
        t[0],
    ))
}

/// A progress that says nothing (the skips stage runs a pipeline of its own inside).
struct Silent;

impl drapelab_pipeline::Progress for Silent {
    fn stage_started(&self, _: &str, _: u64) {}
    fn item_done(&self, _: &str) {}
    fn stage_finished(&self, _: &str, _: &drapelab_pipeline::StageOutcome, _: f64) {}
    fn stage_skipped(&self, _: &str, _: &str) {}
}
