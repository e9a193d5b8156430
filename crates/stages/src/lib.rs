//! drapelab-stages: the stage kinds of drapelab's pipelines, one file each, glue over the library
//! (`drapelab-core` for the science, `drapelab-record` for the files), and the report helpers
//! (Markdown tables from polars, plots with plotters). [`registry`] lists every kind: adding one is
//! a file here and a line there.

#![allow(non_snake_case)]

mod benchmark;
mod benchmark_report;
mod calibrate;
mod calibration_report;
mod calibration_tables;
mod cusick_measure;
mod cusick_plots;
mod cusick_predict;
mod cusick_report;
mod cusick_tables;
mod fit_edges;
mod montage;
mod peers;
pub mod report;
mod score;
mod seed003_report;
mod simulate;
mod skips;
mod surface;
mod sweep;
mod sweep_table;
mod tune;
mod validate;
mod wrinkles;

pub use benchmark::{Benchmark, BenchmarkParams};
pub use benchmark_report::{BenchmarkReport, BenchmarkReportParams};
pub use calibrate::{Calibrate, CalibrateParams};
pub use calibration_report::{CalibrationReport, CalibrationReportParams};
pub use cusick_measure::{CusickMeasure, CusickMeasureParams, ShadowRow, measure_dataset};
pub use cusick_predict::{CusickPredict, CusickPredictParams};
pub use cusick_report::{CusickReport, CusickReportParams, dc_within, nodes_within};
pub use cusick_tables::{OutlineRow, PredictionRow, ProfileRow};
pub use fit_edges::{FitEdges, FitEdgesParams};
pub use peers::{Peers, PeersParams};
pub use report::{Report, ReportParams};
pub use score::{Score, ScoreParams};
pub use seed003_report::{Seed003Report, Seed003ReportParams};
pub use simulate::{Simulate, SimulateParams};
pub use skips::{Skips, SkipsParams};
pub use surface::{
    Drape, Dressed, Surface, SurfaceOutputs, SurfaceParams, SurfaceSummary, dress, load_run,
    load_texture, make_surface, picture, solve_drape,
};
pub use sweep::{Axis, Design, Sweep, SweepParams, sweep_points};
pub use tune::{Levels, Tune, TuneParams};
pub use validate::{Validate, ValidateParams};
pub use wrinkles::{
    SolvedCase, WrinkleOutputs, Wrinkles, WrinklesParams, report_markdown, write_wrinkles,
};

use drapelab_pipeline::{Registry, Slot};

/// The measured edges of the calibration stages (a fit-edges table).
const EDGES_SLOT: Slot = Slot::one(
    "edges",
    "measured edges of every sample (a fit-edges table)",
);
/// Table 2's densities of the calibration stages.
const SAMPLES_SLOT: Slot = Slot::one("samples", "Table 2's densities (knitted_samples.csv)");
/// The hang scene of the calibration stages.
const SCENE_SLOT: Slot = Slot::one("scene", "the hang scene each sample is simulated in");

/// Loads scene `file` with the overrides a stage's parameters make; an error an override causes
/// names the pipeline, the stage and the parameter (`param_key` of the override's scene key), and
/// the scene.
pub(crate) fn load_scene(
    ctx: &drapelab_pipeline::StageContext<'_>,
    file: &std::path::Path,
    overrides: &[(String, toml::Value)],
    param_key: impl Fn(&str) -> String,
) -> anyhow::Result<drapelab_core::scene::LoadedScene> {
    drapelab_core::scene::Scene::load(file, overrides).map_err(|e| {
        match drapelab_core::config::override_culprit(&e.key, overrides) {
            Some(i) => ctx
                .param_error(
                    &param_key(&overrides[i].0),
                    format!("{} (scene {}, key `{}`)", e.message, file.display(), e.key),
                )
                .into(),
            None => e.into(),
        }
    })
}

/// Every stage kind drapelab knows.
pub fn registry() -> Registry {
    Registry::new()
        .with::<Simulate>()
        .with_items::<Sweep>()
        .with::<Report>()
        .with::<FitEdges>()
        .with::<Score>()
        .with_items::<Calibrate>()
        .with::<Validate>()
        .with::<Tune>()
        .with::<CalibrationReport>()
        .with::<Wrinkles>()
        .with::<Seed003Report>()
        .with::<Benchmark>()
        .with::<Peers>()
        .with::<BenchmarkReport>()
        .with::<Skips>()
        .with::<CusickMeasure>()
        .with::<CusickPredict>()
        .with::<CusickReport>()
        .with::<Surface>()
}

/// Every Parquet table drapelab writes, each traced from its row type, as the Markdown the README's
/// "Tables" section holds (`drapelab tables` prints it).
pub fn tables_markdown() -> anyhow::Result<String> {
    use drapelab_record::table_markdown as md;
    let sections = [
        md::<drapelab_record::ParticleRow>()?,
        md::<drapelab_record::EdgeRow>()?,
        md::<sweep_table::SweepPoint>()?,
        md::<sweep_table::SweepOutcome>()?,
        md::<drapelab_core::edges::ScoreRow>()?,
        md::<calibration_tables::ResultRow>()?,
        md::<calibration_tables::ComparisonRow>()?,
        md::<calibration_tables::EvaluationRow>()?,
        md::<validate::ValidationRow>()?,
        md::<tune::TuneRow>()?,
        md::<tune::MainEffectRow>()?,
        md::<wrinkles::WrinkleRow>()?,
        md::<wrinkles::WrinkleMeshRow>()?,
        md::<drapelab_core::benchmark::BenchRow>()?,
        md::<drapelab_core::benchmark::PopulationRow>()?,
        md::<drapelab_core::benchmark::SkipRow>()?,
        md::<peers::PeerRow>()?,
        md::<cusick_measure::ShadowRow>()?,
        md::<cusick_tables::PredictionRow>()?,
        md::<cusick_tables::OutlineRow>()?,
        md::<cusick_tables::ProfileRow>()?,
    ];
    Ok(sections.join("\n"))
}
