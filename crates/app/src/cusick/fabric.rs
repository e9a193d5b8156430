//! `cusick-fabric` (issue 77): a fabric file out of a Cusick calibration, so that a scene can drape
//! what the tester measured (`[material] fabric = "FILE"` or `drapelab simulate SCENE --fabric
//! FILE`). The calibrated model of a Cusick drape (core::cusick::drape_model) is hinge bending of
//! rigidity B = w g c³ (w the areal density, c the bending length), anisotropic by ρ = B_warp /
//! B_weft, saturating at κ₀, with a natural curl; so the file holds
//!
//! - `bending_warp_N_m` = w g c_warp³ and `bending_weft_N_m` = w g c_weft³ (c_warp = c ρ^(1/6),
//!   c_weft = c ρ^(−1/6)), calibrated, with the 2σ interval of c carried through B ∝ c³;
//! - `bending_saturation_per_m` (κ₀) where the chosen law saturates, calibrated (chosen among the
//!   laws tried, no interval);
//! - `curl_per_m` where the face gap gave one, calibrated, with its 2σ interval;
//! - tensile and shear rigidity, which the tester does not measure: stated defaults, not in
//!   `calibrated` (those of the drape model's stretching springs).
//!
//! A fabric whose areal density the dataset does not give is written with its bending lengths
//! (`bending_length_warp_m`, `bending_length_weft_m`) in place of rigidities and no density: a
//! scene draping it gives the density, and the rigidity B = w g c³ follows.

use crate::cusick::tables::PredictionRow;
use crate::job::Job;
use anyhow::{Result, bail};
use drapelab_core::material::Continuum;
use drapelab_core::scene::Fabric;
use drapelab_record::cusick::CusickDataset;
use drapelab_record::read_table;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::PathBuf;

/// Parameters of a cusick-fabric stage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CusickFabricParams {
    /// The fabric's number in the dataset (`fabrics.csv`), written to `outputs.fabric`; none (the
    /// default) writes every fabric of the predictions beside `outputs.fabrics` (an index).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fabric: Option<i32>,
    /// Tensile rigidity written (warp and weft alike), N/m: not measured by the tester, so a stated
    /// default, that of the drape model's stretching springs. Default 500.
    #[serde(default = "default_tensile")]
    pub tensile_N_per_m: f64,
    /// Shear rigidity written, N/m: not measured by the tester, a stated default. Default 50 (a
    /// tenth of the tensile rigidity, as woven dress fabrics shear).
    #[serde(default = "default_shear")]
    pub shear_N_per_m: f64,
}

fn default_tensile() -> f64 {
    500.0
}
fn default_shear() -> f64 {
    50.0
}

/// The inputs of a cusick-fabric stage.
pub struct CusickFabricInputs {
    /// A cusick-predict stage's predictions.parquet.
    pub predictions: PathBuf,
    /// The dataset's captures_index.csv (its folder's fabrics.csv names the fabric and its density).
    pub index: PathBuf,
}

/// Standard gravity, m/s² (the drape model's).
const G: f64 = 9.81;

/// The fabric file of one calibrated fabric: `row` of predictions.parquet, `name` and areal density
/// `w` from the dataset (where known), `source` the provenance line. With `w` the bending is
/// written as rigidities (N·m); without, as bending lengths, which a scene turns into rigidities
/// with its own areal density.
pub fn fabric_of(
    row: &PredictionRow,
    name: &str,
    w: Option<f64>,
    source: String,
) -> Result<Fabric> {
    let (Some(cw), Some(cf), Some(c)) = (
        row.bending_length_warp_m,
        row.bending_length_weft_m,
        row.bending_length_mean_m,
    ) else {
        bail!(
            "fabric {}: its calibration failed ({})",
            row.fabric,
            row.status
        );
    };
    // What is written per direction: B = w g c³ (N·m) where the weight is known, else c (m); both
    // move with c at a fixed anisotropy.
    let (keys, power, unit) = match w {
        Some(w) => (["bending_warp_N_m", "bending_weft_N_m"], 3, w * G),
        None => (["bending_length_warp_m", "bending_length_weft_m"], 1, 1.0),
    };
    let value = |len: f64| unit * len.powi(power);
    let mut intervals = BTreeMap::new();
    if let (Some(lo), Some(hi)) = (row.bending_length_lo_m, row.bending_length_hi_m) {
        for (key, len) in keys.iter().zip([cw, cf]) {
            intervals.insert(key.to_string(), [value(len * lo / c), value(len * hi / c)]);
        }
    }
    let mut calibrated: Vec<String> = keys.iter().map(|k| k.to_string()).collect();
    let saturation = row
        .bending_saturation_curvature_per_m
        .filter(|v| v.is_finite());
    if saturation.is_some() {
        calibrated.push("bending_saturation_per_m".into());
    }
    let curl = row.curl_per_m.filter(|v| v.is_finite());
    if curl.is_some() {
        calibrated.push("curl_per_m".into());
        if let (Some(lo), Some(hi)) = (row.curl_lo_per_m, row.curl_hi_per_m) {
            intervals.insert("curl_per_m".into(), [lo, hi]);
        }
    }
    let known = w.is_some();
    Ok(Fabric {
        name: name.to_string(),
        source: Some(source),
        build_id: Some(drapelab_core::provenance::build_id().to_string()),
        areal_density_kg_per_m2: w,
        bending_length_warp_m: (!known).then_some(cw),
        bending_length_weft_m: (!known).then_some(cf),
        continuum: Some(Continuum {
            bending_warp_N_m: known.then(|| value(cw)),
            bending_weft_N_m: known.then(|| value(cf)),
            bending_saturation_per_m: saturation,
            curl_per_m: curl,
            ..Continuum::default()
        }),
        mass_spring: None,
        calibrated,
        intervals,
    })
}

