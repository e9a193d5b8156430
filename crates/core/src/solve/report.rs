//! The report every solve returns.

use serde::{Deserialize, Serialize};

/// How a solve ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Status {
    /// The largest residual force (and, in dynamics, the largest speed) fell below tolerance.
    Converged,
    /// The iteration, step or time budget ran out first; the state is not an equilibrium.
    MaxIterations,
    /// NaN, an energy blow-up or a strain beyond bound; the state is not a result.
    Diverged,
    /// The problem could not be solved as posed (e.g. nothing is free, a singular system).
    Invalid,
}

impl Status {
    /// The name written into outputs.
    pub fn as_str(self) -> &'static str {
        match self {
            Status::Converged => "converged",
            Status::MaxIterations => "max-iterations",
            Status::Diverged => "diverged",
            Status::Invalid => "invalid",
        }
    }
}

/// Where and why a solve diverged.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Divergence {
    /// Step or iteration at which divergence was detected.
    pub step: usize,
    /// Time step in s (dynamics) at divergence.
    pub dt_s: Option<f64>,
    /// What was detected: "non-finite", "energy blow-up", "strain beyond bound".
    pub reason: String,
}

/// The outcome of a solve.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SolveReport {
    /// Solver name: "static-newton", "explicit-euler", "symplectic-euler", "implicit-euler".
    pub solver: String,
    /// How the solve ended.
    pub status: Status,
    /// Newton iterations or time steps taken.
    pub iterations: usize,
    /// Linear solves (Cholesky factorizations or CG solves).
    pub linear_solves: usize,
    /// Inner iterations of the linear solver (CG), 0 for direct solves.
    pub inner_iterations: usize,
    /// Numeric Cholesky factorizations attempted, those that failed (an indefinite matrix) included.
    #[serde(default)]
    pub factorizations: usize,
    /// Wall time of the factorizations and triangular solves alone, s.
    #[serde(default)]
    pub factor_time_s: f64,
    /// Largest residual force on a free particle in N, at the final state.
    pub max_residual_N: f64,
    /// The same relative to the weight of the lightest free particle.
    pub max_residual_rel: f64,
    /// Total potential energy at the final state in J.
    pub energy_J: f64,
    /// Simulated time in s (dynamics).
    pub sim_time_s: Option<f64>,
    /// Time step used in s (dynamics).
    pub dt_s: Option<f64>,
    /// Wall time of the solve in s.
    pub wall_time_s: f64,
    /// Set when status is diverged.
    pub divergence: Option<Divergence>,
    /// A human-readable note (why it stopped).
    pub message: String,
    /// For a converged static solve of a scene: whether the equilibrium is a minimum of the energy
    /// ([`super::is_minimum`]). None when not checked (dynamics, no convergence).
    pub minimum: Option<bool>,
}

impl SolveReport {
    /// Whether the final state is an equilibrium that may be written as a result.
    pub fn is_converged(&self) -> bool {
        self.status == Status::Converged
    }
}

impl SolveReport {
    /// The running total of a solve made of several solves (load increments, contact rounds): work
    /// and time add up, the status, residual, energy and message are the latest one's.
    pub fn accumulate(total: Option<SolveReport>, latest: SolveReport) -> SolveReport {
        match total {
            None => latest,
            Some(mut t) => {
                t.iterations += latest.iterations;
                t.linear_solves += latest.linear_solves;
                t.factorizations += latest.factorizations;
                t.factor_time_s += latest.factor_time_s;
                t.wall_time_s += latest.wall_time_s;
                t.status = latest.status;
                t.max_residual_N = latest.max_residual_N;
                t.max_residual_rel = latest.max_residual_rel;
                t.energy_J = latest.energy_J;
                t.divergence = latest.divergence;
                t.message = latest.message;
                t.minimum = latest.minimum;
                t
            }
        }
    }
}
