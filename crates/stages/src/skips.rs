//! `skips`: each skip the engine makes, measured on and off in the same run.

use anyhow::{Context, Result};
use arrow::array::{ArrayRef, Float64Array, RecordBatch, StringArray};
use arrow::datatypes::{DataType, Field, Schema};
use drapelab_core::scene::Scene;
use drapelab_core::simulate::solve_scene;
use drapelab_core::solve::NoObserver;
use drapelab_pipeline::{Slot, StageContext, StageKind};
use drapelab_record::write_parquet;
use serde::{Deserialize, Serialize};
use std::sync::Arc;

fn f64s(v: Vec<f64>) -> ArrayRef {
    Arc::new(Float64Array::from(v))
}

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
    use std::time::Instant;
    let load = |slot: &str| -> Result<Scene> { Ok(Scene::load(ctx.input(slot)?, &[])?.scene) };
    ctx.progress.stage_started(&ctx.stage.name, 6);
    let mut rows: Vec<(String, String, f64, f64)> = Vec::new();
    let timed = |f: &mut dyn FnMut()| {
        let t = Instant::now();
        f();
        t.elapsed().as_secs_f64()
    };
    // 1. Symmetry: the quarter model instead of the full one (the same drape, tests/it/contact.rs).
    let (full, quarter) = (load("full")?, load("quarter")?);
    let tq = timed(&mut || {
        solve_scene(&quarter, &mut NoObserver);
    });
    let tf = timed(&mut || {
        solve_scene(&full, &mut NoObserver);
    });
    rows.push((
        "symmetry reduction (quarter model)".into(),
        full.name.clone(),
        tq,
        tf,
    ));
    ctx.progress.item_done(&ctx.stage.name);
    // 2. Recording off: simulate with the timeline and the rerun recording off and on.
    let mut hang4 = load("hang")?;
    hang4.cloth.nx = 21;
    hang4.cloth.ny = 21;
    let tmp = tempfile::tempdir()?;
    let mut with_rec = hang4.clone();
    with_rec.record.timeline = true;
    with_rec.record.rerun = true;
    let mut times = Vec::new();
    for (k, s) in [&hang4, &with_rec].iter().enumerate() {
        let loaded = drapelab_core::scene::LoadedScene {
            scene: (*s).clone(),
            path: ctx.input("hang")?.to_path_buf(),
        };
        let out = tmp.path().join(format!("r{k}"));
        let t = Instant::now();
        drapelab_record::simulate_to_dir(&loaded, &out, &mut NoObserver)?;
        times.push(t.elapsed().as_secs_f64());
    }
    rows.push((
        "timeline and rerun recording off".into(),
        hang4.name.clone(),
        times[0],
        times[1],
    ));
    ctx.progress.item_done(&ctx.stage.name);
    // 3. Cached parameter vectors: the same ICA run with the cost cache on and off.
    let mut net = load("hang")?;
    net.cloth.nx = 11;
    net.cloth.ny = 11;
    let probe = drapelab_core::calibrate::Problem::new(net.clone(), vec![], 50.0);
    let measured = probe
        .drape(&[0.4, 0.5, 0.5, 0.3, 0.1])
        .1
        .context("the reference drape did not converge")?;
    // The identifiability analysis sweeps damping and the elongation rate, which a static drape does not
    // see: the cache (keyed on stiffness, natural length and topology) answers those sweeps.
    let best = [0.4, 0.5, 0.5, 0.3, 0.1];
    let mut t_cache = [0.0; 2];
    for (k, caching) in [true, false].into_iter().enumerate() {
        // Sharing the probe's warm-start lattice, so that only the costs are timed.
        let mut problem = probe.fresh();
        problem.measured = measured.clone();
        problem.caching = caching;
        let t = Instant::now();
        drapelab_core::calibrate::identifiability(
            &problem,
            &best,
            0.1,
            7,
            drapelab_core::calibrate::Noise::FromResidual,
            0.05,
        );
        t_cache[k] = t.elapsed().as_secs_f64();
    }
    rows.push((
        "cached parameter vectors (identifiability analysis)".into(),
        net.name.clone(),
        t_cache[0],
        t_cache[1],
    ));
    ctx.progress.item_done(&ctx.stage.name);
    // 4. Up-to-date stages: a one-stage pipeline run from scratch, then again (nothing to do).
    let proj = tempfile::tempdir()?;
    std::fs::create_dir_all(proj.path().join("pipelines"))?;
    std::fs::create_dir_all(proj.path().join("datasets/scenes"))?;
    std::fs::copy(
        ctx.input("hang")?,
        proj.path().join("datasets/scenes/hang4.toml"),
    )?;
    let file = proj.path().join("pipelines/p.toml");
    std::fs::write(
        &file,
        "name = \"p\"\n[stages.h]\nkind = \"simulate\"\ninputs.scene = \"datasets/scenes/hang4.toml\"\n\
         outputs = { particles = \"{run}/h/particles.parquet\", run = \"{run}/h/run.json\" }\n\
         params.set = { \"cloth.nx\" = 41, \"cloth.ny\" = 41 }\n",
    )?;
    let plan = drapelab_pipeline::load_plan(&file, &crate::registry())?;
    let quiet = Silent;
    let mut t_pipe = [0.0; 2];
    for t in &mut t_pipe {
        let start = Instant::now();
        drapelab_pipeline::run_pipeline(&plan, &Default::default(), &quiet)?;
        *t = start.elapsed().as_secs_f64();
    }
    rows.push((
        "up-to-date stage skipped".into(),
        "hang4 41×41".into(),
        t_pipe[1],
        t_pipe[0],
    ));
    ctx.progress.item_done(&ctx.stage.name);
    // 5. Terms a scene does not need: hang4 (no obstacle, so no contact term is built) against the
    // same scene with a floor 10 m below that it never reaches (the barrier term is built and
    // evaluated every iteration). 19 a side: both solve from flat (no coarse start).
    let mut bare = load("hang")?;
    bare.cloth.nx = 19;
    bare.cloth.ny = 19;
    let mut floored = bare.clone();
    floored
        .obstacles
        .push(drapelab_core::contact::Obstacle::Plane {
            point_m: [0.0, 0.0, -10.0],
            normal: [0.0, 0.0, 1.0],
        });
    let mut t_terms = [0.0; 2];
    for (k, s) in [&bare, &floored].into_iter().enumerate() {
        let mut best = f64::INFINITY;
        for _ in 0..3 {
            best = best.min(timed(&mut || {
                solve_scene(s, &mut NoObserver);
            }));
        }
        t_terms[k] = best;
    }
    rows.push((
        "contact term not built (no obstacle within reach)".into(),
        "hang4 19×19".into(),
        t_terms[0],
        t_terms[1],
    ));
    ctx.progress.item_done(&ctx.stage.name);
    // 6. Threads: one ICA population (16 countries of a calibration, the cache off) costed on a
    // rayon pool of 2 threads against 1.
    let mut rng = <rand::rngs::StdRng as rand::SeedableRng>::seed_from_u64(7);
    let population: Vec<Vec<f64>> = (0..16)
        .map(|_| (0..5).map(|_| rand::Rng::random::<f64>(&mut rng)).collect())
        .collect();
    let mut problem = probe.fresh();
    problem.measured = measured.clone();
    problem.caching = false;
    let mut t_threads = [0.0; 2];
    for (k, threads) in [2usize, 1].into_iter().enumerate() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()?;
        t_threads[k] = timed(&mut || {
            pool.install(|| {
                use rayon::prelude::*;
                let _: Vec<f64> = population.par_iter().map(|u| problem.cost(u)).collect();
            });
        });
    }
    rows.push((
        "second thread (one calibration population of 16, 2 threads against 1)".into(),
        format!("{} 11×11", net.name),
        t_threads[0],
        t_threads[1],
    ));
    ctx.progress.item_done(&ctx.stage.name);
    let schema = Arc::new(Schema::new(vec![
        Field::new("skip", DataType::Utf8, false),
        Field::new("scene", DataType::Utf8, false),
        Field::new("time_with_skip_s", DataType::Float64, false),
        Field::new("time_without_skip_s", DataType::Float64, false),
        Field::new("saved_fraction", DataType::Float64, false),
    ]));
    let cols: Vec<ArrayRef> = vec![
        Arc::new(StringArray::from_iter_values(
            rows.iter().map(|r| r.0.clone()),
        )),
        Arc::new(StringArray::from_iter_values(
            rows.iter().map(|r| r.1.clone()),
        )),
        f64s(rows.iter().map(|r| r.2).collect()),
        f64s(rows.iter().map(|r| r.3).collect()),
        f64s(rows.iter().map(|r| 1.0 - r.2 / r.3).collect()),
    ];
    write_parquet(
        ctx.output("table")?,
        &RecordBatch::try_new(schema, cols)?,
        None,
    )
}

/// A progress that says nothing (the skips stage runs a pipeline of its own inside).
struct Silent;

impl drapelab_pipeline::Progress for Silent {
    fn stage_started(&self, _: &str, _: u64) {}
    fn item_done(&self, _: &str) {}
    fn stage_finished(&self, _: &str, _: &str, _: f64) {}
    fn stage_skipped(&self, _: &str, _: &str) {}
}
