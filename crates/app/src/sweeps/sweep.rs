//! `sweep`: every input scene solved at every point of a grid or a Latin hypercube over scene keys,
//! one item per scene and point (a part each, run by the pipeline's executor), gathered into one
//! Parquet table. The schema is documented in the README.

use crate::job::Job;
use crate::sweeps::table::{SweepOutcome, SweepPoint, as_f64, write_sweep};
use anyhow::{Result, bail};
use drapelab_core::error::KeyError;
use drapelab_core::scene::Scene;
use drapelab_core::simulate::solve_scene;
use drapelab_core::solve::NoObserver;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

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

/// Default of `samples`: 16 points of a Latin hypercube.
pub fn default_samples() -> usize {
    16
}

impl SweepParams {
    /// Checks the axes against the design: Err(KeyError::new(key, message)).
    pub fn check(&self) -> Result<(), KeyError> {
        if self.axes.is_empty() && self.design == Design::Lhs {
            return Err(KeyError::new(
                "axes",
                "a Latin hypercube needs at least one axis",
            ));
        }
        for (k, a) in &self.axes {
            match a {
                Axis::Values(v) if v.is_empty() => {
                    return Err(KeyError::new(
                        format!("axes.{k}"),
                        "an empty list of values",
                    ));
                }
                Axis::Range { min, max } => {
                    if self.design == Design::Grid {
                        return Err(KeyError::new(
                            format!("axes.{k}"),
                            "a grid needs a list of values; ranges are for design = \"lhs\"",
                        ));
                    }
                    match (as_f64(min), as_f64(max)) {
                        (Some(a), Some(b)) if a.is_finite() && b.is_finite() && a <= b => {}
                        _ => {
                            return Err(KeyError::new(
                                format!("axes.{k}"),
                                "min and max must be finite numbers with min ≤ max",
                            ));
                        }
                    }
                }
                _ => {}
            }
        }
        if self.design == Design::Lhs && self.samples == 0 {
            return Err(KeyError::new("samples", "must be ≥ 1"));
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

/// The scene of item `k`: scene file `k / points`, design point `k % points`, with the sweep's keys
/// set (recording off).
pub fn item_scene(
    ctx: &Job<'_, SweepInputs>,
    files: &[std::path::PathBuf],
    p: &SweepParams,
    points: &[Vec<toml::Value>],
    k: usize,
) -> Result<(u32, Scene)> {
    let (file, i) = (&files[k / points.len()], k % points.len());
    let mut overrides: Vec<(String, toml::Value)> =
        p.set.iter().map(|(k, v)| (k.clone(), v.clone())).collect();
    for (key, v) in p.axes.keys().zip(&points[i]) {
        for sub in key.split(',') {
            overrides.push((sub.trim().to_string(), v.clone()));
        }
    }
    let param_key = |k: &str| match p.axes.keys().find(|a| a.split(',').any(|s| s.trim() == k)) {
        Some(axis) => format!("axes.\"{axis}\""),
        None => format!("set.\"{k}\""),
    };
    let mut scene = ctx
        .load_scene(file, &overrides, param_key)?
        .scene
        .into_inner();
    scene.record.timeline = false;
    scene.record.rerun = false;
    Ok((i as u32, scene))
}

/// The input of a sweep stage.
pub struct SweepInputs {
    /// Scene TOMLs, each solved at every point.
    pub scenes: Vec<std::path::PathBuf>,
}

/// The scene files of the stage, at least one.
pub fn scene_files<'a>(ctx: &'a Job<'_, SweepInputs>) -> Result<&'a [std::path::PathBuf]> {
    let files = ctx.inputs.scenes.as_slice();
    if files.is_empty() {
        bail!("input `scenes` matched no scene file");
    }
    Ok(files)
}

/// Solves one point and measures its drape (when it converged).
pub fn solve_point(scene: &Scene, i: u32) -> (SweepPoint, SweepOutcome) {
    let sol = solve_scene(scene, &mut NoObserver);
    let point = SweepPoint {
        scene: scene.name.clone(),
        point: i,
    };
    (point, SweepOutcome::new(scene, &sol))
}

/// The `count` of the stage kind over this workflow.
pub fn count(ctx: &Job<'_, SweepInputs>, p: &SweepParams) -> Result<usize> {
    let files = scene_files(ctx)?;
    let points = sweep_points(p);
    let n = files.len() * points.len();
    for k in 0..n {
        item_scene(ctx, files, p, &points, k)?;
    }
    Ok(n)
}

/// The `compute` of the stage kind over this workflow.
pub fn compute(
    ctx: &Job<'_, SweepInputs>,
    p: &SweepParams,
    item: usize,
    part: &Path,
) -> Result<()> {
    let points = sweep_points(p);
    let (i, scene) = item_scene(ctx, scene_files(ctx)?, p, &points, item)?;
    let keys: Vec<&String> = p.axes.keys().collect();
    write_sweep(part, &[solve_point(&scene, i)], &points, &keys)
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
