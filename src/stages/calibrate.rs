//! `calibrate`: for each sample of a fit-edges table, ICA runs over Table 3's box against the sample's
//! measured 4-corner edges (the scene input with the sample's Table 2 density); the best run is kept.
//! Writes `results.parquet` (one row per sample, with the runs' spread and each parameter's
//! identifiability) and `evaluations.parquet` (every country of every decade of every run).

use super::StageContext;
use crate::calibrate::{Noise, Problem, identifiability, sample_scene};
use crate::edges::{EdgeFit, eq5_objective_pct, read_edges};
use crate::io::write_parquet;
use crate::optim::IcaSettings;
use anyhow::{Context, Result, bail};
use arrow::array::{
    ArrayRef, BooleanArray, Float64Array, RecordBatch, StringArray, UInt32Array, UInt64Array,
};
use arrow::datatypes::{DataType, Field, Schema};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::sync::Arc;

/// Parameters of a calibrate stage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CalibrateParams {
    /// Independent ICA runs per sample (seeds seed, seed+1, ...). Default 10 (seed 000).
    #[serde(default = "default_runs")]
    pub runs: usize,
    /// ICA settings (seed is the first run's); or give `ica_from`.
    #[serde(default)]
    pub ica: Option<IcaSettings>,
    /// A JSON file of ICA settings among the inputs (a tune stage's `best_ica.json`), instead of `ica`.
    #[serde(default)]
    pub ica_from: Option<String>,
    /// Particles per side of the simulated net. Default 14.
    #[serde(default = "default_grid")]
    pub grid: usize,
    /// Side of the samples, cm. Default 50.
    #[serde(default = "default_side")]
    pub side_cm: f64,
    /// Measurement error of the photos in the cost's unit (curve distance, % of the side), for the
    /// identifiability analysis: a worst-case bound (0.03 is the photo-to-particle gap of the bundled
    /// dataset, README "Edges from photos"). Default: none, the standard error of least squares
    /// estimated from the residual at the optimum ([`crate::calibrate::Noise`]).
    #[serde(default)]
    pub measurement_noise_pct: Option<f64>,
    /// A parameter is identifiable when the photos pin it to within this fraction of its value (the
    /// half-width over which the cost stays within the noise). Default 0.05.
    #[serde(default = "default_ident")]
    pub identifiable_rel: f64,
    /// Half-width of the window swept around the optimum for each parameter, as a fraction of its
    /// Table 3 range. Default 0.1.
    #[serde(default = "default_window")]
    pub identifiability_window: f64,
    /// Nelder–Mead iterations that polish the best ICA optimum over stiffness and natural length
    /// ([`crate::calibrate::Problem::polish`]); 0 keeps seed 000's ICA alone. Default 60.
    #[serde(default = "default_polish")]
    pub polish_iterations: u64,
    /// Also run CMA-ES with the same number of cost evaluations as each ICA run (the baseline), into
    /// the `comparison.parquet` output. Default false.
    #[serde(default)]
    pub baseline_cmaes: bool,
}

fn default_runs() -> usize {
    10
}
fn default_grid() -> usize {
    14
}
fn default_side() -> f64 {
    50.0
}
fn default_ident() -> f64 {
    0.05
}
fn default_polish() -> u64 {
    60
}
fn default_window() -> f64 {
    0.1
}

impl CalibrateParams {
    /// Checks the parameters: Err((key, message)).
    pub fn check(&self) -> Result<(), (String, String)> {
        match (&self.ica, &self.ica_from) {
            (Some(ica), None) => ica.check().map_err(|(k, m)| (format!("ica.{k}"), m))?,
            (None, Some(_)) => {}
            _ => {
                return Err((
                    "ica".into(),
                    "give exactly one of `ica` (settings) and `ica_from` (a file)".into(),
                ));
            }
        }
        if self.runs == 0 {
            return Err(("runs".into(), "must be ≥ 1".into()));
        }
        if self.grid < 3 {
            return Err(("grid".into(), "must be ≥ 3".into()));
        }
        for (key, v, lo, hi) in [
            (
                "measurement_noise_pct",
                self.measurement_noise_pct.unwrap_or(1.0),
                0.0,
                100.0,
            ),
            ("identifiable_rel", self.identifiable_rel, 0.0, 1.0),
            (
                "identifiability_window",
                self.identifiability_window,
                0.0,
                1.0,
            ),
        ] {
            if !(v.is_finite() && v > lo && v <= hi) {
                return Err((key.into(), format!("must be in ({lo}, {hi}], got {v}")));
            }
        }
        Ok(())
    }
}

