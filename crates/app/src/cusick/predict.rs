//! `cusick-predict` (issue 16): per fabric, the bending length calibrated on the drape coefficient
//! of its lowest-numbered specimen (the mean over that specimen's photos), then the drapes of that
//! bending length under several seeded perturbations predicted against every other specimen: DC
//! (mean and spread), nodes, and the azimuthally averaged height profile z(r) against the
//! registered meshes (independent of where the folds fall). Besides the predictions it writes the
//! simulated shadow outlines and height profiles (for the report's pictures) and a rerun recording
//! overlaying each fabric's registered meshes and simulated drapes.

use crate::cusick::captures::FacePredictions;
use crate::cusick::measure::ShadowRow;
use crate::cusick::over_fabrics::{Outcome, rows_over_fabrics};
use crate::cusick::tables::{OutlineRow, PredictionRow, ProfileRow};
use crate::cusick::targets::{empty_row, fill_distribution, fill_faces, fill_fit, targets};
use crate::job::Job;
use anyhow::Result;
use drapelab_core::cusick::{
    DiscMesh, DrapeParams, FabricSettings, Face, GapLine, SeededDrape, Tester,
    calibrate_and_predict, gap_lines, height_profile, polar_disc, sector_angle_rad, subdivide_disc,
    two_fold,
};
use drapelab_core::measure::mean_sd;
use drapelab_record::cusick::{CaptureKey, CusickDataset, Template};
use drapelab_record::{NamedMesh, read_table, write_cusick_drapes, write_table};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::time::Instant;

/// Parameters of a cusick-predict stage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CusickPredictParams {
    /// Perturbation seeds of each prediction (after the calibration's seeds). Default 6.
    pub seeds: u64,
    /// Rings of the height profile z(r) between pedestal and edge. Default 12.
    pub profile_bins: usize,
    /// Rings of a polar disc mesh to simulate on (6k vertices on ring k); 0, the default, simulates
    /// on the dataset's own template disc (2699 vertices), which agrees better with its own
    /// refinement (README, "Cusick drape tester").
    pub polar_rings: usize,
    /// Times the simulated mesh is refined (each triangle split into four). Default 0.
    pub subdivisions: usize,
    /// How each fabric is calibrated: anisotropies tried, seeds per candidate, the bending-length
    /// bracket.
    pub calibration: FabricSettings,
    /// The drape model (its bending length and anisotropy are what is calibrated).
    pub drape: DrapeParams,
    /// The fabrics to calibrate and predict, by number; empty (the default) for every fabric of
    /// the dataset. A pipeline that needs two fabrics' files names them here.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub fabrics: Vec<i32>,
}

impl Default for CusickPredictParams {
    fn default() -> Self {
        CusickPredictParams {
            seeds: 6,
            profile_bins: 12,
            polar_rings: 0,
            subdivisions: 0,
            calibration: FabricSettings::default(),
            drape: DrapeParams::default(),
            fabrics: Vec::new(),
        }
    }
}

/// A capture's registered mesh: its key and vertices.
pub type KeyedMesh = (CaptureKey, Vec<Vector3<f64>>);

/// The registered meshes of a dataset, in the photos' frame.
pub struct Measured<'a> {
    template: &'a Template,
    meshes: &'a BTreeMap<CaptureKey, Vec<Vector3<f64>>>,
    /// Captures whose meshes are stored turned by 90° about +z.
    rotated: std::collections::BTreeSet<CaptureKey>,
    /// Each photo's outline r(θ) in 1° sectors from +x, m.
    photo_outlines: BTreeMap<CaptureKey, Vec<f64>>,
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
pub struct FabricPrediction {
    row: PredictionRow,
    outlines: Vec<OutlineRow>,
    profiles: Vec<ProfileRow>,
    /// (seed, vertices) of each converged simulated drape.
    drapes: Vec<(u64, Vec<Vector3<f64>>)>,
    /// The registered meshes of the fabric (key, vertices).
    measured: Vec<KeyedMesh>,
    /// The calibration specimen.
    calib: i32,
    /// The model's predictions per face (none where the fabric was not predicted).
    faces: Option<FacePredictions>,
    /// The model's own DC spread, % (the fallback interval's): its seeds' SD and the calibration
    /// specimen's standard error.
    spread_pct: f64,
}

