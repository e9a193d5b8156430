//! The accuracy–speed benchmark: a scene solved at several resolutions, tolerances and with every
//! solver, each result's wall time, work (iterations or steps, linear solves), peak memory, and its
//! error: the largest distance to the finest static solution at the grid points both share.

mod population;
mod skips;

pub use population::{
    PopulationRow, min_median_max, population_table, slack_net_population, warm_start_population,
    warm_start_population_with,
};
pub use skips::{SkipRow, skip_cost_cache, skip_second_thread, skip_symmetry, skip_unneeded_terms};

use crate::scene::{Scene, SolverKind};
use crate::simulate::solve_scene;
use crate::solve::NoObserver;
use crate::table::Table;
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// One benchmark point.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct BenchRow {
    /// Scene name.
    pub scene: String,
    /// Particles per side.
    #[serde(rename = "particles_per_side")]
    pub n: usize,
    /// Solver.
    pub solver: SolverKind,
    /// Force tolerance: largest residual force / lightest particle's weight.
    #[serde(rename = "tolerance_rel")]
    pub tol: f64,
    /// Solver status.
    pub status: crate::solve::Status,
    /// Wall time in s (whole solve including assembly).
    pub wall_time_s: f64,
    /// Newton iterations or time steps.
    pub iterations: usize,
    /// Linear solves (factorizations or CG solves).
    pub linear_solves: usize,
    /// Numeric factorizations attempted (failed ones on an indefinite matrix included).
    pub factorizations: usize,
    /// Triangular solves with a factor (back-substitutions).
    pub back_substitutions: usize,
    /// Wall time of the factorizations and triangular solves alone, s.
    pub factor_time_s: f64,
    /// Simulated time a dynamic point reached (its settle time when converged), s; None for static.
    pub sim_time_s: Option<f64>,
    /// Largest distance to the reference (the finest static solution at the shared grid points, or
    /// the exact elastica), in m (None when the grids share no points or the solve did not converge).
    pub error_m: Option<f64>,
    /// Peak resident memory of the process during the point, bytes (Linux; None elsewhere).
    pub peak_rss_bytes: Option<u64>,
    /// The scene's `contact.self` for this point: "auto", "on" or "off".
    pub self_contact: crate::scene::SelfContactMode,
    /// Wall time spent in self-contact (broad phase, collision detection, energy), s; 0 when the
    /// solve did not model it.
    pub self_contact_time_s: f64,
    /// Self-contact pairs within the activation distance at the end.
    pub self_contact_pairs: usize,
    /// Mesh edges of the final state that cross a triangle of the sheet (segment–triangle tests).
    pub crossing_edges: usize,
}

impl Table for BenchRow {
    const FILE: &'static str = "bench.parquet";
    const ROW: &'static str =
        "One solve of the accuracy–speed benchmark: scene × size × tolerance × solver.";
}

/// Which solvers run up to which size.
#[derive(Debug, Clone, PartialEq)]
pub struct BenchLimits {
    /// The solvers to run.
    pub solvers: Vec<SolverKind>,
    /// Largest side for explicit and symplectic Euler (their step counts grow as (ω_max/ω_min)²).
    pub max_explicit_size: usize,
    /// Largest side for implicit Euler.
    pub max_implicit_size: usize,
    /// Measure errors against the exact heavy elastica (a strip clamped at x-min) instead of the
    /// finest static solution.
    pub exact_elastica: bool,
    /// Wall-clock budget of one dynamic point in s (it ends as max-iterations past it); None: no cap.
    pub max_wall_time_s: Option<f64>,
    /// The `contact.self` settings each point is solved with (one row each).
    pub self_contact: Vec<crate::scene::SelfContactMode>,
}

/// What a benchmark point's error is measured against.
enum Reference {
    /// The static solution at the finest size and a tight tolerance.
    FinestStatic(Box<crate::simulate::Solution>),
    /// The exact elastica of a cantilever strip.
    Elastica(crate::elastica::HeavyElastica),
}

