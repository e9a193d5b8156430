//! The stage kind over [`drapelab_reports::seed003_report`]: its slots and parameters checked when the plan loads,
//! and a call of the workflow with the stage's files.

use anyhow::Result;
use drapelab_pipeline::{Slot, StageContext, StageKind};
pub use drapelab_reports::seed003_report::*;

/// The scenes' table.
const SCENES: Slot = Slot::one("scenes", "a seed003-solve stage's scenes.parquet");
/// The drapes' table.
const DRAPES: Slot = Slot::one("drapes", "a seed003-solve stage's drapes.parquet");
/// Table 10.2's points.
const TABLE_EDGES: Slot = Slot::optional(
    "table_edges",
    "a seed003-solve stage's table_edges.parquet (Table 10.2, with table_reference)",
);
/// The rod's treatments.
const ROD: Slot = Slot::optional(
    "rod",
    "a seed003-solve stage's rod.parquet (Table 10.4, with rod_grid and rod_reference)",
);
/// The rod's grid study.
const ROD_GRID: Slot = Slot::optional("rod_grid", "a seed003-solve stage's rod_grid.parquet");
/// Table 10.4.
const ROD_REFERENCE: Slot = Slot::optional(
    "rod_reference",
    "Table 10.4's corner A (fvm_rod_corner.csv)",
);
/// §10.3.3's steps.
const LOAD_DISPLACEMENT: Slot = Slot::optional(
    "load_displacement",
    "a seed003-solve stage's load_displacement.parquet (§10.3.3)",
);
/// Table 10.1's grids.
const CANTILEVER_GRID: Slot = Slot::optional(
    "cantilever_grid",
    "a seed003-solve stage's cantilever_grid.parquet (Table 10.1, with cantilever_reference)",
);
/// Table 10.1.
const CANTILEVER_REFERENCE: Slot = Slot::optional(
    "cantilever_reference",
    "Table 10.1's free end against the grid (fvm_cantilever_convergence.csv)",
);
/// Sweep tables.
const SWEEPS: Slot = Slot::optional_many("sweeps", "sweep tables shown as they are");
/// §10.8's pictures.
const SURFACES: Slot = Slot::optional_many(
    "surfaces",
    "pictures of textured drape surfaces (surface stages), shown in §10.8's section",
);

/// The `seed003-report` stage kind.
pub struct Seed003Report;

impl StageKind for Seed003Report {
    type Params = Seed003ReportParams;
    const KIND: &'static str = "seed003-report";
    const SUMMARY: &'static str =
        "Seed 003's drape scenes beside the seed's numbers, from a seed003-solve stage's tables";
    const INPUTS: &'static [Slot] = &[
        SCENES,
        DRAPES,
        TABLE_EDGES,
        crate::seed003_solve::TABLE_REFERENCE,
        ROD,
        ROD_GRID,
        ROD_REFERENCE,
        LOAD_DISPLACEMENT,
        CANTILEVER_GRID,
        CANTILEVER_REFERENCE,
        SWEEPS,
        SURFACES,
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
        let inputs = Seed003ReportInputs {
            scenes: ctx.file(&SCENES)?,
            drapes: ctx.file(&DRAPES)?,
            table_edges: ctx.optional_file(&TABLE_EDGES)?,
            table_reference: ctx.optional_file(&crate::seed003_solve::TABLE_REFERENCE)?,
            rod: ctx.optional_file(&ROD)?,
            rod_grid: ctx.optional_file(&ROD_GRID)?,
            rod_reference: ctx.optional_file(&ROD_REFERENCE)?,
            load_displacement: ctx.optional_file(&LOAD_DISPLACEMENT)?,
            cantilever_grid: ctx.optional_file(&CANTILEVER_GRID)?,
            cantilever_reference: ctx.optional_file(&CANTILEVER_REFERENCE)?,
            sweeps: ctx.files(&SWEEPS),
            surfaces: ctx.files(&SURFACES),
        };
        let ctx = &crate::job(ctx, inputs);
        run(ctx, p)
    }
}
