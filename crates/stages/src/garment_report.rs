//! The stage kind over [`drapelab_reports::garment_report`]: its slots and parameters checked when the plan loads,
//! and a call of the workflow with the stage's files.

use anyhow::Result;
use drapelab_pipeline::{Slot, StageContext, StageKind};
pub use drapelab_reports::garment_report::*;

/// The garments' measures.
const MEASURES: Slot = Slot::many(
    "measures",
    "garment stages' garment.parquet files, one per fabric",
);
/// Their pictures.
const PICTURES: Slot = Slot::optional_many(
    "pictures",
    "pictures of the drapes (e.g. surface stages' .png), in the measures' order",
);

/// The `garment-report` stage kind.
pub struct GarmentReport;

impl StageKind for GarmentReport {
    type Params = GarmentReportParams;
    const KIND: &'static str = "garment-report";
    const SUMMARY: &'static str = "Markdown of a garment draped in calibrated fabrics: solves, the hem's flare with its interval, pictures";
    const INPUTS: &'static [Slot] = &[MEASURES, PICTURES];
    const OUTPUTS: &'static [Slot] = &[Slot::one("markdown", "the report, .md")];
    fn run(ctx: &StageContext<'_>, p: &GarmentReportParams) -> Result<()> {
        let inputs = GarmentReportInputs {
            measures: ctx.files(&MEASURES),
            pictures: ctx.files(&PICTURES),
        };
        run(&crate::job(ctx, inputs), p)
    }
}
