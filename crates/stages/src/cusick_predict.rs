//! `cusick-predict` (issue 16): per fabric, the bending length calibrated on the drape coefficient
//! of its lowest-numbered specimen (the mean over that specimen's photos), then the drapes of that
//! bending length under several seeded perturbations predicted against every other specimen: DC
//! (mean and spread), nodes, and the azimuthally averaged height profile z(r) against the
//! registered meshes (independent of where the folds fall). Besides the predictions it writes the
//! simulated shadow outlines and height profiles (for the report's pictures) and a rerun recording
//! overlaying each fabric's registered meshes and simulated drapes.

use crate::cusick_measure::ShadowRow;
use crate::cusick_tables::{OutlineRow, PredictionRow, ProfileRow};
use anyhow::Result;
use drapelab_core::cusick::{
    DiscMesh, DrapeParams, Tester, calibrate_bending_length, drape_dc, height_profile,
    mesh_projection, polar_disc, sector_angle_rad, shadow_measures, subdivide_disc,
};
use drapelab_pipeline::{Slot, StageContext, StageKind};
use drapelab_record::cusick::{CaptureKey, CusickDataset, Template};
use drapelab_record::{NamedMesh, read_table, write_cusick_drapes, write_table};
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
    /// Bending lengths the calibration searches, m. Default [0.008, 0.06] (below 8 mm the solves need more than their 1000 Newton iterations).
    pub bracket_m: [f64; 2],
    /// Relative width at which the calibration's bisection stops. Default 0.02.
    pub rel_tol: f64,
    /// Rings of the height profile z(r) between pedestal and edge. Default 12.
    pub profile_bins: usize,
    /// Rings of a polar disc mesh to simulate on (6k vertices on ring k); 0, the default, simulates
    /// on the dataset's own template disc (2699 vertices), which agrees better with its own
    /// refinement (README, "Cusick drape tester").
    pub polar_rings: usize,
    /// Times the simulated mesh is refined (each triangle split into four). Default 0.
    pub subdivisions: usize,
    /// The drape model (its bending length is what is calibrated).
    pub drape: DrapeParams,
}

impl Default for CusickPredictParams {
    fn default() -> Self {
        CusickPredictParams {
            seeds: 4,
            bracket_m: [0.008, 0.06],
            rel_tol: 0.02,
            profile_bins: 12,
            polar_rings: 0,
            subdivisions: 0,
            drape: DrapeParams::default(),
        }
    }
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
    const OUTPUTS: &'static [Slot] = &[
        Slot::one("predictions", "predictions.parquet: one row per fabric"),
        Slot::one(
            "outlines",
            "outlines.parquet: the simulated drapes' shadow outlines r(θ)",
        ),
        Slot::one(
            "profiles",
            "profiles.parquet: measured and simulated height profiles z(r)",
        ),
        Slot::one(
            "recording",
            "drapes.rrd: registered meshes and simulated drapes overlaid, per fabric",
        ),
    ];
    fn run(ctx: &StageContext<'_>, p: &CusickPredictParams) -> Result<()> {
        let index = ctx.input("index")?;
        let data = CusickDataset::open(index.parent().unwrap_or(std::path::Path::new(".")))?;
        let shadows = read_table::<ShadowRow>(ctx.input("shadows")?)?;
        let template = data.template()?;
        let meshes = data.meshes()?;
        let radius = Tester::default().specimen_radius_m;
        let mut model_mesh = match p.polar_rings {
            0 => (template.rest_xy.clone(), template.triangles.clone()),
            rings => polar_disc(radius, rings),
        };
        for _ in 0..p.subdivisions {
            model_mesh = subdivide_disc(&model_mesh.0, &model_mesh.1, radius);
        }
        let measured = Measured {
            template: &template,
            meshes: &meshes,
            rotated: data
                .captures
                .iter()
                .filter(|c| c.mesh_rotated())
                .map(|c| c.key())
                .collect(),
        };
        ctx.progress
            .stage_started(&ctx.stage.name, data.fabrics.len() as u64);
        let fabrics: Vec<FabricPrediction> = data
            .fabrics
            .par_iter()
            .map(|f| {
                let rows: Vec<&ShadowRow> =
                    shadows.iter().filter(|r| r.fabric == f.fabric).collect();
                let mut q = p.clone();
                if let Some(w) = f.areal_density_kg_per_m2 {
                    q.drape.areal_density_kg_per_m2 = w;
                }
                let mesh = DiscMesh {
                    rest_xy: &model_mesh.0,
                    triangles: &model_mesh.1,
                };
                let density_known = f.areal_density_kg_per_m2.is_some();
                let out = predict_fabric(f.fabric, density_known, &rows, &measured, mesh, &q);
                ctx.progress.item_done(&ctx.stage.name);
                out
            })
            .collect();
        let rows: Vec<PredictionRow> = fabrics.iter().map(|f| f.row.clone()).collect();
        write_table(ctx.output("predictions")?, &rows)?;
        let outlines: Vec<OutlineRow> = fabrics.iter().flat_map(|f| f.outlines.clone()).collect();
        write_table(ctx.output("outlines")?, &outlines)?;
        let profiles: Vec<ProfileRow> = fabrics.iter().flat_map(|f| f.profiles.clone()).collect();
        write_table(ctx.output("profiles")?, &profiles)?;
        let overlay: Vec<(i32, Vec<NamedMesh<'_>>)> = fabrics
            .iter()
            .map(|f| (f.row.fabric, f.overlay(&measured, &model_mesh.1)))
            .collect();
        write_cusick_drapes(
            ctx.output("recording")?,
            Tester::default().pedestal_radius_m,
            &overlay,
        )
    }
}

