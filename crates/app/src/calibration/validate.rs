//! `validate`: the calibrated parameters of each sample (a calibrate `results.parquet`) on the 2-corner
//! hang, scored against the sample's measured 2-corner edges (a fit-edges table): `validation.parquet`
//! with `sample`, `objective_pct` (Eq. 5, mean over the edges) and `curve_distance_pct` (seed 000 Table 6).

use crate::calibration::calibrate::SampleInputs;
use crate::calibration::tables::ResultRow;
use crate::job::Job;
use anyhow::{Context, Result};
use drapelab_core::calibrate::{
    Params, Problem, read_sample_densities, sample_number, sample_scene,
};
use drapelab_core::edges::{EdgeFit, EdgeSource, scene_view, score_edges, simulated_edges};
use drapelab_core::simulate::solve_scene;
use drapelab_core::solve::NoObserver;
use drapelab_record::{Table, read_edges, read_table, write_table};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// Parameters of a validate stage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ValidateParams {
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
}

/// Calibrated parameters by sample number from a results table.
pub fn read_results(path: &std::path::Path) -> Result<BTreeMap<u32, Params>> {
    let mut out = BTreeMap::new();
    for r in read_table::<ResultRow>(path)? {
        let n = sample_number(&r.sample)
            .with_context(|| format!("`{}`: no sample number", r.sample))?;
        let params = Params {
            stiffness_N_per_m: r.stiffness_N_per_m,
            damping_Ns_per_m: r.damping_Ns_per_m,
            elongation_rate: r.elongation_rate,
            natural_length_m: r.natural_length_m,
            topology: r.topology,
        };
        out.insert(n, params);
    }
    Ok(out)
}

/// One sample's calibrated parameters on the 2-corner hang, scored against its measured edges.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ValidationRow {
    /// Sample name.
    pub sample: String,
    /// Mean seed 000 Eq. 5 over its edges, % (None when the hang did not converge).
    pub objective_pct: Option<f64>,
    /// Mean RMS distance of simulated from measured edges, % of the side (None likewise).
    pub curve_distance_pct: Option<f64>,
}

impl Table for ValidationRow {
    const FILE: &'static str = "validation.parquet";
    const ROW: &'static str =
        "One sample's calibrated parameters validated on the 2-corner hang (seed 000 Table 6).";
}

/// The inputs of a validate stage.
pub struct ValidateInputs {
    /// The 2-corner edges, Table 2's densities and the 2-corner hang scene.
    pub samples: SampleInputs,
    /// A calibrate stage's results.parquet.
    pub calibration: std::path::PathBuf,
}

/// Validates the calibrated net on the 2-corner hang (seed 000), one row per photo.
pub fn run(ctx: &Job<'_, ValidateInputs>, p: &ValidateParams) -> Result<Vec<ValidationRow>> {
    let files = &ctx.inputs.samples;
    let densities = read_sample_densities(&files.samples)?;
    let scene_file = &files.scene;
    let results = read_results(&ctx.inputs.calibration)?;
    let edges_file = &files.edges;
    let mut by_sample: BTreeMap<String, Vec<(String, EdgeFit)>> = BTreeMap::new();
    for (s, e) in read_edges(edges_file)? {
        by_sample.entry(s.clone()).or_default().push((s, e));
    }
    ctx.started(by_sample.len());
    let (mut names, mut eq5, mut dist) = (Vec::new(), Vec::new(), Vec::new());
    for (sample, measured) in &by_sample {
        let n = sample_number(sample)
            .with_context(|| format!("`{sample}`: no sample_NN in the path"))?;
        let params = results
            .get(&n)
            .with_context(|| format!("sample {n} has no calibrated parameters"))?;
        let problem = Problem::new(
            sample_scene(scene_file, &densities, sample, p.grid)?,
            measured.iter().map(|(_, e)| e.clone()).collect(),
            p.side_cm,
        );
        let scene = problem.scene_for(params);
        let sol = solve_scene(&scene, &mut NoObserver);
        let (view, corners) = scene_view(&scene)?;
        let sim: Vec<(String, EdgeFit)> = simulated_edges(
            &sol.grid,
            &sol.x,
            view,
            corners,
            p.edge_source,
            problem.projection,
        )
        .into_iter()
        .filter_map(|(name, pts)| EdgeFit::from_points(&name, &pts, 4))
        .map(|e| (sample.clone(), e))
        .collect();
        let rows = if sol.report.is_converged() {
            score_edges(measured, &sim, p.side_cm)
        } else {
            Vec::new()
        };
        let mean = |v: Vec<f64>| {
            if v.is_empty() {
                f64::NAN
            } else {
                v.iter().sum::<f64>() / v.len() as f64
            }
        };
        names.push(sample.clone());
        eq5.push(mean(rows.iter().map(|r| r.objective_pct).collect()));
        dist.push(mean(rows.iter().map(|r| r.curve_distance_pct).collect()));
        ctx.item_done();
    }
    let opt = |x: f64| x.is_finite().then_some(x);
    let rows: Vec<ValidationRow> = names
        .into_iter()
        .zip(eq5.into_iter().zip(dist))
        .map(|(sample, (e, d))| ValidationRow {
            sample,
            objective_pct: opt(e),
            curve_distance_pct: opt(d),
        })
        .collect();
    write_table(ctx.output("validation")?, &rows)?;
    Ok(rows)
}