/// Every solver, cheapest first.
pub const ALL_SOLVERS: [SolverKind; 4] = [
    SolverKind::Static,
    SolverKind::ImplicitEuler,
    SolverKind::SymplecticEuler,
    SolverKind::ExplicitEuler,
];

/// Resets the peak-RSS counter of this process (Linux: `5` into /proc/self/clear_refs).
fn reset_peak_rss() {
    let _ = std::fs::write("/proc/self/clear_refs", "5");
}

/// Peak resident memory since the last reset, bytes (Linux: VmHWM of /proc/self/status).
fn peak_rss_bytes() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// The scene at side `n` with solver `kind` stopping at force tolerance `tol`: explicit integrators
/// at 0.8 of their stability limit within 5 s of simulated time, implicit Euler from a 10 ms step
/// (adaptive) within 1e5 s (seed 000's overdamped sheets creep for hundreds of seconds); Baraff–Witkin
/// at 10 ms steps within 5 s; particles named by index moved with the grid ([`Scene::regridded`]).
pub fn bench_scene(scene: &Scene, n: usize, kind: SolverKind, tol: f64) -> Scene {
    let (nx0, ny0) = (scene.cloth.nx, scene.cloth.ny);
    // Keep the aspect: a strip keeps its particle count across.
    let ny = if ny0 == nx0 {
        n
    } else {
        nx0.min(ny0)
            .max(((n - 1) * (ny0 - 1)).div_ceil(nx0 - 1) + 1)
    };
    let mut s = scene.regridded(n, ny);
    s.solver.kind = kind;
    s.solver.static_.residual_tol_rel = tol;
    s.solver.dynamic.residual_tol_rel = tol;
    s.solver.dynamic.speed_tol_m_per_s = 1e-5;
    // 5 s of simulated time: enough for hang4 to settle to 1e-6 at 21 a side (3.3 s); a tolerance below
    // the integrator's round-off floor then ends as max-iterations instead of running for hours.
    s.solver.dynamic.max_time_s = 5.0;
    match kind {
        SolverKind::ImplicitEuler => {
            s.solver.dynamic.dt_s = 0.01;
            s.solver.dynamic.max_time_s = 1e5;
        }
        SolverKind::BaraffWitkin => s.solver.dynamic.dt_s = 0.01,
        SolverKind::ExplicitEuler | SolverKind::SymplecticEuler => {
            s.solver.dynamic.auto_dt_fraction = 0.8
        }
        SolverKind::Static => {}
    }
    s.record.timeline = false;
    s.record.rerun = false;
    s
}

/// Solves `scene` at each size, tolerance and solver (within `limits`), and measures each against the
/// static solution at the finest size and a tolerance 100 times below the tightest (the tightest
/// itself when that one does not converge), or the exact elastica when `limits.exact_elastica`.
pub fn bench_rows(
    scene: &Scene,
    sizes: &[usize],
    tols: &[f64],
    limits: &BenchLimits,
    mut log: impl FnMut(&str),
) -> Vec<BenchRow> {
    let finest = *sizes.iter().max().unwrap_or(&11);
    let tightest = tols.iter().copied().fold(1e-6, f64::min);
    let t0 = Instant::now();
    let reference = match limits
        .exact_elastica
        .then(|| crate::elastica::HeavyElastica::of_cantilever(scene))
        .flatten()
    {
        Some(e) => {
            log(&format!("{}: reference: the exact elastica", scene.name));
            Reference::Elastica(e)
        }
        None => {
            // 100 times below the tightest tolerance; where round-off forbids that, the tightest.
            let mut r = solve_scene(
                &bench_scene(scene, finest, SolverKind::Static, tightest * 1e-2),
                &mut NoObserver,
            );
            if !r.report.is_converged() {
                r = solve_scene(
                    &bench_scene(scene, finest, SolverKind::Static, tightest),
                    &mut NoObserver,
                );
            }
            log(&format!(
                "{}: reference {finest} static: {} in {:.3} s",
                scene.name,
                r.report.status.as_str(),
                t0.elapsed().as_secs_f64()
            ));
            Reference::FinestStatic(Box::new(r))
        }
    };
    let mut rows = Vec::new();
    for &n in sizes {
        for &tol in tols {
            for &kind in &limits.solvers {
                let skip = match kind {
                    SolverKind::ExplicitEuler | SolverKind::SymplecticEuler => {
                        n > limits.max_explicit_size
                    }
                    SolverKind::ImplicitEuler | SolverKind::BaraffWitkin => {
                        n > limits.max_implicit_size
                    }
                    SolverKind::Static => false,
                };
                if skip {
                    continue;
                }
                for &mode in &limits.self_contact {
                    let mut s = bench_scene(scene, n, kind, tol);
                    s.solver.dynamic.max_wall_time_s = limits.max_wall_time_s;
                    s.contact.self_contact = mode;
                    rows.push(bench_point(&s, &reference, &mut log));
                }
            }
        }
    }
    rows
}