/// One country of one decade: sample, run, decade, empire, cost, parameters, and its simulation.
type EvalRow = (
    String,
    u32,
    u32,
    u32,
    f64,
    crate::calibrate::Params,
    Option<crate::calibrate::Evaluation>,
);

struct SampleResult {
    sample: String,
    best: crate::calibrate::Params,
    curve_pct: f64,
    ica_curve_pct: f64,
    eq5_pct: f64,
    spread_pct: f64,
    simulations: usize,
    failures: usize,
    identifiability: Vec<crate::calibrate::Identifiability>,
}

/// Runs the stage.
pub fn run(ctx: &StageContext<'_>, p: &CalibrateParams) -> Result<()> {
    let (scene_file, densities) = ctx.knitted_inputs()?;
    let edges_file = ctx.input_named("edges.parquet")?;
    let mut by_sample: BTreeMap<String, Vec<EdgeFit>> = BTreeMap::new();
    for (s, e) in read_edges(edges_file)? {
        by_sample.entry(s).or_default().push(e);
    }
    if by_sample.is_empty() {
        bail!("{}: no edges", edges_file.display());
    }
    ctx.progress
        .stage_started(&ctx.stage.name, (by_sample.len() * p.runs) as u64);
    let ica = match (&p.ica, &p.ica_from) {
        (Some(ica), _) => ica.clone(),
        (None, Some(f)) => {
            let path = ctx
                .plan
                .root
                .join(f.replace("{run}", &format!("runs/{}", ctx.plan.name)));
            let ica: IcaSettings = serde_json::from_slice(
                &std::fs::read(&path).with_context(|| format!("cannot read {}", path.display()))?,
            )?;
            ica.check()
                .map_err(|(k, m)| anyhow::anyhow!("{}: {k}: {m}", path.display()))?;
            ica
        }
        (None, None) => bail!("no ICA settings"),
    };
    let recorder = match ctx
        .outputs
        .iter()
        .find(|o| o.extension().is_some_and(|e| e == "rrd"))
    {
        Some(path) => Some(crate::io::CalibrationRecorder::new(path)?),
        None => None,
    };
    let mut comparison: Vec<(String, &str, u32, u64, f64)> = Vec::new();
    let mut results = Vec::new();
    let mut evals: Vec<EvalRow> = Vec::new();
    for (sample, measured) in &by_sample {
        let scene = sample_scene(scene_file, &densities, sample, p.grid)?;
        let problem = Problem::new(scene, measured.clone(), p.side_cm);
        let mut best: Option<(f64, Vec<f64>)> = None;
        let mut costs = Vec::new();
        for r in 0..p.runs {
            let settings = IcaSettings {
                seed: ica.seed + r as u64,
                ..ica.clone()
            };
            let mut record_error: Option<anyhow::Error> = None;
            let report =
                crate::optim::Ica { settings, dim: 5 }.run(&|u: &[f64]| problem.cost(u), |ev| {
                    for (k, e) in ev.empires.iter().enumerate() {
                        for c in std::iter::once(&e.imperialist).chain(&e.colonies) {
                            evals.push((
                                sample.clone(),
                                r as u32,
                                ev.decade as u32,
                                k as u32,
                                c.cost,
                                problem.bounds.decode(&c.x),
                                problem.lookup(&c.x),
                            ));
                        }
                    }
                    if let (Some(rec), None) = (&recorder, &record_error) {
                        let best = ev
                            .empires
                            .iter()
                            .map(|e| &e.imperialist)
                            .min_by(|a, b| a.cost.total_cmp(&b.cost));
                        let drape = best
                            .map(|b| problem.drape(&b.x))
                            .and_then(|(s, e)| Some((s, e?)));
                        let origin = drape.as_ref().map(|(s, _)| s.x[0]).unwrap_or_default();
                        let logged = rec.decade(
                            sample,
                            r,
                            ev,
                            |x| [x[0] as f32, x[3] as f32, x[4] as f32],
                            drape
                                .as_ref()
                                .map(|(s, e)| (&s.grid, s.x.as_slice(), e.as_slice())),
                            measured,
                            origin,
                            p.side_cm,
                        );
                        record_error = logged.err();
                    }
                });
            if let Some(e) = record_error {
                return Err(e.context("writing the calibration recording"));
            }
            costs.push(report.best_cost);
            comparison.push((
                sample.clone(),
                "ica",
                r as u32,
                report.evaluations as u64,
                report.best_cost,
            ));
            if p.baseline_cmaes {
                let fresh = problem.fresh();
                let cm = crate::optim::cmaes(
                    &|u: &[f64]| fresh.cost(u),
                    5,
                    report.evaluations,
                    ica.seed + r as u64,
                );
                comparison.push((
                    sample.clone(),
                    "cma-es",
                    r as u32,
                    cm.evaluations as u64,
                    cm.best_cost,
                ));
            }
            if best.as_ref().is_none_or(|b| report.best_cost < b.0) {
                best = Some((report.best_cost, report.best_x.clone()));
            }
            ctx.progress.item_done(&ctx.stage.name);
        }
        let (ica_cost, ica_u) = best.expect("runs ≥ 1");
        let (u, cost) = problem.polish(&ica_u, p.polish_iterations);
        let params = problem.bounds.decode(&u);
        let mean = costs.iter().sum::<f64>() / costs.len() as f64;
        let spread =
            (costs.iter().map(|c| (c - mean).powi(2)).sum::<f64>() / costs.len() as f64).sqrt();
        let ident = identifiability(
            &problem,
            &u,
            p.identifiability_window,
            7,
            p.measurement_noise_pct
                .map_or(Noise::FromResidual, Noise::Given),
            p.identifiable_rel,
        );
        // Eq. 5 of the best drape against the measurement.
        let sim: Vec<EdgeFit> = problem.drape(&u).1.unwrap_or_default();
        let eq5: Vec<f64> = measured
            .iter()
            .filter_map(|m| {
                sim.iter()
                    .find(|s| s.edge == m.edge)
                    .map(|s| eq5_objective_pct(m, s, p.side_cm))
            })
            .collect();
        results.push(SampleResult {
            sample: sample.clone(),
            best: params,
            curve_pct: cost,
            ica_curve_pct: ica_cost,
            eq5_pct: eq5.iter().sum::<f64>() / eq5.len().max(1) as f64,
            spread_pct: spread,
            simulations: problem
                .simulations
                .load(std::sync::atomic::Ordering::Relaxed),
            failures: problem.failures.load(std::sync::atomic::Ordering::Relaxed),
            identifiability: ident,
        });
    }
    let f64s = |v: Vec<f64>| -> ArrayRef { Arc::new(Float64Array::from(v)) };
    let mut fields = vec![
        Field::new("sample", DataType::Utf8, false),
        Field::new("objective_pct", DataType::Float64, false),
        Field::new("curve_distance_pct", DataType::Float64, false),
        Field::new("ica_curve_distance_pct", DataType::Float64, false),
        Field::new("stiffness_N_per_m", DataType::Float64, false),
        Field::new("damping_Ns_per_m", DataType::Float64, false),
        Field::new("elongation_rate", DataType::Float64, false),
        Field::new("natural_length_m", DataType::Float64, false),
        Field::new("topology", DataType::Utf8, false),
        Field::new("runs", DataType::UInt32, false),
        Field::new("spread_curve_distance_pct", DataType::Float64, false),
        Field::new("simulations", DataType::UInt64, false),
        Field::new("failed_simulations", DataType::UInt64, false),
    ];
    let mut cols: Vec<ArrayRef> = vec![
        Arc::new(StringArray::from_iter_values(
            results.iter().map(|r| r.sample.clone()),
        )),
        f64s(results.iter().map(|r| r.eq5_pct).collect()),
        f64s(results.iter().map(|r| r.curve_pct).collect()),
        f64s(results.iter().map(|r| r.ica_curve_pct).collect()),
        f64s(results.iter().map(|r| r.best.stiffness_N_per_m).collect()),
        f64s(results.iter().map(|r| r.best.damping_Ns_per_m).collect()),
        f64s(results.iter().map(|r| r.best.elongation_rate).collect()),
        f64s(results.iter().map(|r| r.best.natural_length_m).collect()),
        Arc::new(StringArray::from_iter_values(
            results.iter().map(|r| r.best.topology.letter()),
        )),
        Arc::new(UInt32Array::from_iter_values(
            results.iter().map(|_| p.runs as u32),
        )),
        f64s(results.iter().map(|r| r.spread_pct).collect()),
        Arc::new(UInt64Array::from_iter_values(
            results.iter().map(|r| r.simulations as u64),
        )),
        Arc::new(UInt64Array::from_iter_values(
            results.iter().map(|r| r.failures as u64),
        )),
    ];
    for (k, name) in [
        "stiffness",
        "damping",
        "elongation_rate",
        "natural_length",
        "topology",
    ]
    .iter()
    .enumerate()
    {
        fields.push(Field::new(
            format!("identifiable_{name}"),
            DataType::Boolean,
            false,
        ));
        cols.push(Arc::new(BooleanArray::from(
            results
                .iter()
                .map(|r| r.identifiability[k].identifiable)
                .collect::<Vec<_>>(),
        )));
    }
    // Half-widths of the intervals the photos allow (null where the cost is flat).
    for (k, name) in [
        "stiffness_uncertainty_N_per_m",
        "damping_uncertainty_Ns_per_m",
        "elongation_rate_uncertainty",
        "natural_length_uncertainty_m",
    ]
    .iter()
    .enumerate()
    {
        fields.push(Field::new(*name, DataType::Float64, true));
        cols.push(Arc::new(Float64Array::from_iter(results.iter().map(|r| {
            let u = r.identifiability[k].uncertainty;
            u.is_finite().then_some(u)
        }))));
    }
    write_parquet(
        &ctx.outputs[0],
        &RecordBatch::try_new(Arc::new(Schema::new(fields)), cols)?,
        None,
    )?;
    if let Some(rec) = recorder {
        rec.finish()?;
    }
    if let Some(out) = ctx
        .outputs
        .iter()
        .find(|o| o.file_name().is_some_and(|n| n == "comparison.parquet"))
    {
        let schema = Arc::new(Schema::new(vec![
            Field::new("sample", DataType::Utf8, false),
            Field::new("optimizer", DataType::Utf8, false),
            Field::new("run", DataType::UInt32, false),
            Field::new("evaluations", DataType::UInt64, false),
            Field::new("best_cost_pct", DataType::Float64, false),
        ]));
        let cols: Vec<ArrayRef> = vec![
            Arc::new(StringArray::from_iter_values(
                comparison.iter().map(|c| c.0.clone()),
            )),
            Arc::new(StringArray::from_iter_values(
                comparison.iter().map(|c| c.1),
            )),
            Arc::new(UInt32Array::from_iter_values(
                comparison.iter().map(|c| c.2),
            )),
            Arc::new(UInt64Array::from_iter_values(
                comparison.iter().map(|c| c.3),
            )),
            f64s(comparison.iter().map(|c| c.4).collect()),
        ];
        write_parquet(out, &RecordBatch::try_new(schema, cols)?, None)?;
    }
    if let Some(out) = ctx
        .outputs
        .iter()
        .find(|o| o.file_name().is_some_and(|n| n == "evaluations.parquet"))
    {
        let schema = Arc::new(Schema::new(vec![
            Field::new("sample", DataType::Utf8, false),
            Field::new("run", DataType::UInt32, false),
            Field::new("decade", DataType::UInt32, false),
            Field::new("empire", DataType::UInt32, false),
            Field::new("cost_pct", DataType::Float64, false),
            Field::new("stiffness_N_per_m", DataType::Float64, false),
            Field::new("natural_length_m", DataType::Float64, false),
            Field::new("topology", DataType::Utf8, false),
            Field::new("solver_status", DataType::Utf8, true),
            Field::new("simulation_time_s", DataType::Float64, true),
        ]));
        let cols: Vec<ArrayRef> = vec![
            Arc::new(StringArray::from_iter_values(
                evals.iter().map(|e| e.0.clone()),
            )),
            Arc::new(UInt32Array::from_iter_values(evals.iter().map(|e| e.1))),
            Arc::new(UInt32Array::from_iter_values(evals.iter().map(|e| e.2))),
            Arc::new(UInt32Array::from_iter_values(evals.iter().map(|e| e.3))),
            f64s(evals.iter().map(|e| e.4).collect()),
            f64s(evals.iter().map(|e| e.5.stiffness_N_per_m).collect()),
            f64s(evals.iter().map(|e| e.5.natural_length_m).collect()),
            Arc::new(StringArray::from_iter_values(
                evals.iter().map(|e| e.5.topology.letter()),
            )),
            Arc::new(StringArray::from_iter(
                evals.iter().map(|e| e.6.map(|v| v.status)),
            )),
            Arc::new(Float64Array::from_iter(
                evals.iter().map(|e| e.6.map(|v| v.simulation_time_s)),
            )),
        ];
        write_parquet(out, &RecordBatch::try_new(schema, cols)?, None)?;
    }
    Ok(())
}