impl FabricPrediction {
    /// What the tables over fabrics take of it, with its captures `shadows`.
    fn outcome<'a>(&'a self, shadows: Vec<&'a ShadowRow>) -> Outcome<'a> {
        Outcome {
            row: &self.row,
            calib: self.calib,
            faces: self.faces.as_ref(),
            spread_pct: self.spread_pct,
            shadows,
        }
    }

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

/// Per ring, the mean and SD over `profiles` (None where no profile has the ring).
pub fn ring_stats(profiles: &[Vec<f64>], bins: usize) -> Vec<Option<(f64, f64)>> {
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
pub fn profile_rows(
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

/// Calibrates one fabric on its calibration specimen and predicts its other specimens.
pub fn predict_fabric(
    fabric: i32,
    density_known: bool,
    rows: &[&ShadowRow],
    measured: &Measured<'_>,
    mesh: DiscMesh<'_>,
    p: &CusickPredictParams,
    line: Option<GapLine>,
) -> FabricPrediction {
    let start = Instant::now();
    let tester = Tester::default();
    let mut tg = targets(rows);
    if tg.specimen.face_gap.is_some() {
        tg.specimen.predicted_face_gap_pct = line.map(|l| l.predicted_pct);
    }
    let mut out = FabricPrediction {
        row: empty_row(fabric, &tg, line),
        outlines: Vec::new(),
        profiles: Vec::new(),
        drapes: Vec::new(),
        measured: measured.of_fabric(fabric),
        calib: tg.calib,
        faces: None,
        spread_pct: f64::NAN,
    };
    let outcome = match calibrate_and_predict(
        mesh,
        &tg.specimen,
        &p.drape,
        &tester,
        &p.calibration,
        p.seeds,
    ) {
        Ok(o) => o,
        Err(why) => {
            out.row.status = format!("not calibrated: {why}");
            out.row.wall_time_s = start.elapsed().as_secs_f64();
            return out;
        }
    };
    let weight =
        density_known.then_some(p.drape.areal_density_kg_per_m2 * p.drape.gravity_m_per_s2);
    fill_fit(&mut out.row, &outcome.fit, weight);
    out.row.solves = outcome.solves as i32;
    out.row.prediction_seeds = p.seeds as i32;
    out.row.solve_time_mean_s = start.elapsed().as_secs_f64() / outcome.solves as f64;
    match &outcome.distribution {
        Some(d) => {
            fill_distribution(&mut out.row, d);
            out.spread_pct = d.dc_sd_pct.hypot(tg.specimen.dc_se_pct);
        }
        None => out.row.status = "no perturbed drape converged".into(),
    }
    out.faces = fill_faces(&mut out.row, &outcome);
    let drapes = outcome.drapes;
    fill_two_fold(&mut out.row, rows, measured, tg.calib, &drapes);
    if !drapes.is_empty() {
        let meas: Vec<Vec<f64>> = out
            .measured
            .iter()
            .filter(|(k, _)| tg.others.contains(k))
            .map(|(_, x)| height_profile(&measured.template.rest_xy, x, &tester, p.profile_bins))
            .collect();
        let sim: Vec<Vec<f64>> = drapes
            .iter()
            .map(|d| height_profile(mesh.rest_xy, &d.x, &tester, p.profile_bins))
            .collect();
        let (profiles, rms) = profile_rows(fabric, &meas, &sim, p.profile_bins);
        out.profiles = profiles;
        out.row.profile_rms_mm = if meas.is_empty() { None } else { rms };
        out.outlines = drapes
            .iter()
            .flat_map(|d| simulated_outline(fabric, d.seed, &d.outline_m))
            .collect();
    }
    out.drapes = drapes.into_iter().map(|d| (d.seed, d.x)).collect();
    out.row.wall_time_s = start.elapsed().as_secs_f64();
    out
}

/// The warp: the two-fold maximum of the calibration specimen `calib`'s face-up photos (turned
/// over, the direction mirrors about an unknown axis, so the face-down ones are left out), and the
/// simulated drapes' two-fold amplitude.
fn fill_two_fold(
    row: &mut PredictionRow,
    rows: &[&ShadowRow],
    measured: &Measured<'_>,
    calib: i32,
    drapes: &[SeededDrape],
) {
    let up: Vec<Vec<f64>> = rows
        .iter()
        .filter(|r| r.sample == calib && r.face == Face::Up)
        .filter_map(|r| {
            measured
                .photo_outlines
                .get(&(r.fabric, r.sample, r.capture))
                .cloned()
        })
        .collect();
    if !up.is_empty() {
        let (amp, dir) = two_fold(&up);
        row.outline_two_fold_measured_m = Some(amp);
        row.warp_direction_deg = Some(dir.to_degrees());
    }
    let sim: Vec<Vec<f64>> = drapes.iter().map(|d| d.outline_m.clone()).collect();
    if !sim.is_empty() {
        row.outline_two_fold_predicted_m = Some(two_fold(&sim).0);
    }
}

/// `work(k)` for every k of `order`, started in that order by as many workers as rayon has threads
/// (each takes the next k when it finishes one), returned by k.
fn longest_first<T: Send>(order: &[usize], work: impl Fn(usize) -> T + Sync) -> Vec<T> {
    let next = std::sync::atomic::AtomicUsize::new(0);
    let done = std::sync::Mutex::new(Vec::with_capacity(order.len()));
    rayon::scope(|s| {
        for _ in 0..rayon::current_num_threads().min(order.len()) {
            s.spawn(|_| {
                while let Some(&k) =
                    order.get(next.fetch_add(1, std::sync::atomic::Ordering::Relaxed))
                {
                    let out = work(k);
                    done.lock()
                        .unwrap_or_else(|e| e.into_inner())
                        .push((k, out));
                }
            });
        }
    });
    let mut done = done.into_inner().unwrap_or_else(|e| e.into_inner());
    done.sort_by_key(|d| d.0);
    done.into_iter().map(|d| d.1).collect()
}

/// The outline rows of a simulated drape's shadow outline r(θ).
pub fn simulated_outline(fabric: i32, seed: u64, outline_m: &[f64]) -> Vec<OutlineRow> {
    let n = outline_m.len();
    outline_m
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

/// The inputs of a cusick-predict stage.
pub struct CusickPredictInputs {
    /// captures_index.csv of a Cusick dataset (its folder holds the rest).
    pub index: std::path::PathBuf,
    /// A cusick-measure stage's shadows.parquet.
    pub shadows: std::path::PathBuf,
    /// A cusick-measure stage's outlines.parquet (the photos' outlines r(θ)).
    pub photo_outlines: std::path::PathBuf,
}

/// The `run` of the stage kind over this workflow.
pub fn run(
    ctx: &Job<'_, CusickPredictInputs>,
    p: &CusickPredictParams,
) -> Result<Vec<PredictionRow>> {
    let files = &ctx.inputs;
    let data = dataset(ctx, p)?;
    let shadows = read_table::<ShadowRow>(&files.shadows)?;
    let photo_outlines = outlines_by_capture(read_table::<OutlineRow>(&files.photo_outlines)?);
    let template = data.template()?;
    let meshes = data.meshes()?;
    let model_mesh = model_mesh(&template, p);
    let measured = Measured {
        template: &template,
        meshes: &meshes,
        photo_outlines,
        rotated: rotated_captures(&data),
    };
    ctx.started(data.fabrics.len());
    let lines = gap_lines(
        &shadows
            .iter()
            .map(ShadowRow::dc_capture)
            .collect::<Vec<_>>(),
    );
    let rows_of = |fabric: i32| -> Vec<&ShadowRow> {
        shadows.iter().filter(|r| r.fabric == fabric).collect()
    };
    let predict = |k: usize| {
        let f = &data.fabrics[k];
        let mut q = p.clone();
        if let Some(w) = f.areal_density_kg_per_m2 {
            q.drape.areal_density_kg_per_m2 = w;
        }
        let mesh = DiscMesh {
            rest_xy: &model_mesh.0,
            triangles: &model_mesh.1,
        };
        let density_known = f.areal_density_kg_per_m2.is_some();
        let out = predict_fabric(
            f.fabric,
            density_known,
            &rows_of(f.fabric),
            &measured,
            mesh,
            &q,
            lines.get(&f.fabric).copied(),
        );
        ctx.item_done();
        out
    };
    // The limpest fabrics first (their drapes take the most Newton iterations), so that none is
    // left to run alone at the end: the order changes no fabric's result.
    let cost: Vec<f64> = (data.fabrics.iter())
        .map(|f| targets(&rows_of(f.fabric)).specimen.dc_pct)
        .collect();
    let mut order: Vec<usize> = (0..data.fabrics.len()).collect();
    order.sort_by(|&a, &b| cost[a].total_cmp(&cost[b]));
    let fabrics = longest_first(&order, predict);
    let outcomes: Vec<Outcome<'_>> = (fabrics.iter())
        .map(|f| f.outcome(rows_of(f.row.fabric)))
        .collect();
    let (rows, captures) = rows_over_fabrics(&outcomes);
    write_table(ctx.output("predictions")?, &rows)?;
    write_table(ctx.output("by_capture")?, &captures)?;
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
    )?;
    Ok(rows)
}

/// The dataset of the index's folder, its fabrics those of `p.fabrics` (all when empty); a fabric
/// it lacks is an error naming the parameter.
fn dataset(ctx: &Job<'_, CusickPredictInputs>, p: &CusickPredictParams) -> Result<CusickDataset> {
    let index = &ctx.inputs.index;
    let mut data = CusickDataset::open(index.parent().unwrap_or(std::path::Path::new(".")))?;
    if let Some(f) = p
        .fabrics
        .iter()
        .find(|f| !data.fabrics.iter().any(|d| d.fabric == **f))
    {
        let m = format!("no fabric {f} in the dataset's fabrics.csv");
        return Err(ctx.param_error("fabrics", m).into());
    }
    data.fabrics
        .retain(|f| p.fabrics.is_empty() || p.fabrics.contains(&f.fabric));
    Ok(data)
}

/// The captures whose meshes the dataset rotated.
fn rotated_captures(data: &CusickDataset) -> std::collections::BTreeSet<CaptureKey> {
    (data.captures.iter())
        .filter(|c| c.mesh_rotated())
        .map(|c| c.key())
        .collect()
}

/// Each capture's photographed outline radii, m, in sector order (rows come in that order).
fn outlines_by_capture(rows: Vec<OutlineRow>) -> BTreeMap<CaptureKey, Vec<f64>> {
    let mut out: BTreeMap<CaptureKey, Vec<f64>> = BTreeMap::new();
    for o in rows {
        if let (Some(sample), Some(capture)) = (o.sample, o.capture) {
            out.entry((o.fabric, sample, capture))
                .or_default()
                .push(o.radius_m);
        }
    }
    out
}

/// The disc the drapes are solved on: the template's mesh, or a polar disc of `polar_rings`
/// rings, subdivided `subdivisions` times (rest positions, triangles).
fn model_mesh(template: &Template, p: &CusickPredictParams) -> (Vec<[f64; 2]>, Vec<[usize; 3]>) {
    let radius = Tester::default().specimen_radius_m;
    let mut mesh = match p.polar_rings {
        0 => (template.rest_xy.clone(), template.triangles.clone()),
        rings => polar_disc(radius, rings),
    };
    for _ in 0..p.subdivisions {
        mesh = subdivide_disc(&mesh.0, &mesh.1, radius);
    }
    mesh
}
