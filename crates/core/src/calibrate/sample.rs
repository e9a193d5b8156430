//! The calibration of one sample (seed 000 §3): independent ICA runs over Table 3's box against the
//! sample's measured edges, the best run polished by Nelder–Mead, each parameter's identifiability,
//! Eq. 5 of the best drape, and (optionally) a CMA-ES run at each ICA run's budget as the baseline.
//! Observers see every decade and may fail (argmin's habit); the caller writes the tables.

use super::{Evaluation, Identifiability, Noise, Params, Problem, identifiability};
use crate::edges::{EdgeFit, eq5_objective_pct};
use crate::optim::{Cmaes, DecadeEvent, Ica, IcaSettings, Minimizer};
use anyhow::Result;
use std::sync::atomic::Ordering;

/// How one sample is calibrated.
#[derive(Debug, Clone)]
pub struct SampleSettings {
    /// Independent ICA runs (seeds `ica.seed`, `ica.seed + 1`, …).
    pub runs: usize,
    /// ICA's settings.
    pub ica: IcaSettings,
    /// Side of the sample, cm (normalises the costs).
    pub side_cm: f64,
    /// Nelder–Mead iterations polishing the best ICA optimum (0: ICA alone).
    pub polish_iterations: u64,
    /// The photos' measurement error for the identifiability analysis.
    pub noise: Noise,
    /// Identifiable when pinned to within this fraction of the value.
    pub identifiable_rel: f64,
    /// Half-width of the identifiability window, as a fraction of Table 3's range.
    pub identifiability_window: f64,
    /// Run CMA-ES at each ICA run's budget as a baseline.
    pub baseline_cmaes: bool,
    /// Calibrate by gradients too ([`Problem::run_lm`]), once, as a third optimizer.
    pub levenberg_marquardt: bool,
}

/// One country of one decade of one run.
#[derive(Debug, Clone)]
pub struct EvaluatedCountry {
    /// Run number (0-based).
    pub run: u32,
    /// Decade (0 = the initial empires).
    pub decade: u32,
    /// Its empire.
    pub empire: u32,
    /// Cost, % of the side.
    pub cost_pct: f64,
    /// The parameters it stands for.
    pub params: Params,
    /// Its simulation, when the cost came from one.
    pub evaluation: Option<Evaluation>,
}

/// One optimiser run's best cost (ICA or the CMA-ES baseline).
#[derive(Debug, Clone)]
pub struct OptimizerRun {
    /// "ica", "cma-es" or "levenberg-marquardt".
    pub optimizer: &'static str,
    /// Run number.
    pub run: u32,
    /// Cost evaluations spent.
    pub evaluations: u64,
    /// Best cost, % of the side.
    pub best_cost_pct: f64,
    /// Levenberg–Marquardt's estimate with its 2σ half-widths from JᵀJ: (stiffness N/m, ±),
    /// (natural length m, ±); None for the other optimizers.
    pub estimate: Option<[(f64, Option<f64>); 2]>,
}

/// What the calibration of one sample found.
#[derive(Debug, Clone)]
pub struct SampleCalibration {
    /// The polished optimum.
    pub best: Params,
    /// Its cost (curve distance, % of the side).
    pub curve_pct: f64,
    /// The best ICA run's cost before polishing.
    pub ica_curve_pct: f64,
    /// Mean Eq. 5 over the edges of the best drape, %.
    pub eq5_pct: f64,
    /// Standard deviation of the runs' best costs.
    pub spread_pct: f64,
    /// Simulations run (cached look-ups not counted).
    pub simulations: usize,
    /// Simulations that did not converge.
    pub failures: usize,
    /// Each parameter's identifiability (stiffness, damping, elongation rate, natural length, topology).
    pub identifiability: Vec<Identifiability>,
    /// Every run of every optimiser.
    pub runs: Vec<OptimizerRun>,
    /// Every country of every decade of every ICA run.
    pub evaluations: Vec<EvaluatedCountry>,
}

