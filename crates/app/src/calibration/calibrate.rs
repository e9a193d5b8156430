//! `calibrate`: for each sample of a fit-edges table, ICA runs over Table 3's box against the sample's
//! measured 4-corner edges (the scene input with the sample's Table 2 density); the best run is kept.
//! Writes `results.parquet` (one row per sample, with the runs' spread and each parameter's
//! identifiability) and `evaluations.parquet` (every country of every decade of every run). Each
//! sample is an item: one part per sample, run by the pipeline's executor, then gathered.

use crate::calibration::tables::{ComparisonRow, EvaluationRow, ResultRow};
use crate::job::Job;
use anyhow::{Context, Result, bail};
use drapelab_core::calibrate::{
    Noise, Problem, SampleSettings, calibrate_sample, read_sample_densities, sample_scene,
};
use drapelab_core::edges::{EdgeFit, EdgeSource};
use drapelab_core::error::KeyError;
use drapelab_core::optim::{DecadeEvent, IcaSettings};
use drapelab_record::{
    CalibrationRecorder, gather_parquet, merge_recordings, read_edges, write_table,
};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Parameters of a calibrate stage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CalibrateParams {
    /// Independent ICA runs per sample (seeds seed, seed+1, ...). Default 10 (seed 000).
    #[serde(default = "default_runs")]
    pub runs: usize,
    /// ICA settings (seed is the first run's); or set `ica_from_input`.
    #[serde(default)]
    pub ica: Option<IcaSettings>,
    /// Read ICA's settings from the `ica` input (a tune stage's `best_ica.json`) instead of `ica`.
    #[serde(default)]
    pub ica_from_input: bool,
    /// Particles per side of the simulated net. Default 14.
    #[serde(default = "crate::defaults::grid")]
    pub grid: usize,
    /// Side of the samples, cm. Default 50.
    #[serde(default = "crate::defaults::side_cm")]
    pub side_cm: f64,
    /// Which curve of a simulated drape stands for its edges: "silhouette" (of its triangles, as a
    /// photo shows it; default) or "particles" (the polyline through the edge particles).
    #[serde(default)]
    pub edge_source: EdgeSource,
    /// Measurement error of the photos in the cost's unit (curve distance, % of the side), for the
    /// identifiability analysis: a worst-case bound (0.03 is the photo-to-particle gap of the bundled
    /// dataset, docs/src/guide/photos.md). Default: none, the standard error of least squares
    /// estimated from the residual at the optimum ([`drapelab_core::calibrate::Noise`]).
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
    /// Add the photos' systematic uncertainty (the `systematic_pct` of their edges: corners, scale,
    /// blur and light perturbed) to the residual's in the identifiability intervals. Default true.
    #[serde(default = "default_true")]
    pub include_systematic: bool,
    /// Nelder–Mead iterations that polish the best ICA optimum over stiffness and natural length
    /// ([`drapelab_core::calibrate::Problem::polish`]); 0 keeps seed 000's ICA alone. Default 60.
    #[serde(default = "default_polish")]
    pub polish_iterations: u64,
    /// Also run CMA-ES with the same number of cost evaluations as each ICA run (the baseline), into
    /// the `comparison.parquet` output. Default false.
    #[serde(default)]
    pub baseline_cmaes: bool,
    /// Also calibrate by gradients: Levenberg–Marquardt over stiffness and natural length per
    /// topology on the edge-curve residuals, its Jacobian from the drapes' sensitivities
    /// ([`drapelab_core::calibrate::Problem::run_lm`]), once per sample, into `comparison.parquet`
    /// (optimizer `levenberg-marquardt`, evaluations = its equilibrium solves). Default false; the
    /// main job turns it on.
    #[serde(default)]
    pub levenberg_marquardt: bool,
}

/// Default `true` of the stage's switches (e.g. `include_systematic`).
pub fn default_true() -> bool {
    true
}
/// Default of `runs`: 10 independent ICA runs per sample (seed 000).
pub fn default_runs() -> usize {
    10
}
/// Default of `identifiable_rel`: 0.05.
pub fn default_ident() -> f64 {
    0.05
}
/// Default of `polish_iterations`: 60 Nelder–Mead iterations.
pub fn default_polish() -> u64 {
    60
}
/// Default of `identifiability_window`: 0.1 of each parameter's Table 3 range.
pub fn default_window() -> f64 {
    0.1
}