/// One point of [`bench_rows`]: `s` solved, timed and measured against `reference`.
fn bench_point(s: &Scene, reference: &Reference, log: &mut impl FnMut(&str)) -> BenchRow {
    let (n, kind, tol) = (s.cloth.nx, s.solver.kind, s.solver.static_.residual_tol_rel);
    reset_peak_rss();
    let t = Instant::now();
    let sol = solve_scene(s, &mut NoObserver);
    let wall = t.elapsed().as_secs_f64();
    let peak = peak_rss_bytes();
    let error_m = match reference {
        Reference::FinestStatic(r) => distance_to(&sol, r),
        Reference::Elastica(e) => e.distance(&sol),
    };
    log(&format!(
        "{} {n} tol {tol:.0e} {kind:?} self {:?}: {} {wall:.4} s, error {error_m:.2e} m",
        s.name,
        s.contact.self_contact,
        sol.report.status.as_str(),
    ));
    let sc =
        (!sol.x.is_empty()).then(|| crate::simulate::self_contact_summary(s, &sol.model, &sol.x));
    BenchRow {
        scene: s.name.clone(),
        n,
        solver: kind,
        tol,
        status: sol.report.status,
        wall_time_s: wall,
        iterations: sol.report.iterations,
        linear_solves: sol.report.linear_solves,
        factorizations: sol.report.factorizations,
        back_substitutions: sol.report.back_substitutions,
        factor_time_s: sol.report.factor_time_s,
        sim_time_s: sol.report.sim_time_s,
        error_m: error_m.is_finite().then_some(error_m),
        peak_rss_bytes: peak,
        self_contact: s.contact.self_contact,
        self_contact_time_s: sc.as_ref().map_or(0.0, |c| c.time_s),
        self_contact_pairs: sc.as_ref().map_or(0, |c| c.active_pairs),
        crossing_edges: sc.as_ref().map_or(0, |c| c.crossing_edges),
    }
}

/// Largest distance between `sol` and `reference` at the grid points they share (the coarse grid's
/// lines must fall on the fine grid's); NaN when they share none or either did not converge.
pub fn distance_to(sol: &crate::simulate::Solution, reference: &crate::simulate::Solution) -> f64 {
    if !sol.report.is_converged() || !reference.report.is_converged() {
        return f64::NAN;
    }
    let (g, r) = (&sol.grid, &reference.grid);
    if g.nx < 2 || g.ny < 2 {
        return f64::NAN;
    }
    if !(r.nx - 1).is_multiple_of(g.nx - 1) || !(r.ny - 1).is_multiple_of(g.ny - 1) {
        return f64::NAN;
    }
    let (sx, sy) = ((r.nx - 1) / (g.nx - 1), (r.ny - 1) / (g.ny - 1));
    let mut err: f64 = 0.0;
    for j in 0..g.ny {
        for i in 0..g.nx {
            err = err.max((sol.at(i, j) - reference.at(i * sx, j * sy)).norm());
        }
    }
    err
}

