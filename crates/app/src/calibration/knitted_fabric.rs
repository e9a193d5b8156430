//! `knitted-fabric` (issue 77): a fabric file out of seed 000's calibration of a knitted sample, as
//! `cusick-fabric` writes one out of the drape tester: the calibrated mass-spring parameters (spring
//! stiffness, damping, elongation rate, natural length, topology) of `results.parquet`, the
//! sample's areal density from Table 2, `calibrated` the parameters the photos pin down, and their
//! intervals (the calibration's: the parameter ± the half-width the photos allow).

use crate::calibration::tables::ResultRow;
use crate::job::Job;
use anyhow::{Result, bail};
use drapelab_core::calibrate::{read_sample_densities, sample_number};
use drapelab_core::material::MassSpring;
use drapelab_core::scene::Fabric;
use drapelab_record::read_table;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::PathBuf;

/// Parameters of a knitted-fabric stage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KnittedFabricParams {
    /// The sample's number (Table 2's `sample`; the results' row whose sample path holds
    /// `sample_NN`). Required.
    pub sample: u32,
}

/// The inputs of a knitted-fabric stage.
pub struct KnittedFabricInputs {
    /// A calibrate stage's results.parquet.
    pub results: PathBuf,
    /// Table 2's densities (knitted_samples.csv).
    pub samples: PathBuf,
}

/// The fabric file of a calibrated sample: `row` of results.parquet, areal density `w`.
pub fn fabric_of(row: &ResultRow, w: f64, source: String) -> Fabric {
    let mut calibrated = Vec::new();
    let mut intervals = BTreeMap::new();
    let keys = [
        (
            "stiffness_N_per_m",
            row.identifiable_stiffness,
            row.stiffness_N_per_m,
            row.stiffness_uncertainty_N_per_m,
        ),
        (
            "damping_Ns_per_m",
            row.identifiable_damping,
            row.damping_Ns_per_m,
            row.damping_uncertainty_Ns_per_m,
        ),
        (
            "elongation_rate",
            row.identifiable_elongation_rate,
            row.elongation_rate,
            row.elongation_rate_uncertainty,
        ),
        (
            "natural_length_m",
            row.identifiable_natural_length,
            row.natural_length_m,
            row.natural_length_uncertainty_m,
        ),
    ];
    for (key, pinned, value, half) in keys {
        if !pinned {
            continue;
        }
        calibrated.push(key.to_string());
        if let Some(h) = half.filter(|h| h.is_finite()) {
            intervals.insert(key.to_string(), [value - h, value + h]);
        }
    }
    if row.identifiable_topology {
        calibrated.push("topology".into());
    }
    Fabric {
        name: format!("knitted sample {}", sample_number(&row.sample).unwrap_or(0)),
        source: Some(source),
        build_id: Some(drapelab_core::provenance::build_id().to_string()),
        areal_density_kg_per_m2: Some(w),
        bending_length_warp_m: None,
        bending_length_weft_m: None,
        continuum: None,
        mass_spring: Some(MassSpring {
            stiffness_N_per_m: row.stiffness_N_per_m,
            structural_stiffness_N_per_m: None,
            shear_stiffness_N_per_m: None,
            bend_stiffness_N_per_m: None,
            damping_Ns_per_m: row.damping_Ns_per_m,
            elongation_rate: row.elongation_rate,
            natural_length_m: Some(row.natural_length_m),
            topology: row.topology,
        }),
        calibrated,
        intervals,
    }
}

/// The `run` of the stage kind over this workflow: the sample's fabric file, written atomically.
pub fn run(ctx: &Job<'_, KnittedFabricInputs>, p: &KnittedFabricParams) -> Result<Fabric> {
    let files = &ctx.inputs;
    let densities = read_sample_densities(&files.samples)?;
    let Some(&w) = densities.get(&p.sample) else {
        let m = format!("no sample {} in {}", p.sample, files.samples.display());
        return Err(ctx.param_error("sample", m).into());
    };
    let rows = read_table::<ResultRow>(&files.results)?;
    let Some(row) = rows
        .iter()
        .find(|r| sample_number(&r.sample) == Some(p.sample))
    else {
        bail!(
            "{}: no row for sample {}",
            files.results.display(),
            p.sample
        );
    };
    let source = format!(
        "seed 000's knitted sample {} calibrated on its 4-corner hang photos ({}), stage `{}` of {}",
        p.sample,
        ctx.relative(&files.results).display(),
        ctx.stage,
        ctx.source.display()
    );
    let fabric = fabric_of(row, w, source);
    let text = format!(
        "# A fabric file written by drapelab's knitted-fabric stage (crates/app/src/knitted_fabric.rs):\n\
         # seed 000's mass-spring model calibrated on the photos of a knitted sample.\n{}",
        fabric.to_toml()
    );
    drapelab_core::atomic::write_text(ctx.output("fabric")?, &text)?;
    Ok(fabric)
}
