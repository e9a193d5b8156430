//! `benchmark` (issue 8): every input scene × size × tolerance × solver, with its time, work, memory
//! and error, into a Parquet table; optionally seed 000's slack-net population. The sibling kinds are
//! `peers`, `skips` and `benchmark-report`.

use crate::report::f64s;
use anyhow::{Context, Result, bail};
use arrow::array::{ArrayRef, Float64Array, RecordBatch, StringArray, UInt64Array};
use arrow::datatypes::{DataType, Field, Schema};
use drapelab_core::benchmark::{BenchLimits, BenchRow, bench_rows};
use drapelab_core::scene::{Scene, SolverKind};
use drapelab_pipeline::{Slot, StageContext, StageKind};
use drapelab_record::write_parquet;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::sync::Arc;

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
}

pub(crate) fn default_sizes() -> Vec<usize> {
    vec![11, 21, 41]
}
fn default_tols() -> Vec<f64> {
    vec![1e-4, 1e-6, 1e-8]
}
fn default_explicit() -> usize {
    21
}

/// Runs a benchmark stage.
/// The `benchmark` stage kind.
pub struct Benchmark;

impl StageKind for Benchmark {
    type Params = BenchmarkParams;
    const KIND: &'static str = "benchmark";
    const SUMMARY: &'static str =
        "Every scene × size × tolerance × solver: time, work, memory, error";
    const INPUTS: &'static [Slot] = &[Slot::many("scenes", "scene TOMLs")];
    const OUTPUTS: &'static [Slot] = &[
        Slot::one("table", "bench.parquet: one row per point"),
        Slot::optional(
            "population",
            "population.parquet, with params.slack_net_population",
        ),
    ];
    fn run(ctx: &StageContext<'_>, p: &BenchmarkParams) -> Result<()> {
        run(ctx, p)
    }
}

fn run(ctx: &StageContext<'_>, p: &BenchmarkParams) -> Result<()> {
    let scenes: Vec<Scene> = ctx
        .input_files("scenes")
        .iter()
        .map(|f| Ok(Scene::load(f, &[])?.scene.into_inner()))
        .collect::<Result<_>>()?;
    if scenes.is_empty() {
        bail!("a benchmark needs at least one scene file as input");
    }
    ctx.progress
        .stage_started(&ctx.stage.name, scenes.len() as u64);
    let limits = BenchLimits {
        solvers: p
            .solvers
            .clone()
            .unwrap_or_else(|| drapelab_core::benchmark::ALL_SOLVERS.to_vec()),
        max_explicit_size: p.max_explicit_size,
        max_implicit_size: p.max_implicit_size,
        exact_elastica: p.exact_elastica,
        max_wall_time_s: p.max_wall_time_s,
    };
    // Serial on purpose: the points are timed, and peak memory is per process.
    let mut rows: Vec<BenchRow> = Vec::new();
    for s in &scenes {
        let sizes = p.sizes.get(&s.name).unwrap_or(&p.default_sizes);
        rows.extend(bench_rows(s, sizes, &p.tolerances, &limits, |_| {}));
        ctx.progress.item_done(&ctx.stage.name);
    }
    let schema = Arc::new(Schema::new(vec![
        Field::new("scene", DataType::Utf8, false),
        Field::new("particles_per_side", DataType::UInt64, false),
        Field::new("solver", DataType::Utf8, false),
        Field::new("tolerance_rel", DataType::Float64, false),
        Field::new("status", DataType::Utf8, false),
        Field::new("wall_time_s", DataType::Float64, false),
        Field::new("iterations", DataType::UInt64, false),
        Field::new("linear_solves", DataType::UInt64, false),
        Field::new("factorizations", DataType::UInt64, false),
        Field::new("factor_time_s", DataType::Float64, false),
        Field::new("error_m", DataType::Float64, true),
        Field::new("peak_rss_bytes", DataType::UInt64, true),
    ]));
    let cols: Vec<ArrayRef> = vec![
        Arc::new(StringArray::from_iter_values(
            rows.iter().map(|r| r.scene.clone()),
        )),
        Arc::new(UInt64Array::from_iter_values(
            rows.iter().map(|r| r.n as u64),
        )),
        Arc::new(StringArray::from_iter_values(
            rows.iter().map(|r| r.solver.name().to_string()),
        )),
        f64s(rows.iter().map(|r| r.tol).collect()),
        Arc::new(StringArray::from_iter_values(
            rows.iter().map(|r| r.status.clone()),
        )),
        f64s(rows.iter().map(|r| r.wall_time_s).collect()),
        Arc::new(UInt64Array::from_iter_values(
            rows.iter().map(|r| r.iterations as u64),
        )),
        Arc::new(UInt64Array::from_iter_values(
            rows.iter().map(|r| r.linear_solves as u64),
        )),
        Arc::new(UInt64Array::from_iter_values(
            rows.iter().map(|r| r.factorizations as u64),
        )),
        f64s(rows.iter().map(|r| r.factor_time_s).collect()),
        Arc::new(Float64Array::from_iter(
            rows.iter()
                .map(|r| r.error_m.is_finite().then_some(r.error_m)),
        )),
        Arc::new(UInt64Array::from_iter(
            rows.iter().map(|r| r.peak_rss_bytes),
        )),
    ];
    write_parquet(
        ctx.output("table")?,
        &RecordBatch::try_new(schema, cols)?,
        None,
    )?;
    if p.slack_net_population > 0 {
        let out = ctx
            .optional_output("population")
            .context("slack_net_population needs the output `population`")?;
        let mut rows =
            drapelab_core::benchmark::slack_net_population(&scenes[0], p.slack_net_population, 8);
        rows.extend(
            drapelab_core::benchmark::warm_start_population(&scenes[0], p.slack_net_population, 9)
                .0,
        );
        write_population(out, &rows)?;
    }
    Ok(())
}

