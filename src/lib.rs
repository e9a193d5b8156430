//! drapelab: fabric drape simulation, measurement, calibration and recording.
//!
//! The library is organised one concept per module (see `README.md` for the map):
//! [`material`] and [`cloth`] describe the fabric, [`physics`] turns them into energy terms,
//! [`solve`] finds equilibria and trajectories, [`scene`] reads and validates TOML scenes,
//! [`io`] writes Parquet, MCAP and rerun recordings atomically, and [`cli`] is the command line.

#![allow(non_snake_case)] // units in names: stiffness_N_per_m, damping_Ns_per_m

pub mod benchmark;
pub mod calibrate;
pub mod cli;
pub mod cloth;
pub mod contact;
pub mod edges;
pub mod elastica;
pub mod error;
pub mod io;
pub mod material;
pub mod measure;
pub mod optim;
pub mod physics;
pub mod pipeline;
pub mod scene;
pub mod simulate;
pub mod solve;
pub mod stages;
pub mod wrinkles;

/// Standard gravity in m/s², the default of every scene.
pub const STANDARD_GRAVITY_M_PER_S2: f64 = 9.806_65;

/// The drapelab version recorded in every output.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
