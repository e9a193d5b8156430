//! One damped Newton iteration (seed 003 §10.2) put together from the step's parts
//! ([`super::strategy`]): the Hessian regularized ([`Regularization`]), a straight or curved step
//! ([`Direction`]), a chord step with the factor at hand ([`FactorReuse`]), and a backtracking
//! line search ([`Backtracking`] over [`Armijo`]) bounded by the terms' collision-free step
//! ([`Model::max_step_with`]). [`super::newton`] owns the loop over iterations, the executor
//! ([`super::execute`]) the loop over load increments and other stages.

mod factor;
mod reuse;
mod search;

pub(super) use factor::mean_free_diagonal;

use super::linear::{DofMap, SparseSpd};
use super::static_options::StaticOptions;
use super::strategy::{
    Acceptance, Armijo, Backtracking, Direction, FactorReuse, Regularization, Verdict,
};
use super::{Globalization, SolveReport};
use crate::physics::{CandidateSet, Contacts, HessianBlocks, HessianMode, Model, PairCurvature};
use nalgebra::Vector3;

/// (first DOF, component) of every held component of the free particles.
fn held_dofs(model: &Model, dofs: &DofMap) -> Vec<(usize, usize)> {
    (0..model.len())
        .filter_map(|p| dofs.dof(p).map(|d| (p, d)))
        .flat_map(|(p, d)| {
            (0..3)
                .filter(move |&c| model.is_held(p, c))
                .map(move |c| (d, c))
        })
        .collect()
}

/// Which Hessian an iteration factorizes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Hessian {
    /// The exact one (quadratic convergence).
    Exact,
    /// Every term's indefinite part dropped (positive semi-definite).
    Projected,
}

impl Hessian {
    fn is_projected(self) -> bool {
        self == Hessian::Projected
    }
}

/// How an iteration's step was taken.
/// How one Newton iteration ([`Workspace::iterate`]) ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Iteration {
    /// A step that lowered the energy was taken.
    Stepped,
    /// No damping made the Hessian factorizable: no step.
    Unfactorizable,
    /// No step lowered the energy, the residual within ten times the tolerance: round-off near the
    /// solution.
    NoDecreaseNearSolution,
    /// No step lowered the energy at any damping tried.
    NoDecrease,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Taken {
    /// Whole (length 1, no term bounding it): the factor at hand may serve a chord step.
    Whole,
    /// Shortened by the line search or a term's bound, or no step yet.
    Partial,
}

/// The Newton step's parts, from the options.
#[derive(Debug, Clone, Copy)]
struct Parts {
    regularization: Regularization,
    direction: Direction,
    factor_reuse: FactorReuse,
    /// The largest shift of the exact Hessian ([`StaticOptions::shift_max_rel`]).
    shift_max: f64,
    /// The damping's initial value (where a carried damping returns when the Hessian is projected).
    mu_initial: f64,
    /// [`StaticOptions::exact_retry_every`].
    exact_retry_every: usize,
    search: Backtracking<Armijo>,
}

/// The line search every Newton step uses.
const SEARCH: Backtracking<Armijo> = Backtracking {
    condition: Armijo {
        decrease: ARMIJO_DECREASE,
        flat_rel: ENERGY_FLAT_REL,
    },
    halvings: LINE_SEARCH_HALVINGS,
};

