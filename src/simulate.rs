//! Running one scene: build the model, solve it with the scene's solver, and (for the CLI) write
//! `particles.parquet`, `run.json` and, when asked, `timeline.mcap` and `drape.rrd`.

use crate::cloth::{BuiltScene, Grid, build_scene};
use crate::io::{RerunRecorder, TimelineRecorder, write_atomic, write_particles};
use crate::scene::{LoadedScene, Scene};
use crate::solve::{Observer, Observers, SolveReport, StateEvent, Status, solve_dynamic, solve_static};
use anyhow::{Context, Result};
use nalgebra::Vector3;
use serde::Serialize;
use std::path::Path;

/// A solved scene.
pub struct Solution {
    /// The grid of real particles.
    pub grid: Grid,
    /// Final positions of all particles (virtual points after the grid ones) in m.
    pub x: Vec<Vector3<f64>>,
    /// How the solve went.
    pub report: SolveReport,
    /// The energy terms that were built.
    pub terms: Vec<String>,
    /// The model, for evaluating residuals or energies afterwards.
    pub model: crate::physics::Model,
}

impl Solution {
    /// Positions of the grid particles only.
    pub fn grid_positions(&self) -> &[Vector3<f64>] {
        &self.x[..self.grid.len()]
    }
    /// Position of grid particle (i, j).
    pub fn at(&self, i: usize, j: usize) -> Vector3<f64> {
        self.x[self.grid.index(i, j)]
    }
}

/// Solves a validated scene in memory with its configured solver; the observer sees each state.
pub fn solve_scene(scene: &Scene, observer: &mut dyn Observer) -> Solution {
    let BuiltScene { grid, model, x0 } = build_scene(scene);
    let mut x = x0;
    let report = match scene.solver.kind.integrator() {
        None => solve_static(&model, &mut x, &scene.solver.static_, observer),
        Some(integ) => {
            let mut v = vec![Vector3::zeros(); x.len()];
            solve_dynamic(&model, integ, &mut x, &mut v, &scene.solver.dynamic, observer)
        }
    };
    Solution { grid, terms: model.term_names(), x, report, model }
}

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
    scene: &'a Scene,
}

/// Solves `loaded` and writes its outputs into `out` (created if needed). Returns the report; a
/// solve that did not converge writes `run.json` with its status and `last_state.parquet`, never
/// `particles.parquet`.
pub fn simulate_to_dir(loaded: &LoadedScene, out: &Path, progress: &mut dyn Observer) -> Result<SolveReport> {
    let scene = &loaded.scene;
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    let BuiltScene { grid, model, x0 } = build_scene(scene);
    let pins: Vec<usize> = (0..grid.len()).filter(|&p| model.fixed[p]).collect();
    let every = scene.record.every;
    let mut timeline = if scene.record.timeline { Some(TimelineRecorder::new(&out.join("timeline.mcap"), &grid, every)?) } else { None };
    let mut rrd = if scene.record.rerun { Some(RerunRecorder::new(&out.join("drape.rrd"), &scene.name, &grid, &x0, &pins, every)?) } else { None };
    let mut x = x0;
    let report = {
        let mut obs: Vec<&mut dyn Observer> = vec![progress];
        if let Some(t) = timeline.as_mut() {
            obs.push(t);
        }
        if let Some(r) = rrd.as_mut() {
            obs.push(r);
        }
        let mut all = Observers(obs);
        match scene.solver.kind.integrator() {
            None => solve_static(&model, &mut x, &scene.solver.static_, &mut all),
            Some(integ) => {
                let mut v = vec![Vector3::zeros(); x.len()];
                solve_dynamic(&model, integ, &mut x, &mut v, &scene.solver.dynamic, &mut all)
            }
        }
    };
    let final_ev = StateEvent {
        index: report.iterations,
        time_s: report.sim_time_s,
        x: &x,
        max_residual_N: report.max_residual_N,
        energy_J: report.energy_J,
    };
    let finite = x.iter().all(|p| p.iter().all(|c| c.is_finite()));
    let mut outputs = vec!["run.json"];
    if let Some(t) = timeline {
        t.finish(finite.then_some(&final_ev))?;
        outputs.push("timeline.mcap");
    }
    if let Some(r) = rrd {
        r.finish(finite.then_some(&final_ev))?;
        outputs.push("drape.rrd");
    }
    let meta = [("drapelab_version", crate::VERSION.to_string()), ("status", report.status.as_str().to_string()), ("solver", report.solver.clone()), ("scene", scene.name.clone())];
    if report.status == Status::Converged {
        write_particles(&out.join("particles.parquet"), &grid, &x, &meta)?;
        outputs.push("particles.parquet");
    } else if finite && report.status != Status::Diverged {
        write_particles(&out.join("last_state.parquet"), &grid, &x, &meta)?;
        outputs.push("last_state.parquet");
    }
    let terms = model.term_names();
    let record = RunRecord {
        drapelab_version: crate::VERSION,
        scene_file: loaded.path.display().to_string(),
        command_line: std::env::args().collect(),
        status: report.status.as_str(),
        report: &report,
        terms: &terms,
        particles: grid.len(),
        outputs,
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
