//! One scene solved into a folder: `particles.parquet` (or `last_state.parquet`), `run.json` and,
//! when the scene asks, `timeline.mcap` and `drape.rrd`.

use crate::{RerunRecorder, Sampled, TimelineRecorder, write_particles};
use anyhow::{Context, Result};
use drapelab_core::build::{BuiltScene, build_scene};
use drapelab_core::cloth::Grid;
use drapelab_core::physics::Model;
use drapelab_core::scene::{LoadedScene, Scene};
use drapelab_core::simulate::{solve_model, solve_model_warm};
use drapelab_core::solve::{Observer, Observers, SolveReport, StateEvent, Status, StopReason};
use serde::Serialize;

pub use crate::run_sensitivity::KeyedSensitivities;
use crate::run_sensitivity::{SensitivityRecord, sensitivities};
use std::path::Path;

#[derive(Serialize)]
struct RunRecord<'a> {
    drapelab_version: &'a str,
    /// The build that ran: the first 16 hex digits of the executable's blake3 hash.
    build_id: &'a str,
    /// When the run finished, RFC 3339 UTC.
    finished_utc: String,
    /// The machine it ran on.
    host: String,
    scene_file: String,
    command_line: Vec<String>,
    status: &'a str,
    report: &'a SolveReport,
    terms: &'a [String],
    particles: usize,
    outputs: Vec<&'static str>,
    /// Drape coefficient, folds and penetration, for a converged scene with obstacles.
    drape: Option<drapelab_core::measure::DrapeMeasures>,
    /// The sheet's self-contact at the end: smallest distance, active pairs, crossings.
    self_contact: drapelab_core::simulate::SelfContactSummary,
    /// The sensitivities asked for (`--sensitivity`): written, or why not.
    #[serde(skip_serializing_if = "Option::is_none")]
    sensitivity: Option<SensitivityRecord>,
    /// The rigid motions the converged equilibrium is free to make (a turn about a held point on
    /// a frictionless sphere), empty when none; absent for a run that is no converged static
    /// equilibrium. A sensitivity is the one orthogonal to them.
    #[serde(skip_serializing_if = "Option::is_none")]
    neutral_modes: Option<Vec<drapelab_core::solve::NeutralMode>>,
    /// The saved state the solve started from (`--start`), if any.
    #[serde(skip_serializing_if = "Option::is_none")]
    start_file: Option<String>,
    /// How the solve took up that start's state.
    #[serde(skip_serializing_if = "Option::is_none")]
    start: Option<StartRecord>,
    /// How a garment from a sewing pattern (`cloth.pattern`) was sewn before it was draped: seam
    /// gaps before welding, stages, crossing edges of the welded garment, penetration of the body.
    #[serde(skip_serializing_if = "Option::is_none")]
    sewing: Option<&'a drapelab_core::sewing::sew::SewReport>,
    scene: &'a Scene,
}

/// Every file `simulate` may write into its folder.
pub const SIMULATE_FILES: [&str; 10] = [
    "run.json",
    "body.obj",
    "iterations.parquet",
    "particles.parquet",
    "last_state.parquet",
    "triangles.parquet",
    "drape.obj",
    "timeline.mcap",
    "drape.rrd",
    "sensitivity.parquet",
];

/// What a simulate run adds to the scene's own outputs.
#[derive(Debug, Clone, Default)]
pub struct SimulateExtras {
    /// Continuous scene keys whose sensitivities dx*/dθ to write into `sensitivity.parquet`
    /// (`simulate --sensitivity KEY`); checked by [`drapelab_core::sensitivity::check_key`] first.
    pub sensitivity_keys: Vec<String>,
    /// A saved drape to start from (`simulate --start FILE`).
    pub start: Option<StartState>,
    /// Also write the converged drape as `drape.obj` (`simulate --obj`).
    pub obj: bool,
}

