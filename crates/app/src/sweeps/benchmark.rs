//! `benchmark` (issue 8): every input scene × size × tolerance × solver, with its time, work, memory
//! and error, into a Parquet table; optionally seed 000's slack-net population. The sibling kinds are
//! `peers`, `skips` and `benchmark-report`.

use crate::job::Job;
use anyhow::{Context, Result, bail};
use drapelab_core::benchmark::{BenchLimits, BenchRow, bench_rows};
use drapelab_core::scene::{Scene, SolverKind};
use drapelab_record::write_table;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// Parameters of a benchmark stage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BenchmarkParams {
    /// Particles per side, per scene name; scenes not named use `default_sizes`.
    #[serde(default)]
    pub sizes: BTreeMap<String, Vec<usize>>,
    /// Particles per side for scenes not in `sizes`. Default [11, 21, 41].
    #[serde(default = "default_sizes")]
    pub default_sizes: Vec<usize>,
    /// Force tolerances (largest residual / lightest particle's weight). Default [1e-4, 1e-6, 1e-8].
    #[serde(default = "default_tols")]
    pub tolerances: Vec<f64>,
    /// Solvers to run: "static", "implicit-euler", "symplectic-euler", "explicit-euler". Default all.
    #[serde(default)]
    pub solvers: Option<Vec<SolverKind>>,
    /// Largest side for the explicit integrators. Default 21.
    #[serde(default = "default_explicit")]
    pub max_explicit_size: usize,
    /// Largest side for implicit Euler. Default 21.
    #[serde(default = "default_explicit")]
    pub max_implicit_size: usize,
    /// Errors against the exact heavy elastica (scenes that are strips clamped at x-min) instead of
    /// the finest static solution. Default false.
    #[serde(default)]
    pub exact_elastica: bool,
    /// Wall-clock budget of one dynamic point in s: past it the point ends as max-iterations.
    /// Default none.
    #[serde(default)]
    pub max_wall_time_s: Option<f64>,
    /// Static solves of seed 000's slack-net population (the first scene on the 14 × 14 net over
    /// Table 3's box, [`drapelab_core::benchmark::slack_net_population`]) written to the output named
    /// `population.parquet`. Default 0 (none).
    #[serde(default)]
    pub slack_net_population: usize,
    /// The `contact.self` settings every point is solved with, a row each ("auto", "on", "off").
    /// Default ["auto"] (the scenes' own).
    #[serde(default = "default_self_contact")]
    pub self_contact: Vec<drapelab_core::scene::SelfContactMode>,
}

/// Default of `self_contact`: ["auto"].
pub fn default_self_contact() -> Vec<drapelab_core::scene::SelfContactMode> {
    vec![drapelab_core::scene::SelfContactMode::Auto]
}

/// Default of `default_sizes` (particles per side): [11, 21, 41].
pub fn default_sizes() -> Vec<usize> {
    vec![11, 21, 41]
}
/// Default of `tolerances` (force tolerances): [1e-4, 1e-6, 1e-8].
pub fn default_tols() -> Vec<f64> {
    vec![1e-4, 1e-6, 1e-8]
}
/// Default of `max_explicit_size` and of implicit Euler's largest side: 21.
pub fn default_explicit() -> usize {
    21
}

/// The input of a benchmark stage.
pub struct BenchmarkInputs {
    /// The scene TOMLs benchmarked.
    pub scenes: Vec<std::path::PathBuf>,
}

/// Runs the benchmark: every scene, size, tolerance and solver, one row each (run time against error).
pub fn run(ctx: &Job<'_, BenchmarkInputs>, p: &BenchmarkParams) -> Result<Vec<BenchRow>> {
    let scenes: Vec<Scene> = ctx
        .inputs
        .scenes
        .iter()
        .map(|f| Ok(Scene::load(f, &[])?.scene.into_inner()))
        .collect::<Result<_>>()?;
    if scenes.is_empty() {
        bail!("a benchmark needs at least one scene file as input");
    }
    ctx.started(scenes.len());
    let limits = BenchLimits {
        solvers: p
            .solvers
            .clone()
            .unwrap_or_else(|| drapelab_core::benchmark::ALL_SOLVERS.to_vec()),
        max_explicit_size: p.max_explicit_size,
        max_implicit_size: p.max_implicit_size,
        exact_elastica: p.exact_elastica,
        max_wall_time_s: p.max_wall_time_s,
        self_contact: p.self_contact.clone(),
    };
    // Serial on purpose: the points are timed, and peak memory is per process.
    let mut rows: Vec<BenchRow> = Vec::new();
    for s in &scenes {
        let sizes = p.sizes.get(&s.name).unwrap_or(&p.default_sizes);
        rows.extend(bench_rows(s, sizes, &p.tolerances, &limits, |_| {}));
        ctx.item_done();
    }
    write_table(ctx.output("table")?, &rows)?;
    if p.slack_net_population > 0 {
        let out = ctx
            .optional_output("population")
            .context("slack_net_population needs the output `population`")?;
        let mut population =
            drapelab_core::benchmark::slack_net_population(&scenes[0], p.slack_net_population, 8);
        population.extend(
            drapelab_core::benchmark::warm_start_population(&scenes[0], p.slack_net_population, 9)
                .0,
        );
        write_table(out, &population)?;
    }
    Ok(rows)
}