/// A capture's registered mesh: its key and vertices.
type KeyedMesh = (CaptureKey, Vec<Vector3<f64>>);

/// The registered meshes of a dataset, in the photos' frame.
struct Measured<'a> {
    template: &'a Template,
    meshes: &'a BTreeMap<CaptureKey, Vec<Vector3<f64>>>,
    /// Captures whose meshes are stored turned by 90° about +z.
    rotated: std::collections::BTreeSet<CaptureKey>,
}

impl Measured<'_> {
    /// The registered template meshes of `fabric`'s captures (key, vertices in the photo's frame).
    fn of_fabric(&self, fabric: i32) -> Vec<KeyedMesh> {
        self.meshes
            .iter()
            .filter(|(k, x)| k.0 == fabric && x.len() == self.template.rest_xy.len())
            .map(|(k, x)| {
                let x = if self.rotated.contains(k) {
                    x.iter().map(|p| Vector3::new(-p.y, p.x, p.z)).collect()
                } else {
                    x.clone()
                };
                (*k, x)
            })
            .collect()
    }
}

/// What one fabric's prediction leaves: its row, the simulated outlines and profiles, the drapes.
struct FabricPrediction {
    row: PredictionRow,
    outlines: Vec<OutlineRow>,
    profiles: Vec<ProfileRow>,
    /// (seed, vertices) of each converged simulated drape.
    drapes: Vec<(u64, Vec<Vector3<f64>>)>,
    /// The registered meshes of the fabric (key, vertices).
    measured: Vec<KeyedMesh>,
}

impl FabricPrediction {
    /// The meshes of the rerun overlay: every registered mesh and every simulated drape.
    fn overlay<'a>(
        &'a self,
        m: &'a Measured<'_>,
        model_triangles: &'a [[usize; 3]],
    ) -> Vec<NamedMesh<'a>> {
        let measured = self.measured.iter().map(|(k, x)| NamedMesh {
            name: format!("measured/s{}_c{}", k.1, k.2),
            vertices: x,
            triangles: &m.template.triangles,
        });
        let simulated = self.drapes.iter().map(|(seed, x)| NamedMesh {
            name: format!("simulated/seed_{seed}"),
            vertices: x,
            triangles: model_triangles,
        });
        measured.chain(simulated).collect()
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