/// A saved drape a run starts from: a restart that continues the run that wrote it.
#[derive(Debug, Clone)]
pub struct StartState {
    /// The grid particles' positions in particles.parquet's row order, m.
    pub x: Vec<nalgebra::Vector3<f64>>,
    /// The file's name, for run.json.
    pub file: String,
    /// What the run that wrote it adapted (κ growth), from the file's metadata; None for a table
    /// written elsewhere (the solve then starts its model as built, and run.json says so).
    pub adapted: Option<drapelab_core::physics::Adapted>,
}

/// How a run took up its start, for run.json.
#[derive(Debug, Clone, Serialize)]
struct StartRecord {
    /// The saved drape's file.
    file: String,
    /// The self-contact κ growth the solve started with (from the file; 1 where it had none).
    kappa_growth_taken_up: f64,
    /// What the run did with the file's solve state.
    note: &'static str,
}

impl StartState {
    /// run.json's account of the start.
    fn record(&self) -> StartRecord {
        StartRecord {
            file: self.file.clone(),
            kappa_growth_taken_up: self.adapted.unwrap_or_default().kappa_growth,
            note: match self.adapted {
                Some(_) => {
                    "the solve continued the run that wrote the start (its κ growth taken up)"
                }
                None => {
                    "the start carries no solve state (not written by drapelab): the model started as built, κ growth 1"
                }
            },
        }
    }
}

impl SimulateExtras {
    /// Copies the given start into `x` when it has one position per particle of `x` and gives the
    /// model the state the start's run adapted; whether it did.
    fn start_into(&self, x: &mut [nalgebra::Vector3<f64>], model: &mut Model) -> bool {
        match &self.start {
            Some(start) if start.x.len() == x.len() => {
                x.copy_from_slice(&start.x);
                if let Some(a) = &start.adapted {
                    a.apply_to(model);
                }
                true
            }
            _ => false,
        }
    }
}

/// Solves `loaded` and writes its outputs into `out` (created if needed). Returns the report; a
/// solve that did not converge writes `run.json` with its status and `last_state.parquet`, never
/// `particles.parquet`.
///
/// The outputs are written into a fresh folder inside `out` and moved in when the solve is done,
/// `run.json` last; the files of an earlier run that this one does not write are removed first. So
/// `out` never holds a result beside a `run.json` that contradicts it, and a run that fails with an
/// error leaves the earlier result whole. Other files in `out` are left alone.
pub fn simulate_to_dir(
    loaded: &LoadedScene,
    out: &Path,
    progress: &mut dyn Observer,
) -> Result<SolveReport> {
    Ok(simulate_to_dir_state(loaded, out, progress)?.report)
}

/// A scene solved into a folder: its report and final state.
#[derive(Debug, Clone)]
pub struct Simulated {
    /// The solve's report (its status first).
    pub report: SolveReport,
    /// The particles' final positions, m, in grid order `j * nx + i`.
    pub x: Vec<nalgebra::Vector3<f64>>,
    /// Whether each particle is outside the sheet's shape (a disc's corners).
    pub absent: Vec<bool>,
    /// The sheet's grid.
    pub grid: drapelab_core::cloth::Grid,
    /// The sensitivities asked for ([`SimulateExtras::sensitivity_keys`]), key by key: dx*/dθ of
    /// the grid particles, m per unit of the key; empty when none were asked for or none exist
    /// (run.json says why).
    pub sensitivity: KeyedSensitivities,
}

/// [`simulate_to_dir`], also returning the final state (the Python package's `simulate`).
pub fn simulate_to_dir_state(
    loaded: &LoadedScene,
    out: &Path,
    progress: &mut dyn Observer,
) -> Result<Simulated> {
    simulate_to_dir_with(loaded, out, progress, &SimulateExtras::default())
}

