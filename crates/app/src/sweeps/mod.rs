//! Sweeps over scenes, solvers and sizes: the sweep, the accuracy–speed benchmark, its peers and the skips.

pub mod benchmark;
pub mod peers;
pub mod skips;
pub mod sweep;
pub mod table;
