//! The skips the engine makes, each measured on and off in the same run.

use crate::job::Job;
use anyhow::Result;
use drapelab_core::benchmark::{
    SkipRow, skip_cost_cache, skip_second_thread, skip_symmetry, skip_unneeded_terms,
};
use drapelab_core::scene::{LoadedScene, Scene};
use drapelab_core::solve::NoObserver;
use drapelab_record::simulate_to_dir;
use drapelab_record::write_table;
use serde::{Deserialize, Serialize};
use std::path::Path;
use std::time::Instant;

/// Parameters of a skips stage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct SkipsParams {}

/// The inputs of a skips stage.
pub struct SkipsInputs {
    /// A drape on a table, whole (table_wool.toml).
    pub full: std::path::PathBuf,
    /// The same drape as a quarter model (table_wool_quarter.toml).
    pub quarter: std::path::PathBuf,
    /// A hang without obstacles (hang4.toml).
    pub hang: std::path::PathBuf,
}

/// Runs a skips stage: each skip the engine makes (a quarter model, recording off, the cost cache, an
/// up-to-date stage (`up_to_date`: the engine's, measured by the caller), a contact term a scene does not need), and the second thread of a calibration
/// population, measured on and off in the same run, into a Parquet table (`skip`, `scene`,
/// `time_with_skip_s`, `time_without_skip_s`, `saved_fraction`).
pub fn run(
    ctx: &Job<'_, SkipsInputs>,
    _p: &SkipsParams,
    up_to_date: impl Fn(&Path, &str) -> Result<SkipRow>,
) -> Result<()> {
    let files = &ctx.inputs;
    let load = |file: &Path| -> Result<Scene> { Ok(Scene::load(file, &[])?.scene.into_inner()) };
    let (full, quarter, hang) = (
        load(&files.full)?,
        load(&files.quarter)?,
        load(&files.hang)?,
    );
    ctx.started(6);
    let done = || ctx.item_done();
    let mut rows = vec![skip_symmetry(&full, &quarter)];
    done();
    rows.push(skip_recording(&hang, &files.hang)?);
    done();
    rows.push(skip_cost_cache(&hang)?);
    done();
    rows.push(up_to_date(&files.hang, &hang.name)?);
    done();
    rows.push(skip_unneeded_terms(&hang));
    done();
    rows.push(skip_second_thread(&hang)?);
    done();
    write_table(ctx.output("table")?, &rows)
}

/// Recording off: simulate at 21 × 21 with the timeline and the rerun recording off and on.
pub fn skip_recording(hang: &Scene, path: &Path) -> Result<SkipRow> {
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
