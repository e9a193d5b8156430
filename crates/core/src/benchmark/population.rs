//! Seed 000's slack-net population: Latin-hypercube draws of Table 3's box solved from the sagged
//! start or from the calibration's warm-start lattice, each solve's work and time, summarised.

use crate::scene::{Scene, SolverKind};
use crate::simulate::solve_scene;
use crate::solve::NoObserver;
use crate::table::Table;
use serde::{Deserialize, Serialize};
use std::time::Instant;

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
