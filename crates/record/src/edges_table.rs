//! `edges.parquet`: one row per sample, edge and power of a fitted edge polynomial (seed 000 §2.3).

use crate::table::{Table, write_table};
use anyhow::Result;
use drapelab_core::edges::{EdgeFit, Projection};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// One coefficient of one sample's edge polynomial, with the edge's fit statistics repeated.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct EdgeRow {
    /// Photo or simulation name.
    pub sample: String,
    /// Edge name (e.g. `left`, `bottom`).
    pub edge: String,
    /// Power of x this coefficient multiplies.
    pub power: u32,
    /// Coefficient of x^power in y(x) with x and y in cm: its unit is cm^(1 − power). Files
    /// written before the unit was in the name (column `coefficient`) are read as well.
    pub coefficient_cm: f64,
    /// RMS distance of the edge points from the polynomial, cm.
    pub rms_residual_cm: f64,
    /// Edge points fitted.
    pub n_points: u32,
    /// Fitted x range, cm.
    pub x_min_cm: f64,
    /// Fitted x range, cm.
    pub x_max_cm: f64,
    /// Systematic uncertainty of a photographed edge (corners, scale, blur, light perturbed), % of
    /// the side; None for a simulated edge.
    pub systematic_pct: Option<f64>,
    /// The pinhole camera's distance to the corners' plane, m; None for an orthographic view.
    pub camera_distance_m: Option<f64>,
    /// Where the pinhole camera's axis meets the corners' plane, along the reference line, cm.
    pub camera_axis_along_cm: Option<f64>,
    /// Where the pinhole camera's axis meets the corners' plane, up from the reference line, cm.
    pub camera_axis_up_cm: Option<f64>,
}

impl Table for EdgeRow {
    const FILE: &'static str = "edges.parquet";
    const ROW: &'static str = "One coefficient of a sample's 4th-order edge polynomial y(x) (seed 000 §2.3), x and y in cm.";
}

/// Writes (sample, fit) pairs atomically.
pub fn write_edges(path: &Path, fits: &[(String, EdgeFit)]) -> Result<()> {
    let rows: Vec<EdgeRow> = fits
        .iter()
        .flat_map(|(s, f)| {
            let pinhole = match f.projection {
                Projection::Orthographic => None,
                Projection::Pinhole {
                    distance_m,
                    axis_cm,
                } => Some((distance_m, axis_cm)),
            };
            f.coefficients
                .iter()
                .enumerate()
                .map(move |(p, c)| EdgeRow {
                    sample: s.clone(),
                    edge: f.edge.clone(),
                    power: p as u32,
                    coefficient_cm: *c,
                    rms_residual_cm: f.rms_residual_cm,
                    n_points: f.n_points as u32,
                    x_min_cm: f.x_min_cm,
                    x_max_cm: f.x_max_cm,
                    systematic_pct: f.systematic_pct,
                    camera_distance_m: pinhole.map(|p| p.0),
                    camera_axis_along_cm: pinhole.map(|p| p.1.0),
                    camera_axis_up_cm: pinhole.map(|p| p.1.1),
                })
        })
        .collect();
    write_table(path, &rows)
}

/// Reads (sample, fit) pairs back, in file order, coefficients by power.
pub fn read_edges(path: &Path) -> Result<Vec<(String, EdgeFit)>> {
    let mut out: Vec<(String, EdgeFit)> = Vec::new();
    for r in
        crate::table::read_table_renamed::<EdgeRow>(path, &[("coefficient", "coefficient_cm")])?
    {
        let k = match out
            .iter()
            .position(|(s, e)| *s == r.sample && e.edge == r.edge)
        {
            Some(k) => k,
            None => {
                let fit = EdgeFit {
                    edge: r.edge.clone(),
                    coefficients: Vec::new(),
                    rms_residual_cm: r.rms_residual_cm,
                    n_points: r.n_points as usize,
                    x_min_cm: r.x_min_cm,
                    x_max_cm: r.x_max_cm,
                    systematic_pct: r.systematic_pct,
                    projection: match (
                        r.camera_distance_m,
                        r.camera_axis_along_cm,
                        r.camera_axis_up_cm,
                    ) {
                        (Some(distance_m), Some(a), Some(u)) => Projection::Pinhole {
                            distance_m,
                            axis_cm: (a, u),
                        },
                        _ => Projection::Orthographic,
                    },
                };
                out.push((r.sample.clone(), fit));
                out.len() - 1
            }
        };
        let c = &mut out[k].1.coefficients;
        let p = r.power as usize;
        if c.len() <= p {
            c.resize(p + 1, 0.0);
        }
        c[p] = r.coefficient_cm;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_table_with_the_old_coefficient_column_reads_as_the_new_one() {
        // The bundled ground truth was written with the column `coefficient`.
        let old = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../datasets/knitted/sample_08/hang4/edges_truth.parquet");
        let fits = read_edges(&old).unwrap();
        assert!(!fits.is_empty());
        // Written again, it has `coefficient_cm`, and reads back the same.
        let dir = tempfile::tempdir().unwrap();
        let new = dir.path().join("edges.parquet");
        write_edges(&new, &fits).unwrap();
        let again = read_edges(&new).unwrap();
        for ((s, a), (t, b)) in fits.iter().zip(&again) {
            assert_eq!((s, &a.edge, &a.coefficients), (t, &b.edge, &b.coefficients));
            assert!(a.coefficients.iter().any(|c| *c != 0.0));
        }
    }
}