/// Calibrates one sample. `observe(run, decade)` sees every decade of every ICA run; its first
/// error stops the calibration. `run_done()` is called after each run.
pub fn calibrate_sample(
    problem: &Problem,
    measured: &[EdgeFit],
    s: &SampleSettings,
    observe: &mut dyn FnMut(usize, &DecadeEvent<'_>) -> Result<()>,
    run_done: &dyn Fn(),
) -> Result<SampleCalibration> {
    let mut best: Option<(f64, Vec<f64>)> = None;
    let mut costs = Vec::new();
    let mut runs = Vec::new();
    let mut evaluations = Vec::new();
    for r in 0..s.runs {
        let settings = IcaSettings {
            seed: s.ica.seed + r as u64,
            ..s.ica.clone()
        };
        let mut observer_error: Option<anyhow::Error> = None;
        let report = Ica { settings, dim: 5 }.run(&|u: &[f64]| problem.cost(u), |ev| {
            record_decade(problem, r, ev, &mut evaluations);
            if observer_error.is_none() {
                observer_error = observe(r, ev).err();
            }
        });
        if let Some(e) = observer_error {
            return Err(e);
        }
        costs.push(report.best_cost);
        runs.push(OptimizerRun {
            optimizer: "ica",
            run: r as u32,
            evaluations: report.evaluations as u64,
            best_cost_pct: report.best_cost,
            estimate: None,
        });
        if s.baseline_cmaes {
            runs.push(cmaes_baseline(
                problem,
                report.evaluations,
                s.ica.seed + r as u64,
                r,
            ));
        }
        if best.as_ref().is_none_or(|b| report.best_cost < b.0) {
            best = Some((report.best_cost, report.best_x.clone()));
        }
        run_done();
    }
    if s.levenberg_marquardt {
        runs.push(levenberg_marquardt_run(problem));
    }
    let (ica_cost, ica_u) = best.ok_or_else(|| anyhow::anyhow!("no ICA run (runs = 0)"))?;
    let (u, cost) = problem.polish(&ica_u, s.polish_iterations);
    let mean = costs.iter().sum::<f64>() / costs.len() as f64;
    let spread =
        (costs.iter().map(|c| (c - mean).powi(2)).sum::<f64>() / costs.len() as f64).sqrt();
    let ident = identifiability(
        problem,
        &u,
        s.identifiability_window,
        7,
        s.noise,
        s.identifiable_rel,
    );
    Ok(SampleCalibration {
        best: problem.bounds.decode(&u),
        curve_pct: cost,
        ica_curve_pct: ica_cost,
        eq5_pct: mean_eq5_pct(problem, &u, measured, s.side_cm),
        spread_pct: spread,
        simulations: problem.simulations.load(Ordering::Relaxed),
        failures: problem.failures.load(Ordering::Relaxed),
        identifiability: ident,
        runs,
        evaluations,
    })
}

/// Every country of a decade `ev` of ICA run `r`, with its cost and the evaluation behind it.
fn record_decade(
    problem: &Problem,
    r: usize,
    ev: &DecadeEvent<'_>,
    evaluations: &mut Vec<EvaluatedCountry>,
) {
    for (k, e) in ev.empires.iter().enumerate() {
        for c in std::iter::once(&e.imperialist).chain(&e.colonies) {
            evaluations.push(EvaluatedCountry {
                run: r as u32,
                decade: ev.decade as u32,
                empire: k as u32,
                cost_pct: c.cost,
                params: problem.bounds.decode(&c.x),
                evaluation: problem.lookup(&c.x),
            });
        }
    }
}

/// CMA-ES with ICA run `r`'s budget on a fresh cache (a baseline for the comparison table).
fn cmaes_baseline(problem: &Problem, budget: usize, seed: u64, r: usize) -> OptimizerRun {
    let fresh = problem.fresh();
    let cm = Cmaes {
        dim: 5,
        budget,
        seed,
    }
    .minimize(&|u: &[f64]| fresh.cost(u), None);
    OptimizerRun {
        optimizer: "cma-es",
        run: r as u32,
        evaluations: cm.evaluations as u64,
        best_cost_pct: cm.best_cost,
        estimate: None,
    }
}

/// The calibration by gradients ([`Problem::run_lm`]) as one optimizer run: on its own problem
/// (counters and cache) over the same warm-start lattice, which ICA's runs have solved already.
fn levenberg_marquardt_run(problem: &Problem) -> OptimizerRun {
    let lm = problem.fresh().run_lm(&super::LmSettings::default());
    OptimizerRun {
        optimizer: "levenberg-marquardt",
        run: 0,
        evaluations: lm.solves as u64,
        best_cost_pct: lm.best_cost_pct,
        estimate: Some([
            (lm.best.stiffness_N_per_m, lm.half_width_2sigma[0]),
            (lm.best.natural_length_m, lm.half_width_2sigma[1]),
        ]),
    }
}

/// Mean Eq. 5 (seed 000) of the drape at `u` against the measured edges, %.
fn mean_eq5_pct(problem: &Problem, u: &[f64], measured: &[EdgeFit], side_cm: f64) -> f64 {
    let sim: Vec<EdgeFit> = problem.drape(u).1.unwrap_or_default();
    let eq5: Vec<f64> = measured
        .iter()
        .filter_map(|m| {
            sim.iter()
                .find(|s| s.edge == m.edge)
                .map(|s| eq5_objective_pct(m, s, side_cm))
        })
        .collect();
    eq5.iter().sum::<f64>() / eq5.len().max(1) as f64
}
