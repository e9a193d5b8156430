//! The engine benchmark: time to equilibrium of a scene at several resolutions with every solver,
//! and each result's largest particle distance to the finest static solution.

use crate::scene::{Scene, SolverKind};
use crate::simulate::solve_scene;
use crate::solve::NoObserver;
use std::time::Instant;

/// One benchmark row.
#[derive(Debug, Clone)]
pub struct BenchRow {
    /// Particles per side.
    pub n: usize,
    /// Solver.
    pub solver: SolverKind,
    /// Solver status.
    pub status: String,
    /// Wall time in s (whole solve including assembly).
    pub wall_time_s: f64,
    /// Iterations or steps.
    pub iterations: usize,
    /// Largest distance to the finest static solution, at the shared grid points, in m.
    pub error_m: f64,
}

/// Solves `scene` at each size with each solver and measures against the finest static solve.
/// Explicit and symplectic Euler run only up to `max_explicit_size`, implicit Euler up to
/// `max_implicit_size` (their step counts grow fast).
/// Every solver stops at the largest residual force `tol` × the lightest particle's weight.
pub fn hang4_rows(
    scene: &Scene,
    sizes: &[usize],
    max_explicit_size: usize,
    max_implicit_size: usize,
    tol: f64,
    mut log: impl FnMut(&str),
) -> Vec<BenchRow> {
    let finest = *sizes.iter().max().unwrap_or(&11);
    let at = |n: usize, kind: SolverKind| {
        let mut s = scene.clone();
        s.cloth.nx = n;
        s.cloth.ny = n;
        s.solver.kind = kind;
        // One force tolerance for every solver; explicit integrators at 0.8 of their stability limit,
        // implicit Euler at a large step.
        s.solver.static_.residual_tol_rel = tol;
        s.solver.dynamic.residual_tol_rel = tol;
        s.solver.dynamic.speed_tol_m_per_s = 1e-5;
        s.solver.dynamic.max_time_s = 1e3;
        match kind {
            SolverKind::ImplicitEuler => s.solver.dynamic.dt_s = 0.01,
            SolverKind::ExplicitEuler | SolverKind::SymplecticEuler => {
                s.solver.dynamic.auto_dt_fraction = 0.8
            }
            SolverKind::Static => {}
        }
        s.record.timeline = false;
        s.record.rerun = false;
        s
    };
    let t0 = Instant::now();
    let mut reference_scene = at(finest, SolverKind::Static);
    reference_scene.solver.static_.residual_tol_rel = 1e-8;
    let reference = solve_scene(&reference_scene, &mut NoObserver);
    log(&format!(
        "reference {finest}×{finest} static: {} in {:.3} s",
        reference.report.status.as_str(),
        t0.elapsed().as_secs_f64()
    ));
    let mut rows = Vec::new();
    for &n in sizes {
        for kind in [
            SolverKind::Static,
            SolverKind::ImplicitEuler,
            SolverKind::SymplecticEuler,
            SolverKind::ExplicitEuler,
        ] {
            let skip = match kind {
                SolverKind::ExplicitEuler | SolverKind::SymplecticEuler => n > max_explicit_size,
                SolverKind::ImplicitEuler => n > max_implicit_size,
                SolverKind::Static => false,
            };
            if skip {
                continue;
            }
            let s = at(n, kind);
            let t = Instant::now();
            let sol = solve_scene(&s, &mut NoObserver);
            let wall = t.elapsed().as_secs_f64();
            // Compare at grid points shared with the reference grid ((finest-1)/(n-1) must be whole).
            let ratio = (finest - 1) / (n - 1);
            let mut err: f64 = 0.0;
            if (finest - 1).is_multiple_of(n - 1) {
                for j in 0..n {
                    for i in 0..n {
                        let d = (sol.at(i, j) - reference.at(i * ratio, j * ratio)).norm();
                        err = err.max(d);
                    }
                }
            } else {
                err = f64::NAN;
            }
            log(&format!(
                "{n}×{n} {:?}: {} {:.4} s",
                kind,
                sol.report.status.as_str(),
                wall
            ));
            rows.push(BenchRow {
                n,
                solver: kind,
                status: sol.report.status.as_str().into(),
                wall_time_s: wall,
                iterations: sol.report.iterations,
                error_m: err,
            });
        }
    }
    rows
}

/// The rows as a Markdown table.
pub fn markdown_table(rows: &[BenchRow]) -> String {
    let mut s = String::from(
        "| particles | solver | status | wall time (ms) | iterations/steps | error vs finest static (m) |\n|---|---|---|---|---|---|\n",
    );
    for r in rows {
        s += &format!(
            "| {n}×{n} | {:?} | {} | {:.3} | {} | {:.2e} |\n",
            r.solver,
            r.status,
            r.wall_time_s * 1e3,
            r.iterations,
            r.error_m,
            n = r.n
        );
    }
    s
}
