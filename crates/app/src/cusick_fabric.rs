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
//! A fabric whose areal density the dataset does not give is refused: its rigidity needs its weight.

use crate::cusick_tables::PredictionRow;
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
    /// The fabric's number in the dataset (`fabrics.csv`). Required.
    pub fabric: i32,
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
/// `w` from the dataset, `source` the provenance line.
pub fn fabric_of(row: &PredictionRow, name: &str, w: f64, source: String) -> Result<Fabric> {
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
    let rigidity = |len: f64| w * G * len.powi(3);
    let mut intervals = BTreeMap::new();
    if let (Some(lo), Some(hi)) = (row.bending_length_lo_m, row.bending_length_hi_m) {
        // B ∝ c³ at a fixed anisotropy: both rigidities move with c.
        let scale = |x: f64| (x / c).powi(3);
        for (key, b) in [
            ("bending_warp_N_m", rigidity(cw)),
            ("bending_weft_N_m", rigidity(cf)),
        ] {
            intervals.insert(key.to_string(), [b * scale(lo), b * scale(hi)]);
        }
    }
    let mut calibrated = vec!["bending_warp_N_m".to_string(), "bending_weft_N_m".into()];
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
    Ok(Fabric {
        name: name.to_string(),
        source: Some(source),
        build_id: Some(drapelab_core::provenance::build_id().to_string()),
        areal_density_kg_per_m2: Some(w),
        continuum: Some(Continuum {
            bending_warp_N_m: Some(rigidity(cw)),
            bending_weft_N_m: Some(rigidity(cf)),
            bending_saturation_per_m: saturation,
            curl_per_m: curl,
            ..Continuum::default()
        }),
        mass_spring: None,
        calibrated,
        intervals,
    })
}

/// The `run` of the stage kind over this workflow: the fabric's file, written atomically.
pub fn run(ctx: &Job<'_, CusickFabricInputs>, p: &CusickFabricParams) -> Result<Fabric> {
    let files = &ctx.inputs;
    let data = CusickDataset::open(files.index.parent().unwrap_or(std::path::Path::new(".")))?;
    let Some(info) = data.fabrics.iter().find(|f| f.fabric == p.fabric) else {
        let known: Vec<String> = data.fabrics.iter().map(|f| f.fabric.to_string()).collect();
        let m = format!(
            "no fabric {} in the dataset (it has {})",
            p.fabric,
            known.join(", ")
        );
        return Err(ctx.param_error("fabric", m).into());
    };
    let Some(w) = info.areal_density_kg_per_m2 else {
        let m = format!(
            "fabric {} has no areal density in fabrics.csv: its bending rigidity B = w g c³ needs its weight; add it there",
            p.fabric
        );
        return Err(ctx.param_error("fabric", m).into());
    };
    let rows = read_table::<PredictionRow>(&files.predictions)?;
    let Some(row) = rows.iter().find(|r| r.fabric == p.fabric) else {
        bail!(
            "{}: no row for fabric {}",
            files.predictions.display(),
            p.fabric
        );
    };
    let name = match info.name.as_str() {
        "" => format!("Cusick fabric {}", p.fabric),
        n => n.to_string(),
    };
    let source = format!(
        "Cusick drape tester: fabric {} calibrated on specimen {} ({}), stage `{}` of {}",
        p.fabric,
        row.calibration_sample,
        ctx.relative(&files.predictions).display(),
        ctx.stage,
        ctx.source.display()
    );
    let mut fabric = fabric_of(row, &name, w, source)?;
    if let Some(c) = fabric.continuum.as_mut() {
        c.tensile_warp_N_per_m = Some(p.tensile_N_per_m);
        c.tensile_weft_N_per_m = Some(p.tensile_N_per_m);
        c.shear_N_per_m = Some(p.shear_N_per_m);
    }
    let text = format!(
        "# A fabric file written by drapelab's cusick-fabric stage (crates/app/src/cusick_fabric.rs):\n\
         # bending calibrated on the Cusick drape tester; tensile and shear are stated defaults.\n{}",
        fabric.to_toml()
    );
    drapelab_core::atomic::write_text(ctx.output("fabric")?, &text)?;
    Ok(fabric)
}
