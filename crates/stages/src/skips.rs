//! `skips`: each skip the engine makes, measured on and off in the same run.

use anyhow::Result;
use drapelab_core::benchmark::{
    SkipRow, skip_cost_cache, skip_second_thread, skip_symmetry, skip_unneeded_terms,
};
use drapelab_core::scene::{LoadedScene, Scene};
use drapelab_core::solve::NoObserver;
use drapelab_pipeline::{Slot, StageContext, StageKind};
use drapelab_record::simulate_to_dir;
use drapelab_record::write_table;
use serde::{Deserialize, Serialize};
use std::path::Path;
use std::time::Instant;

/// Parameters of a skips stage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct SkipsParams {}

/// The `skips` stage kind.
pub struct Skips;

impl StageKind for Skips {
    type Params = SkipsParams;
    const KIND: &'static str = "skips";
    const SUMMARY: &'static str = "Each skip the engine makes, measured on and off";
    const INPUTS: &'static [Slot] = &[
        Slot::one("full", "a drape on a table, whole (table_wool.toml)"),
        Slot::one(
            "quarter",
            "the same drape as a quarter model (table_wool_quarter.toml)",
        ),
        Slot::one("hang", "a hang without obstacles (hang4.toml)"),
    ];
    const OUTPUTS: &'static [Slot] = &[Slot::one("table", "skips.parquet")];
    fn run(ctx: &StageContext<'_>, p: &SkipsParams) -> Result<()> {
        run(ctx, p)
    }
}

/// Runs a skips stage: each skip the engine makes (a quarter model, recording off, the cost cache, an
/// up-to-date stage, a contact term a scene does not need), and the second thread of a calibration
/// population, measured on and off in the same run, into a Parquet table (`skip`, `scene`,
/// `time_with_skip_s`, `time_without_skip_s`, `saved_fraction`).
fn run(ctx: &StageContext<'_>, _p: &SkipsParams) -> Result<()> {
    let load = |slot: &str| -> Result<Scene> {
        Ok(Scene::load(ctx.input(slot)?, &[])?.scene.into_inner())
    };
    let (full, quarter, hang) = (load("full")?, load("quarter")?, load("hang")?);
    ctx.started(6);
    let done = || ctx.item_done();
    let mut rows = vec![skip_symmetry(&full, &quarter)];
    done();
    rows.push(skip_recording(&hang, ctx.input("hang")?)?);
    done();
    rows.push(skip_cost_cache(&hang)?);
    done();
    rows.push(skip_up_to_date_stage(ctx.input("hang")?, &hang.name)?);
    done();
    rows.push(skip_unneeded_terms(&hang));
    done();
    rows.push(skip_second_thread(&hang)?);
    done();
    write_table(ctx.output("table")?, &rows)
}

/// Recording off: simulate at 21 × 21 with the timeline and the rerun recording off and on.
fn skip_recording(hang: &Scene, path: &Path) -> Result<SkipRow> {
    let mut hang4 = hang.clone();
    hang4.cloth.nx = 21;
    hang4.cloth.ny = 21;
    let tmp = tempfile::tempdir()?;
    let mut with_rec = hang4.clone();
    with_rec.record.timeline = true;
    with_rec.record.rerun = true;
    let mut times = Vec::new();
    for (k, s) in [&hang4, &with_rec].iter().enumerate() {
        let loaded = LoadedScene {
            scene: (*s).clone().validated()?,
            path: path.to_path_buf(),
        };
        let out = tmp.path().join(format!("r{k}"));
        let t = Instant::now();
        simulate_to_dir(&loaded, &out, &mut NoObserver)?;
        times.push(t.elapsed().as_secs_f64());
    }
    Ok(SkipRow::new(
        "timeline and rerun recording off",
        hang4.name.clone(),
        times[0],
        times[1],
    ))
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
