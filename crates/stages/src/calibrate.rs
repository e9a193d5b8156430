//! The stage kind over [`drapelab_app::calibration::calibrate`]: its slots and parameters checked when the plan loads,
//! and a call of the workflow with the stage's files.

use anyhow::Result;
pub use drapelab_app::calibration::calibrate::*;
use drapelab_pipeline::{ItemKind, KeyError, Slot, StageContext, StageKind};
use std::path::{Path, PathBuf};

/// ICA's settings from a file.
const ICA: Slot = Slot::optional(
    "ica",
    "ICA settings as JSON (a tune stage's best_ica.json), with params.ica_from_input",
);

/// The workflow's inputs from the stage's files.
fn inputs(ctx: &StageContext<'_>) -> Result<CalibrateInputs> {
    Ok(CalibrateInputs {
        samples: crate::sample_inputs(
            ctx,
            [&crate::EDGES_SLOT, &crate::SAMPLES_SLOT, &crate::SCENE_SLOT],
        )?,
        ica: ctx.optional_file(&ICA)?,
    })
}

/// The `calibrate` stage kind.
pub struct Calibrate;

impl StageKind for Calibrate {
    type Params = CalibrateParams;
    const KIND: &'static str = "calibrate";
    const SUMMARY: &'static str =
        "ICA calibration of mass-spring parameters against measured edges";
    const INPUTS: &'static [Slot] = &[
        crate::EDGES_SLOT,
        crate::SAMPLES_SLOT,
        crate::SCENE_SLOT,
        ICA,
    ];
    const OUTPUTS: &'static [Slot] = &[
        Slot::one("results", "results.parquet: one row per sample"),
        Slot::optional(
            "evaluations",
            "evaluations.parquet: every country of every decade",
        ),
        Slot::optional(
            "recording",
            "calibration.rrd: the empires and best drapes, decade by decade",
        ),
        Slot::optional(
            "comparison",
            "comparison.parquet: ICA against the CMA-ES baseline per run",
        ),
    ];
    fn check(p: &CalibrateParams) -> Result<(), KeyError> {
        p.check()
    }
}

/// Items: the samples of the `edges` input, in name order; each sample's ICA runs stay in one item
/// (they share the sample's cost cache, and its results do not depend on the executor).
impl ItemKind for Calibrate {
    fn count(ctx: &StageContext<'_>, p: &CalibrateParams) -> Result<usize> {
        let ctx = &crate::job(ctx, inputs(ctx)?);
        count(ctx, p)
    }
    fn compute(
        ctx: &StageContext<'_>,
        p: &CalibrateParams,
        item: usize,
        part: &Path,
    ) -> Result<()> {
        let ctx = &crate::job(ctx, inputs(ctx)?);
        compute(ctx, p, item, part)
    }
    fn gather(ctx: &StageContext<'_>, _p: &CalibrateParams, parts: &[PathBuf]) -> Result<()> {
        let ctx = &crate::job(ctx, inputs(ctx)?);
        gather(ctx, parts)
    }
}