/// What the Newton loop carries between iterations: the buffers (nothing is allocated per
/// iteration) and the Levenberg–Marquardt damping.
pub(super) struct Workspace {
    pub(super) dofs: DofMap,
    held: Vec<(usize, usize)>,
    pub(super) spd: SparseSpd,
    pub(super) g: Vec<Vector3<f64>>,
    h: HessianBlocks,
    rhs: Vec<f64>,
    dx: Vec<Vector3<f64>>,
    trial: Vec<Vector3<f64>>,
    g_trial: Vec<Vector3<f64>>,
    g_back: Vec<Vector3<f64>>,
    /// The step's geodesic acceleration (zero on a straight step).
    acc: Vec<Vector3<f64>>,
    shift: Vec<f64>,
    /// Levenberg–Marquardt damping relative to the mean free diagonal of the Hessian.
    mu: f64,
    /// The step's parts.
    parts: Parts,
    /// The Hessian of the last factorization (see [`Workspace::top_fails`]).
    last_hessian: Hessian,
    /// Which contact pairs carry their distance's curvature in the exact Hessian this iteration
    /// ([`HessianMode::Newton`]): set by the run ([`super::newton`]) before each iteration.
    pub(super) pairs: PairCurvature,
    /// Iterations in a row that stepped on the projected Hessian ([`Workspace::skips_exact`]).
    projected_run: usize,
    /// The largest residual force at the start of the previous iteration, N.
    r_prev: f64,
    /// How the previous iteration's step was taken.
    last_step: Taken,
    /// What the globalization did so far.
    pub(super) stats: Globalization,
    /// The last iteration's step length (a fraction of its Newton step) and the terms' bound on
    /// it (infinite where no term bounded it): iterations.parquet's columns.
    pub(super) last_alpha_bound: (f64, f64),
    /// Whether steps are solved by conjugate gradients preconditioned with a neighbour's factor
    /// ([`super::WarmData::factor`]); off for the rest of the run once that fails or the
    /// line search shortens one of its steps.
    krylov: bool,
    /// Whether the factorizer holds the Hessian in `h` assembled (a new shift of it needs no new
    /// assembly: [`SparseSpd::refactorize`]).
    assembled: bool,
    /// The constant part of the Hessian and its free diagonal's trace (summed once per model:
    /// summing its blocks at every iteration was 6 % of a Cusick drape's solve).
    constant_trace: Option<(std::sync::Arc<HessianBlocks>, f64)>,
    /// The contact set at the run's current state, built by the run: at its start
    /// ([`Workspace::enter`]) and with every step it accepts (the accepted trial's set), so that
    /// gradient and Hessian at a state use the set its energy was measured with.
    pub(super) contacts: Contacts,
    /// The broad phase's candidate set the run carries from state to state: every contact set
    /// and step bound of the run is measured over it ([`Model::contacts_with`],
    /// [`Model::max_step_with`]), so that a broad phase runs only where the state leaves the
    /// region it covers.
    pub(super) candidates: CandidateSet,
}

/// Conjugate-gradient iterations of one Newton step with a neighbour's factor before the step
/// falls back to a factorization of its own. Ten back-substitutions cost about what one
/// factorization of the 14 × 14 net does: the calibration's population needs 3 a step (its counts
/// unchanged from 40), and implicit Euler's steps, preconditioned with the previous step's factor,
/// did 1,137 back-substitutions on hang4 with 40 against 328 with 10 (issue 47).
const KRYLOV_ITERATIONS: usize = 10;

/// The forcing term of a Krylov step: CG stops when the residual of the Newton system is below
/// this fraction of the gradient (an inexact Newton step, Eisenstat & Walker's fixed choice).
const KRYLOV_FORCING: f64 = 1e-2;

/// The largest geodesic acceleration taken, relative to the step: |½ a| ≤ |dx|.
const ACCELERATION_MAX: f64 = 1.0;
/// The finite-difference step (in units of dx) of the acceleration's second derivative.
const ACCELERATION_FD: f64 = 0.1;

/// Armijo's sufficient-decrease constant: a step is accepted when the energy falls by at least this
/// fraction of the decrease its slope promises. The textbook value (Nocedal & Wright); a larger one
/// rejects more steps, a smaller one accepts steps that barely descend.
pub const ARMIJO_DECREASE: f64 = 1e-4;

/// An energy change below this fraction of the energy is round-off: such a step is accepted when it
/// lowers the residual instead. Raise it only if a solve stalls at its round-off floor.
pub const ENERGY_FLAT_REL: f64 = 1e-11;

/// The factor by which damping and shifts grow after a failed factorization or line search (and
/// the damping's ladder of shifts, 1e-8, 1e-7, …). A larger factor reaches a working shift in fewer
/// factorizations but overshoots it.
pub const DAMPING_GROWTH: f64 = 10.0;

/// The damping is divided by this after a whole step (Levenberg–Marquardt's decrease).
pub const DAMPING_DECREASE: f64 = 4.0;

/// Factorization attempts (shifts, projection, damping) of one iteration before it gives up.
pub const FACTORIZE_ATTEMPTS: usize = 40;

/// Halvings of the step a line search tries before it gives up (2⁻³⁰ of the step).
pub const LINE_SEARCH_HALVINGS: usize = 30;

/// Rounds of (factorize, line search) in one iteration, each with more damping, before it gives up.
pub const DAMPED_ROUNDS: usize = 20;

/// The damping above which [`Regularization::CarriedDamping`] switches to the projected Hessian.
pub const CARRIED_DAMPING_MAX: f64 = 1e-3;

/// A chord step is tried while the largest residual force falls at least by this factor per
/// iteration ([`FactorReuse::Chord`]).
const CHORD_CONTRACTION: f64 = 0.5;

