//! The tables a `calibrate` stage writes (seed 000 §3–4), each row type its schema: `results.parquet`
//! (read back by `validate`), `comparison.parquet` and `evaluations.parquet`.

use drapelab_core::calibrate::{EvaluatedCountry, OptimizerRun, SampleCalibration};
use drapelab_core::material::Topology;
use drapelab_core::table::Table;
use serde::{Deserialize, Serialize};

/// One calibrated sample: the best parameters of its runs, their spread, and what the photos pin down.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ResultRow {
    /// Sample name (of the measured edges table).
    pub sample: String,
    /// Mean seed 000 Eq. 5 over the edges of the best drape, %.
    pub objective_pct: f64,
    /// RMS vertical distance between simulated and measured edges at the optimum, % of the side.
    pub curve_distance_pct: f64,
    /// The same before the Nelder–Mead polish (ICA's best), % of the side.
    pub ica_curve_distance_pct: f64,
    /// Spring stiffness, N/m.
    pub stiffness_N_per_m: f64,
    /// Damping, N·s/m.
    pub damping_Ns_per_m: f64,
    /// Elongation rate (seed 000 Table 3), dimensionless.
    pub elongation_rate: f64,
    /// Natural spring length, m.
    pub natural_length_m: f64,
    /// Spring topology (a, b or c; seed 000 Fig. 1).
    pub topology: Topology,
    /// Independent ICA runs.
    pub runs: u32,
    /// Standard deviation of the runs' best curve distances, % of the side.
    pub spread_curve_distance_pct: f64,
    /// Simulations run (cached look-ups not counted).
    pub simulations: u64,
    /// Simulations that did not converge (costed as failures, never as results).
    pub failed_simulations: u64,
    /// Whether the photos pin the stiffness down.
    pub identifiable_stiffness: bool,
    /// Whether the photos pin the damping down.
    pub identifiable_damping: bool,
    /// Whether the photos pin the elongation rate down.
    pub identifiable_elongation_rate: bool,
    /// Whether the photos pin the natural length down.
    pub identifiable_natural_length: bool,
    /// Whether the photos pin the topology down.
    pub identifiable_topology: bool,
    /// Half-width of the stiffness interval the photos allow, N/m (None where the cost is flat).
    pub stiffness_uncertainty_N_per_m: Option<f64>,
    /// Half-width of the damping interval, N·s/m.
    pub damping_uncertainty_Ns_per_m: Option<f64>,
    /// Half-width of the elongation-rate interval.
    pub elongation_rate_uncertainty: Option<f64>,
    /// Half-width of the natural-length interval, m.
    pub natural_length_uncertainty_m: Option<f64>,
}

impl Table for ResultRow {
    const FILE: &'static str = "results.parquet";
    const ROW: &'static str =
        "One sample calibrated by ICA against its 4-corner edges (seed 000 §3, Table 4).";
}

impl ResultRow {
    /// The row of one sample's calibration over `runs` runs.
    pub fn new(sample: &str, c: &SampleCalibration, runs: usize) -> Self {
        let id = |k: usize| c.identifiability.get(k).is_some_and(|i| i.identifiable);
        let u = |k: usize| {
            c.identifiability
                .get(k)
                .map(|i| i.uncertainty)
                .filter(|u| u.is_finite())
        };
        ResultRow {
            sample: sample.to_string(),
            objective_pct: c.eq5_pct,
            curve_distance_pct: c.curve_pct,
            ica_curve_distance_pct: c.ica_curve_pct,
            stiffness_N_per_m: c.best.stiffness_N_per_m,
            damping_Ns_per_m: c.best.damping_Ns_per_m,
            elongation_rate: c.best.elongation_rate,
            natural_length_m: c.best.natural_length_m,
            topology: c.best.topology,
            runs: runs as u32,
            spread_curve_distance_pct: c.spread_pct,
            simulations: c.simulations as u64,
            failed_simulations: c.failures as u64,
            identifiable_stiffness: id(0),
            identifiable_damping: id(1),
            identifiable_elongation_rate: id(2),
            identifiable_natural_length: id(3),
            identifiable_topology: id(4),
            stiffness_uncertainty_N_per_m: u(0),
            damping_uncertainty_Ns_per_m: u(1),
            elongation_rate_uncertainty: u(2),
            natural_length_uncertainty_m: u(3),
        }
    }
}

