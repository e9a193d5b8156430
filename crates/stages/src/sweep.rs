//! `sweep`: every input scene solved at every point of a grid or a Latin hypercube over scene keys,
//! in parallel (rayon), into one Parquet table. The schema is documented in the README.

use anyhow::{Result, bail};
use arrow::array::{
    ArrayRef, Float64Array, Int64Array, RecordBatch, StringArray, UInt32Array, UInt64Array,
};
use arrow::datatypes::{DataType, Field, Schema};
use drapelab_core::cloth::Corner;
use drapelab_core::scene::Scene;
use drapelab_core::simulate::solve_scene;
use drapelab_core::solve::{NoObserver, Status};
use drapelab_pipeline::{ParamError, Slot, StageContext, StageKind};
use drapelab_record::write_parquet;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::sync::Arc;

/// How sweep points are chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Design {
    /// The Cartesian product of every axis's values.
    #[default]
    Grid,
    /// A Latin hypercube of `samples` points over the axes' ranges (or value lists).
    Lhs,
}

/// One swept key: a list of values, or a range (Latin hypercube only).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Axis {
    /// Values to take (numbers, strings).
    Values(Vec<toml::Value>),
    /// A range [min, max]; integers when both bounds are integers.
    Range {
        /// Lower bound.
        min: toml::Value,
        /// Upper bound.
        max: toml::Value,
    },
}

/// Parameters of a sweep stage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SweepParams {
    /// "grid" (default) or "lhs".
    #[serde(default)]
    pub design: Design,
    /// Points of a Latin hypercube. Default 16.
    #[serde(default = "default_samples")]
    pub samples: usize,
    /// Seed of the Latin hypercube. Default 0.
    #[serde(default)]
    pub seed: u64,
    /// Swept keys by dotted path; "cloth.nx,cloth.ny" sets both keys to each value. None: each scene
    /// is solved once (a grid of one point).
    #[serde(default)]
    pub axes: BTreeMap<String, Axis>,
    /// Keys fixed for every point.
    #[serde(default)]
    pub set: BTreeMap<String, toml::Value>,
}

fn default_samples() -> usize {
    16
}

fn as_f64(v: &toml::Value) -> Option<f64> {
    v.as_float().or_else(|| v.as_integer().map(|i| i as f64))
}

impl SweepParams {
    /// Checks the axes against the design: Err((key, message)).
    pub fn check(&self) -> Result<(), (String, String)> {
        if self.axes.is_empty() && self.design == Design::Lhs {
            return Err((
                "axes".into(),
                "a Latin hypercube needs at least one axis".into(),
            ));
        }
        for (k, a) in &self.axes {
            match a {
                Axis::Values(v) if v.is_empty() => {
                    return Err((format!("axes.{k}"), "an empty list of values".into()));
                }
                Axis::Range { min, max } => {
                    if self.design == Design::Grid {
                        return Err((
                            format!("axes.{k}"),
                            "a grid needs a list of values; ranges are for design = \"lhs\"".into(),
                        ));
                    }
                    match (as_f64(min), as_f64(max)) {
                        (Some(a), Some(b)) if a.is_finite() && b.is_finite() && a <= b => {}
                        _ => {
                            return Err((
                                format!("axes.{k}"),
                                "min and max must be finite numbers with min ≤ max".into(),
                            ));
                        }
                    }
                }
                _ => {}
            }
        }
        if self.design == Design::Lhs && self.samples == 0 {
            return Err(("samples".into(), "must be ≥ 1".into()));
        }
        Ok(())
    }
}

