//! Outputs: every file is written to a temporary name in its folder and renamed when complete, so a
//! killed run never leaves an artifact that looks finished.

mod atomic;
mod calibration_rrd;
mod particles;
mod rrd;
mod table;
mod timeline;

pub use atomic::{Staged, write_atomic, write_text};
pub use calibration_rrd::CalibrationRecorder;
pub use particles::{read_particles, write_particles};
pub use rrd::RerunRecorder;
pub use table::write_parquet;
pub use timeline::{TimelineRecorder, cell_triangles, grid_triangles};