impl CalibrateParams {
    /// Checks the parameters: Err(KeyError::new(key, message)).
    pub fn check(&self) -> Result<(), KeyError> {
        match (&self.ica, self.ica_from_input) {
            (Some(ica), false) => ica
                .check()
                .map_err(|e| KeyError::new(format!("ica.{}", e.key), e.message))?,
            (None, true) => {}
            _ => {
                return Err(KeyError::new(
                    "ica",
                    "give exactly one of `ica` (settings) and `ica_from_input = true` (the `ica` input)",
                ));
            }
        }
        if self.runs == 0 {
            return Err(KeyError::new("runs", "must be ≥ 1"));
        }
        if self.grid < 3 {
            return Err(KeyError::new("grid", "must be ≥ 3"));
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
                return Err(KeyError::new(
                    key,
                    format!("must be in ({lo}, {hi}], got {v}"),
                ));
            }
        }
        Ok(())
    }
}

/// The files of the calibration workflows (calibrate, tune, validate): a sample's measured edges,
/// Table 2's densities and the hang scene.
pub struct SampleInputs {
    /// The measured edges of every sample (a fit-edges table).
    pub edges: PathBuf,
    /// Table 2's densities (knitted_samples.csv).
    pub samples: PathBuf,
    /// The hang scene each sample is simulated in.
    pub scene: PathBuf,
}

/// The inputs of a calibrate stage.
pub struct CalibrateInputs {
    /// The samples' files.
    pub samples: SampleInputs,
    /// ICA's settings as JSON (a tune stage's best_ica.json), read with `ica_from_input`.
    pub ica: Option<PathBuf>,
}

/// The ICA settings: given, or read from the `ica` input.
pub fn ica_settings(ctx: &Job<'_, CalibrateInputs>, p: &CalibrateParams) -> Result<IcaSettings> {
    if let Some(ica) = &p.ica {
        return Ok(ica.clone());
    }
    let Some(path) = ctx.inputs.ica.as_deref() else {
        bail!(
            "`{}` reads ICA's settings from input `ica`: add `inputs.ica = \"PATH\"`",
            ctx.stage
        );
    };
    let ica: IcaSettings = serde_json::from_slice(
        &std::fs::read(path).with_context(|| format!("cannot read {}", path.display()))?,
    )?;
    ica.check()
        .map_err(|e| anyhow::anyhow!("{}: {}: {}", path.display(), e.key, e.message))?;
    Ok(ica)
}

/// The measured edges of every sample of the `edges` input, by sample (the items, in this order).
pub fn edges_by_sample(edges_file: &Path) -> Result<BTreeMap<String, Vec<EdgeFit>>> {
    let mut by_sample: BTreeMap<String, Vec<EdgeFit>> = BTreeMap::new();
    for (s, e) in read_edges(edges_file)? {
        by_sample.entry(s).or_default().push(e);
    }
    if by_sample.is_empty() {
        bail!("{}: no edges", edges_file.display());
    }
    Ok(by_sample)
}

/// A side file of a sample's part: `part-00003.NAME`.
pub fn side(part: &Path, name: &str) -> PathBuf {
    part.with_extension(name)
}