/// The sweep's points: for each, the value of each axis (in key order).
pub fn sweep_points(p: &SweepParams) -> Vec<Vec<toml::Value>> {
    let axes: Vec<&Axis> = p.axes.values().collect();
    match p.design {
        Design::Grid => {
            let mut pts: Vec<Vec<toml::Value>> = vec![vec![]];
            for a in axes {
                let Axis::Values(vals) = a else {
                    unreachable!("checked")
                };
                pts = pts
                    .into_iter()
                    .flat_map(|pt| {
                        vals.iter()
                            .map(move |v| [pt.clone(), vec![v.clone()]].concat())
                    })
                    .collect();
            }
            pts
        }
        Design::Lhs => {
            let n = p.samples;
            let design = drapelab_core::optim::latin_hypercube(n, axes.len(), p.seed);
            let mut cols = Vec::new();
            for (a, us) in axes.iter().zip(&design) {
                let col: Vec<toml::Value> = us
                    .iter()
                    .map(|&u| match a {
                        Axis::Values(vals) => {
                            vals[((u * vals.len() as f64) as usize).min(vals.len() - 1)].clone()
                        }
                        Axis::Range { min, max } => {
                            let (lo, hi) = (as_f64(min).unwrap_or(0.0), as_f64(max).unwrap_or(0.0));
                            let x = lo + u * (hi - lo);
                            if min.is_integer() && max.is_integer() {
                                toml::Value::Integer(x.round() as i64)
                            } else {
                                toml::Value::Float(x)
                            }
                        }
                    })
                    .collect();
                cols.push(col);
            }
            (0..n)
                .map(|i| cols.iter().map(|c| c[i].clone()).collect())
                .collect()
        }
    }
}

/// Results of one point.
struct PointResult {
    scene: String,
    point: u32,
    particles: u32,
    solver: String,
    status: Status,
    iterations: u64,
    linear_solves: u64,
    wall_time_s: f64,
    max_residual_N: f64,
    /// Whether a converged static equilibrium is a minimum (None: not checked).
    minimum: Option<bool>,
    /// centre z, min z, max z, corners (x, y, z) × 4, drape coefficient, folds, projected area, penetration
    /// (NaN where not defined); None unless converged.
    measures: Option<Vec<f64>>,
}

const CORNERS: [(Corner, &str); 4] = [
    (Corner::XminYmin, "xmin_ymin"),
    (Corner::XmaxYmin, "xmax_ymin"),
    (Corner::XminYmax, "xmin_ymax"),
    (Corner::XmaxYmax, "xmax_ymax"),
];

/// Names of the measure columns, in order.
pub fn measure_columns() -> Vec<String> {
    let mut v = vec![
        "centre_z_m".to_string(),
        "min_z_m".to_string(),
        "max_z_m".to_string(),
    ];
    for (_, n) in CORNERS {
        for c in ["x", "y", "z"] {
            v.push(format!("corner_{n}_{c}_m"));
        }
    }
    v.extend(
        [
            "drape_coefficient_pct",
            "folds",
            "projected_area_m2",
            "max_penetration_m",
        ]
        .map(String::from),
    );
    v
}

/// Runs the stage.
fn run(ctx: &StageContext<'_>, p: &SweepParams) -> Result<()> {
    let files = ctx.input_files("scenes");
    if files.is_empty() {
        bail!("input `scenes` matched no scene file");
    }
    let points = sweep_points(p);
    let keys: Vec<&String> = p.axes.keys().collect();
    let jobs = load_jobs(files, p, &points, &keys)?;
    let name = &ctx.stage.name;
    ctx.progress.stage_started(name, jobs.len() as u64);
    // Largest grids first, so that the last items to finish are small (balanced threads); the rows
    // are put back in design order afterwards.
    let mut order: Vec<usize> = (0..jobs.len()).collect();
    order.sort_by_key(|&k| std::cmp::Reverse(jobs[k].1.cloth.nx * jobs[k].1.cloth.ny));
    let mut unordered: Vec<(usize, PointResult)> = order
        .par_iter()
        .map(|&k| {
            let (i, scene) = &jobs[k];
            let row = solve_point(scene, *i);
            ctx.progress.item_done(name);
            (k, row)
        })
        .collect();
    unordered.sort_by_key(|(k, _)| *k);
    let results: Vec<PointResult> = unordered.into_iter().map(|(_, r)| r).collect();
    write_table(ctx.output("table")?, &results, &points, &keys)
}

/// Every scene at every point, loaded first: bad values are refused before any work.
fn load_jobs(
    files: &[std::path::PathBuf],
    p: &SweepParams,
    points: &[Vec<toml::Value>],
    keys: &[&String],
) -> Result<Vec<(u32, Scene)>> {
    let mut jobs = Vec::new();
    for file in files {
        for (i, pt) in points.iter().enumerate() {
            let mut overrides: Vec<(String, toml::Value)> =
                p.set.iter().map(|(k, v)| (k.clone(), v.clone())).collect();
            for (k, v) in keys.iter().zip(pt) {
                for sub in k.split(',') {
                    overrides.push((sub.trim().to_string(), v.clone()));
                }
            }
            let mut scene = Scene::load(file, &overrides)?.scene.into_inner();
            scene.record.timeline = false;
            scene.record.rerun = false;
            jobs.push((i as u32, scene));
        }
    }
    Ok(jobs)
}