/// [`simulate_to_dir_state`] with a start from a saved drape and sensitivities ([`SimulateExtras`]).
pub fn simulate_to_dir_with(
    loaded: &LoadedScene,
    out: &Path,
    progress: &mut dyn Observer,
    extras: &SimulateExtras,
) -> Result<Simulated> {
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    remove_stale_staging(out);
    let staging = tempfile::Builder::new()
        .prefix(&format!(".simulate.{}.", std::process::id()))
        .suffix(".partial")
        .tempdir_in(out)
        .with_context(|| format!("cannot write into {}", out.display()))?;
    drapelab_core::atomic::note_unfinished(staging.path(), drapelab_core::atomic::Removal::Whole);
    let done = simulate_into(loaded, staging.path(), progress, extras)
        .and_then(|(simulated, written)| publish(staging.path(), out, &written).map(|_| simulated));
    drapelab_core::atomic::note_finished(staging.path());
    done
}

/// Removes staging folders that a killed run left in `out`: those whose process (the pid in the
/// name, `.simulate.PID.XXXX.partial`) is gone. A run still writing into the same folder keeps its
/// own: two runs into one `--out` both finish, the later's files last.
fn remove_stale_staging(out: &Path) {
    for e in std::fs::read_dir(out).into_iter().flatten().flatten() {
        let name = e.file_name().to_string_lossy().to_string();
        let Some(middle) = name
            .strip_prefix(".simulate.")
            .and_then(|n| n.strip_suffix(".partial"))
        else {
            continue;
        };
        let owner = middle.split('.').next().and_then(|p| p.parse::<u32>().ok());
        if !owner.is_some_and(process_alive) {
            std::fs::remove_dir_all(e.path()).ok();
        }
    }
}

/// Whether process `pid` is running (Linux's /proc; elsewhere assumed, so nothing live is removed).
fn process_alive(pid: u32) -> bool {
    !cfg!(target_os = "linux") || Path::new("/proc").join(pid.to_string()).exists()
}

/// Moves the files `written` from `staging` into `out`, `run.json` last, after removing the
/// simulate files of an earlier run that are not among them.
fn publish(staging: &Path, out: &Path, written: &[&str]) -> Result<()> {
    for f in SIMULATE_FILES.iter().filter(|f| !written.contains(f)) {
        let old = out.join(f);
        if old.exists() {
            std::fs::remove_file(&old)
                .with_context(|| format!("cannot remove the earlier {}", old.display()))?;
        }
    }
    let mut order: Vec<&&str> = written.iter().filter(|f| **f != "run.json").collect();
    order.extend(written.iter().filter(|f| **f == "run.json"));
    for f in order {
        std::fs::rename(staging.join(f), out.join(f))
            .with_context(|| format!("cannot move {f} into {}", out.display()))?;
    }
    Ok(())
}

/// The timeline (MCAP) and rerun recorders of a solve, each when the scene asks for it.
type Recorders = (
    Option<Sampled<TimelineRecorder>>,
    Option<Sampled<RerunRecorder>>,
);

/// The recorders a scene asks for (`record.timeline`, `record.rerun`), writing into `out`.
fn recorders(
    scene: &Scene,
    out: &Path,
    grid: &drapelab_core::cloth::Grid,
    model: &drapelab_core::physics::Model,
    x0: &[nalgebra::Vector3<f64>],
) -> Result<Recorders> {
    let pins: Vec<usize> = (0..grid.len()).filter(|&p| model.fixed[p]).collect();
    let triangles = drapelab_core::build::scene_triangles(scene);
    let sheet = (grid.len(), triangles.as_slice());
    let every = scene.record.every;
    let timeline = if scene.record.timeline {
        Some(
            TimelineRecorder::new(&out.join("timeline.mcap"), sheet, every)?
                .at_frame_rate(scene.record.frame_rate_hz),
        )
    } else {
        None
    };
    let rrd = if scene.record.rerun {
        let mut r =
            RerunRecorder::new(&out.join("drape.rrd"), &scene.name, sheet, x0, &pins, every)?
                .at_frame_rate(scene.record.frame_rate_hz);
        if let Some(sewing) = &scene.cloth.sewing {
            r.log_sewing(sewing)?;
        }
        Some(r)
    } else {
        None
    };
    Ok((timeline, rrd))
}