/// Smallest damping used once damping is needed (relative to the mean diagonal).
const MU_MIN: f64 = 1e-8;

impl Workspace {
    /// The workspace of a run of `model` from `x`; with a neighbour's `factor`, its Newton steps
    /// are solved by conjugate gradients preconditioned with it while that converges.
    /// Its contact sets are measured over `candidates` (a neighbour's, or the last run's).
    pub(super) fn new(
        model: &Model,
        x: &[Vector3<f64>],
        opts: &StaticOptions,
        (factor, candidates): (Option<&super::NeighbourFactor>, CandidateSet),
    ) -> Self {
        let mut ws = Self::fresh(model, x, opts);
        ws.candidates = candidates;
        if let Some(nf) = factor {
            ws.spd = nf.0.copy();
            ws.krylov = true;
        }
        ws
    }

    fn fresh(model: &Model, x: &[Vector3<f64>], opts: &StaticOptions) -> Self {
        let dofs = DofMap::new(&model.fixed);
        let held = held_dofs(model, &dofs);
        let n = dofs.n;
        Self {
            dofs,
            held,
            spd: SparseSpd::with_ordering(opts.ordering),
            g: Vec::new(),
            h: HessianBlocks::default(),
            rhs: vec![0.0; n],
            dx: vec![Vector3::zeros(); x.len()],
            trial: x.to_vec(),
            g_trial: Vec::new(),
            g_back: Vec::new(),
            acc: vec![Vector3::zeros(); x.len()],
            shift: vec![0.0; n],
            mu: opts.lm_damping_initial,
            parts: Parts {
                regularization: opts.regularization,
                direction: opts.direction,
                factor_reuse: opts.factor_reuse,
                shift_max: opts.shift_max_rel,
                mu_initial: opts.lm_damping_initial,
                exact_retry_every: opts.exact_retry_every,
                search: SEARCH,
            },
            last_hessian: Hessian::Exact,
            pairs: PairCurvature::NormalOnly,
            projected_run: 0,
            r_prev: f64::INFINITY,
            last_step: Taken::Partial,
            stats: Globalization::default(),
            last_alpha_bound: (1.0, f64::INFINITY),
            krylov: false,
            assembled: false,
            constant_trace: None,
            contacts: Contacts::default(),
            candidates: CandidateSet::default(),
        }
    }

    /// Enters the state `x` (a stage's start): its contact set, and its energy at `load`, J.
    pub(super) fn enter(&mut self, model: &Model, x: &[Vector3<f64>], load: f64) -> f64 {
        self.contacts = model.contacts_with(x, &mut self.candidates);
        model.energy_on(x, &self.contacts, load)
    }

    /// The gradient at the current state `x` into `g`, with its contact set.
    pub(super) fn gradient_here(&mut self, model: &Model, x: &[Vector3<f64>], load: f64) {
        model.gradient_on(x, &self.contacts, load, &mut self.g);
    }

    /// The Newton step −(H + μD)⁻¹ g into `dx` (zero on fixed particles and held components), and
    /// the directional derivative gᵀdx.
    fn step(&mut self, x_len: usize) -> f64 {
        let mut dx = std::mem::take(&mut self.dx);
        let g = std::mem::take(&mut self.g);
        self.solve_for(&g, &mut dx);
        let slope = (0..x_len).map(|p| g[p].dot(&dx[p])).sum();
        self.g = g;
        self.dx = dx;
        slope
    }

    /// −(H + μD)⁻¹ f into `out` with the last factorization, zero on fixed particles and held
    /// components.
    fn solve_for(&mut self, f: &[Vector3<f64>], out: &mut [Vector3<f64>]) {
        for (p, fp) in f.iter().enumerate() {
            if let Some(d) = self.dofs.dof(p) {
                self.rhs[d] = -fp.x;
                self.rhs[d + 1] = -fp.y;
                self.rhs[d + 2] = -fp.z;
            }
        }
        for &(d, c) in &self.held {
            self.rhs[d + c] = 0.0;
        }
        self.spd.solve_in_place(&mut self.rhs);
        for &(d, c) in &self.held {
            self.rhs[d + c] = 0.0;
        }
        for (p, o) in out.iter_mut().enumerate() {
            *o = match self.dofs.dof(p) {
                Some(d) => Vector3::new(self.rhs[d], self.rhs[d + 1], self.rhs[d + 2]),
                None => Vector3::zeros(),
            };
        }
    }