/// The `run` of the stage kind over this workflow: one fabric's file (`params.fabric`,
/// `outputs.fabric`), or every fabric's beside an index (`outputs.fabrics`), written atomically.
pub fn run(ctx: &Job<'_, CusickFabricInputs>, p: &CusickFabricParams) -> Result<Vec<Fabric>> {
    let files = &ctx.inputs;
    let data = CusickDataset::open(files.index.parent().unwrap_or(std::path::Path::new(".")))?;
    let rows = read_table::<PredictionRow>(&files.predictions)?;
    let Some(number) = p.fabric else {
        return write_all(ctx, p, &data, &rows);
    };
    let Some(row) = rows.iter().find(|r| r.fabric == number) else {
        let known: Vec<String> = rows.iter().map(|r| r.fabric.to_string()).collect();
        let m = format!(
            "no fabric {number} in the predictions (they have {})",
            known.join(", ")
        );
        return Err(ctx.param_error("fabric", m).into());
    };
    let fabric = fabric_file(ctx, p, &data, row)?;
    write(ctx.output("fabric")?, &fabric)?;
    Ok(vec![fabric])
}

/// Every fabric of `rows` as `fabric_NN.toml` beside the index `outputs.fabrics`, which lists them.
fn write_all(
    ctx: &Job<'_, CusickFabricInputs>,
    p: &CusickFabricParams,
    data: &CusickDataset,
    rows: &[PredictionRow],
) -> Result<Vec<Fabric>> {
    let index = ctx.output("fabrics")?;
    let dir = index.parent().unwrap_or(std::path::Path::new("."));
    let mut text = String::from(
        "# The fabric files of a Cusick calibration, one per fabric (drapelab's cusick-fabric stage).\n",
    );
    let mut out = Vec::new();
    for row in rows.iter().filter(|r| r.bending_length_mean_m.is_some()) {
        let fabric = fabric_file(ctx, p, data, row)?;
        let file = format!("fabric_{:02}.toml", row.fabric);
        write(&dir.join(&file), &fabric)?;
        text += &format!(
            "\n[[fabrics]]\nfabric = {}\nname = {:?}\nfile = {file:?}\nareal_density_known = {}\n",
            row.fabric,
            fabric.name,
            fabric.areal_density_kg_per_m2.is_some()
        );
        out.push(fabric);
    }
    drapelab_core::atomic::write_text(index, &text)?;
    Ok(out)
}

/// The fabric file of prediction `row`, its name and density from the dataset, the stated tensile
/// and shear rigidities of `p`.
fn fabric_file(
    ctx: &Job<'_, CusickFabricInputs>,
    p: &CusickFabricParams,
    data: &CusickDataset,
    row: &PredictionRow,
) -> Result<Fabric> {
    let info = data.fabrics.iter().find(|f| f.fabric == row.fabric);
    let name = match info.map(|f| f.name.as_str()) {
        Some(n) if !n.is_empty() => n.to_string(),
        _ => format!("Cusick fabric {}", row.fabric),
    };
    let source = format!(
        "Cusick drape tester: fabric {} calibrated on specimen {} ({}), stage `{}` of {}",
        row.fabric,
        row.calibration_sample,
        ctx.relative(&ctx.inputs.predictions).display(),
        ctx.stage,
        ctx.source.display()
    );
    let w = info.and_then(|f| f.areal_density_kg_per_m2);
    let mut fabric = fabric_of(row, &name, w, source)?;
    if let Some(c) = fabric.continuum.as_mut() {
        c.tensile_warp_N_per_m = Some(p.tensile_N_per_m);
        c.tensile_weft_N_per_m = Some(p.tensile_N_per_m);
        c.shear_N_per_m = Some(p.shear_N_per_m);
    }
    Ok(fabric)
}

/// Writes `fabric` to `path` with its header.
fn write(path: &std::path::Path, fabric: &Fabric) -> Result<()> {
    let text = format!(
        "# A fabric file written by drapelab's cusick-fabric stage (crates/app/src/cusick_fabric.rs):\n\
         # bending calibrated on the Cusick drape tester; tensile and shear are stated defaults.\n{}",
        fabric.to_toml()
    );
    drapelab_core::atomic::write_text(path, &text)?;
    Ok(())
}
