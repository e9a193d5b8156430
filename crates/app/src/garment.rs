//! `garment` (issue 77): a garment scene draped in a fabric file — the chain from the drape tester
//! to a garment: the scene's material replaced by the fabric's, the drape solved and recorded as
//! `simulate` records it, and one measure of it with the interval that the fabric's calibrated
//! bending gives through the drape's sensitivity. The measure is the hem's flare: the mean
//! horizontal distance of the hem's vertices (the pattern's group `measure_group`) from the
//! vertical through the origin (the body's axis), m. Its interval is linear in the fabric's 2σ
//! bending intervals: r̄ + Σ_k ∂r̄/∂B_k (B_k,end − B_k) at each end, ∂r̄/∂B_k from the drape's
//! sensitivity dx*/dB_k (one back-substitution each at the converged equilibrium).

use crate::job::Job;
use anyhow::{Context, Result, bail};
use drapelab_core::scene::Fabric;
use drapelab_core::solve::Status;
use drapelab_core::table::Table;
use drapelab_record::{SimulateExtras, simulate_to_dir_with, write_table};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::PathBuf;

/// Parameters of a garment stage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GarmentParams {
    /// Scene keys to override by dotted path, e.g. { "cloth.mesh_refine" = 0 } for a quick look.
    #[serde(default)]
    pub set: BTreeMap<String, toml::Value>,
    /// The pattern's vertex group whose flare is measured. Default "hem".
    #[serde(default = "default_group")]
    pub measure_group: String,
}

fn default_group() -> String {
    "hem".into()
}

impl Default for GarmentParams {
    fn default() -> Self {
        GarmentParams {
            set: BTreeMap::new(),
            measure_group: default_group(),
        }
    }
}

/// The inputs of a garment stage.
pub struct GarmentInputs {
    /// The garment scene (a mesh sheet with the group to measure).
    pub scene: PathBuf,
    /// The fabric file it is draped in.
    pub fabric: PathBuf,
}

/// The bending keys whose calibrated intervals make the measure's.
const BENDING_KEYS: [&str; 2] = ["bending_warp_N_m", "bending_weft_N_m"];

/// One garment draped in one fabric: the solve, the measure and its interval.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GarmentRow {
    /// The fabric's name (its file's `fabric.name`).
    pub fabric: String,
    /// The fabric file, relative to the project.
    pub fabric_file: String,
    /// The scene's name.
    pub scene: String,
    /// Particles of the garment.
    pub particles: u64,
    /// The solve's status ("converged", …).
    pub status: String,
    /// Newton iterations.
    pub iterations: u64,
    /// Wall time of the solve, s.
    pub wall_time_s: f64,
    /// Mean horizontal distance of the measured group's vertices from the body's axis, m.
    pub hem_radius_m: Option<f64>,
    /// Lower end of its interval from the fabric's 2σ bending intervals (linearized), m.
    pub hem_radius_lo_m: Option<f64>,
    /// Upper end of that interval, m.
    pub hem_radius_hi_m: Option<f64>,
    /// d r̄ / d ln B with both bending rigidities scaled together, m.
    pub hem_radius_per_ln_bending_m: Option<f64>,
    /// Why the interval is missing, where it is.
    pub interval_note: String,
    /// Edges of the garment crossing its triangles at the end (0: uncrossed).
    pub crossing_edges: Option<u64>,
}

impl Table for GarmentRow {
    const FILE: &'static str = "garment.parquet";
    const ROW: &'static str =
        "One garment draped in one fabric file: the solve, the hem's flare and its interval.";
}

/// The mean horizontal distance of vertices `group` at `x` from the z axis, and its derivative
/// along each sensitivity dx/dθ.
fn flare(x: &[Vector3<f64>], group: &[usize], dx: &[&[Vector3<f64>]]) -> (f64, Vec<f64>) {
    let n = group.len() as f64;
    let r = group.iter().map(|&v| x[v].xy().norm()).sum::<f64>() / n;
    let d = dx
        .iter()
        .map(|s| {
            group
                .iter()
                .map(|&v| x[v].xy().dot(&s[v].xy()) / x[v].xy().norm())
                .sum::<f64>()
                / n
        })
        .collect();
    (r, d)
}

