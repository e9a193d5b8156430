//! The stage kind over [`drapelab_app::seed003::solve`]: its slots and parameters checked when the plan
//! loads, and a call of the workflow with the stage's files.

use anyhow::Result;
pub use drapelab_app::seed003::solve::*;
use drapelab_pipeline::{Slot, StageContext, StageKind};

/// The scenes solved.
const SCENES: Slot = Slot::many(
    "scenes",
    "scene TOMLs, each solved at its grid and at twice its resolution",
);
/// Table 10.2's scene.
const QUARTER_TABLE: Slot = Slot::optional(
    "quarter_table",
    "the quarter table scene (one of `scenes`) put at Table 10.2's points",
);
/// Table 10.2.
pub(crate) const TABLE_REFERENCE: Slot = Slot::optional(
    "table_reference",
    "Table 10.2's edge points (fvm_table_drape_edges.csv)",
);
/// Table 10.4's scene.
const ROD: Slot = Slot::optional(
    "rod",
    "the rod scene (one of `scenes`) under every contact treatment and material, with a grid study",
);
/// Table 10.1's and §10.3.3's scene.
const CANTILEVER: Slot = Slot::optional(
    "cantilever",
    "the cantilever of §10.3.3 (load–displacement) and Table 10.1 (grids)",
);

/// The workflow's inputs from the stage's files.
fn inputs(ctx: &StageContext<'_>) -> Result<Seed003SolveInputs> {
    Ok(Seed003SolveInputs {
        scenes: ctx.files(&SCENES),
        quarter_table: ctx.optional_file(&QUARTER_TABLE)?,
        table_reference: ctx.optional_file(&TABLE_REFERENCE)?,
        rod: ctx.optional_file(&ROD)?,
        cantilever: ctx.optional_file(&CANTILEVER)?,
    })
}

/// The `seed003-solve` stage kind.
pub struct Seed003Solve;

impl StageKind for Seed003Solve {
    type Params = Seed003SolveParams;
    const KIND: &'static str = "seed003-solve";
    const SUMMARY: &'static str =
        "Seed 003's drape scenes at two grids, and the studies beside Tables 10.1, 10.2 and 10.4";
    const INPUTS: &'static [Slot] = &[SCENES, QUARTER_TABLE, TABLE_REFERENCE, ROD, CANTILEVER];
    const OUTPUTS: &'static [Slot] = &[
        Slot::one("scenes", "scenes.parquet: one row per scene"),
        Slot::one(
            "drapes",
            "drapes.parquet: every scene's particles at its grid",
        ),
        Slot::optional(
            "table_edges",
            "table_edges.parquet: Table 10.2's points (with quarter_table and table_reference)",
        ),
        Slot::optional(
            "rod",
            "rod.parquet: the rod's corners per treatment (with rod)",
        ),
        Slot::optional(
            "rod_grid",
            "rod_grid.parquet: the rod's grid study (with rod)",
        ),
        Slot::optional(
            "load_displacement",
            "load_displacement.parquet: the cantilever's load steps (with cantilever)",
        ),
        Slot::optional(
            "cantilever_grid",
            "cantilever_grid.parquet: Table 10.1's grids (with cantilever)",
        ),
    ];
    /// An output whose inputs are not given is refused when the plan loads.
    fn precheck(ctx: &StageContext<'_>, _: &Seed003SolveParams) -> Result<()> {
        check_outputs(&crate::job(ctx, inputs(ctx)?))
    }
    fn run(ctx: &StageContext<'_>, p: &Seed003SolveParams) -> Result<()> {
        run(&crate::job(ctx, inputs(ctx)?), p)
    }
}
