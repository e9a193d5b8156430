//! drapelab: fabric drape simulation, measurement, calibration and recording.
//!
//! The workspace, layered with dependencies pointing down (README, "Module map"):
//! `drapelab-core` (the science, no I/O stack) ← `drapelab-record` (Parquet, MCAP, rerun) and
//! `drapelab-pipeline` (the engine and the `Stage` trait) ← `drapelab-app` (the workflows, over files)
//! ← `drapelab-reports` (polars, plotters, Markdown) ← `drapelab-stages` (the stage kinds, adapters)
//! ← this crate (the command line). This crate re-exports the layers below under one name, so that
//! `drapelab::scene`, `drapelab::io`, `drapelab::app` or `drapelab::pipeline` read as before.

#![allow(non_snake_case)]

pub mod cli;

pub use drapelab_app as app;
pub use drapelab_core::*;
pub use drapelab_pipeline as pipeline;
pub use drapelab_record as io;
pub use drapelab_stages as stages;