    /// One damped Newton iteration from `x`: factorize, step (curved where the acceleration is
    /// small), line search, then adapt the damping (divided by 4 after a whole step, raised tenfold
    /// from 1e-8 when no step lowers the energy); how it ended.
    pub(super) fn iterate(
        &mut self,
        model: &Model,
        x: &mut [Vector3<f64>],
        load: f64,
        e: &mut f64,
        (r, tol): (f64, f64),
        report: &mut SolveReport,
    ) -> Iteration {
        self.last_alpha_bound = (1.0, f64::INFINITY);
        if self.krylov {
            if self.krylov_step(model, x, load, e, r, report) {
                return Iteration::Stepped;
            }
            // The neighbour's factor no longer serves: factorize from here on.
            self.krylov = false;
            self.last_step = Taken::Partial;
        }
        // Shamanskii: while whole steps halve the residual, the factor at hand serves again.
        let chord = self.parts.factor_reuse == FactorReuse::Chord
            && self.last_step == Taken::Whole
            && r <= CHORD_CONTRACTION * self.r_prev;
        self.r_prev = r;
        if chord && self.chord_step(model, x, load, e, report) {
            self.last_step = Taken::Whole;
            return Iteration::Stepped;
        }
        self.last_step = Taken::Partial;
        let mut hessian = match self.skips_exact() {
            true => Hessian::Projected,
            false => Hessian::Exact,
        };
        self.hessian(model, x, hessian);
        // The damping's scale: the mean diagonal of this iteration's Hessian.
        let scale = self.damping_scale();
        for _ in 0..DAMPED_ROUNDS {
            if !self.factorize(model, x, &mut hessian, scale, report) {
                return Iteration::Unfactorizable;
            }
            let slope = self.step(x.len());
            let mut bound = model.max_step_with(x, &self.dx, &mut self.candidates);
            let curved = self.parts.direction == Direction::Curved
                && !hessian.is_projected()
                && self.acceleration(model, x, load);
            if curved {
                // The bound of the chord to the curve's end as well as of the tangent (the chord
                // into g_back, free until the next acceleration).
                for ((c, d), a) in self.g_back.iter_mut().zip(&self.dx).zip(&self.acc) {
                    *c = d + a * 0.5;
                }
                bound = bound.min(model.max_step_with(x, &self.g_back, &mut self.candidates));
            } else {
                self.acc.iter_mut().for_each(|a| *a = Vector3::zeros());
            }
            match self.line_search(model, x, load, (e, r), (bound.min(1.0), slope)) {
                Some(alpha) => {
                    self.count(alpha, bound, (curved, hessian.is_projected()));
                    self.projected_run = match hessian.is_projected() {
                        true => self.projected_run + 1,
                        false => 0,
                    };
                    if alpha == 1.0 && bound >= 1.0 {
                        self.last_step = Taken::Whole;
                        self.mu = if self.mu < 1e-12 {
                            0.0
                        } else {
                            self.mu / DAMPING_DECREASE
                        };
                    }
                    return Iteration::Stepped;
                }
                // A step that does not decrease the energy: near the solution, round-off.
                None if r <= 10.0 * tol => return Iteration::NoDecreaseNearSolution,
                None => self.mu = (self.mu * DAMPING_GROWTH).max(MU_MIN),
            }
        }
        Iteration::NoDecrease
    }

    /// Whether this iteration goes straight to the projected Hessian: on the ladder of shifts,
    /// after two iterations in a row stepped on it, except every
    /// [`StaticOptions::exact_retry_every`]th. Where
    /// folds keep the exact Hessian indefinite, each such iteration otherwise factorizes it twice
    /// (the damping, the ladder's top: [`Workspace::top_fails`]) before the projected one.
    fn skips_exact(&self) -> bool {
        let every = self.parts.exact_retry_every;
        self.parts.regularization == Regularization::ShiftLadder
            && every > 1
            && self.projected_run >= 2
            && !self.projected_run.is_multiple_of(every)
    }

    /// Counts an accepted step of length `alpha` under the terms' `bound`.
    fn count(&mut self, alpha: f64, bound: f64, (curved, projected): (bool, bool)) {
        self.last_alpha_bound = (alpha, bound);
        let s = &mut self.stats;
        if alpha == 1.0 {
            s.full_steps += 1;
        } else if alpha == bound {
            s.bounded_steps += 1;
        } else {
            s.shortened_steps += 1;
        }
        s.curved_steps += usize::from(curved);
        s.projected_steps += usize::from(projected);
    }
}

#[cfg(test)]
mod tests;