/// One optimiser run's best cost: ICA against the CMA-ES baseline.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ComparisonRow {
    /// Sample name.
    pub sample: String,
    /// "ica", "cma-es" (the baseline at ICA's budget) or "levenberg-marquardt" (calibration by
    /// gradients; its evaluations are equilibrium solves).
    pub optimizer: String,
    /// Run number.
    pub run: u32,
    /// Cost evaluations spent.
    pub evaluations: u64,
    /// Best cost, % of the side.
    pub best_cost_pct: f64,
    /// Levenberg–Marquardt's stiffness, N/m (null for the other optimizers).
    pub stiffness_N_per_m: Option<f64>,
    /// Its 2σ half-width from JᵀJ (residuals taken as independent), N/m.
    pub stiffness_2sigma_N_per_m: Option<f64>,
    /// Levenberg–Marquardt's natural length, m.
    pub natural_length_m: Option<f64>,
    /// Its 2σ half-width from JᵀJ, m.
    pub natural_length_2sigma_m: Option<f64>,
}

impl Table for ComparisonRow {
    const FILE: &'static str = "comparison.parquet";
    const ROW: &'static str = "One optimiser run's best cost on one sample (ICA, the CMA-ES baseline or Levenberg–Marquardt).";
}

impl ComparisonRow {
    /// The row of one run on `sample`.
    pub fn new(sample: &str, r: &OptimizerRun) -> Self {
        ComparisonRow {
            sample: sample.to_string(),
            optimizer: r.optimizer.to_string(),
            run: r.run,
            evaluations: r.evaluations,
            best_cost_pct: r.best_cost_pct,
            stiffness_N_per_m: r.estimate.map(|e| e[0].0),
            stiffness_2sigma_N_per_m: r.estimate.and_then(|e| e[0].1),
            natural_length_m: r.estimate.map(|e| e[1].0),
            natural_length_2sigma_m: r.estimate.and_then(|e| e[1].1),
        }
    }
}

/// One country of one ICA decade: where it stood and what it cost.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct EvaluationRow {
    /// Sample name.
    pub sample: String,
    /// Run number (0-based).
    pub run: u32,
    /// Decade (0 = the initial empires).
    pub decade: u32,
    /// Its empire.
    pub empire: u32,
    /// Cost, % of the side.
    pub cost_pct: f64,
    /// Spring stiffness, N/m.
    pub stiffness_N_per_m: f64,
    /// Natural spring length, m.
    pub natural_length_m: f64,
    /// Spring topology (a, b or c).
    pub topology: Topology,
    /// Status of its simulation (None when the cost did not come from one).
    pub solver_status: Option<String>,
    /// Simulated time of its simulation, s.
    pub simulation_time_s: Option<f64>,
}

impl Table for EvaluationRow {
    const FILE: &'static str = "evaluations.parquet";
    const ROW: &'static str = "One country of one ICA decade of one run (seed 000 §3.2).";
}

impl EvaluationRow {
    /// The row of one evaluated country of `sample`.
    pub fn new(sample: &str, e: &EvaluatedCountry) -> Self {
        EvaluationRow {
            sample: sample.to_string(),
            run: e.run,
            decade: e.decade,
            empire: e.empire,
            cost_pct: e.cost_pct,
            stiffness_N_per_m: e.params.stiffness_N_per_m,
            natural_length_m: e.params.natural_length_m,
            topology: e.params.topology,
            solver_status: e.evaluation.map(|v| v.status.to_string()),
            simulation_time_s: e.evaluation.map(|v| v.simulation_time_s),
        }
    }
}
