//! The Cusick drape tester: measuring captures, predicting them, the statistics over fabrics, fabric files.

pub mod captures;
pub mod fabric;
pub mod face_prior;
pub mod measure;
pub mod node_prior;
pub mod predict;
pub mod tables;
pub mod targets;