/// Per ring, the mean and SD over `profiles` (None where no profile has the ring).
fn ring_stats(profiles: &[Vec<f64>], bins: usize) -> Vec<Option<(f64, f64)>> {
    (0..bins)
        .map(|b| {
            let v: Vec<f64> = profiles
                .iter()
                .map(|p| p[b])
                .filter(|z| z.is_finite())
                .collect();
            (!v.is_empty()).then(|| mean_sd(&v))
        })
        .collect()
}

/// The height profile rows of a fabric: measured (the meshes of the predicted specimens) against
/// simulated (the drapes), and the RMS of their difference in mm.
fn profile_rows(
    fabric: i32,
    measured: &[Vec<f64>],
    simulated: &[Vec<f64>],
    bins: usize,
) -> (Vec<ProfileRow>, Option<f64>) {
    let t = Tester::default();
    let (r0, r1) = (t.pedestal_radius_m, t.specimen_radius_m);
    let (meas, sim) = (ring_stats(measured, bins), ring_stats(simulated, bins));
    let rows: Vec<ProfileRow> = (0..bins)
        .map(|b| ProfileRow {
            fabric,
            radius_m: r0 + (r1 - r0) * (b as f64 + 0.5) / bins as f64,
            z_measured_m: meas[b].map(|s| s.0),
            z_measured_sd_m: meas[b].map(|s| s.1),
            z_predicted_m: sim[b].map(|s| s.0),
            z_predicted_sd_m: sim[b].map(|s| s.1),
        })
        .collect();
    let d2: Vec<f64> = rows
        .iter()
        .filter_map(|r| Some((r.z_predicted_m? - r.z_measured_m?).powi(2)))
        .collect();
    let rms = (!d2.is_empty()).then(|| 1e3 * (d2.iter().sum::<f64>() / d2.len() as f64).sqrt());
    (rows, rms)
}

/// The measured side of a fabric: the calibration specimen, its target DC and that target's
/// standard error, and the other specimens' DC mean, SD and median node count.
struct Targets {
    calib: i32,
    target_pct: f64,
    target_se_pct: f64,
    others: Vec<CaptureKey>,
    dc_mean_pct: f64,
    dc_sd_pct: f64,
    nodes_median: f64,
}

fn targets(rows: &[&ShadowRow]) -> Targets {
    let calib = rows.iter().map(|r| r.sample).min().unwrap_or(0);
    let own: Vec<f64> = rows
        .iter()
        .filter(|r| r.sample == calib)
        .map(|r| r.dc_photo_pct)
        .collect();
    let (target_pct, sd) = mean_sd(&own);
    let others: Vec<&&ShadowRow> = rows.iter().filter(|r| r.sample != calib).collect();
    let (dc_mean_pct, dc_sd_pct) =
        mean_sd(&others.iter().map(|r| r.dc_photo_pct).collect::<Vec<_>>());
    Targets {
        calib,
        target_pct,
        target_se_pct: sd / (own.len().max(1) as f64).sqrt(),
        others: others
            .iter()
            .map(|r| (r.fabric, r.sample, r.capture))
            .collect(),
        dc_mean_pct,
        dc_sd_pct,
        nodes_median: median(others.iter().map(|r| r.nodes_photo as f64).collect()),
    }
}

