//! The stage kind over [`drapelab_app::sweeps::benchmark`]: its slots and parameters checked when the plan loads,
//! and a call of the workflow with the stage's files.

use anyhow::Result;
pub use drapelab_app::sweeps::benchmark::*;
use drapelab_pipeline::{Slot, StageContext, StageKind};

/// Runs a benchmark stage.
/// The scenes benchmarked.
const SCENES: Slot = Slot::many("scenes", "scene TOMLs");

/// The `benchmark` stage kind.
pub struct Benchmark;

impl StageKind for Benchmark {
    type Params = BenchmarkParams;
    const KIND: &'static str = "benchmark";
    const SUMMARY: &'static str =
        "Every scene × size × tolerance × solver: time, work, memory, error";
    const INPUTS: &'static [Slot] = &[SCENES];
    const OUTPUTS: &'static [Slot] = &[
        Slot::one("table", "bench.parquet: one row per point"),
        Slot::optional(
            "population",
            "population.parquet, with params.slack_net_population",
        ),
    ];
    fn run(ctx: &StageContext<'_>, p: &BenchmarkParams) -> Result<()> {
        let scenes = ctx.files(&SCENES);
        let ctx = &crate::job(ctx, BenchmarkInputs { scenes });
        run(ctx, p).map(drop)
    }
}
