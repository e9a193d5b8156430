//! `sensitivity.parquet`: how each particle of a solved drape moves per unit of a scene parameter,
//! one row per particle and key, in the row order of `particles.parquet` within each key.

use crate::table::{Table, read_table, write_table};
use anyhow::Result;
use drapelab_core::cloth::Grid;
use drapelab_core::sensitivity::KeySensitivity;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// One particle's sensitivity to one key.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SensitivityRow {
    /// Column index along x, as in particles.parquet.
    pub i: u32,
    /// Row index along y, as in particles.parquet.
    pub j: u32,
    /// The dotted scene key, as the scene file writes it (e.g. `material.mass_spring.stiffness_N_per_m`).
    pub key: String,
    /// dx*/dθ: metres per unit of the key as the file writes it (per N/m, per gf·cm²/cm, ...).
    pub dx_m_per_unit: f64,
    /// dy*/dθ, metres per unit of the key.
    pub dy_m_per_unit: f64,
    /// dz*/dθ, metres per unit of the key.
    pub dz_m_per_unit: f64,
}

impl Table for SensitivityRow {
    const FILE: &'static str = "sensitivity.parquet";
    const ROW: &'static str = "One grid particle's sensitivity dx*/dθ to one scene key (`simulate --sensitivity KEY`), at a converged minimum: dx*/dθ = −H⁻¹ ∂g/∂θ with the factor of the exact Hessian. Within each key the rows follow particles.parquet; fixed particles move as their pins do.";
}

/// Writes the sensitivities of the grid particles, key after key.
pub fn write_sensitivities(path: &Path, grid: &Grid, s: &[KeySensitivity]) -> Result<()> {
    let rows: Vec<SensitivityRow> = s
        .iter()
        .flat_map(|k| {
            (0..grid.len()).map(move |p| SensitivityRow {
                i: grid.ij(p).0 as u32,
                j: grid.ij(p).1 as u32,
                key: k.key.clone(),
                dx_m_per_unit: k.dx[p].x,
                dy_m_per_unit: k.dx[p].y,
                dz_m_per_unit: k.dx[p].z,
            })
        })
        .collect();
    write_table(path, &rows)
}

/// Reads `sensitivity.parquet` back.
pub fn read_sensitivities(path: &Path) -> Result<Vec<SensitivityRow>> {
    read_table::<SensitivityRow>(path)
}
