//! The stage kind over [`drapelab_app::photos::fit_edges`]: its slots and parameters checked when the plan loads,
//! and a call of the workflow with the stage's files.

use anyhow::Result;
pub use drapelab_app::photos::fit_edges::*;
use drapelab_pipeline::{Slot, StageContext, StageKind};

/// The photos fitted.
const PHOTOS: Slot = Slot::many(
    "photos",
    "photos (.png, .jpg), each with its camera.json beside it",
);

/// The `fit-edges` stage kind.
pub struct FitEdges;

impl StageKind for FitEdges {
    type Params = FitEdgesParams;
    const KIND: &'static str = "fit-edges";
    const SUMMARY: &'static str = "Fit edge polynomials to photos (seed 000 Figs 11-12)";
    const INPUTS: &'static [Slot] = &[
        PHOTOS,
        Slot::optional_many(
            "cameras",
            "the camera.json files beside the photos (listed so that a changed calibration reruns)",
        ),
    ];
    const OUTPUTS: &'static [Slot] = &[Slot::one("edges", "edges.parquet of every photo")];
    fn run(ctx: &StageContext<'_>, p: &FitEdgesParams) -> Result<()> {
        let photos = ctx.files(&PHOTOS);
        let ctx = &crate::job(ctx, FitEdgesInputs { photos });
        run(ctx, p).map(drop)
    }
}