/// Calibrates sample `item` (in sample order) and writes its part: the results row at `part` (last),
/// its evaluations, CMA-ES comparison and recording beside it when the stage writes them.
pub fn compute(
    ctx: &Job<'_, CalibrateInputs>,
    p: &CalibrateParams,
    item: usize,
    part: &Path,
) -> Result<()> {
    let files = &ctx.inputs.samples;
    let by_sample = edges_by_sample(&files.edges)?;
    let Some((sample, measured)) = by_sample.iter().nth(item) else {
        bail!("no sample {item} in {}", files.edges.display());
    };
    let (problem, settings) = sample_setup(
        (&files.scene, &files.samples),
        sample,
        measured,
        p,
        ica_settings(ctx, p)?,
    )?;
    let recorder = match ctx.optional_output("recording") {
        Some(_) => Some(CalibrationRecorder::new(&side(part, "rrd"))?),
        None => None,
    };
    let mut observe = |r: usize, ev: &DecadeEvent<'_>| -> Result<()> {
        match &recorder {
            Some(rec) => record_decade(rec, &problem, sample, r, ev, measured, p.side_cm)
                .context("writing the calibration recording"),
            None => Ok(()),
        }
    };
    let found = calibrate_sample(&problem, measured, &settings, &mut observe, &|| {})?;
    if let Some(rec) = recorder {
        rec.finish()?;
    }
    if ctx.optional_output("evaluations").is_some() {
        let rows: Vec<EvaluationRow> = found
            .evaluations
            .iter()
            .map(|e| EvaluationRow::new(sample, e))
            .collect();
        write_table(&side(part, "evaluations.parquet"), &rows)?;
    }
    if ctx.optional_output("comparison").is_some() {
        let rows: Vec<ComparisonRow> = found
            .runs
            .iter()
            .map(|r| ComparisonRow::new(sample, r))
            .collect();
        write_table(&side(part, "comparison.parquet"), &rows)?;
    }
    write_table(part, &[ResultRow::new(sample, &found, p.runs)])
}

/// The problem and settings of calibrating `sample` against its `measured` edges: the net of
/// `scene` with the sample's density from the `samples` table (seed 000 Table 2), and `p`'s settings
/// with ICA's `ica`.
pub fn sample_setup(
    (scene, samples): (&Path, &Path),
    sample: &str,
    measured: &[EdgeFit],
    p: &CalibrateParams,
    ica: IcaSettings,
) -> Result<(Problem, SampleSettings)> {
    let problem = sample_problem((scene, samples), sample, measured, p)?;
    let settings = SampleSettings {
        runs: p.runs,
        ica,
        side_cm: p.side_cm,
        polish_iterations: p.polish_iterations,
        noise: Noise::for_edges(p.measurement_noise_pct, measured, p.include_systematic),
        identifiable_rel: p.identifiable_rel,
        identifiability_window: p.identifiability_window,
        baseline_cmaes: p.baseline_cmaes,
        levenberg_marquardt: p.levenberg_marquardt,
    };
    Ok((problem, settings))
}

/// The problem of calibrating `sample` against its `measured` edges: the net of `scene` with the
/// sample's density from the `samples` table (seed 000 Table 2), `p`'s grid, side and edge source.
fn sample_problem(
    (scene, samples): (&Path, &Path),
    sample: &str,
    measured: &[EdgeFit],
    p: &CalibrateParams,
) -> Result<Problem> {
    let densities = read_sample_densities(samples)?;
    let scene = sample_scene(scene, &densities, sample, p.grid)?;
    let mut problem = Problem::new(scene, measured.to_vec(), p.side_cm);
    problem.edge_source = p.edge_source;
    Ok(problem)
}

/// What the calibration by gradients found for one sample (the Python package's
/// `calibrate(optimizer="levenberg-marquardt")`).
#[derive(Debug, Clone, Serialize)]
pub struct LmRow {
    /// Sample name.
    pub sample: String,
    /// Always "levenberg-marquardt".
    pub optimizer: String,
    /// The spring families found best ("a", "b" or "c").
    pub topology: String,
    /// Spring stiffness, N/m.
    pub stiffness_N_per_m: f64,
    /// Natural length, m.
    pub natural_length_m: f64,
    /// 2σ half-width of the stiffness from JᵀJ, N/m (None where JᵀJ is singular).
    pub stiffness_2sigma_N_per_m: Option<f64>,
    /// 2σ half-width of the natural length from JᵀJ, m.
    pub natural_length_2sigma_m: Option<f64>,
    /// Mean curve distance over the measured edges, % of the side.
    pub curve_distance_pct: f64,
    /// Equilibrium solves over the three topologies (the warm-start lattice not counted).
    pub solves: u64,
    /// Accepted steps.
    pub steps: u64,
    /// Why the best topology's run stopped.
    pub stop: String,
}

