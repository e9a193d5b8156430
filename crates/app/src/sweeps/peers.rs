//! `peers`: a scipy sparse-Newton script, a CHOLMOD (cvxopt) Newton and a numpy explicit-Euler script
//! from `benches/peers/`, run beside drapelab in the same stage so that the ratios hold on a noisy
//! machine.

use crate::job::Job;
use anyhow::{Context, Result, bail};
use drapelab_core::benchmark::bench_scene;
use drapelab_core::scene::{Scene, SolverKind};
use drapelab_core::simulate::solve_scene;
use drapelab_core::solve::NoObserver;
use drapelab_record::{Table, write_table};
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// One comparison of drapelab with an independent implementation (`peers.parquet`).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct PeerRow {
    /// What is compared, e.g. "static Newton: scipy / drapelab".
    pub comparison: String,
    /// Particles per side.
    pub particles_per_side: u64,
    /// The peer's wall time, s.
    pub peer_time_s: f64,
    /// drapelab's wall time, s.
    pub drapelab_time_s: f64,
    /// peer_time_s / drapelab_time_s.
    pub ratio: f64,
    /// The peer's centre height, m (None where the comparison has no solution to compare).
    pub peer_centre_z_m: Option<f64>,
    /// drapelab's centre height, m.
    pub drapelab_centre_z_m: Option<f64>,
}

impl Table for PeerRow {
    const FILE: &'static str = "peers.parquet";
    const ROW: &'static str =
        "One timing of drapelab against an independent Python implementation of the same solve.";
}

/// Parameters of a peers stage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PeersParams {
    /// The Python interpreter (of a virtual environment; numpy and scipy are installed into it when
    /// missing). Default ".venv/bin/python".
    #[serde(default = "default_python")]
    pub python: String,
    /// Sides of the hang4 grid for the static comparison. Default [11, 21, 41].
    #[serde(default = "crate::sweeps::benchmark::default_sizes")]
    pub static_sizes: Vec<usize>,
    /// Sides for the per-step explicit Euler comparison. Default [21, 41].
    #[serde(default = "default_step_sizes")]
    pub explicit_sizes: Vec<usize>,
    /// Explicit steps timed. Default 2000.
    #[serde(default = "default_steps")]
    pub explicit_steps: usize,
}

/// Default of `python`: the interpreter that runs the peer solvers.
pub fn default_python() -> String {
    ".venv/bin/python".into()
}
/// Default of `explicit_sizes`: [21, 41].
pub fn default_step_sizes() -> Vec<usize> {
    vec![21, 41]
}
/// Default of `explicit_steps`: 2000.
pub fn default_steps() -> usize {
    2000
}

/// Runs peer `script` with `args` under `python` in the script's folder; its JSON on stdout.
fn run_peer(
    python: &std::path::Path,
    script: &std::path::Path,
    args: &[String],
) -> Result<serde_json::Value> {
    let o = std::process::Command::new(python)
        .arg(script)
        .args(args)
        .current_dir(script.parent().unwrap_or(std::path::Path::new(".")))
        .output()?;
    if !o.status.success() {
        bail!(
            "{}: {}",
            script.display(),
            String::from_utf8_lossy(&o.stderr)
                .lines()
                .last()
                .unwrap_or("failed")
        );
    }
    Ok(serde_json::from_slice(&o.stdout)?)
}

/// Makes sure `python` (inside a virtual environment) can import numpy, scipy and cvxopt, creating
/// the environment and installing them from PyPI when it cannot.
fn ensure_peer_python(python: &std::path::Path) -> Result<()> {
    let has = |py: &std::path::Path| {
        std::process::Command::new(py)
            .args(["-c", "import numpy, scipy, cvxopt"])
            .output()
            .is_ok_and(|o| o.status.success())
    };
    if has(python) {
        return Ok(());
    }
    let venv = python
        .parent()
        .and_then(|b| b.parent())
        .context("python is not inside a virtual environment")?;
    if !python.exists() {
        std::process::Command::new("python3")
            .args(["-m", "venv"])
            .arg(venv)
            .status()
            .context("python3 -m venv")?;
    }
    let ok = std::process::Command::new(python)
        .args(["-m", "pip", "install", "-q", "numpy", "scipy", "cvxopt"])
        .status()
        .context("pip install numpy scipy cvxopt")?;
    if !ok.success() || !has(python) {
        bail!(
            "{}: cannot install numpy, scipy and cvxopt",
            python.display()
        );
    }
    Ok(())
}

