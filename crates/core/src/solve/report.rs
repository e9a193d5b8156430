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
    pub const fn as_str(self) -> &'static str {
        match self {
            Status::Converged => "converged",
            Status::MaxIterations => "max-iterations",
            Status::Diverged => "diverged",
            Status::Invalid => "invalid",
        }
    }
}

impl std::fmt::Display for Status {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Why a solve stopped (argmin's habit: the reason is data; [`SolveReport::message`] says it in words).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum StopReason {
    /// The residual force (and in dynamics the speed) fell below tolerance.
    Converged,
    /// The residual reached the round-off floor of the forces after the tolerance proved unreachable.
    RoundoffFloor,
    /// The Newton iteration budget (`max_iterations`) ran out.
    #[default]
    Iterations,
    /// The simulated-time budget (`max_time_s`) ran out.
    SimulatedTime,
    /// The wall-clock budget (`max_wall_time_s`) ran out.
    WallTime,
    /// The line search found no step that lowers the energy away from the solution.
    LineSearch,
    /// The vertical-gap contact rounds, or the lagged friction's anchor updates, did not settle.
    ContactRounds,
    /// A divergence was detected ([`SolveReport::divergence`] says which).
    Diverged,
    /// The problem cannot be solved as posed (nothing free, a non-positive step).
    Invalid,
    /// An observer failed (a recording could not be written); the message says why.
    Observer,
    /// An explicit integrator reached contact that its step cannot resolve (a step would carry a
    /// particle into an obstacle): use implicit-euler. The state is not a result.
    ContactTooStiff,
    /// The implicit integrator's adaptive step fell below its minimum without Newton converging.
    StepTooSmall,
    /// The solve met its tolerance but the sheet passes through itself (self-contact off, or a
    /// solver without it): the state is not a drape. `contact.self = "auto"` prevents it.
    PassesThroughItself,
}

impl StopReason {
    /// The status a solve that stopped for this reason has.
    pub fn status(self) -> Status {
        match self {
            StopReason::Converged | StopReason::RoundoffFloor => Status::Converged,
            StopReason::Iterations
            | StopReason::SimulatedTime
            | StopReason::WallTime
            | StopReason::LineSearch
            | StopReason::ContactRounds
            | StopReason::StepTooSmall => Status::MaxIterations,
            StopReason::Diverged => Status::Diverged,
            StopReason::Invalid
            | StopReason::Observer
            | StopReason::ContactTooStiff
            | StopReason::PassesThroughItself => Status::Invalid,
        }
    }
}

/// What a divergence check detected.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum DivergenceReason {
    /// A NaN or infinite energy or force.
    NonFinite,
    /// The total energy rose far above its start (dynamics).
    EnergyBlowUp {
        /// Total energy when detected, J.
        energy_J: f64,
        /// Total energy at the start, J.
        initial_J: f64,
    },
    /// A spring or membrane strain beyond the solver's `strain_bound`.
    StrainBeyondBound {
        /// The largest strain.
        strain: f64,
        /// The bound.
        bound: f64,
    },
}

impl std::fmt::Display for DivergenceReason {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            DivergenceReason::NonFinite => write!(f, "non-finite"),
            DivergenceReason::EnergyBlowUp {
                energy_J,
                initial_J,
            } => write!(f, "energy blow-up: {energy_J:.3e} J from {initial_J:.3e} J"),
            DivergenceReason::StrainBeyondBound { strain, bound } => {
                write!(f, "strain {strain:.3e} beyond bound {bound}")
            }
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
    /// What was detected.
    pub reason: DivergenceReason,
}

/// What the static solver's globalization did: its Newton iterations by the step they took. Zero
/// for the dynamic solvers (their Newton steps are counted in the implicit integrator's own report).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct Globalization {
    /// Iterations whose step was taken whole (α = 1).
    pub full_steps: usize,
    /// Iterations whose step the line search shortened (backtracking from α = 1 or from the bound).
    pub shortened_steps: usize,
    /// Iterations whose step a term's bound cut first (contact: no particle closes more than 90 %
    /// of its gap in one step).
    pub bounded_steps: usize,
    /// Iterations along the curved path x + α dx + ½ α² a (geodesic acceleration).
    pub curved_steps: usize,
    /// Iterations on the projected Hessian (the exact one indefinite beyond the largest shift).
    pub projected_steps: usize,
    /// Line-search trials rejected over the solve (an energy that did not fall enough).
    pub rejected_trials: usize,
    /// Iterations that skipped the ladder of shifts of the exact Hessian: its top failed too, so
    /// every shift below it would have (see `StaticOptions::shift_max_rel`).
    #[serde(default)]
    pub skipped_shifts: usize,
    /// Iterations that reused the factorization at hand (chord steps of
    /// `FactorReuse::Chord`; counted among the full steps too).
    #[serde(default)]
    pub chord_steps: usize,
    /// Iterations whose step was solved by conjugate gradients preconditioned with a neighbour's
    /// factor (`WarmData::factor`; no factorization of their own).
    #[serde(default)]
    pub krylov_steps: usize,
}

impl Globalization {
    /// Adds another solve's counts (a coarse start, a load increment).
    pub fn add(&mut self, o: &Globalization) {
        self.full_steps += o.full_steps;
        self.shortened_steps += o.shortened_steps;
        self.bounded_steps += o.bounded_steps;
        self.curved_steps += o.curved_steps;
        self.projected_steps += o.projected_steps;
        self.rejected_trials += o.rejected_trials;
        self.skipped_shifts += o.skipped_shifts;
        self.chord_steps += o.chord_steps;
        self.krylov_steps += o.krylov_steps;
    }
}

