//! The stage kind over [`drapelab_reports::seed003_report`]: its slots and parameters checked when the plan loads,
//! and a call of the workflow with the stage's files.

use anyhow::Result;
use drapelab_pipeline::{Slot, StageContext, StageKind};
pub use drapelab_reports::seed003_report::*;

/// The `seed003-report` stage kind.
pub struct Seed003Report;

impl StageKind for Seed003Report {
    type Params = Seed003ReportParams;
    const KIND: &'static str = "seed003-report";
    const SUMMARY: &'static str = "Seed 003's drape scenes beside the seed's numbers";
    const INPUTS: &'static [Slot] = &[
        Slot::many(
            "scenes",
            "scene TOMLs, each solved at its grid and at twice its resolution",
        ),
        Slot::optional(
            "quarter_table",
            "the quarter table scene compared with Table 10.2",
        ),
        Slot::optional(
            "table_reference",
            "Table 10.2's edge points (fvm_table_drape_edges.csv)",
        ),
        Slot::optional("rod", "the rod scene compared with Table 10.4"),
        Slot::optional(
            "rod_reference",
            "Table 10.4's corner A (fvm_rod_corner.csv)",
        ),
        Slot::optional("cantilever", "the cantilever of §10.3.3 and Table 10.1"),
        Slot::optional(
            "cantilever_reference",
            "Table 10.1's free end against the grid (fvm_cantilever_convergence.csv)",
        ),
        Slot::optional_many("sweeps", "sweep tables shown as they are"),
        Slot::optional_many(
            "surfaces",
            "pictures of textured drape surfaces (surface stages), shown in §10.8's section",
        ),
    ];
    const OUTPUTS: &'static [Slot] = &[
        Slot::one("markdown", "the report, .md"),
        Slot::one("drapes", "the drapes from above and from the side, .svg"),
        Slot::optional(
            "load_displacement",
            "the cantilever's load–displacement curve, .svg",
        ),
        Slot::optional("montage", "every drape rendered, .png"),
    ];
    fn run(ctx: &StageContext<'_>, p: &Seed003ReportParams) -> Result<()> {
        let ctx = &crate::job(ctx);
        run(ctx, p)
    }
}