/// The inputs of a peers stage.
pub struct PeersInputs {
    /// The hang4 scene.
    pub scene: PathBuf,
    /// benches/peers/scipy_newton.py.
    pub scipy_newton: PathBuf,
    /// benches/peers/numpy_explicit.py.
    pub numpy_explicit: PathBuf,
    /// benches/peers/cholmod_newton.py (runs when given).
    pub cholmod_newton: Option<PathBuf>,
}

/// Runs the peer solvers beside drapelab's and writes their table.
pub fn run(ctx: &Job<'_, PeersInputs>, p: &PeersParams) -> Result<()> {
    let files = &ctx.inputs;
    let scene = Scene::load(&files.scene, &[])?.scene;
    let newton = std::fs::canonicalize(&files.scipy_newton)?;
    let explicit = std::fs::canonicalize(&files.numpy_explicit)?;
    let cholmod = files
        .cholmod_newton
        .as_ref()
        .map(std::fs::canonicalize)
        .transpose()?;
    let python = std::path::absolute(ctx.root.join(&p.python))?;
    ensure_peer_python(&python)?;
    let run_py = |script: &std::path::Path, args: &[String]| run_peer(&python, script, args);
    let total = p.static_sizes.len() + p.explicit_sizes.len();
    ctx.started(total);
    // (comparison, n, peer time, drapelab time, peer centre z, drapelab centre z)
    let mut rows: Vec<(&str, usize, f64, f64, f64, f64)> = Vec::new();
    for &n in &p.static_sizes {
        let peer = run_py(&newton, &[n.to_string(), "1e-6".into()])?;
        let s = bench_scene(&scene, n, SolverKind::Static, 1e-6);
        let sol = solve_scene(&s, &mut NoObserver);
        // A static peer's row: its time and centre height against this solve's.
        let static_row = |label, peer: &serde_json::Value| {
            (
                label,
                n,
                peer["wall_time_s"].as_f64().unwrap_or(f64::NAN),
                sol.report.wall_time_s,
                peer["centre_z_m"].as_f64().unwrap_or(f64::NAN),
                sol.at(n / 2, n / 2).z,
            )
        };
        rows.push(static_row("static: scipy sparse Newton / drapelab", &peer));
        if let Some(script) = &cholmod {
            let peer = run_py(script, &[n.to_string(), "1e-6".into()])?;
            rows.push(static_row(
                "static: CHOLMOD (cvxopt) Newton / drapelab",
                &peer,
            ));
        }
        ctx.item_done();
    }
    for &n in &p.explicit_sizes {
        let peer = run_py(&explicit, &[n.to_string(), p.explicit_steps.to_string()])?;
        let s = fixed_steps(
            bench_scene(&scene, n, SolverKind::ExplicitEuler, 1e-30),
            p.explicit_steps,
        )?;
        let sol = solve_scene(&s, &mut NoObserver);
        let steps = sol.report.iterations.max(1) as f64;
        rows.push((
            "explicit Euler per step: numpy / drapelab",
            n,
            peer["per_step_s"].as_f64().unwrap_or(f64::NAN),
            sol.report.wall_time_s / steps,
            f64::NAN,
            f64::NAN,
        ));
        ctx.item_done();
    }
    let opt = |v: f64| v.is_finite().then_some(v);
    let rows: Vec<PeerRow> = rows
        .into_iter()
        .map(|r| PeerRow {
            comparison: r.0.to_string(),
            particles_per_side: r.1 as u64,
            peer_time_s: r.2,
            drapelab_time_s: r.3,
            ratio: r.2 / r.3,
            peer_centre_z_m: opt(r.4),
            drapelab_centre_z_m: opt(r.5),
        })
        .collect();
    write_table(ctx.output("table")?, &rows)
}

/// An explicit scene that takes `steps` steps at half its stability limit: it stops by time, not
/// by convergence.
fn fixed_steps(mut s: Scene, steps: usize) -> Result<Scene> {
    let built = drapelab_core::build::build_scene(&s.clone().validated()?);
    let dt = 0.5
        * drapelab_core::solve::stability_limit_dt(
            &built.model,
            &built.x0,
            drapelab_core::solve::Integrator::ExplicitEuler,
            built.model.damping_Ns_per_m,
        )
        .unwrap_or(1e-4);
    s.solver.dynamic.auto_dt_fraction = 0.0;
    s.solver.dynamic.dt_s = dt;
    s.solver.dynamic.max_time_s = dt * steps as f64;
    Ok(s)
}
