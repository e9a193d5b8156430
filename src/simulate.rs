//! Running one scene: build the model, solve it with the scene's solver, and (for the CLI) write
//! `particles.parquet`, `run.json` and, when asked, `timeline.mcap` and `drape.rrd`.

use crate::cloth::{BuiltScene, Grid, build_scene};
use crate::io::{RerunRecorder, TimelineRecorder, write_atomic, write_particles};
use crate::scene::{LoadedScene, Scene};
use crate::solve::{
    Observer, Observers, SolveReport, StateEvent, Status, solve_dynamic, solve_static,
};
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
    /// Where the material point at sheet coordinates (u, v) in m (from particle (0, 0) of the flat
    /// sheet) ended: bilinear interpolation over its grid cell, exact at grid particles. Lets grids
    /// of different resolution or grading be compared at the same material points.
    pub fn at_material(&self, u_m: f64, v_m: f64) -> Vector3<f64> {
        let cell = |lines: &[f64], s: f64| {
            let k = lines.partition_point(|&c| c <= s).clamp(1, lines.len() - 1) - 1;
            let t = ((s - lines[k]) / (lines[k + 1] - lines[k])).clamp(0.0, 1.0);
            (k, t)
        };
        let ((i, a), (j, b)) = (cell(&self.grid.xs, u_m), cell(&self.grid.ys, v_m));
        self.at(i, j) * ((1.0 - a) * (1.0 - b))
            + self.at(i + 1, j) * (a * (1.0 - b))
            + self.at(i, j + 1) * ((1.0 - a) * b)
            + self.at(i + 1, j + 1) * (a * b)
    }
}

/// Solves a validated scene in memory with its configured solver; the observer sees each state.
pub fn solve_scene(scene: &Scene, observer: &mut dyn Observer) -> Solution {
    solve_built(scene, None, observer)
}

/// Solves a validated scene statically or dynamically from the given positions of all particles
/// (a warm start: no coarse or sagged start is made); the scene's own start when `x0` does not match
/// the built model's particle count.
pub fn solve_scene_from(
    scene: &Scene,
    x0: &[Vector3<f64>],
    observer: &mut dyn Observer,
) -> Solution {
    solve_built(scene, Some(x0), observer)
}

fn solve_built(
    scene: &Scene,
    start: Option<&[Vector3<f64>]>,
    observer: &mut dyn Observer,
) -> Solution {
    let BuiltScene {
        grid,
        mut model,
        x0: mut x,
    } = build_scene(scene);
    let report = match start {
        Some(x0) if x0.len() == x.len() => {
            x.copy_from_slice(x0);
            // A warm start is near its equilibrium: Newton starts far less damped.
            let mut warm = scene.clone();
            let lm = &mut warm.solver.static_.lm_damping_initial;
            *lm = lm.min(WARM_LM_DAMPING);
            let mut report = static_or_dynamic(&warm, &grid, &mut model, &mut x, observer);
            check_minimum(&model, &x, &mut report);
            report
        }
        _ => solve_model(scene, &grid, &mut model, &mut x, observer),
    };
    Solution {
        grid,
        terms: model.term_names(),
        x,
        report,
        model,
    }
}

/// The initial Levenberg–Marquardt damping of a solve from a warm start (relative to the mean
/// diagonal; the flat or sagged start's default is 1e-3).
const WARM_LM_DAMPING: f64 = 1e-5;

/// The scene's solver from `x` as it is: the static solve, or the dynamic integrator.
fn static_or_dynamic(
    scene: &Scene,
    grid: &Grid,
    model: &mut crate::physics::Model,
    x: &mut [Vector3<f64>],
    observer: &mut dyn Observer,
) -> SolveReport {
    match scene.solver.kind.integrator() {
        None => static_solve(scene, grid, model, x, observer),
        Some(integ) => {
            let mut v = vec![Vector3::zeros(); x.len()];
            solve_dynamic(model, integ, x, &mut v, &scene.solver.dynamic, observer)
        }
    }
}