fn predict_fabric(
    fabric: i32,
    density_known: bool,
    rows: &[&ShadowRow],
    measured: &Measured<'_>,
    mesh: DiscMesh<'_>,
    p: &CusickPredictParams,
) -> FabricPrediction {
    let start = Instant::now();
    let tester = Tester::default();
    let tg = targets(rows);
    let mut out = FabricPrediction {
        row: PredictionRow {
            fabric,
            calibration_sample: tg.calib,
            bending_length_warp_m: None,
            bending_length_weft_m: None,
            bending_length_lo_m: None,
            bending_length_hi_m: None,
            dc_sensitivity_pct: None,
            bending_rigidity_N_m: None,
            dc_predicted_pct: None,
            dc_predicted_sd_pct: None,
            dc_measured_mean_pct: tg.dc_mean_pct,
            dc_measured_sd_pct: tg.dc_sd_pct,
            dc_calibration_pct: tg.target_pct,
            nodes_predicted: None,
            nodes_measured_median: tg.nodes_median,
            profile_rms_mm: None,
            status: String::new(),
            solves: 0,
            solve_time_mean_s: 0.0,
            wall_time_s: 0.0,
        },
        outlines: Vec::new(),
        profiles: Vec::new(),
        drapes: Vec::new(),
        measured: measured.of_fabric(fabric),
    };
    let cal = calibrate_bending_length(
        mesh,
        tg.target_pct,
        &p.drape,
        &tester,
        p.bracket_m,
        p.rel_tol,
    );
    let cal = match cal {
        Ok(c) => c,
        Err(why) => {
            out.row.status = format!("not calibrated: {why}");
            out.row.wall_time_s = start.elapsed().as_secs_f64();
            return out;
        }
    };
    let c = cal.bending_length_m;
    let drapes: Vec<(u64, f64, usize, Vec<Vector3<f64>>)> = (0..p.seeds)
        .into_par_iter()
        .filter_map(|seed| {
            let q = DrapeParams {
                bending_length_m: c,
                seed,
                ..p.drape.clone()
            };
            drape_dc(mesh, &q, &tester).map(|(dc, nodes, x)| (seed, dc, nodes, x))
        })
        .collect();
    let solves = cal.evaluations.len() + p.seeds as usize;
    let row = &mut out.row;
    row.solves = solves as i32;
    row.solve_time_mean_s = start.elapsed().as_secs_f64() / solves as f64;
    row.bending_length_warp_m = Some(c);
    row.bending_length_weft_m = Some(c);
    let w = p.drape.areal_density_kg_per_m2 * p.drape.gravity_m_per_s2;
    row.bending_rigidity_N_m = density_known.then(|| w * c.powi(3));
    row.dc_sensitivity_pct = cal.sensitivity_pct(1.3);
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
        let (m, sd) = mean_sd(&drapes.iter().map(|d| d.1).collect::<Vec<_>>());
        row.dc_predicted_pct = Some(m);
        row.dc_predicted_sd_pct = Some(sd);
        row.nodes_predicted =
            Some(drapes.iter().map(|d| d.2 as f64).sum::<f64>() / drapes.len() as f64);
        // The calibration's DC is uncertain by its photos' standard error and by the seed it used.
        let sigma = tg
            .target_se_pct
            .hypot(if drapes.len() > 1 { sd } else { 0.0 });
        if let Some([lo, hi]) = cal.interval_m(sigma, 2.0) {
            row.bending_length_lo_m = Some(lo);
            row.bending_length_hi_m = Some(hi);
        }
        let meas: Vec<Vec<f64>> = out
            .measured
            .iter()
            .filter(|(k, _)| tg.others.contains(k))
            .map(|(_, x)| height_profile(&measured.template.rest_xy, x, &tester, p.profile_bins))
            .collect();
        let sim: Vec<Vec<f64>> = drapes
            .iter()
            .map(|d| height_profile(mesh.rest_xy, &d.3, &tester, p.profile_bins))
            .collect();
        let (profiles, rms) = profile_rows(fabric, &meas, &sim, p.profile_bins);
        out.profiles = profiles;
        out.row.profile_rms_mm = if meas.is_empty() { None } else { rms };
        out.outlines = drapes
            .iter()
            .flat_map(|(seed, _, _, x)| simulated_outline(fabric, *seed, x, mesh.triangles))
            .collect();
    }
    out.drapes = drapes.into_iter().map(|d| (d.0, d.3)).collect();
    out.row.wall_time_s = start.elapsed().as_secs_f64();
    out
}

/// The outline rows of a simulated drape's vertical projection.
fn simulated_outline(
    fabric: i32,
    seed: u64,
    x: &[Vector3<f64>],
    triangles: &[[usize; 3]],
) -> Vec<OutlineRow> {
    let m = shadow_measures(&mesh_projection(x, triangles), &Tester::default());
    let n = m.outline_m.len();
    m.outline_m
        .iter()
        .enumerate()
        .map(|(k, &radius_m)| OutlineRow {
            fabric,
            sample: None,
            capture: None,
            seed: Some(seed as i32),
            theta_rad: sector_angle_rad(k, n),
            radius_m,
        })
        .collect()
}
