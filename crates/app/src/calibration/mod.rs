//! Seed 000's calibration: the Taguchi tuning, ICA or gradient calibration, validation on the 2-corner hang, its tables and the knitted fabric file.

pub mod calibrate;
pub mod knitted_fabric;
pub mod tables;
pub mod tune;
pub mod validate;