/// Stability of a converged static state (once, after every load increment and contact round).
fn check_minimum(model: &crate::physics::Model, x: &[Vector3<f64>], report: &mut SolveReport) {
    if report.is_converged() && report.solver == "static-newton" {
        let minimum = crate::solve::is_minimum(model, x);
        report.minimum = Some(minimum);
        if !minimum {
            report.message += "; not a minimum: an unstable equilibrium (a saddle), which a \
small perturbation (cloth.initial_perturbation_m, [[loads]]) moves off";
        }
    }
}

/// Solves a built scene from `x` (updated in place) with the scene's solver.
fn solve_model(
    scene: &Scene,
    grid: &Grid,
    model: &mut crate::physics::Model,
    x: &mut [Vector3<f64>],
    observer: &mut dyn Observer,
) -> SolveReport {
    if scene.solver.kind.integrator().is_some() {
        return static_or_dynamic(scene, grid, model, x, observer);
    }
    // Nested iteration: start Newton from the interpolated solution of the scene on the grid with
    // every other line, when that grid exists; far fewer fine iterations are needed. Otherwise,
    // without obstacles, from the sagged sheet.
    let coarse = coarse_start(scene, grid, x);
    if coarse.is_none() && scene.solver.static_.sag_start && scene.obstacles.is_empty() {
        crate::solve::sagged_start(model, x);
    }
    let mut report = static_solve(scene, grid, model, x, observer);
    if let Some((r, _)) = coarse {
        report.iterations += r.iterations;
        report.linear_solves += r.linear_solves;
        report.factorizations += r.factorizations;
        report.factor_time_s += r.factor_time_s;
        report.wall_time_s += r.wall_time_s;
        report.message += &format!(
            " (from a {}×{} start)",
            grid.nx.div_ceil(2),
            grid.ny.div_ceil(2)
        );
    }
    check_minimum(model, x, &mut report);
    report
}

/// The static solve of a built scene from `x`: Newton, wrapped in the vertical-gap active set when the
/// scene asks for that contact treatment.
fn static_solve(
    scene: &Scene,
    grid: &Grid,
    model: &mut crate::physics::Model,
    x: &mut [Vector3<f64>],
    observer: &mut dyn Observer,
) -> SolveReport {
    let opts = &scene.solver.static_;
    if scene.contact.method == crate::scene::ContactMethod::VerticalGap
        && !scene.obstacles.is_empty()
    {
        crate::solve::solve_vertical_gap(
            model,
            x,
            &scene.obstacles,
            grid.min_spacing_m(),
            opts,
            observer,
        )
    } else if scene.contact.friction_coefficient > 0.0 && !scene.obstacles.is_empty() {
        solve_with_friction(scene, model, x, opts, observer)
    } else {
        solve_static(model, x, opts, observer)
    }
}

/// The static solve with lagged friction: the load raised in increments (20 when the scene asks for
/// one step), the friction anchors refreshed before each, then up to 10 more refreshes at full load
/// until no particle moves by more than 1e-7 m.
fn solve_with_friction(
    scene: &Scene,
    model: &mut crate::physics::Model,
    x: &mut [Vector3<f64>],
    opts: &crate::solve::StaticOptions,
    observer: &mut dyn Observer,
) -> SolveReport {
    use crate::physics::{FrictionAnchor, LaggedFriction};
    let contact = crate::cloth::barrier_contact(scene, &model.masses, &model.fixed);
    let mu = scene.contact.friction_coefficient;
    let steps = if opts.load_steps > 1 {
        opts.load_steps
    } else {
        20
    };
    let mut loads: Vec<f64> = (1..=steps).map(|k| k as f64 / steps as f64).collect();
    loads.extend([1.0; 10]);
    model.terms.push(Box::new(LaggedFriction {
        anchors: vec![],
        eps_m: 1e-5,
    }));
    let mut total: Option<SolveReport> = None;
    for (k, &load) in loads.iter().enumerate() {
        let anchors = contact
            .contacts(x)
            .into_iter()
            .map(|(p, n, force)| FrictionAnchor {
                particle: p,
                anchor_m: x[p],
                normal: n,
                limit_N: mu * force,
            })
            .collect();
        if let Some(t) = model.terms.last_mut() {
            *t = Box::new(LaggedFriction {
                anchors,
                eps_m: 1e-5,
            });
        }
        let before = x.to_vec();
        let obs: &mut dyn Observer = if k == 0 {
            &mut *observer
        } else {
            &mut crate::solve::NoObserver
        };
        let r = crate::solve::solve_static_loads(model, x, opts, &[load], obs);
        let moved = x
            .iter()
            .zip(&before)
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, f64::max);
        let mut t = SolveReport::accumulate(total.take(), r);
        if !t.is_converged() {
            return t;
        }
        if k >= steps && moved < 1e-7 {
            t.message = format!("{} (friction μ = {mu}, {} lag updates)", t.message, k + 1);
            return t;
        }
        total = Some(t);
    }
    let mut t = total.expect("at least one solve");
    t.message = format!(
        "{} (friction μ = {mu}: lag updates still moving the sheet)",
        t.message
    );
    t
}