/// Solves `loaded` and writes its outputs into the empty folder `out`; the report and the files
/// written.
fn simulate_into(
    loaded: &LoadedScene,
    out: &Path,
    progress: &mut dyn Observer,
    extras: &SimulateExtras,
) -> Result<(Simulated, Vec<&'static str>)> {
    let scene = &loaded.scene;
    let BuiltScene {
        grid,
        mut model,
        x0,
    } = build_scene(scene);
    let absent = drapelab_core::build::absent_particles(scene, &x0);
    let (mut timeline, mut rrd) = recorders(scene, out, &grid, &model, &x0)?;
    let mut x = x0;
    let warm = extras.start_into(&mut x[..grid.len()], &mut model);
    let every = scene
        .solver
        .kind
        .integrator()
        .map_or(1, |_| scene.solver.dynamic.check_every);
    let mut history = crate::History::every(every);
    let mut obs: Vec<&mut dyn Observer> = vec![progress, &mut history];
    obs.extend(timeline.as_mut().map(|t| t as &mut dyn Observer));
    obs.extend(rrd.as_mut().map(|r| r as &mut dyn Observer));
    let report = observed_solve(
        scene,
        (&grid, &mut model, &mut x),
        warm,
        &mut Observers(obs),
    );
    let mut outputs = vec!["run.json", "iterations.parquet"];
    history.write(&out.join("iterations.parquet"))?;
    finish_recorders(&report, &x, (timeline, rrd), &mut outputs)?;
    let state = (&grid, absent.as_slice(), x.as_slice());
    let adapted = drapelab_core::physics::Adapted::of(&model);
    state_files(
        scene,
        state,
        (&report, adapted),
        extras.obj,
        out,
        &mut outputs,
    )?;
    let asked = &extras.sensitivity_keys;
    let (sensitivity, sens_data) = sensitivities(loaded, &grid, &model, &x, &report, asked, out)?;
    if sensitivity.as_ref().is_some_and(|s| s.written) {
        outputs.push("sensitivity.parquet");
    }
    let solved = (&grid, &model, x.as_slice(), &report);
    let record = run_record(loaded, solved, extras, (outputs, sensitivity))?;
    let written = record.1.clone();
    crate::write_text(&out.join("run.json"), &record.0)?;
    Ok((
        Simulated {
            report,
            x,
            absent,
            grid,
            sensitivity: sens_data,
        },
        written,
    ))
}

