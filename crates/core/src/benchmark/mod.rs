//! The accuracy–speed benchmark: a scene solved at several resolutions, tolerances and with every
//! solver, each result's wall time, work (iterations or steps, linear solves), peak memory, and its
//! error: the largest distance to the finest static solution at the grid points both share.

mod skips;

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

/// One solve of seed 000's slack-net population.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PopulationRow {
    /// Where Newton started: "sagged" (the sagged start) or "lattice" (the calibration's warm start).
    pub start: String,
    /// Spring stiffness, N/m.
    pub stiffness_N_per_m: f64,
    /// Natural length, m.
    pub natural_length_m: f64,
    /// Topology ("a", "b", "c").
    pub topology: String,
    /// Areal density, kg/m².
    pub areal_density_kg_per_m2: f64,
    /// Solver status.
    pub status: crate::solve::Status,
    /// Newton iterations.
    pub iterations: usize,
    /// Numeric factorizations attempted.
    pub factorizations: usize,
    /// Triangular solves with a factor.
    pub back_substitutions: usize,
    /// Wall time of the solve, s.
    pub wall_time_s: f64,
    /// Wall time of its factorizations and triangular solves alone, s.
    pub factor_time_s: f64,
}

impl Table for PopulationRow {
    const FILE: &'static str = "population.parquet";
    const ROW: &'static str =
        "One Newton solve of seed 000's slack-net calibration population (benchmark stage).";
}

impl PopulationRow {
    /// The row of one solve: where it started, (stiffness N/m, natural length m), topology, areal
    /// density kg/m², and (its report, its wall time in s).
    fn of(
        start: &str,
        (stiffness_N_per_m, natural_length_m): (f64, f64),
        topology: crate::material::Topology,
        areal_density_kg_per_m2: f64,
        (report, wall_time_s): (&crate::solve::SolveReport, f64),
    ) -> Self {
        Self {
            start: start.into(),
            stiffness_N_per_m,
            natural_length_m,
            topology: format!("{topology:?}").to_lowercase(),
            areal_density_kg_per_m2,
            status: report.status,
            iterations: report.iterations,
            factorizations: report.factorizations,
            back_substitutions: report.back_substitutions,
            wall_time_s,
            factor_time_s: report.factor_time_s,
        }
    }
}

/// Seed 000's calibration population: hang4 on the 14 × 14 net solved statically at `samples`
/// points of a Latin hypercube over Table 3's stiffness (500–1200 N/m), natural length (40–60 mm),
/// the three topologies, and Table 2's densities (27.6–58.26 g/m²), seeded by `seed`: what one
/// calibration asks of the solver thousands of times.
pub fn slack_net_population(scene: &Scene, samples: usize, seed: u64) -> Vec<PopulationRow> {
    let design = crate::optim::latin_hypercube(samples, 4, seed);
    (0..samples)
        .map(|k| {
            let u: Vec<f64> = design.iter().map(|axis| axis[k]).collect();
            let mut s = scene.regridded(14, 14);
            let ms = s.material.mass_spring.get_or_insert_with(Default::default);
            ms.stiffness_N_per_m = 500.0 + 700.0 * u[0];
            ms.natural_length_m = Some(0.04 + 0.02 * u[1]);
            ms.topology = match (u[2] * 3.0) as usize {
                0 => crate::material::Topology::A,
                1 => crate::material::Topology::B,
                _ => crate::material::Topology::C,
            };
            s.cloth.areal_density_kg_per_m2 = 0.0276 + (0.05826 - 0.0276) * u[3];
            s.solver.kind = SolverKind::Static;
            s.record.timeline = false;
            s.record.rerun = false;
            let t = Instant::now();
            let sol = solve_scene(&s, &mut NoObserver);
            let ms = s.material.mass_spring.as_ref().expect("set above");
            PopulationRow::of(
                "sagged",
                (
                    ms.stiffness_N_per_m,
                    ms.natural_length_m.unwrap_or(f64::NAN),
                ),
                ms.topology,
                s.cloth.areal_density_kg_per_m2,
                (&sol.report, t.elapsed().as_secs_f64()),
            )
        })
        .collect()
}

