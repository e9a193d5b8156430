//! drapelab's workflows, each a function over a [`Job`] (its typed input files, its outputs, its
//! progress) with typed parameters: simulate to a folder, fit photos and score them, tune and run
//! the ICA calibration, validate it, sweep scenes, measure and predict Cusick drapes, the benchmark
//! grids, seed 002's wrinkles, seed 003's scenes and studies, and §10.8's surfaces. Each returns what it found as typed values (the rows
//! it wrote, a solve report, a tuning's main effects); bad input is an `InputError` naming the file
//! or the stage's parameter. The pipeline's stages, the command line, the tests and the Python
//! package call them; the report stack (polars, plotters) is not here.

#![warn(missing_docs)]
#![allow(non_snake_case)]

pub mod job;

pub mod calibration;
pub mod cusick;
pub mod defaults;
pub mod garment;
pub mod photos;
pub mod scene_keys;
pub mod seed003;
pub mod simulate;
pub mod surface;
pub mod sweeps;
pub mod wrinkles;

pub use job::{Job, Progress, Quiet};

/// Points of each series (by label) on one panel of a plot, (x, y).
pub type Lines = std::collections::BTreeMap<String, Vec<(f64, f64)>>;
/// A plot's panels by facet value: what a workflow hands a report to draw.
pub type Panels = std::collections::BTreeMap<String, Lines>;

/// Every Parquet table drapelab writes, each traced from its row type, as the Markdown of the
/// book's Tables page (`drapelab tables` prints it).
pub fn tables_markdown() -> anyhow::Result<String> {
    use drapelab_record::table_markdown as md;
    let sections = [
        md::<drapelab_record::ParticleRow>()?,
        md::<drapelab_record::TriangleRow>()?,
        md::<drapelab_record::IterationRow>()?,
        md::<drapelab_record::SensitivityRow>()?,
        md::<drapelab_record::EdgeRow>()?,
        md::<crate::sweeps::table::SweepPoint>()?,
        md::<crate::sweeps::table::SweepOutcome>()?,
        md::<drapelab_core::edges::ScoreRow>()?,
        md::<crate::calibration::tables::ResultRow>()?,
        md::<crate::calibration::tables::ComparisonRow>()?,
        md::<crate::calibration::tables::EvaluationRow>()?,
        md::<crate::calibration::validate::ValidationRow>()?,
        md::<crate::calibration::tune::TuneRow>()?,
        md::<crate::calibration::tune::MainEffectRow>()?,
        md::<crate::wrinkles::WrinkleRow>()?,
        md::<crate::wrinkles::WrinkleMeshRow>()?,
        md::<crate::wrinkles::tables::WrinkleFullRow>()?,
        md::<crate::wrinkles::tables::FibreRow>()?,
        md::<crate::wrinkles::tables::StartRow>()?,
        md::<drapelab_core::benchmark::BenchRow>()?,
        md::<drapelab_core::benchmark::PopulationRow>()?,
        md::<drapelab_core::benchmark::SkipRow>()?,
        md::<crate::sweeps::peers::PeerRow>()?,
        md::<crate::cusick::measure::ShadowRow>()?,
        md::<crate::cusick::tables::PredictionRow>()?,
        md::<crate::garment::GarmentRow>()?,
        md::<crate::cusick::captures::CaptureRow>()?,
        md::<crate::cusick::tables::OutlineRow>()?,
        md::<crate::cusick::tables::ProfileRow>()?,
        md::<crate::seed003::tables::Seed003SceneRow>()?,
        md::<crate::seed003::tables::DrapeParticleRow>()?,
        md::<crate::seed003::tables::TableEdgeRow>()?,
        md::<crate::seed003::tables::RodCornerRow>()?,
        md::<crate::seed003::tables::RodGridRow>()?,
        md::<crate::seed003::tables::CantileverGridRow>()?,
        md::<crate::seed003::tables::LoadStepRow>()?,
    ];
    Ok(sections.join("\n"))
}