/// run.json's text for a solved scene, and the outputs it lists.
fn run_record(
    loaded: &LoadedScene,
    (grid, model, x, report): (&Grid, &Model, &[nalgebra::Vector3<f64>], &SolveReport),
    extras: &SimulateExtras,
    (outputs, sensitivity): (Vec<&'static str>, Option<SensitivityRecord>),
) -> Result<(String, Vec<&'static str>)> {
    let scene = &loaded.scene;
    let terms = model.term_names();
    let record = RunRecord {
        drapelab_version: drapelab_core::VERSION,
        build_id: drapelab_core::provenance::build_id(),
        finished_utc: drapelab_core::provenance::utc(drapelab_core::provenance::unix_now_s()),
        host: drapelab_core::provenance::host(),
        scene_file: loaded.path.display().to_string(),
        command_line: std::env::args().collect(),
        status: report.status.as_str(),
        report,
        terms: &terms,
        particles: grid.len(),
        outputs,
        drape: (report.is_converged() && !scene.obstacles.is_empty())
            .then(|| drapelab_core::measure::drape_measures(scene, x)),
        self_contact: drapelab_core::simulate::self_contact_summary(scene, model, x),
        sensitivity,
        neutral_modes: (report.is_converged() && scene.solver.kind.integrator().is_none())
            .then(|| drapelab_core::solve::neutral_modes(model, x)),
        start_file: extras.start.as_ref().map(|s| s.file.clone()),
        start: extras.start.as_ref().map(StartState::record),
        sewing: scene.cloth.sewing.as_deref(),
        scene,
    };
    Ok((
        serde_json::to_string_pretty(&record)?,
        record.outputs.clone(),
    ))
}

/// Solves `scene`'s model from `x` (warm: from a given start) under the observers, then checks that
/// the sheet does not pass through itself.
fn observed_solve(
    scene: &Scene,
    (grid, model, x): (&Grid, &mut Model, &mut [nalgebra::Vector3<f64>]),
    warm: bool,
    obs: &mut Observers<'_>,
) -> SolveReport {
    let mut r = if warm {
        let (opts, cold) = (&scene.solver.static_, Default::default());
        solve_model_warm(scene, opts, grid, model, x, cold, obs)
    } else {
        solve_model(scene, grid, model, x, obs)
    };
    drapelab_core::simulate::check_crossings(scene, grid, model, x, &mut r);
    r
}

/// The final state: `particles.parquet` of a converged drape, else `last_state.parquet` of a
/// finite one (labelled by its status, for looking at where it went wrong; a non-finite state is
/// not written), with what the solve adapted (κ growth) in its metadata for a restart; beside it the sheet as a mesh, `triangles.parquet`, and `drape.obj` of a
/// converged drape when asked.
fn state_files(
    scene: &Scene,
    (grid, absent, x): (
        &drapelab_core::cloth::Grid,
        &[bool],
        &[nalgebra::Vector3<f64>],
    ),
    (report, adapted): (&SolveReport, drapelab_core::physics::Adapted),
    obj: bool,
    out: &Path,
    outputs: &mut Vec<&'static str>,
) -> Result<()> {
    let mut meta = vec![
        ("drapelab_version", drapelab_core::VERSION.to_string()),
        ("status", report.status.as_str().to_string()),
        ("solver", report.solver.report_name().to_string()),
        ("scene", scene.name.clone()),
    ];
    meta.extend(adapted.metadata());
    let finite = x.iter().all(|p| p.iter().all(|c| c.is_finite()));
    let file = match (report.status == Status::Converged, finite) {
        (true, _) => "particles.parquet",
        (false, true) => "last_state.parquet",
        (false, false) => return Ok(()),
    };
    write_particles(&out.join(file), grid, x, absent, &meta)?;
    outputs.push(file);
    let tris = drapelab_core::build::scene_triangles(scene);
    crate::write_triangles(&out.join("triangles.parquet"), &tris)?;
    outputs.push("triangles.parquet");
    if obj && report.is_converged() {
        let text = crate::obj_text(&scene.name, &x[..grid.len()], &tris);
        drapelab_core::atomic::write_text(&out.join("drape.obj"), &text)?;
        outputs.push("drape.obj");
    }
    if scene.cloth.is_sewn() {
        crate::mesh_out::write_body_obj(scene, &out.join("body.obj"))?;
        outputs.push("body.obj");
    }
    Ok(())
}

/// Closes the recorders with the final state (when finite) and names their files in `outputs`; a
/// recorder that failed during the solve is dropped (its temporary file with it), not finished.
fn finish_recorders(
    report: &SolveReport,
    x: &[nalgebra::Vector3<f64>],
    (timeline, rrd): Recorders,
    outputs: &mut Vec<&'static str>,
) -> Result<()> {
    if report.stop == StopReason::Observer {
        return Ok(());
    }
    let final_ev = StateEvent {
        index: report.iterations,
        time_s: report.sim_time_s,
        x,
        max_residual_N: report.max_residual_N,
        energy_J: report.energy_J,
        step: None,
    };
    let finite = x.iter().all(|p| p.iter().all(|c| c.is_finite()));
    if let Some(mut t) = timeline {
        t.finish(finite.then_some(&final_ev))?;
        outputs.push("timeline.mcap");
    }
    if let Some(mut r) = rrd {
        r.finish(finite.then_some(&final_ev))?;
        outputs.push("drape.rrd");
    }
    Ok(())
}
