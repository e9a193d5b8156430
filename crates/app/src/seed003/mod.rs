//! Seed 003's drape scenes and studies, and their tables.

pub mod solve;
pub mod studies;
pub mod tables;
