//! drapelab's reports: polars queries over the pipelines' tables, plotters figures, Markdown and
//! pictures (the seed 003 montage), each a function over a [`drapelab_app::Job`].

#![warn(missing_docs)]
#![allow(non_snake_case)]

pub mod benchmark_report;
pub mod calibration_report;
pub mod cusick_faces;
pub mod cusick_headline;
pub mod cusick_plots;
pub mod cusick_report;
pub mod format;
pub mod garment_report;
pub mod montage;
pub mod report;
pub mod seed003_drawings;
pub mod seed003_report;
pub mod seed003_rod;
pub mod seed003_scenes;
pub mod wrinkles_fabric;
pub mod wrinkles_report;
pub mod wrinkles_text;
