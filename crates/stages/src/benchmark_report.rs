//! The stage kind over [`drapelab_reports::benchmark_report`]: its slots and parameters checked when the plan loads,
//! and a call of the workflow with the stage's files.

use anyhow::Result;
use drapelab_pipeline::{Slot, StageContext, StageKind};
pub use drapelab_reports::benchmark_report::*;

/// The `benchmark-report` stage kind.
pub struct BenchmarkReport;

impl StageKind for BenchmarkReport {
    type Params = BenchmarkReportParams;
    const KIND: &'static str = "benchmark-report";
    const SUMMARY: &'static str =
        "Pareto fronts, scaling exponents, skips and peer ratios from the benchmark tables";
    const INPUTS: &'static [Slot] = &[
        Slot::many("bench", "bench.parquet tables of benchmark stages"),
        Slot::optional("population", "population.parquet of a benchmark stage"),
        Slot::optional("peers", "peers.parquet"),
        Slot::optional("skips", "skips.parquet"),
        Slot::optional(
            "self_contact",
            "bench.parquet of a benchmark stage run with self-contact on and off",
        ),
    ];
    const OUTPUTS: &'static [Slot] = &[
        Slot::one("markdown", "the report, .md"),
        Slot::one("plot", "the Pareto fronts, .svg"),
    ];
    fn run(ctx: &StageContext<'_>, p: &BenchmarkReportParams) -> Result<()> {
        let ctx = &crate::job(ctx);
        run(ctx, p)
    }
}