/// One sample of an `edges` table calibrated by gradients ([`Problem::run_lm`]) with `p`'s grid,
/// side and edge source, without files written.
pub fn calibrate_one_lm(
    (edges, samples, scene): (&Path, &Path, &Path),
    sample: &str,
    p: &CalibrateParams,
) -> Result<LmRow> {
    let measured = sample_edges(edges, sample)?;
    let problem = sample_problem((scene, samples), sample, &measured, p)?;
    let r = problem.run_lm(&drapelab_core::calibrate::LmSettings::default());
    Ok(LmRow {
        sample: sample.to_string(),
        optimizer: "levenberg-marquardt".into(),
        topology: format!("{:?}", r.best.topology).to_lowercase(),
        stiffness_N_per_m: r.best.stiffness_N_per_m,
        natural_length_m: r.best.natural_length_m,
        stiffness_2sigma_N_per_m: r.half_width_2sigma[0],
        natural_length_2sigma_m: r.half_width_2sigma[1],
        curve_distance_pct: r.best_cost_pct,
        solves: r.solves as u64,
        steps: r.iterations as u64,
        stop: r.stop.to_string(),
    })
}

/// The measured edges of `sample` in an `edges` table; an error when it has none.
fn sample_edges(edges: &Path, sample: &str) -> Result<Vec<EdgeFit>> {
    let measured: Vec<EdgeFit> = read_edges(edges)?
        .into_iter()
        .filter(|(s, _)| s == sample)
        .map(|(_, e)| e)
        .collect();
    if measured.is_empty() {
        bail!("{}: no edges of sample `{sample}`", edges.display());
    }
    Ok(measured)
}

/// One sample of an `edges` table calibrated with `p` (which gives `ica`), without files written:
/// the results row (the Python package's `calibrate`).
pub fn calibrate_one(
    (edges, samples, scene): (&Path, &Path, &Path),
    sample: &str,
    p: &CalibrateParams,
) -> Result<ResultRow> {
    let measured = sample_edges(edges, sample)?;
    let Some(ica) = p.ica.clone() else {
        bail!("calibrating one sample needs the ICA settings `ica`");
    };
    let (problem, settings) = sample_setup((scene, samples), sample, &measured, p, ica)?;
    let found = calibrate_sample(&problem, &measured, &settings, &mut |_, _| Ok(()), &|| {})?;
    Ok(ResultRow::new(sample, &found, p.runs))
}

/// `results.parquet`, and `evaluations.parquet`, `comparison.parquet` and `calibration.rrd` when
/// asked, from the samples' parts.
pub fn gather(ctx: &Job<'_, CalibrateInputs>, parts: &[PathBuf]) -> Result<()> {
    gather_parquet(parts, ctx.output("results")?)?;
    let sides = |name: &str| -> Vec<PathBuf> { parts.iter().map(|p| side(p, name)).collect() };
    if let Some(out) = ctx.optional_output("evaluations") {
        gather_parquet(&sides("evaluations.parquet"), out)?;
    }
    if let Some(out) = ctx.optional_output("comparison") {
        gather_parquet(&sides("comparison.parquet"), out)?;
    }
    if let Some(out) = ctx.optional_output("recording") {
        merge_recordings(&sides("rrd"), out, "drapelab_calibration")?;
    }
    Ok(())
}

/// Logs a decade: the empires and the drape of the best imperialist.
pub fn record_decade(
    rec: &CalibrationRecorder,
    problem: &Problem,
    sample: &str,
    run: usize,
    ev: &DecadeEvent<'_>,
    measured: &[EdgeFit],
    side_cm: f64,
) -> Result<()> {
    let best = ev
        .empires
        .iter()
        .map(|e| &e.imperialist)
        .min_by(|a, b| a.cost.total_cmp(&b.cost));
    let drape = best
        .map(|b| problem.drape(&b.x))
        .and_then(|(s, e)| Some((s, e?)));
    let origin = drape.as_ref().map(|(s, _)| s.x[0]).unwrap_or_default();
    rec.decade(
        sample,
        run,
        ev,
        |x| [x[0] as f32, x[3] as f32, x[4] as f32],
        drape
            .as_ref()
            .map(|(s, e)| (&s.grid, s.x.as_slice(), e.as_slice())),
        measured,
        origin,
        side_cm,
    )
}

/// The `count` of the stage kind over this workflow.
pub fn count(ctx: &Job<'_, CalibrateInputs>, p: &CalibrateParams) -> Result<usize> {
    ica_settings(ctx, p)?;
    read_sample_densities(&ctx.inputs.samples.samples)?;
    Ok(edges_by_sample(&ctx.inputs.samples.edges)?.len())
}