/// Solves the scene on the grid with every other line and writes the interpolated positions into
/// the free particles of `x`. Only when both sides have an odd count ≥ 21, the coarse solve converges,
/// no absolute natural length ties the springs to the fine spacing, and no hold or point load names
/// particles of the fine grid.
fn coarse_start(scene: &Scene, grid: &Grid, x: &mut [Vector3<f64>]) -> Option<(SolveReport, ())> {
    let (nx, ny) = (grid.nx, grid.ny);
    let natural = scene
        .material
        .mass_spring
        .as_ref()
        .is_some_and(|m| m.natural_length_m.is_some());
    if !scene.solver.static_.coarse_start
        || natural
        || !scene.obstacles.is_empty()
        || !scene.boundary.holds.is_empty()
        || !scene.loads.is_empty()
        || nx < 21
        || ny < 21
        || nx % 2 == 0
        || ny % 2 == 0
    {
        return None;
    }
    if scene
        .boundary
        .pin_particles
        .iter()
        .any(|p| p[0] % 2 == 1 || p[1] % 2 == 1)
    {
        return None;
    }
    let c = scene.regridded(nx.div_ceil(2), ny.div_ceil(2));
    let coarse = solve_scene(&c, &mut crate::solve::NoObserver);
    if !coarse.report.is_converged() {
        return None;
    }
    let cg = &coarse.grid;
    let at = |i: usize, j: usize| coarse.x[cg.index(i, j)];
    for j in 0..ny {
        for i in 0..nx {
            let p = grid.index(i, j);
            let (i0, j0) = (i / 2, j / 2);
            let (i1, j1) = (i0 + i % 2, j0 + j % 2);
            x[p] = (at(i0, j0) + at(i1, j0) + at(i0, j1) + at(i1, j1)) * 0.25;
        }
    }
    Some((coarse.report, ()))
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
    /// Drape coefficient, folds and penetration, for a converged scene with obstacles.
    drape: Option<crate::measure::DrapeMeasures>,
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
        Some(TimelineRecorder::new(
            &out.join("timeline.mcap"),
            &grid,
            every,
        )?)
    } else {
        None
    };
    let mut rrd = if scene.record.rerun {
        Some(RerunRecorder::new(
            &out.join("drape.rrd"),
            &scene.name,
            &grid,
            &x0,
            &pins,
            every,
        )?)
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
        solve_model(scene, &grid, &mut model, &mut x, &mut Observers(obs))
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
    let meta = [
        ("drapelab_version", crate::VERSION.to_string()),
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
        drapelab_version: crate::VERSION,
        scene_file: loaded.path.display().to_string(),
        command_line: std::env::args().collect(),
        status: report.status.as_str(),
        report: &report,
        terms: &terms,
        particles: grid.len(),
        outputs,
        drape: (report.is_converged() && !scene.obstacles.is_empty())
            .then(|| crate::measure::drape_measures(scene, &grid, &x)),
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
