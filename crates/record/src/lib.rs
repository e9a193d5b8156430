//! drapelab-record: every file a solve leaves behind. Parquet tables (particles, edges, any record
//! batch), MCAP timelines in Foxglove's schema, rerun recordings, and the whole output folder of one
//! solved scene. Every file is written to a temporary name in its folder and renamed when complete
//! ([`drapelab_core::atomic`]), so a killed run never leaves an artifact that looks finished.

#![warn(missing_docs)]
#![allow(non_snake_case)]

mod calibration_rrd;
pub mod cusick;
mod cusick_rrd;
mod edges_table;
mod history;
mod mesh_out;
mod particles;
mod parts;
mod photo;
mod rerun;
mod rrd;
mod run_dir;
mod run_sensitivity;
mod sampled;
mod sensitivity_table;
mod start;
mod surface_out;
mod table;
mod timeline;
mod wrinkles_rrd;

pub use calibration_rrd::CalibrationRecorder;
pub use cusick::read_csv;
pub use cusick_rrd::{FABRIC_SPACING_M, NamedMesh, write_cusick_drapes};
pub use drapelab_core::atomic::{Staged, write_atomic, write_text};
pub use edges_table::EdgeRow;
pub use edges_table::{read_edges, write_edges};
pub use history::{History, IterationRow};
pub use mesh_out::{TriangleRow, obj_text, read_triangles, write_triangles};
pub use particles::{ParticleRow, read_particles, read_particles_with_metadata, write_particles};
pub use parts::{gather_parquet, merge_recordings};
pub use photo::{fit_photo, render_scene, score_files};
pub use rrd::RerunRecorder;
pub use run_dir::{
    SimulateExtras, Simulated, StartState, simulate_to_dir, simulate_to_dir_state,
    simulate_to_dir_with,
};
pub use sampled::{Sampled, StateSink};
pub use sensitivity_table::{SensitivityRow, read_sensitivities, write_sensitivities};
pub use start::read_start;
pub use surface_out::{TexturedSurface, glb_bytes, write_glb, write_surface_rrd};
pub use table::{
    Table, join_columns, read_table, table_batch, table_fields, table_markdown, write_parquet,
    write_table,
};
pub use timeline::TimelineRecorder;
pub use wrinkles_rrd::write_wrinkle_meshes;
