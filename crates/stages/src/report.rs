//! The stage kind over [`drapelab_reports::report`]: its slots and parameters checked when the plan loads,
//! and a call of the workflow with the stage's files.

use anyhow::Result;
use drapelab_pipeline::{KeyError, Slot, StageContext, StageKind};
pub use drapelab_reports::report::*;

/// The tables summarised.
const TABLES: Slot = Slot::many("tables", "sweep tables (a sweep stage's sweep.parquet)");

/// The `report` stage kind.
pub struct Report;

impl StageKind for Report {
    type Params = ReportParams;
    const KIND: &'static str = "report";
    const SUMMARY: &'static str = "Summaries and a plot over sweep tables, as Markdown";
    const INPUTS: &'static [Slot] = &[TABLES];
    const OUTPUTS: &'static [Slot] = &[
        Slot::one("markdown", "the report, .md"),
        Slot::one("plot", "the plot, .svg"),
    ];
    fn check(p: &ReportParams) -> Result<(), KeyError> {
        check(p)
    }
    fn run(ctx: &StageContext<'_>, p: &ReportParams) -> Result<()> {
        let tables = ctx.files(&TABLES);
        let ctx = &crate::job(ctx, ReportInputs { tables });
        run(ctx, p)
    }
}
