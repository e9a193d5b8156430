//! drapelab-core: the science of fabric drape, with no I/O stack (no Arrow, Parquet, MCAP, rerun,
//! polars or clap).
//!
//! One concept per module, dependencies pointing down (see the README's module map):
//! [`material`] and [`cloth`] describe the fabric, [`physics`] turns them into energy terms,
//! [`obstacle`] holds the rigid obstacles' geometry, [`proximity`] the sheet's distances to itself and
//! their collision-free step, [`solve`] finds equilibria and trajectories, [`scene`] reads and
//! validates TOML scenes, [`simulate`] solves a scene, [`measure`] and [`edges`] measure drape
//! (seed 000's edge polynomials, seed 003's drape coefficient), [`elastica`] gives exact references,
//! [`optim`] and [`calibrate`] fit parameters (ICA, CMA-ES, Taguchi), [`wrinkles`] is seed 002's
//! tension field, and [`benchmark`] measures time against error.

#![warn(missing_docs)]
#![allow(non_snake_case)] // units in names: stiffness_N_per_m, damping_Ns_per_m

pub mod atomic;
pub mod benchmark;
pub mod build;
pub mod calibrate;
pub mod cloth;
pub mod config;
pub mod cusick;
pub mod edges;
pub mod elastica;
pub mod error;
pub mod material;
pub mod measure;
pub mod memory;
pub mod obstacle;
pub mod optim;
pub mod params;
pub mod pattern;
pub mod physics;
pub mod provenance;
pub mod proximity;
pub mod raster;
pub mod scene;
pub mod sensitivity;
pub mod sewing;
pub mod simulate;
pub mod solve;
pub mod surface;
pub mod table;
pub mod textfile;
pub mod wrinkles;

/// Standard gravity in m/s², the default of every scene.
pub const STANDARD_GRAVITY_M_PER_S2: f64 = 9.806_65;

/// The drapelab version recorded in every output (one version for the whole workspace).
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