/// Solves one point and measures its drape (when it converged).
fn solve_point(scene: &Scene, i: u32) -> PointResult {
    let sol = solve_scene(scene, &mut NoObserver);
    let converged = sol.report.status == Status::Converged;
    let measures = converged.then(|| {
        let g = &sol.grid;
        let zs = sol.grid_positions().iter().map(|p| p.z);
        let mut m = vec![
            sol.at(g.nx / 2, g.ny / 2).z,
            zs.clone().fold(f64::INFINITY, f64::min),
            zs.fold(f64::NEG_INFINITY, f64::max),
        ];
        for (c, _) in CORNERS {
            let (ci, cj) = c.ij(g);
            let q = sol.at(ci, cj);
            m.extend([q.x, q.y, q.z]);
        }
        let d = drapelab_core::measure::drape_measures(scene, g, &sol.x);
        m.extend([
            d.drape_coefficient_pct.unwrap_or(f64::NAN),
            d.folds.map_or(f64::NAN, |f| f as f64),
            d.projected_area_m2,
            d.max_penetration_m,
        ]);
        m
    });
    PointResult {
        scene: scene.name.clone(),
        point: i,
        particles: sol.grid.len() as u32,
        solver: sol.report.solver.clone(),
        status: sol.report.status,
        iterations: sol.report.iterations as u64,
        linear_solves: sol.report.linear_solves as u64,
        wall_time_s: sol.report.wall_time_s,
        max_residual_N: sol.report.max_residual_N,
        minimum: sol.report.minimum,
        measures,
    }
}

/// `sweep.parquet`: one row per scene and point, the axes' values as columns.
fn write_table(
    out: &std::path::Path,
    results: &[PointResult],
    points: &[Vec<toml::Value>],
    keys: &[&String],
) -> Result<()> {
    // Columns.
    let mut fields = vec![
        Field::new("scene", DataType::Utf8, false),
        Field::new("point", DataType::UInt32, false),
    ];
    let mut cols: Vec<ArrayRef> = vec![
        Arc::new(StringArray::from_iter_values(
            results.iter().map(|r| r.scene.clone()),
        )),
        Arc::new(UInt32Array::from_iter_values(
            results.iter().map(|r| r.point),
        )),
    ];
    for (a, key) in keys.iter().enumerate() {
        let vals: Vec<&toml::Value> = results
            .iter()
            .map(|r| &points[r.point as usize][a])
            .collect();
        let col_name = key.split(',').next().unwrap_or(key).trim().to_string();
        if vals.iter().all(|v| v.is_integer()) {
            fields.push(Field::new(col_name, DataType::Int64, false));
            cols.push(Arc::new(Int64Array::from_iter_values(
                vals.iter().map(|v| v.as_integer().unwrap_or(0)),
            )));
        } else if vals.iter().all(|v| as_f64(v).is_some()) {
            fields.push(Field::new(col_name, DataType::Float64, false));
            cols.push(Arc::new(Float64Array::from_iter_values(
                vals.iter().map(|v| as_f64(v).unwrap_or(f64::NAN)),
            )));
        } else {
            fields.push(Field::new(col_name, DataType::Utf8, false));
            cols.push(Arc::new(StringArray::from_iter_values(vals.iter().map(
                |v| {
                    v.as_str()
                        .map(str::to_string)
                        .unwrap_or_else(|| v.to_string())
                },
            ))));
        }
    }
    fields.extend([
        Field::new("particles", DataType::UInt32, false),
        Field::new("solver", DataType::Utf8, false),
        Field::new("status", DataType::Utf8, false),
        Field::new("iterations", DataType::UInt64, false),
        Field::new("linear_solves", DataType::UInt64, false),
        Field::new("wall_time_s", DataType::Float64, false),
        Field::new("max_residual_N", DataType::Float64, true),
        Field::new("minimum", DataType::Boolean, true),
    ]);
    cols.push(Arc::new(UInt32Array::from_iter_values(
        results.iter().map(|r| r.particles),
    )));
    cols.push(Arc::new(StringArray::from_iter_values(
        results.iter().map(|r| r.solver.clone()),
    )));
    cols.push(Arc::new(StringArray::from_iter_values(
        results.iter().map(|r| r.status.as_str()),
    )));
    cols.push(Arc::new(UInt64Array::from_iter_values(
        results.iter().map(|r| r.iterations),
    )));
    cols.push(Arc::new(UInt64Array::from_iter_values(
        results.iter().map(|r| r.linear_solves),
    )));
    cols.push(Arc::new(Float64Array::from_iter_values(
        results.iter().map(|r| r.wall_time_s),
    )));
    cols.push(Arc::new(Float64Array::from_iter(results.iter().map(|r| {
        r.max_residual_N.is_finite().then_some(r.max_residual_N)
    }))));
    cols.push(Arc::new(arrow::array::BooleanArray::from(
        results.iter().map(|r| r.minimum).collect::<Vec<_>>(),
    )));
    for (m, name) in measure_columns().into_iter().enumerate() {
        fields.push(Field::new(name, DataType::Float64, true));
        cols.push(Arc::new(Float64Array::from_iter(results.iter().map(|r| {
            r.measures
                .as_ref()
                .and_then(|v| v[m].is_finite().then_some(v[m]))
        }))));
    }
    let schema = Arc::new(Schema::new(fields));
    let batch = RecordBatch::try_new(schema, cols)?;
    write_parquet(out, &batch, None)
}