/// The hang4 table of `drapelab bench` and `cargo bench`: every solver at tolerance `tol`.
pub fn hang4_rows(
    scene: &Scene,
    sizes: &[usize],
    max_explicit_size: usize,
    max_implicit_size: usize,
    tol: f64,
    log: impl FnMut(&str),
) -> Vec<BenchRow> {
    bench_rows(
        scene,
        sizes,
        &[tol],
        &BenchLimits {
            solvers: ALL_SOLVERS.to_vec(),
            max_explicit_size,
            max_implicit_size,
            exact_elastica: false,
            max_wall_time_s: None,
            self_contact: vec![crate::scene::SelfContactMode::Auto],
        },
        log,
    )
}

/// The rows as a Markdown table.
pub fn markdown_table(rows: &[BenchRow]) -> String {
    let mut s = String::from(
        "| scene | particles | solver | tolerance | status | wall time (ms) | iterations/steps | linear solves | factorizations | back-substitutions | factorization time (ms) | error vs finest static (m) | peak RSS (MB) | self-contact | self-contact time (ms) | crossing edges |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        s += &format!(
            "| {} | {n}×{n} | {:?} | {:.0e} | {} | {:.3} | {} | {} | {} | {} | {:.3} | {:.2e} | {} | {:?} | {:.3} | {} |\n",
            r.scene,
            r.solver,
            r.tol,
            r.status,
            r.wall_time_s * 1e3,
            r.iterations,
            r.linear_solves,
            r.factorizations,
            r.back_substitutions,
            r.factor_time_s * 1e3,
            r.error_m.unwrap_or(f64::NAN),
            r.peak_rss_bytes
                .map_or("–".into(), |b| format!("{:.1}", b as f64 / 1e6)),
            r.self_contact,
            r.self_contact_time_s * 1e3,
            r.crossing_edges,
            n = r.n
        );
    }
    s
}

/// Least-squares slope of log(y) against log(x) over the pairs with both positive: the exponent p
/// of y ∝ x^p.
pub fn fitted_exponent(points: &[(f64, f64)]) -> Option<f64> {
    let pts: Vec<(f64, f64)> = points
        .iter()
        .filter(|(x, y)| *x > 0.0 && *y > 0.0 && x.is_finite() && y.is_finite())
        .map(|(x, y)| (x.ln(), y.ln()))
        .collect();
    if pts.len() < 2 {
        return None;
    }
    let n = pts.len() as f64;
    let (mx, my) = (
        pts.iter().map(|p| p.0).sum::<f64>() / n,
        pts.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

/// The Pareto front of (time, error) points: those no other point beats in both, sorted by time.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut pts: Vec<(f64, f64)> = points
        .iter()
        .copied()
        .filter(|(t, e)| t.is_finite() && e.is_finite())
        .collect();
    pts.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    let mut front: Vec<(f64, f64)> = Vec::new();
    for p in pts {
        if front.last().is_none_or(|l| p.1 < l.1) {
            front.push(p);
        }
    }
    front
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fitted_exponent_of_a_power_law_is_its_power() {
        let pts: Vec<(f64, f64)> = [10.0, 20.0, 40.0, 80.0]
            .iter()
            .map(|&x: &f64| (x, 3.0 * x.powf(1.5)))
            .collect();
        assert!((fitted_exponent(&pts).unwrap() - 1.5).abs() < 1e-12);
    }

    #[test]
    fn the_pareto_front_keeps_only_undominated_points() {
        let pts = [(1.0, 5.0), (2.0, 3.0), (3.0, 4.0), (4.0, 1.0), (0.5, 9.0)];
        assert_eq!(
            pareto_front(&pts),
            vec![(0.5, 9.0), (1.0, 5.0), (2.0, 3.0), (4.0, 1.0)]
        );
    }
}
