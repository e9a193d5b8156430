//! What each skip the engine makes saves, measured on and off in the same process: the quarter model
//! instead of the whole sheet, the calibration's cost cache, the contact term a scene does not need,
//! and the second thread of a calibration population. (Recording off and an up-to-date stage are
//! measured by the `skips` stage, which has the recorders and the pipeline engine.)

use crate::calibrate::{Noise, Problem, identifiability};
use crate::obstacle::Obstacle;
use crate::scene::Scene;
use crate::simulate::solve_scene;
use crate::solve::NoObserver;
use crate::table::Table;
use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// One skip, timed with and without it.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct SkipRow {
    /// What is skipped.
    pub skip: String,
    /// The scene it was measured on.
    pub scene: String,
    /// Wall time with the skip, s.
    pub time_with_skip_s: f64,
    /// Wall time without it, s.
    pub time_without_skip_s: f64,
    /// 1 − with / without: the fraction of the time the skip saves.
    pub saved_fraction: f64,
}

impl SkipRow {
    /// The row of a skip timed `with` and `without` it (s).
    pub fn new(skip: impl Into<String>, scene: impl Into<String>, with: f64, without: f64) -> Self {
        SkipRow {
            skip: skip.into(),
            scene: scene.into(),
            time_with_skip_s: with,
            time_without_skip_s: without,
            saved_fraction: 1.0 - with / without,
        }
    }
}

impl Table for SkipRow {
    const FILE: &'static str = "skips.parquet";
    const ROW: &'static str =
        "One skip drapelab makes (work a scene does not need), timed with and without it.";
}

fn timed(f: &mut dyn FnMut()) -> f64 {
    let t = Instant::now();
    f();
    t.elapsed().as_secs_f64()
}

/// Symmetry: the quarter model instead of the whole sheet (the same drape, tests/it/contact.rs).
pub fn skip_symmetry(full: &Scene, quarter: &Scene) -> SkipRow {
    let tq = timed(&mut || {
        solve_scene(quarter, &mut NoObserver);
    });
    let tf = timed(&mut || {
        solve_scene(full, &mut NoObserver);
    });
    SkipRow::new(
        "symmetry reduction (quarter model)",
        full.name.clone(),
        tq,
        tf,
    )
}

/// The hang on seed 000's net at 11 × 11 with a measured drape to calibrate against.
fn probe(hang: &Scene) -> Result<(Scene, Problem, Vec<crate::edges::EdgeFit>)> {
    let mut net = hang.clone();
    net.cloth.nx = 11;
    net.cloth.ny = 11;
    let probe = Problem::new(net.clone(), vec![], 50.0);
    let measured = probe
        .drape(&[0.4, 0.5, 0.5, 0.3, 0.1])
        .1
        .context("the reference drape did not converge")?;
    Ok((net, probe, measured))
}

/// Cached parameter vectors: the identifiability analysis with the cost cache on and off. It sweeps
/// damping and the elongation rate, which a static drape does not see: the cache (keyed on stiffness,
/// natural length and topology) answers those sweeps.
pub fn skip_cost_cache(hang: &Scene) -> Result<SkipRow> {
    let (net, probe, measured) = probe(hang)?;
    let best = [0.4, 0.5, 0.5, 0.3, 0.1];
    let mut t = [0.0; 2];
    for (k, caching) in [true, false].into_iter().enumerate() {
        // Sharing the probe's warm-start lattice, so that only the costs are timed.
        let mut problem = probe.fresh();
        problem.measured = measured.clone();
        problem.caching = caching;
        t[k] = timed(&mut || {
            identifiability(&problem, &best, 0.1, 7, Noise::FromResidual, 0.05);
        });
    }
    Ok(SkipRow::new(
        "cached parameter vectors (identifiability analysis)",
        net.name,
        t[0],
        t[1],
    ))
}

/// Terms a scene does not need: the hang (no obstacle, so no contact term is built) against the same
/// scene with a floor 10 m below that it never reaches (the barrier term is built and evaluated every
/// iteration). 19 a side: both solve from flat (no coarse start). Best of three.
pub fn skip_unneeded_terms(hang: &Scene) -> SkipRow {
    let mut bare = hang.clone();
    bare.cloth.nx = 19;
    bare.cloth.ny = 19;
    let mut floored = bare.clone();
    floored.obstacles.push(Obstacle::Plane {
        point_m: [0.0, 0.0, -10.0],
        normal: [0.0, 0.0, 1.0],
    });
    let mut t = [0.0; 2];
    for (k, s) in [&bare, &floored].into_iter().enumerate() {
        let mut best = f64::INFINITY;
        for _ in 0..3 {
            best = best.min(timed(&mut || {
                solve_scene(s, &mut NoObserver);
            }));
        }
        t[k] = best;
    }
    SkipRow::new(
        "contact term not built (no obstacle within reach)",
        format!("{} 19×19", hang.name),
        t[0],
        t[1],
    )
}

/// Threads: one ICA population (16 countries of a calibration, the cache off) costed on a rayon pool
/// of 2 threads against 1.
pub fn skip_second_thread(hang: &Scene) -> Result<SkipRow> {
    let (net, probe, measured) = probe(hang)?;
    let mut rng = <rand::rngs::StdRng as rand::SeedableRng>::seed_from_u64(7);
    let population: Vec<Vec<f64>> = (0..16)
        .map(|_| (0..5).map(|_| rand::Rng::random::<f64>(&mut rng)).collect())
        .collect();
    let mut problem = probe.fresh();
    problem.measured = measured;
    problem.caching = false;
    let mut t = [0.0; 2];
    for (k, threads) in [2usize, 1].into_iter().enumerate() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()?;
        t[k] = timed(&mut || {
            pool.install(|| {
                use rayon::prelude::*;
                let _: Vec<f64> = population.par_iter().map(|u| problem.cost(u)).collect();
            });
        });
    }
    Ok(SkipRow::new(
        "second thread (one calibration population of 16, 2 threads against 1)",
        format!("{} 11×11", net.name),
        t[0],
        t[1],
    ))
}
