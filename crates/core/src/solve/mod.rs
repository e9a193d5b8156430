//! Solvers on a [`Model`](crate::physics::Model): static Newton with line search, and the dynamic
//! integrators (explicit Euler with Provot's correction, symplectic Euler, implicit Euler).
//! Every solve returns a [`SolveReport`] with a [`Status`]; solvers never print and never panic on
//! bad numerics. Observers ([`Observer`]) receive states and do the I/O.

mod clock;
mod continuation;
mod dynamic;
mod dynamic_options;
mod equilibrium;
mod executor;
mod implicit_euler;
mod incremental;
mod kind;
mod linear;
mod load_ramp;
mod neutral;
mod newton;
mod report;
mod sag;
mod stability;
mod static_options;
mod step;
mod strategy;
mod time_step;
mod vertical_gap;
mod warm;

pub use continuation::{Continuation, Stage, execute};
pub use dynamic::solve_dynamic;
pub use dynamic_options::DynamicOptions;
pub use equilibrium::{EquilibriumFactor, NoFactor};
pub use implicit_euler::{Settle, integrate_implicit};
pub use incremental::{ImplicitSettings, Inertia};
pub use kind::{Integrator, SolverKind, by_report_name};
pub use linear::{DISSECTION_MIN_PARTICLES, DofMap, FillOrdering, SparseSpd};
pub use load_ramp::{LoadRamp, solve_static, solve_static_loads, solve_static_warm};
pub use neutral::{NEUTRAL_REL, NeutralMode, neutral_modes};
pub use newton::is_minimum;
pub use report::{
    Divergence, DivergenceReason, Globalization, Part, SolveReport, Status, StopReason,
};
pub use sag::{folded_start, sagged_start};
pub use stability::{highest_mode, kinetic_energy, stability_limit_dt};
pub use static_options::StaticOptions;
pub use strategy::{
    Acceptance, Armijo, Backtracking, Direction, FactorReuse, NestedPath, Regularization, Start,
    Verdict,
};
pub use vertical_gap::solve_vertical_gap;
pub use warm::{NeighbourFactor, WarmData};

use nalgebra::Vector3;

/// A state handed to observers: an iteration of Newton or a time step of a dynamic solve.
pub struct StateEvent<'a> {
    /// Newton iteration or time-step index.
    pub index: usize,
    /// Simulated time in s (dynamic solves only).
    pub time_s: Option<f64>,
    /// Positions of all particles in m.
    pub x: &'a [Vector3<f64>],
    /// Largest residual force on a free particle in N.
    pub max_residual_N: f64,
    /// Total energy (potential, plus kinetic in dynamics) in J.
    pub energy_J: f64,
    /// How the Newton iteration that reached this state stepped (None for a start, a time step).
    pub step: Option<StepRecord>,
}

/// How one Newton iteration stepped: where a long path's iterations go (issue 90).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StepRecord {
    /// The step taken as a fraction of the Newton step (1: whole).
    pub alpha: f64,
    /// The terms' collision-free bound on the step (infinite where none bounded it).
    pub bound: f64,
    /// Whether the bound cut the step (the step stopped at it).
    pub bound_cut: bool,
    /// Line-search trials (the accepted one and those rejected).
    pub trials: usize,
    /// Factorizations the iteration made (0: a chord or Krylov step on a factor at hand).
    pub factorizations: usize,
    /// Self-contact pairs within the activation distance at the new state.
    pub active_pairs: usize,
    /// The largest distance a particle moved, m.
    pub max_move_m: f64,
}

/// Receives states during a solve (argmin's observer pattern): recorders, progress bars. Observers do
/// the I/O and may fail: an error stops the solve ([`StopReason::Observer`]).
pub trait Observer {
    /// Whether the observer wants the state at this index (so solvers skip the work of building it).
    fn wants(&self, index: usize) -> bool;
    /// Called with a state the observer wanted.
    fn observe(&mut self, event: &StateEvent<'_>) -> anyhow::Result<()>;
    /// The simulated-time interval at which a dynamic solve should hand this observer its states
    /// (a recording's frame rate), if it wants frames rather than step indices: the implicit
    /// integrator lands a step on every frame time. Default none.
    fn frame_interval_s(&self) -> Option<f64> {
        None
    }
    /// The final call, once the solve is over, with its final state (None when that state is not
    /// finite): recorders write it if they have not and close their files.
    fn finish(&mut self, _final_state: Option<&StateEvent<'_>>) -> anyhow::Result<()> {
        Ok(())
    }
}

/// An observer that wants nothing.
pub struct NoObserver;

impl Observer for NoObserver {
    fn wants(&self, _index: usize) -> bool {
        false
    }
    fn observe(&mut self, _event: &StateEvent<'_>) -> anyhow::Result<()> {
        Ok(())
    }
}

/// Fans one state out to several observers.
pub struct Observers<'a>(pub Vec<&'a mut dyn Observer>);

impl Observer for Observers<'_> {
    fn wants(&self, index: usize) -> bool {
        self.0.iter().any(|o| o.wants(index))
    }
    fn observe(&mut self, event: &StateEvent<'_>) -> anyhow::Result<()> {
        for o in self.0.iter_mut() {
            if o.wants(event.index) {
                o.observe(event)?;
            }
        }
        Ok(())
    }
    fn finish(&mut self, final_state: Option<&StateEvent<'_>>) -> anyhow::Result<()> {
        for o in self.0.iter_mut() {
            o.finish(final_state)?;
        }
        Ok(())
    }
    fn frame_interval_s(&self) -> Option<f64> {
        self.0
            .iter()
            .filter_map(|o| o.frame_interval_s())
            .reduce(f64::min)
    }
}
