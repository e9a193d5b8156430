//! `cusick-predict` (issue 16): per fabric, the bending length calibrated on the drape coefficient
//! of its lowest-numbered specimen (the mean over that specimen's photos), then the drapes of that
//! bending length under several seeded perturbations predicted against every other specimen: DC
//! (mean and spread), nodes, and the azimuthally averaged height profile z(r) against the
//! registered meshes (independent of where the folds fall).

use crate::cusick_measure::ShadowRow;
use anyhow::Result;
use drapelab_core::cusick::{
    DiscMesh, DrapeParams, Tester, calibrate_bending_length, drape_dc, height_profile,
};
use drapelab_core::table::Table;
use drapelab_pipeline::{Slot, StageContext, StageKind};
use drapelab_record::cusick::{CusickDataset, Template};
use drapelab_record::{read_table, write_table};
use nalgebra::Vector3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::time::Instant;

/// Parameters of a cusick-predict stage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CusickPredictParams {
    /// Perturbation seeds of each prediction. Default 4.
    pub seeds: u64,
    /// Bending lengths the calibration searches, m. Default [0.01, 0.06].
    pub bracket_m: [f64; 2],
    /// Relative width at which the calibration's bisection stops. Default 0.02.
    pub rel_tol: f64,
    /// Rings of the height profile z(r) between pedestal and edge. Default 12.
    pub profile_bins: usize,
    /// The drape model (its bending length is what is calibrated).
    pub drape: DrapeParams,
}

impl Default for CusickPredictParams {
    fn default() -> Self {
        CusickPredictParams {
            seeds: 4,
            bracket_m: [0.01, 0.06],
            rel_tol: 0.02,
            profile_bins: 12,
            drape: DrapeParams::default(),
        }
    }
}

/// One fabric: calibrated on one specimen, predicted against the others.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct PredictionRow {
    /// Fabric number.
    pub fabric: i32,
    /// The specimen calibrated on (the lowest-numbered).
    pub calibration_sample: i32,
    /// Bending length along the warp, m (the model is isotropic: warp = weft; None if the calibration failed).
    pub bending_length_warp_m: Option<f64>,
    /// Bending length along the weft, m.
    pub bending_length_weft_m: Option<f64>,
    /// Bending rigidity, N·m (None where the areal density is unknown: it needs the weight).
    pub bending_rigidity_N_m: Option<f64>,
    /// Mean simulated DC over the perturbations, %.
    pub dc_predicted_pct: Option<f64>,
    /// SD of the simulated DC over the perturbations, %.
    pub dc_predicted_sd_pct: Option<f64>,
    /// Mean measured DC (photos) of the other specimens, %.
    pub dc_measured_mean_pct: f64,
    /// SD of the measured DC over the other specimens' captures, %.
    pub dc_measured_sd_pct: f64,
    /// DC of the calibration specimen (the target), %.
    pub dc_calibration_pct: f64,
    /// Mean simulated node count over the perturbations.
    pub nodes_predicted: Option<f64>,
    /// Median measured node count (photos) of the other specimens.
    pub nodes_measured_median: f64,
    /// RMS over the rings of simulated minus measured mean height z(r), mm (None without registered meshes).
    pub profile_rms_mm: Option<f64>,
    /// "ok", or why there is no prediction.
    pub status: String,
    /// Wall time of the fabric's calibration and predictions, s.
    pub wall_time_s: f64,
}

impl Table for PredictionRow {
    const FILE: &'static str = "predictions.parquet";
    const ROW: &'static str = "One Cusick fabric: bending length calibrated on its lowest-numbered specimen, its other specimens predicted.";
}

/// The `cusick-predict` stage kind.
pub struct CusickPredict;

impl StageKind for CusickPredict {
    type Params = CusickPredictParams;
    const KIND: &'static str = "cusick-predict";
    const SUMMARY: &'static str =
        "Calibrate each Cusick fabric's bending length on one specimen, predict the others";
    const INPUTS: &'static [Slot] = &[
        Slot::one(
            "index",
            "captures_index.csv of a Cusick dataset (its folder holds the rest)",
        ),
        Slot::one("shadows", "a cusick-measure stage's shadows.parquet"),
    ];
    const OUTPUTS: &'static [Slot] = &[Slot::one(
        "predictions",
        "predictions.parquet: one row per fabric",
    )];
    fn run(ctx: &StageContext<'_>, p: &CusickPredictParams) -> Result<()> {
        let index = ctx.input("index")?;
        let data = CusickDataset::open(index.parent().unwrap_or(std::path::Path::new(".")))?;
        let shadows = read_table::<ShadowRow>(ctx.input("shadows")?)?;
        let template = data.template()?;
        let meshes = data.meshes()?;
        ctx.progress
            .stage_started(&ctx.stage.name, data.fabrics.len() as u64);
        let rows: Vec<PredictionRow> = data
            .fabrics
            .par_iter()
            .map(|f| {
                let rows: Vec<&ShadowRow> =
                    shadows.iter().filter(|r| r.fabric == f.fabric).collect();
                let mut q = p.clone();
                if let Some(w) = f.areal_density_kg_per_m2 {
                    q.drape.areal_density_kg_per_m2 = w;
                }
                let row = predict_fabric(
                    f.fabric,
                    f.areal_density_kg_per_m2.is_some(),
                    &rows,
                    &template,
                    &meshes,
                    &q,
                );
                ctx.progress.item_done(&ctx.stage.name);
                row
            })
            .collect();
        write_table(ctx.output("predictions")?, &rows)
    }
}

