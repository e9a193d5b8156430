//! The Cusick drape tester: measuring captures, predicting them, the statistics over fabrics, fabric files.

pub mod captures;
pub mod fabric;
pub mod measure;
pub mod over_fabrics;
pub mod predict;
pub mod tables;
pub mod targets;