/// The `sweep` stage kind.
pub struct Sweep;

impl StageKind for Sweep {
    type Params = SweepParams;
    const KIND: &'static str = "sweep";
    const SUMMARY: &'static str = "Solve scenes over a grid or Latin hypercube of scene keys";
    const INPUTS: &'static [Slot] = &[Slot::many(
        "scenes",
        "scene TOMLs, each solved at every point",
    )];
    const OUTPUTS: &'static [Slot] = &[Slot::one(
        "table",
        "sweep.parquet: one row per scene and point",
    )];
    fn check(p: &SweepParams) -> Result<(), ParamError> {
        p.check().map_err(|(k, m)| ParamError::new(k, m))
    }
    fn run(ctx: &StageContext<'_>, p: &SweepParams) -> Result<()> {
        run(ctx, p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn latin_hypercube_hits_every_stratum_of_every_axis_once() {
        let mut axes = BTreeMap::new();
        axes.insert(
            "a".to_string(),
            Axis::Range {
                min: toml::Value::Float(500.0),
                max: toml::Value::Float(1200.0),
            },
        );
        axes.insert(
            "b".to_string(),
            Axis::Range {
                min: toml::Value::Integer(11),
                max: toml::Value::Integer(41),
            },
        );
        let p = SweepParams {
            design: Design::Lhs,
            samples: 7,
            seed: 3,
            axes,
            set: BTreeMap::new(),
        };
        p.check().unwrap();
        let pts = sweep_points(&p);
        assert_eq!(pts.len(), 7);
        let mut strata: Vec<usize> = pts
            .iter()
            .map(|pt| ((pt[0].as_float().unwrap() - 500.0) / 700.0 * 7.0) as usize)
            .collect();
        strata.sort();
        assert_eq!(strata, (0..7).collect::<Vec<_>>());
        assert!(
            pts.iter()
                .all(|pt| pt[1].is_integer() && (11..=41).contains(&pt[1].as_integer().unwrap()))
        );
        // Same seed, same design; another seed, another design.
        assert_eq!(sweep_points(&p), pts);
        assert_ne!(
            sweep_points(&SweepParams {
                seed: 4,
                ..p.clone()
            }),
            pts
        );
    }

    #[test]
    fn grid_is_the_cartesian_product() {
        let mut axes = BTreeMap::new();
        axes.insert(
            "k".to_string(),
            Axis::Values(vec![1.into(), 2.into(), 3.into()]),
        );
        axes.insert(
            "s".to_string(),
            Axis::Values(vec!["static".into(), "implicit-euler".into()]),
        );
        let p = SweepParams {
            design: Design::Grid,
            samples: 0,
            seed: 0,
            axes,
            set: BTreeMap::new(),
        };
        let pts = sweep_points(&p);
        assert_eq!(pts.len(), 6);
        assert_eq!(
            pts[1],
            vec![
                toml::Value::Integer(1),
                toml::Value::String("implicit-euler".into())
            ]
        );
    }
}
