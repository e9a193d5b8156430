//! `sweep.parquet`: one row per scene and design point. Its first columns ([`SweepPoint`]) and its
//! last ([`SweepOutcome`]) are row types; between them is one column per swept key, known only at
//! run time.

use anyhow::Result;
use arrow::array::{ArrayRef, Float64Array, Int64Array, RecordBatch, StringArray};
use arrow::datatypes::{DataType, Field, Schema};
use drapelab_core::cloth::Corner;
use drapelab_core::scene::Scene;
use drapelab_core::simulate::Solution;
use drapelab_core::solve::Status;
use drapelab_core::table::Table;
use drapelab_record::{join_columns, table_batch, write_parquet};
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// Which scene at which design point: the first columns of `sweep.parquet`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct SweepPoint {
    /// Scene name.
    pub scene: String,
    /// Design point, 0-based (the same point for every scene).
    pub point: u32,
}

impl Table for SweepPoint {
    const FILE: &'static str = "sweep.parquet";
    const ROW: &'static str = "One scene at one design point. Its first columns; then one column per swept key (named by its first key, e.g. `material.mass_spring.stiffness_N_per_m`; i64, f64 or string), then the columns below. Schema metadata: `drapelab_version`, `build_id`, `host`, `finished_utc` (as every table gathered from parts).";
}

/// How one point solved and how it drapes: the last columns of `sweep.parquet`. The drape measures
/// are None unless the solve converged (and where a measure is not defined).
#[allow(non_snake_case)]
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct SweepOutcome {
    /// Particles of the sheet.
    pub particles: u32,
    /// Solver that ran.
    pub solver: String,
    /// Solve status (converged, max-iterations, diverged, …).
    pub status: Status,
    /// Newton iterations or time steps.
    pub iterations: u64,
    /// Linear solves.
    pub linear_solves: u64,
    /// Wall time of the solve, s.
    pub wall_time_s: f64,
    /// Largest residual force at the end, N.
    pub max_residual_N: Option<f64>,
    /// Whether a converged static equilibrium is a minimum (None: not checked).
    pub minimum: Option<bool>,
    /// Height of the sheet's centre particle, m.
    pub centre_z_m: Option<f64>,
    /// Lowest particle, m.
    pub min_z_m: Option<f64>,
    /// Highest particle, m.
    pub max_z_m: Option<f64>,
    /// Corner (x min, y min), m.
    pub corner_xmin_ymin_x_m: Option<f64>,
    /// Corner (x min, y min), m.
    pub corner_xmin_ymin_y_m: Option<f64>,
    /// Corner (x min, y min), m.
    pub corner_xmin_ymin_z_m: Option<f64>,
    /// Corner (x max, y min), m.
    pub corner_xmax_ymin_x_m: Option<f64>,
    /// Corner (x max, y min), m.
    pub corner_xmax_ymin_y_m: Option<f64>,
    /// Corner (x max, y min), m.
    pub corner_xmax_ymin_z_m: Option<f64>,
    /// Corner (x min, y max), m.
    pub corner_xmin_ymax_x_m: Option<f64>,
    /// Corner (x min, y max), m.
    pub corner_xmin_ymax_y_m: Option<f64>,
    /// Corner (x min, y max), m.
    pub corner_xmin_ymax_z_m: Option<f64>,
    /// Corner (x max, y max), m.
    pub corner_xmax_ymax_x_m: Option<f64>,
    /// Corner (x max, y max), m.
    pub corner_xmax_ymax_y_m: Option<f64>,
    /// Corner (x max, y max), m.
    pub corner_xmax_ymax_z_m: Option<f64>,
    /// Drape coefficient (Cusick), % (scenes on a pedestal only).
    pub drape_coefficient_pct: Option<f64>,
    /// Folds (nodes) around the pedestal.
    pub folds: Option<f64>,
    /// Area of the sheet's vertical projection, m².
    pub projected_area_m2: Option<f64>,
    /// Deepest penetration of an obstacle, m.
    pub max_penetration_m: Option<f64>,
}

impl Table for SweepOutcome {
    const FILE: &'static str = "sweep.parquet";
    const ROW: &'static str = "Its last columns, after the swept keys: how the point solved and how it drapes (the measures are null unless it converged; the drape coefficient and folds need a table or pedestal).";
}