fn mean_sd(v: &[f64]) -> (f64, f64) {
    let n = v.len().max(1) as f64;
    let m = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
    (m, var.sqrt())
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    match v.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => v[n / 2],
        n => 0.5 * (v[n / 2 - 1] + v[n / 2]),
    }
}

/// The mean height profile of the registered meshes of `keys`.
fn measured_profile(
    t: &Template,
    meshes: &BTreeMap<(i32, i32, i32), Vec<Vector3<f64>>>,
    keys: &[(i32, i32, i32)],
    bins: usize,
) -> Option<Vec<f64>> {
    let tester = Tester::default();
    let profiles: Vec<Vec<f64>> = keys
        .iter()
        .filter_map(|k| meshes.get(k))
        .filter(|x| x.len() == t.rest_xy.len())
        .map(|x| height_profile(&t.rest_xy, x, &tester, bins))
        .collect();
    (!profiles.is_empty()).then(|| {
        (0..bins)
            .map(|b| profiles.iter().map(|p| p[b]).sum::<f64>() / profiles.len() as f64)
            .collect()
    })
}

fn predict_fabric(
    fabric: i32,
    density_known: bool,
    rows: &[&ShadowRow],
    t: &Template,
    meshes: &BTreeMap<(i32, i32, i32), Vec<Vector3<f64>>>,
    p: &CusickPredictParams,
) -> PredictionRow {
    let start = Instant::now();
    let tester = Tester::default();
    let calib = rows.iter().map(|r| r.sample).min().unwrap_or(0);
    let (target, _) = mean_sd(
        &rows
            .iter()
            .filter(|r| r.sample == calib)
            .map(|r| r.dc_photo_pct)
            .collect::<Vec<_>>(),
    );
    let others: Vec<&&ShadowRow> = rows.iter().filter(|r| r.sample != calib).collect();
    let (dc_m, dc_sd) = mean_sd(&others.iter().map(|r| r.dc_photo_pct).collect::<Vec<_>>());
    let nodes_m = median(others.iter().map(|r| r.nodes_photo as f64).collect());
    let mut row = PredictionRow {
        fabric,
        calibration_sample: calib,
        bending_length_warp_m: None,
        bending_length_weft_m: None,
        bending_rigidity_N_m: None,
        dc_predicted_pct: None,
        dc_predicted_sd_pct: None,
        dc_measured_mean_pct: dc_m,
        dc_measured_sd_pct: dc_sd,
        dc_calibration_pct: target,
        nodes_predicted: None,
        nodes_measured_median: nodes_m,
        profile_rms_mm: None,
        status: String::new(),
        wall_time_s: 0.0,
    };
    let mesh = DiscMesh {
        rest_xy: &t.rest_xy,
        triangles: &t.triangles,
    };
    let c = match calibrate_bending_length(mesh, target, &p.drape, &tester, p.bracket_m, p.rel_tol)
    {
        Ok(c) => c,
        Err(why) => {
            row.status = format!("not calibrated: {why}");
            row.wall_time_s = start.elapsed().as_secs_f64();
            return row;
        }
    };
    let drapes: Vec<(f64, usize, Vec<Vector3<f64>>)> = (0..p.seeds)
        .filter_map(|seed| {
            let q = DrapeParams {
                bending_length_m: c,
                seed,
                ..p.drape.clone()
            };
            drape_dc(mesh, &q, &tester)
        })
        .collect();
    row.bending_length_warp_m = Some(c);
    row.bending_length_weft_m = Some(c);
    let w = p.drape.areal_density_kg_per_m2 * p.drape.gravity_m_per_s2;
    row.bending_rigidity_N_m = density_known.then(|| w * c.powi(3));
    row.status = if drapes.len() as u64 == p.seeds {
        "ok".into()
    } else {
        format!(
            "{} of {} perturbed drapes did not converge",
            p.seeds as usize - drapes.len(),
            p.seeds
        )
    };
    if !drapes.is_empty() {
        let (m, sd) = mean_sd(&drapes.iter().map(|d| d.0).collect::<Vec<_>>());
        row.dc_predicted_pct = Some(m);
        row.dc_predicted_sd_pct = Some(sd);
        row.nodes_predicted =
            Some(drapes.iter().map(|d| d.1 as f64).sum::<f64>() / drapes.len() as f64);
        let keys: Vec<(i32, i32, i32)> = others
            .iter()
            .map(|r| (r.fabric, r.sample, r.capture))
            .collect();
        if let Some(meas) = measured_profile(t, meshes, &keys, p.profile_bins) {
            let sim: Vec<Vec<f64>> = drapes
                .iter()
                .map(|d| height_profile(&t.rest_xy, &d.2, &tester, p.profile_bins))
                .collect();
            let d2: Vec<f64> = (0..p.profile_bins)
                .map(|b| sim.iter().map(|s| s[b]).sum::<f64>() / sim.len() as f64 - meas[b])
                .filter(|d| d.is_finite())
                .map(|d| d * d)
                .collect();
            row.profile_rms_mm =
                (!d2.is_empty()).then(|| 1e3 * (d2.iter().sum::<f64>() / d2.len() as f64).sqrt());
        }
    }
    row.wall_time_s = start.elapsed().as_secs_f64();
    row
}
