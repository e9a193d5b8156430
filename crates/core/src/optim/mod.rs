//! Optimisers for calibration (seed 000): the Imperialist Competitive Algorithm and the Taguchi L27
//! design that tunes it. Problems are cost functions over the unit box; solvers never print, and an
//! observer receives every decade (argmin's habit).

mod cmaes;
mod ica;
mod lhs;
mod minimizer;
mod taguchi;

pub use cmaes::{CmaesReport, cmaes};
pub use ica::{DecadeEvent, Ica, IcaReport, IcaSettings};
pub use lhs::latin_hypercube;
pub use minimizer::{Cmaes, Cost, Minimizer, NelderMead, OptimReport, OptimStop};
pub use taguchi::{L27, l27, main_effects, sn_smaller_the_better};