/// What a calibration asks of the solver: the 14 × 14 net of `scene` (its density) at `samples`
/// Latin-hypercube points of Table 3's stiffness, natural length and topology, each solved from the
/// drape at the nearest node of the calibration's warm-start lattice
/// ([`crate::calibrate::SharedLattice`]). Returns the rows and the lattice's own solve time in s.
pub fn warm_start_population(
    scene: &Scene,
    samples: usize,
    seed: u64,
) -> (Vec<PopulationRow>, f64) {
    warm_start_population_with(scene, samples, seed, true)
}

/// [`warm_start_population`], each solve from its lattice node's tangent and Hermite predictions
/// (`SharedLattice::starts`) or (`tangent` false) from the node's drape itself.
pub fn warm_start_population_with(
    scene: &Scene,
    samples: usize,
    seed: u64,
    tangent: bool,
) -> (Vec<PopulationRow>, f64) {
    let mut net = scene.regridded(14, 14);
    net.solver.kind = SolverKind::Static;
    net.record.timeline = false;
    net.record.rerun = false;
    let mut problem = crate::calibrate::Problem::new(net.clone(), vec![], 50.0);
    problem.tangent_start = tangent;
    let t = Instant::now();
    problem.drape(&[0.5; 5]);
    let lattice_s = t.elapsed().as_secs_f64();
    let design = crate::optim::latin_hypercube(samples, 3, seed);
    let rows = (0..samples)
        .map(|k| {
            let mut u = vec![0.5; 5];
            for (axis, &dim) in design.iter().zip(&[0usize, 3, 4]) {
                u[dim] = axis[k];
            }
            let p = problem.bounds.decode(&u);
            let t = Instant::now();
            let (sol, _) = problem.drape(&u);
            PopulationRow::of(
                "lattice",
                (p.stiffness_N_per_m, p.natural_length_m),
                p.topology,
                net.cloth.areal_density_kg_per_m2,
                (&sol.report, t.elapsed().as_secs_f64()),
            )
        })
        .collect();
    (rows, lattice_s)
}

/// min / median / max of `v` (NaN for an empty slice).
pub fn min_median_max(v: &[f64]) -> (f64, f64, f64) {
    let mut s: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
    if s.is_empty() {
        return (f64::NAN, f64::NAN, f64::NAN);
    }
    s.sort_by(f64::total_cmp);
    (s[0], crate::measure::median(&s), s[s.len() - 1])
}

/// The population as a Markdown summary: converged count, then min / median / max of iterations,
/// factorizations, wall time and factorization time per solve.
pub fn population_table(rows: &[PopulationRow]) -> String {
    let conv: Vec<&PopulationRow> = rows
        .iter()
        .filter(|r| r.status == crate::solve::Status::Converged)
        .collect();
    let stat = |f: &dyn Fn(&PopulationRow) -> f64| {
        min_median_max(&conv.iter().map(|r| f(r)).collect::<Vec<_>>())
    };
    let mut s = format!(
        "{} of {} solves converged; min / median / max over the converged ones:\n\n| per solve | min | median | max |\n|---|---|---|---|\n",
        conv.len(),
        rows.len()
    );
    type Line<'a> = (&'a str, &'a dyn Fn(&PopulationRow) -> f64, f64);
    let lines: [Line; 5] = [
        ("Newton iterations", &|r| r.iterations as f64, 1.0),
        ("factorizations", &|r| r.factorizations as f64, 1.0),
        ("back-substitutions", &|r| r.back_substitutions as f64, 1.0),
        ("wall time (ms)", &|r| r.wall_time_s, 1e3),
        ("factorization time (ms)", &|r| r.factor_time_s, 1e3),
    ];
    for (name, f, k) in lines {
        let (a, b, c) = stat(f);
        s += &format!("| {name} | {:.3} | {:.3} | {:.3} |\n", a * k, b * k, c * k);
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