/// Writes the slack-net population's solves as a Parquet table.
fn write_population(
    out: &std::path::Path,
    rows: &[drapelab_core::benchmark::PopulationRow],
) -> Result<()> {
    let schema = Arc::new(Schema::new(vec![
        Field::new("start", DataType::Utf8, false),
        Field::new("stiffness_N_per_m", DataType::Float64, false),
        Field::new("natural_length_m", DataType::Float64, false),
        Field::new("topology", DataType::Utf8, false),
        Field::new("areal_density_kg_per_m2", DataType::Float64, false),
        Field::new("status", DataType::Utf8, false),
        Field::new("iterations", DataType::UInt64, false),
        Field::new("factorizations", DataType::UInt64, false),
        Field::new("wall_time_s", DataType::Float64, false),
        Field::new("factor_time_s", DataType::Float64, false),
    ]));
    let u64s = |f: &dyn Fn(&drapelab_core::benchmark::PopulationRow) -> usize| -> ArrayRef {
        Arc::new(UInt64Array::from_iter_values(
            rows.iter().map(|r| f(r) as u64),
        ))
    };
    let strs = |f: &dyn Fn(&drapelab_core::benchmark::PopulationRow) -> String| -> ArrayRef {
        Arc::new(StringArray::from_iter_values(rows.iter().map(f)))
    };
    let cols: Vec<ArrayRef> = vec![
        strs(&|r| r.start.clone()),
        f64s(rows.iter().map(|r| r.stiffness_N_per_m).collect()),
        f64s(rows.iter().map(|r| r.natural_length_m).collect()),
        strs(&|r| r.topology.clone()),
        f64s(rows.iter().map(|r| r.areal_density_kg_per_m2).collect()),
        strs(&|r| r.status.clone()),
        u64s(&|r| r.iterations),
        u64s(&|r| r.factorizations),
        f64s(rows.iter().map(|r| r.wall_time_s).collect()),
        f64s(rows.iter().map(|r| r.factor_time_s).collect()),
    ];
    write_parquet(out, &RecordBatch::try_new(schema, cols)?, None)
}