/// The `run` of the stage kind over this workflow.
pub fn run(ctx: &Job<'_, GarmentInputs>, p: &GarmentParams) -> Result<GarmentRow> {
    let files = &ctx.inputs;
    let fabric = Fabric::read(&files.fabric)?;
    let dir = ctx.output("run")?.parent().expect("a folder").to_path_buf();
    let mut overrides: Vec<(String, toml::Value)> =
        p.set.iter().map(|(k, v)| (k.clone(), v.clone())).collect();
    let absolute = std::path::absolute(&files.fabric)?;
    let mut material = toml::Table::new();
    material.insert("fabric".into(), absolute.display().to_string().into());
    overrides.push(("material".into(), toml::Value::Table(material)));
    if ctx.optional_output("recording").is_some() {
        overrides.push(("record.rerun".into(), true.into()));
    }
    let loaded = ctx.load_scene(&files.scene, &overrides, |k| format!("set.{k}"))?;
    let Some(group) = loaded
        .scene
        .pattern()
        .and_then(|q| q.groups.get(&p.measure_group))
    else {
        let m = format!("the scene's mesh has no group `{}`", p.measure_group);
        return Err(ctx.param_error("measure_group", m).into());
    };
    let group = group.clone();
    let keys: Vec<String> = BENDING_KEYS
        .iter()
        .map(|k| format!("material.continuum.{k}"))
        .collect();
    let extras = SimulateExtras {
        sensitivity_keys: keys.clone(),
        ..SimulateExtras::default()
    };
    ctx.started(1);
    let sim = simulate_to_dir_with(
        &loaded,
        &dir,
        &mut drapelab_core::solve::NoObserver,
        &extras,
    )?;
    ctx.item_done();
    let report = &sim.report;
    let run: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("run.json"))?)
            .context("run.json")?;
    let mut row = GarmentRow {
        fabric: fabric.name.clone(),
        fabric_file: ctx.relative(&files.fabric).display().to_string(),
        scene: loaded.scene.name.clone(),
        particles: sim.x.len() as u64,
        status: report.status.as_str().into(),
        iterations: report.iterations as u64,
        wall_time_s: report.wall_time_s,
        hem_radius_m: None,
        hem_radius_lo_m: None,
        hem_radius_hi_m: None,
        hem_radius_per_ln_bending_m: None,
        interval_note: String::new(),
        crossing_edges: run["self_contact"]["crossing_edges"].as_u64(),
    };
    if report.status == Status::Converged {
        measure(&mut row, &sim, &group, &fabric, &keys);
    }
    write_table(ctx.output("measure")?, std::slice::from_ref(&row))?;
    if report.status != Status::Converged {
        bail!("{}: {} ({})", row.scene, row.status, report.message);
    }
    Ok(row)
}

/// Fills the row's flare and its interval from the converged drape and its sensitivities.
fn measure(
    row: &mut GarmentRow,
    sim: &drapelab_record::Simulated,
    group: &[usize],
    fabric: &Fabric,
    keys: &[String],
) {
    let dx: Vec<&[Vector3<f64>]> = keys
        .iter()
        .filter_map(|k| sim.sensitivity.iter().find(|(s, _)| s == k))
        .map(|(_, v)| v.as_slice())
        .collect();
    let (r, d) = flare(&sim.x, group, &dx);
    row.hem_radius_m = Some(r);
    if dx.len() != keys.len() {
        row.interval_note = "no sensitivity of the drape to its bending (run.json says why)".into();
        return;
    }
    let c = fabric.continuum.as_ref();
    let value = |k: &str| match k {
        "bending_warp_N_m" => c.and_then(|c| c.bending_warp_N_m),
        _ => c.and_then(|c| c.bending_weft_N_m),
    };
    let mut ends = [r, r];
    let mut per_ln = 0.0;
    for (k, dk) in BENDING_KEYS.iter().zip(&d) {
        let (Some(b), Some([lo, hi])) = (value(k), fabric.intervals.get(*k)) else {
            row.interval_note = format!("the fabric gives no interval of `{k}` in N·m");
            return;
        };
        ends[0] += dk * (lo - b);
        ends[1] += dk * (hi - b);
        per_ln += dk * b;
    }
    row.hem_radius_lo_m = Some(ends[0].min(ends[1]));
    row.hem_radius_hi_m = Some(ends[0].max(ends[1]));
    row.hem_radius_per_ln_bending_m = Some(per_ln);
}