/// The outcome of a solve.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SolveReport {
    /// The solver, written by its report name: "static-newton", "explicit-euler",
    /// "symplectic-euler", "implicit-euler", "baraff-witkin".
    #[serde(with = "super::kind::by_report_name")]
    pub solver: super::SolverKind,
    /// How the solve ended.
    pub status: Status,
    /// Why it stopped.
    #[serde(default)]
    pub stop: StopReason,
    /// Newton iterations or time steps taken.
    pub iterations: usize,
    /// Linear solves (Cholesky factorizations or CG solves).
    pub linear_solves: usize,
    /// Inner iterations of the linear solver (CG), 0 for direct solves.
    pub inner_iterations: usize,
    /// Numeric Cholesky factorizations attempted, those that failed (an indefinite matrix) included.
    #[serde(default)]
    pub factorizations: usize,
    /// Triangular solves with a factor (back-substitutions): one per Newton or chord step and one
    /// per geodesic acceleration.
    #[serde(default)]
    pub back_substitutions: usize,
    /// Wall time of the factorizations and triangular solves alone, s.
    #[serde(default)]
    pub factor_time_s: f64,
    /// Symbolic analyses of a new sparsity pattern (ordering, elimination tree): one per pattern
    /// the process has not seen, e.g. each new set of self-contact pairs.
    #[serde(default)]
    pub analyses: usize,
    /// Wall time of those analyses (and of finding a cached pattern), s.
    #[serde(default)]
    pub analysis_time_s: f64,
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
    /// For a converged solve of a scene (static, or dynamic once settled): whether the equilibrium is
    /// a minimum of the energy ([`super::is_minimum`]). None when not checked (no convergence).
    pub minimum: Option<bool>,
    /// Steps of an explicit or linearised integrator cut short where they would have carried a
    /// particle into an obstacle (Baraff–Witkin); 0 for other solvers.
    #[serde(default)]
    pub contact_cut_steps: usize,
    /// What the static solver's globalization did (its iterations by step).
    #[serde(default)]
    pub globalization: Globalization,
}

impl SolveReport {
    /// The report a solve starts from: nothing done yet, stopped by its iteration budget until said
    /// otherwise, residual and energy unknown.
    pub fn unsolved(solver: super::SolverKind) -> Self {
        SolveReport {
            solver,
            status: Status::MaxIterations,
            stop: StopReason::Iterations,
            iterations: 0,
            linear_solves: 0,
            inner_iterations: 0,
            factorizations: 0,
            back_substitutions: 0,
            factor_time_s: 0.0,
            analyses: 0,
            analysis_time_s: 0.0,
            max_residual_N: f64::NAN,
            max_residual_rel: f64::NAN,
            energy_J: f64::NAN,
            sim_time_s: None,
            dt_s: None,
            wall_time_s: 0.0,
            divergence: None,
            message: String::new(),
            minimum: None,
            contact_cut_steps: 0,
            globalization: Globalization::default(),
        }
    }
    /// Whether the final state is an equilibrium that may be written as a result.
    pub fn is_converged(&self) -> bool {
        self.status == Status::Converged
    }
    /// Records why the solve stopped, and so its status.
    pub fn stop_for(&mut self, reason: StopReason) {
        self.stop = reason;
        self.status = reason.status();
    }
    /// Stops for `reason` with `message`.
    pub fn stop_with(&mut self, reason: StopReason, message: impl Into<String>) {
        self.stop_for(reason);
        self.message = message.into();
    }
    /// Records a divergence detected at `step`.
    pub fn diverge(&mut self, step: usize, dt_s: Option<f64>, reason: DivergenceReason) {
        self.stop_for(StopReason::Diverged);
        self.divergence = Some(Divergence { step, dt_s, reason });
    }
}

/// How a part's report joins the report of the whole solve ([`SolveReport::merge`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Part {
    /// Work that gave the solve its start (a coarser grid's solve, the Cusick drape's fall): its
    /// counters and times add up; the whole keeps its own outcome.
    Start,
    /// A stage of a continuation (a load increment, a friction update, a contact round): counters
    /// and times add up; the outcome (status, residual, energy, message, minimum) is the stage's.
    Stage,
    /// The Newton solve of one implicit time step: its iterations are the integration's inner
    /// iterations; factorizations, linear solves and their time add up.
    InnerSolve,
}

impl SolveReport {
    /// Merges the report of a part of this solve into it, as `how` says: the one place where
    /// reports are merged.
    pub fn merge(&mut self, part: &SolveReport, how: Part) {
        self.linear_solves += part.linear_solves;
        self.factorizations += part.factorizations;
        self.back_substitutions += part.back_substitutions;
        self.factor_time_s += part.factor_time_s;
        self.analyses += part.analyses;
        self.analysis_time_s += part.analysis_time_s;
        if how == Part::InnerSolve {
            self.inner_iterations += part.iterations;
            return;
        }
        self.iterations += part.iterations;
        self.inner_iterations += part.inner_iterations;
        self.wall_time_s += part.wall_time_s;
        self.globalization.add(&part.globalization);
        if how == Part::Stage {
            self.status = part.status;
            self.stop = part.stop;
            self.max_residual_N = part.max_residual_N;
            self.max_residual_rel = part.max_residual_rel;
            self.energy_J = part.energy_J;
            self.divergence = part.divergence.clone();
            self.message = part.message.clone();
            self.minimum = part.minimum;
        }
    }
}