impl SweepOutcome {
    /// The outcome of `scene`'s solve `sol`.
    pub fn new(scene: &Scene, sol: &Solution) -> Self {
        let r = &sol.report;
        let ok = r.status == Status::Converged;
        let g = &sol.grid;
        let zs: Vec<f64> = sol.grid_positions().iter().map(|p| p.z).collect();
        let c = |corner: Corner, k: usize| {
            let (i, j) = corner.ij(g);
            // A mesh sheet has no corners by grid index.
            (ok && !scene.cloth.is_mesh()).then(|| sol.at(i, j)[k])
        };
        let d = ok.then(|| drapelab_core::measure::drape_measures(scene, &sol.x));
        let fin = |v: f64| v.is_finite().then_some(v);
        SweepOutcome {
            particles: g.len() as u32,
            solver: r.solver.report_name().to_string(),
            status: r.status,
            iterations: r.iterations as u64,
            linear_solves: r.linear_solves as u64,
            wall_time_s: r.wall_time_s,
            max_residual_N: fin(r.max_residual_N),
            minimum: r.minimum,
            centre_z_m: ok.then(|| sol.at(g.nx / 2, g.ny / 2).z),
            min_z_m: ok.then(|| zs.iter().copied().fold(f64::INFINITY, f64::min)),
            max_z_m: ok.then(|| zs.iter().copied().fold(f64::NEG_INFINITY, f64::max)),
            corner_xmin_ymin_x_m: c(Corner::XminYmin, 0),
            corner_xmin_ymin_y_m: c(Corner::XminYmin, 1),
            corner_xmin_ymin_z_m: c(Corner::XminYmin, 2),
            corner_xmax_ymin_x_m: c(Corner::XmaxYmin, 0),
            corner_xmax_ymin_y_m: c(Corner::XmaxYmin, 1),
            corner_xmax_ymin_z_m: c(Corner::XmaxYmin, 2),
            corner_xmin_ymax_x_m: c(Corner::XminYmax, 0),
            corner_xmin_ymax_y_m: c(Corner::XminYmax, 1),
            corner_xmin_ymax_z_m: c(Corner::XminYmax, 2),
            corner_xmax_ymax_x_m: c(Corner::XmaxYmax, 0),
            corner_xmax_ymax_y_m: c(Corner::XmaxYmax, 1),
            corner_xmax_ymax_z_m: c(Corner::XmaxYmax, 2),
            drape_coefficient_pct: d.as_ref().and_then(|d| d.drape_coefficient_pct),
            folds: d.as_ref().and_then(|d| d.folds.map(|f| f as f64)),
            projected_area_m2: d.as_ref().and_then(|d| fin(d.projected_area_m2)),
            max_penetration_m: d.as_ref().and_then(|d| fin(d.max_penetration_m)),
        }
    }
}

/// One swept key's values at every row, as the narrowest column that holds every value of the
/// design `all` (integers, then floats, then strings; so that one row's part has the whole table's
/// type); named by its first key.
pub fn axis_column(key: &str, vals: &[&toml::Value], all: &[&toml::Value]) -> (Field, ArrayRef) {
    let name = key.split(',').next().unwrap_or(key).trim().to_string();
    if all.iter().all(|v| v.is_integer()) {
        let a = Int64Array::from_iter_values(vals.iter().map(|v| v.as_integer().unwrap_or(0)));
        (Field::new(name, DataType::Int64, false), Arc::new(a))
    } else if all.iter().all(|v| as_f64(v).is_some()) {
        let a = Float64Array::from_iter_values(vals.iter().map(|v| as_f64(v).unwrap_or(f64::NAN)));
        (Field::new(name, DataType::Float64, false), Arc::new(a))
    } else {
        let a = StringArray::from_iter_values(vals.iter().map(|v| {
            v.as_str()
                .map(str::to_string)
                .unwrap_or_else(|| v.to_string())
        }));
        (Field::new(name, DataType::Utf8, false), Arc::new(a))
    }
}

/// A TOML number as f64 (integers too).
pub fn as_f64(v: &toml::Value) -> Option<f64> {
    v.as_float().or_else(|| v.as_integer().map(|i| i as f64))
}

/// Writes `sweep.parquet`: each row's point, the swept keys' values at it, its outcome.
pub fn write_sweep(
    out: &std::path::Path,
    rows: &[(SweepPoint, SweepOutcome)],
    points: &[Vec<toml::Value>],
    keys: &[&String],
) -> Result<()> {
    let (pts, outcomes): (Vec<SweepPoint>, Vec<SweepOutcome>) = rows.iter().cloned().unzip();
    let (fields, cols): (Vec<Field>, Vec<ArrayRef>) = keys
        .iter()
        .enumerate()
        .map(|(a, key)| {
            let vals: Vec<&toml::Value> =
                pts.iter().map(|p| &points[p.point as usize][a]).collect();
            let all: Vec<&toml::Value> = points.iter().map(|p| &p[a]).collect();
            axis_column(key, &vals, &all)
        })
        .unzip();
    let axes = RecordBatch::try_new_with_options(
        Arc::new(Schema::new(fields)),
        cols,
        &arrow::array::RecordBatchOptions::new().with_row_count(Some(pts.len())),
    )?;
    let batch = join_columns(&[table_batch(&pts)?, axes, table_batch(&outcomes)?])?;
    write_parquet(out, &batch, None)
}
