//! The stage kind over [`drapelab_app::wrinkles::full`] and [`drapelab_reports::wrinkles_report`]:
//! seed 002's hung sheets as full simulations beside the seed and the tension-field model.

use anyhow::Result;
use drapelab_app::wrinkles::full::simulate;
pub use drapelab_app::wrinkles::params::WrinklesSimulateParams;
use drapelab_app::wrinkles::tables::write_outputs;
use drapelab_pipeline::{KeyError, Slot, StageContext, StageKind};

/// The `wrinkles-simulate` stage kind.
pub struct WrinklesSimulate;

impl StageKind for WrinklesSimulate {
    type Params = WrinklesSimulateParams;
    const KIND: &'static str = "wrinkles-simulate";
    const SUMMARY: &'static str = "Seed 002's hung sheets as full continuum simulations on two meshes, beside the seed's tables and the tension-field model";
    const INPUTS: &'static [Slot] = &[crate::WRINKLE_CONFIG_SLOT];
    const OUTPUTS: &'static [Slot] = &[
        Slot::optional(
            "table",
            "wrinkles_full.parquet: one row per case and reading",
        ),
        Slot::optional("fibres", "fibres.parquet: the sheets' centre fibres"),
        Slot::optional(
            "starts",
            "starts.parquet: every case from every start, coarser mesh",
        ),
        Slot::optional("recording", "the simulated sheets as rerun meshes, .rrd"),
        Slot::optional("sheets", "the simulated sheets as a picture strip, .png"),
        Slot::optional("fibres_plot", "the centre fibres, .svg"),
        Slot::optional("markdown", "the report, .md"),
    ];
    fn check(p: &WrinklesSimulateParams) -> Result<(), KeyError> {
        p.check()
    }
    fn run(ctx: &StageContext<'_>, p: &WrinklesSimulateParams) -> Result<()> {
        let cfg = drapelab_core::wrinkles::load_config(&ctx.file(&crate::WRINKLE_CONFIG_SLOT)?)?;
        let job = &crate::job(ctx, ());
        let found = simulate(job, &cfg, p)?;
        write_outputs(job, &found, p)?;
        drapelab_reports::wrinkles_report::write_report(job, &cfg, &found, p)
    }
}
