//! One scene solved into a folder: `particles.parquet` (or `last_state.parquet`), `run.json` and,
//! when the scene asks, `timeline.mcap` and `drape.rrd`.

use crate::{RerunRecorder, TimelineRecorder, write_particles};
use anyhow::{Context, Result};
use drapelab_core::atomic::write_atomic;
use drapelab_core::build::{BuiltScene, build_scene};
use drapelab_core::scene::{LoadedScene, Scene};
use drapelab_core::simulate::solve_model;
use drapelab_core::solve::{Observer, Observers, SolveReport, StateEvent, Status, StopReason};
use serde::Serialize;
use std::path::Path;

#[derive(Serialize)]
struct RunRecord<'a> {
    drapelab_version: &'a str,
    scene_file: String,
    command_line: Vec<String>,
    status: &'a str,
    report: &'a SolveReport,
    terms: &'a [String],
    particles: usize,
    outputs: Vec<&'a str>,
    /// Drape coefficient, folds and penetration, for a converged scene with obstacles.
    drape: Option<drapelab_core::measure::DrapeMeasures>,
    /// The sheet's self-contact at the end: smallest distance, active pairs, crossings.
    self_contact: drapelab_core::simulate::SelfContactSummary,
    scene: &'a Scene,
}

/// Solves `loaded` and writes its outputs into `out` (created if needed). Returns the report; a
/// solve that did not converge writes `run.json` with its status and `last_state.parquet`, never
/// `particles.parquet`.
pub fn simulate_to_dir(
    loaded: &LoadedScene,
    out: &Path,
    progress: &mut dyn Observer,
) -> Result<SolveReport> {
    let scene = &loaded.scene;
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    let BuiltScene {
        grid,
        mut model,
        x0,
    } = build_scene(scene);
    let pins: Vec<usize> = (0..grid.len()).filter(|&p| model.fixed[p]).collect();
    let every = scene.record.every;
    let mut timeline = if scene.record.timeline {
        Some(
            TimelineRecorder::new(&out.join("timeline.mcap"), &grid, every)?
                .at_frame_rate(scene.record.frame_rate_hz),
        )
    } else {
        None
    };
    let mut rrd = if scene.record.rerun {
        Some(
            RerunRecorder::new(
                &out.join("drape.rrd"),
                &scene.name,
                &grid,
                &x0,
                &pins,
                every,
            )?
            .at_frame_rate(scene.record.frame_rate_hz),
        )
    } else {
        None
    };
    let mut x = x0;
    let report = {
        let mut obs: Vec<&mut dyn Observer> = vec![progress];
        if let Some(t) = timeline.as_mut() {
            obs.push(t);
        }
        if let Some(r) = rrd.as_mut() {
            obs.push(r);
        }
        let mut r = solve_model(scene, &grid, &mut model, &mut x, &mut Observers(obs));
        drapelab_core::simulate::check_crossings(scene, &grid, &model, &x, &mut r);
        r
    };
    let final_ev = StateEvent {
        index: report.iterations,
        time_s: report.sim_time_s,
        x: &x,
        max_residual_N: report.max_residual_N,
        energy_J: report.energy_J,
    };
    let finite = x.iter().all(|p| p.iter().all(|c| c.is_finite()));
    // A recorder that failed during the solve is dropped (its temporary file with it), not finished.
    if report.stop == StopReason::Observer {
        timeline = None;
        rrd = None;
    }
    let mut outputs = vec!["run.json"];
    if let Some(mut t) = timeline {
        t.finish(finite.then_some(&final_ev))?;
        outputs.push("timeline.mcap");
    }
    if let Some(mut r) = rrd {
        r.finish(finite.then_some(&final_ev))?;
        outputs.push("drape.rrd");
    }
    let meta = [
        ("drapelab_version", drapelab_core::VERSION.to_string()),
        ("status", report.status.as_str().to_string()),
        ("solver", report.solver.clone()),
        ("scene", scene.name.clone()),
    ];
    if report.status == Status::Converged {
        write_particles(&out.join("particles.parquet"), &grid, &x, &meta)?;
        outputs.push("particles.parquet");
    } else if finite && report.status != Status::Diverged {
        write_particles(&out.join("last_state.parquet"), &grid, &x, &meta)?;
        outputs.push("last_state.parquet");
    }
    let terms = model.term_names();
    let record = RunRecord {
        drapelab_version: drapelab_core::VERSION,
        scene_file: loaded.path.display().to_string(),
        command_line: std::env::args().collect(),
        status: report.status.as_str(),
        report: &report,
        terms: &terms,
        particles: grid.len(),
        outputs,
        drape: (report.is_converged() && !scene.obstacles.is_empty())
            .then(|| drapelab_core::measure::drape_measures(scene, &grid, &x)),
        self_contact: drapelab_core::simulate::self_contact_summary(scene, &grid, &model, &x),
        scene,
    };
    let json = serde_json::to_string_pretty(&record)?;
    write_atomic(&out.join("run.json"), |f| {
        use std::io::Write;
        f.write_all(json.as_bytes())?;
        Ok(())
    })?;
    Ok(report)
}
