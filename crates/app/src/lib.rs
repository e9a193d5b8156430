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

pub mod benchmark;
pub mod calibrate;
pub mod calibration_tables;
pub mod cusick_captures;
pub mod cusick_fabric;
pub mod cusick_face_prior;
pub mod cusick_measure;
pub mod cusick_node_prior;
pub mod cusick_predict;
pub mod cusick_tables;
pub mod cusick_targets;
pub mod defaults;
pub mod fit_edges;
pub mod garment;
pub mod knitted_fabric;
pub mod peers;
pub mod scene_keys;
pub mod score;
pub mod seed003_solve;
pub mod seed003_studies;
pub mod seed003_tables;
pub mod simulate;
pub mod skips;
pub mod surface;
pub mod sweep;
pub mod sweep_table;
pub mod tune;
pub mod validate;
pub mod wrinkles;
pub mod wrinkles_full;
pub mod wrinkles_params;
pub mod wrinkles_points;
pub mod wrinkles_tables;

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
        md::<crate::sweep_table::SweepPoint>()?,
        md::<crate::sweep_table::SweepOutcome>()?,
        md::<drapelab_core::edges::ScoreRow>()?,
        md::<crate::calibration_tables::ResultRow>()?,
        md::<crate::calibration_tables::ComparisonRow>()?,
        md::<crate::calibration_tables::EvaluationRow>()?,
        md::<crate::validate::ValidationRow>()?,
        md::<crate::tune::TuneRow>()?,
        md::<crate::tune::MainEffectRow>()?,
        md::<crate::wrinkles::WrinkleRow>()?,
        md::<crate::wrinkles::WrinkleMeshRow>()?,
        md::<crate::wrinkles_tables::WrinkleFullRow>()?,
        md::<crate::wrinkles_tables::FibreRow>()?,
        md::<crate::wrinkles_tables::StartRow>()?,
        md::<drapelab_core::benchmark::BenchRow>()?,
        md::<drapelab_core::benchmark::PopulationRow>()?,
        md::<drapelab_core::benchmark::SkipRow>()?,
        md::<crate::peers::PeerRow>()?,
        md::<crate::cusick_measure::ShadowRow>()?,
        md::<crate::cusick_tables::PredictionRow>()?,
        md::<crate::garment::GarmentRow>()?,
        md::<crate::cusick_captures::CaptureRow>()?,
        md::<crate::cusick_tables::OutlineRow>()?,
        md::<crate::cusick_tables::ProfileRow>()?,
        md::<crate::seed003_tables::Seed003SceneRow>()?,
        md::<crate::seed003_tables::DrapeParticleRow>()?,
        md::<crate::seed003_tables::TableEdgeRow>()?,
        md::<crate::seed003_tables::RodCornerRow>()?,
        md::<crate::seed003_tables::RodGridRow>()?,
        md::<crate::seed003_tables::CantileverGridRow>()?,
        md::<crate::seed003_tables::LoadStepRow>()?,
    ];
    Ok(sections.join("\n"))
}
