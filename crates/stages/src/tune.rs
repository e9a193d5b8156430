//! The stage kind over [`drapelab_app::calibration::tune`]: its slots and parameters checked when the plan loads,
//! and a call of the workflow with the stage's files.

use anyhow::Result;
pub use drapelab_app::calibration::tune::*;
use drapelab_pipeline::{KeyError, Slot, StageContext, StageKind};

/// The `tune` stage kind.
pub struct Tune;

impl StageKind for Tune {
    type Params = TuneParams;
    const KIND: &'static str = "tune";
    const SUMMARY: &'static str =
        "Taguchi L27 tuning of ICA's seven settings (seed 000 Table 1, Fig. 10)";
    const INPUTS: &'static [Slot] = &[crate::EDGES_SLOT, crate::SAMPLES_SLOT, crate::SCENE_SLOT];
    const OUTPUTS: &'static [Slot] = &[
        Slot::one("table", "tune.parquet: one row per design row"),
        Slot::one(
            "main_effects",
            "main_effects.parquet: mean S/N of every factor level",
        ),
        Slot::one("best_ica", "best_ica.json: the best level of each factor"),
        Slot::optional("plot", "main_effects.svg"),
    ];
    fn check(p: &TuneParams) -> Result<(), KeyError> {
        if p.repeats == 0 {
            Err(KeyError::new("repeats", "must be ≥ 1"))
        } else {
            Ok(())
        }
    }
    fn run(ctx: &StageContext<'_>, p: &TuneParams) -> Result<()> {
        let files = [&crate::EDGES_SLOT, &crate::SAMPLES_SLOT, &crate::SCENE_SLOT];
        let job = crate::job(ctx, crate::sample_inputs(ctx, files)?);
        let outcome = run(&job, p)?;
        if let Some(svg) = job.optional_output("plot") {
            let text = drapelab_reports::report::plot_panels(
                &outcome.main_effects,
                "factor level (1..3)",
                "mean S/N (dB, smaller-the-better)",
                None,
            )?;
            drapelab_record::write_text(svg, &text)?;
        }
        Ok(())
    }
}
