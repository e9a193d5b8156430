//! The stage kind over [`drapelab_app::surface`]: its slots and parameters checked when the plan loads,
//! and a call of the workflow with the stage's files.

use anyhow::Result;
pub use drapelab_app::surface::*;
use drapelab_pipeline::{KeyError, Slot, StageContext, StageKind};

/// The drape dressed.
const DRAPE: Slot = Slot::one(
    "drape",
    "a scene TOML (solved here) or a run's run.json (its particles.parquet beside it)",
);
/// Its texture.
const TEXTURE: Slot = Slot::optional(
    "texture",
    "the texture image, PNG or JPEG (default: drapelab's woven check)",
);

/// The `surface` stage kind.
pub struct Surface;

impl StageKind for Surface {
    type Params = SurfaceParams;
    const KIND: &'static str = "surface";
    const SUMMARY: &'static str = "A drape as a smooth textured B-spline surface: drape.glb, a picture, a rerun recording (seed 003 §10.8)";
    const INPUTS: &'static [Slot] = &[DRAPE, TEXTURE];
    const OUTPUTS: &'static [Slot] = &[
        Slot::optional("glb", "the textured surface, binary glTF 2.0 (.glb)"),
        Slot::optional("picture", "the textured drape rendered, .png"),
        Slot::optional(
            "recording",
            "the textured surface as a rerun recording, .rrd",
        ),
        Slot::optional("summary", "counts, areas and settings, .json"),
    ];
    fn check(p: &SurfaceParams) -> Result<(), KeyError> {
        p.check()
    }
    fn run(ctx: &StageContext<'_>, p: &SurfaceParams) -> Result<()> {
        let inputs = SurfaceInputs {
            drape: ctx.file(&DRAPE)?,
            texture: ctx.optional_file(&TEXTURE)?,
        };
        let ctx = &crate::job(ctx, inputs);
        run(ctx, p)
    }
}
