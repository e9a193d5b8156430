//! The stage kind over [`drapelab_reports::benchmark_report`]: its slots and parameters checked when the plan loads,
//! and a call of the workflow with the stage's files.

use anyhow::Result;
use drapelab_pipeline::{Slot, StageContext, StageKind};
pub use drapelab_reports::benchmark_report::*;

/// The benchmark tables.
const BENCH: Slot = Slot::many("bench", "bench.parquet tables of benchmark stages");
/// A slack net's population.
const POPULATION: Slot = Slot::optional("population", "population.parquet of a benchmark stage");
/// The peers' table.
const PEERS: Slot = Slot::optional("peers", "peers.parquet");
/// The skips' table.
const SKIPS: Slot = Slot::optional("skips", "skips.parquet");
/// Self-contact on and off.
const SELF_CONTACT: Slot = Slot::optional(
    "self_contact",
    "bench.parquet of a benchmark stage run with self-contact on and off",
);

/// The `benchmark-report` stage kind.
pub struct BenchmarkReport;

impl StageKind for BenchmarkReport {
    type Params = BenchmarkReportParams;
    const KIND: &'static str = "benchmark-report";
    const SUMMARY: &'static str =
        "Pareto fronts, scaling exponents, skips and peer ratios from the benchmark tables";
    const INPUTS: &'static [Slot] = &[BENCH, POPULATION, PEERS, SKIPS, SELF_CONTACT];
    const OUTPUTS: &'static [Slot] = &[
        Slot::one("markdown", "the report, .md"),
        Slot::one("plot", "the Pareto fronts, .svg"),
    ];
    fn run(ctx: &StageContext<'_>, p: &BenchmarkReportParams) -> Result<()> {
        let inputs = BenchmarkReportInputs {
            bench: ctx.files(&BENCH),
            population: ctx.optional_file(&POPULATION)?,
            peers: ctx.optional_file(&PEERS)?,
            skips: ctx.optional_file(&SKIPS)?,
            self_contact: ctx.optional_file(&SELF_CONTACT)?,
        };
        let ctx = &crate::job(ctx, inputs);
        run(ctx, p)
    }
}
