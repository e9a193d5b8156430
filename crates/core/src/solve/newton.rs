//! Static equilibrium: Newton's method on the total potential energy with Levenberg–Marquardt
//! damping and a backtracking (Armijo) line search, as seed 003 §10.2 recommends; optionally with
//! incremental loading (the external loads raised in `load_steps` equal steps, §10.3.3).
//!
//! A flat net has no transverse stiffness at the start, so its Hessian is singular: the damping
//! `μ` (added on the diagonal, scaled by the mean diagonal) keeps every system positive definite,
//! grows when a line search fails and shrinks after each whole step, so the last iterations are
//! plain Newton with quadratic convergence. An indefinite exact Hessian (compressed springs, a sheet
//! buckling into a fold) is shifted for that iteration only, up to `shift_max_rel`, then replaced by
//! the projected one; the shift is not carried on as damping. A nearly inextensible sheet turning
//! about its supports (a hang, an overhang swinging down) limits straight steps to a fraction of a
//! spring's length: the step follows the curve x + α dx + ½ α² a, a the geodesic acceleration
//! (Transtrum & Sethna 2012), which bends it along the arcs the springs allow.

use super::executor::{Budget, Verdict};
use super::static_options::StaticOptions;
use super::step::{Iteration, Workspace};
use super::warm::NeighbourFactor;
use super::{DivergenceReason, Observer, SolveReport, StateEvent, Status, StepRecord, StopReason};
use crate::physics::{CandidateSet, Contacts, HessianBlocks, HessianMode, Model, PairCurvature};
use nalgebra::Vector3;
use std::time::Instant;

/// [`super::solve_static_loads`] at full load that also hands back the run's last factor when it
/// converged: the preconditioner of the next solve of a nearby model ([`NeighbourFactor`]), as the
/// next step of implicit Euler is. The run measures contact over `candidates` and leaves there
/// the candidate set it ends with, for the next solve.
pub fn solve_static_keeping_factor(
    model: &mut Model,
    x: &mut [Vector3<f64>],
    opts: &StaticOptions,
    (factor, candidates): (Option<&NeighbourFactor>, &mut CandidateSet),
    pairs: PairCurvature,
) -> (SolveReport, Option<NeighbourFactor>) {
    let carried = std::mem::take(candidates);
    let mut run = match NewtonRun::new(model, x, opts, (factor, carried)) {
        Ok(r) => r.with_pairs(pairs),
        Err(invalid) => return (*invalid, None),
    };
    let reached = run.stage(
        model,
        x,
        opts,
        (1.0, Goal::Tolerance),
        &mut super::NoObserver,
    );
    let factor = (reached && run.ws.spd.has_factor())
        .then(|| NeighbourFactor(std::sync::Arc::new(run.ws.spd.copy())));
    let (report, left) = run.finish(model, x);
    *candidates = left;
    (report, factor)
}

/// How far a stage of a Newton run solves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Goal {
    /// An increment of incremental loading: to the tolerance or 10⁻⁶ of the lightest weight,
    /// whichever is looser.
    Increment,
    /// To the tolerance (or the round-off floor of forces).
    Tolerance,
}

/// One Newton run: its workspace (damping, factor, sparsity structure), its iterations and its
/// report, carried over the stages of a load ramp. The executor ([`super::execute`]) owns the loop
/// over stages; [`NewtonRun::stage`] owns the loop over iterations.
pub(super) struct NewtonRun {
    ws: Workspace,
    report: SolveReport,
    iter: usize,
    floor: bool,
    start: Instant,
    /// The load of the last stage.
    load: f64,
    /// The closest barrier pair's gap after the last accepted step, relative to its band.
    last_gap_rel: f64,
    /// Which contact pairs carry their distance's curvature in Newton's Hessian until
    /// [`StaticOptions::exact_contact_after`] iterations, then every active pair's.
    pairs: PairCurvature,
}

impl NewtonRun {
    /// A run of `model` from `x`, with a neighbour's `factor` and the candidate set it starts
    /// measuring contact over; the report of an invalid one (no free particle with mass).
    pub(super) fn new(
        model: &Model,
        x: &[Vector3<f64>],
        opts: &StaticOptions,
        start: (Option<&NeighbourFactor>, CandidateSet),
    ) -> Result<Self, Box<SolveReport>> {
        let mut report = SolveReport::unsolved(super::SolverKind::Static);
        let ws = Workspace::new(model, x, opts, start);
        if ws.dofs.n == 0 || !model.reference_weight().is_finite() {
            report.stop_with(
                StopReason::Invalid,
                "no free particle with mass: nothing to solve",
            );
            return Err(Box::new(report));
        }
        Ok(Self {
            ws,
            report,
            iter: 0,
            floor: false,
            start: Instant::now(),
            load: 1.0,
            last_gap_rel: f64::INFINITY,
            pairs: PairCurvature::NormalOnly,
        })
    }

    /// The run with `pairs` carrying their distance's curvature in Newton's Hessian (an implicit
    /// time step's [`PairCurvature::Pinned`]; an equilibrium solve's default is none).
    pub(super) fn with_pairs(mut self, pairs: PairCurvature) -> Self {
        self.pairs = pairs;
        self
    }

    /// Newton's iterations at load factor `load` up to `goal`, under the executor
    /// ([`super::executor::run`]): true when reached, false when the run stopped (its report says
    /// why).
    pub(super) fn stage(
        &mut self,
        model: &mut Model,
        x: &mut [Vector3<f64>],
        opts: &StaticOptions,
        (load, goal): (f64, Goal),
        observer: &mut dyn Observer,
    ) -> bool {
        self.load = load;
        let w_ref = model.reference_weight();
        let e = self.ws.enter(model, x, load);
        let mut stage = Stage {
            run: self,
            model,
            x,
            opts,
            load,
            last: goal == Goal::Tolerance,
            tol: opts.residual_tol_rel * w_ref,
            w_ref,
            e,
            r: f64::NAN,
            step: None,
            before: Vec::new(),
        };
        let budget = Budget::iterations(opts.max_iterations);
        let verdict = super::executor::run(&mut stage, budget, observer);
        super::executor::conclude(verdict, self.iter, &mut self.report)
    }

    /// The run's report, with the final numbers at its last stage's load, and the candidate set
    /// it ends with (the next run's start).
    pub(super) fn finish(
        mut self,
        model: &Model,
        x: &[Vector3<f64>],
    ) -> (SolveReport, CandidateSet) {
        let timing = (self.iter, self.floor, self.start);
        finish_report(model, x, self.load, &mut self.ws, timing, &mut self.report);
        (self.report, self.ws.candidates)
    }
}

/// One stage of a Newton run as an iterative solver: its run, the model and state, and the
/// stage's load and goal.
struct Stage<'a> {
    run: &'a mut NewtonRun,
    model: &'a mut Model,
    x: &'a mut [Vector3<f64>],
    opts: &'a StaticOptions,
    load: f64,
    /// Whether the stage solves to the tolerance (the last of a ramp), not to an increment's.
    last: bool,
    /// The tolerance on the largest residual force, N.
    tol: f64,
    /// The lightest free particle's weight, N.
    w_ref: f64,
    /// The energy at the current state, J.
    e: f64,
    /// The largest residual force at the current state, N.
    r: f64,
    /// How the iteration that reached the current state stepped (None at the start).
    step: Option<StepRecord>,
    /// The state the current iteration started from (a buffer).
    before: Vec<Vector3<f64>>,
}

impl super::executor::Iterative for Stage<'_> {
    fn iterations(&self) -> usize {
        self.run.iter
    }

    fn terminate(&mut self, observer: &mut dyn Observer) -> Option<Verdict> {
        let ws = &mut self.run.ws;
        ws.gradient_here(self.model, self.x, self.load);
        let (r, tol) = (self.model.max_residual(&ws.g), self.tol);
        self.r = r;
        if !r.is_finite() || !self.e.is_finite() {
            let reason = DivergenceReason::NonFinite;
            return Some(Verdict::Diverged {
                reason,
                dt_s: None,
                message: None,
            });
        }
        let at = (self.run.iter, self.step.take());
        if let Err(err) = observe_iterate(observer, at, self.x, (r, self.e)) {
            let message = format!("an observer failed at iteration {}: {err:#}", self.run.iter);
            return Some(Verdict::Stopped(StopReason::Observer, message));
        }
        if r <= tol && self.last {
            return Some(Verdict::Reached(Some(StopReason::Converged), None));
        }
        // Round-off floor: the residual cannot fall below ~16 ε k |x| (see Model::roundoff_force);
        // reaching it after the tolerance proved unreachable is convergence, said in the message.
        if self.last && r <= self.model.roundoff_force(self.x) && r <= 1e3 * tol {
            self.run.floor = true;
            return Some(Verdict::Reached(Some(StopReason::RoundoffFloor), None));
        }
        if r <= tol.max(1e-6 * self.w_ref) && !self.last {
            return Some(Verdict::Reached(None, None));
        }
        None
    }

    fn next_iter(&mut self) -> Result<(), Verdict> {
        let run = &mut *self.run;
        run.iter += 1;
        run.ws.pairs = match run.iter > self.opts.exact_contact_after {
            true => PairCurvature::All,
            false => run.pairs,
        };
        let (model, x, load) = (&*self.model, &mut *self.x, self.load);
        self.before.clear();
        self.before.extend_from_slice(x);
        let counters = (run.report.factorizations, run.ws.stats.rejected_trials);
        let taken = run.ws.iterate(
            model,
            x,
            load,
            &mut self.e,
            (self.r, self.tol),
            &mut run.report,
        );
        if taken != Iteration::Stepped {
            // No step lowers the energy: near the solution, round-off.
            run.ws.gradient_here(model, x, load);
            let r = model.max_residual(&run.ws.g);
            if r <= self.tol && self.last {
                return Err(Verdict::Reached(Some(StopReason::Converged), None));
            }
            let message = format!(
                "line search failed at iteration {} with residual {r:.3e} N",
                run.iter
            );
            return Err(Verdict::Stopped(StopReason::LineSearch, message));
        }
        self.step = Some(step_record(run, x, &self.before, counters));
        let contacts = &run.ws.contacts;
        if adapt_kappa(self.model, contacts, self.opts, &mut run.last_gap_rel) {
            self.e = self.model.energy_on(self.x, contacts, load);
        }
        let strain = self.model.max_strain(self.x);
        if strain > self.opts.strain_bound {
            let bound = self.opts.strain_bound;
            let reason = DivergenceReason::StrainBeyondBound { strain, bound };
            return Err(Verdict::Diverged {
                reason,
                dt_s: None,
                message: None,
            });
        }
        Ok(())
    }

    fn out_of_iterations(&self, budget: usize) -> String {
        format!("{budget} Newton iterations without reaching the tolerance")
    }
}

/// Doubles the barriers' κ after an accepted step whose state's contact set (`contacts`) has the
/// closest barrier pair within
/// [`StaticOptions::kappa_adapt_gap_rel`] of its band and closer than the step before did
/// (`last_gap_rel`, updated; IPC's adaptive κ): true when the energy changed.
fn adapt_kappa(
    model: &mut Model,
    contacts: &Contacts,
    opts: &StaticOptions,
    last_gap_rel: &mut f64,
) -> bool {
    if opts.kappa_adapt_gap_rel <= 0.0 {
        return false;
    }
    let gap = model.closest_gap_rel(contacts);
    let closing = gap < opts.kappa_adapt_gap_rel && gap < *last_gap_rel;
    *last_gap_rel = gap;
    closing && model.stiffen_barriers(contacts)
}

/// Hands Newton iterate `iter` (residual `r` N, energy `e` J, reached by `step`) to `observer`
/// when it wants it.
fn observe_iterate(
    observer: &mut dyn Observer,
    (iter, step): (usize, Option<StepRecord>),
    x: &[Vector3<f64>],
    (r, e): (f64, f64),
) -> anyhow::Result<()> {
    if !observer.wants(iter) {
        return Ok(());
    }
    observer.observe(&StateEvent {
        index: iter,
        time_s: None,
        x,
        max_residual_N: r,
        energy_J: e,
        step,
    })
}

/// What the run's counters and `before` (the state the iteration started from) say of the
/// iteration that just stepped to `x`.
fn step_record(
    run: &NewtonRun,
    x: &[Vector3<f64>],
    before: &[Vector3<f64>],
    (factorizations, rejected): (usize, usize),
) -> StepRecord {
    let (alpha, bound) = run.ws.last_alpha_bound;
    StepRecord {
        alpha,
        bound,
        bound_cut: alpha == bound && alpha < 1.0,
        trials: 1 + run.ws.stats.rejected_trials - rejected,
        factorizations: run.report.factorizations - factorizations,
        active_pairs: run.ws.contacts.len(),
        max_move_m: x
            .iter()
            .zip(before)
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, f64::max),
    }
}

/// The final numbers of a static solve (residual and energy at the final load, times) and, when it
/// converged, its message: in how many iterations, and whether to the round-off floor of forces.
fn finish_report(
    model: &Model,
    x: &[Vector3<f64>],
    final_load: f64,
    ws: &mut Workspace,
    (iter, floor, start): (usize, bool, Instant),
    report: &mut SolveReport,
) {
    // The state may have moved since the run's last step (a continuation's end): its contact set
    // measured afresh, over the run's candidates.
    let contacts = model.contacts_with(x, &mut ws.candidates);
    model.gradient_on(x, &contacts, final_load, &mut ws.g);
    report.iterations = iter;
    report.globalization = ws.stats;
    report.factor_time_s = ws.spd.factor_time_s;
    report.back_substitutions = ws.spd.back_substitutions;
    report.analyses = ws.spd.analyses;
    report.analysis_time_s = ws.spd.analysis_time_s;
    report.max_residual_N = model.max_residual(&ws.g);
    report.max_residual_rel = report.max_residual_N / model.reference_weight();
    report.energy_J = model.energy_on(x, &contacts, final_load);
    report.wall_time_s = start.elapsed().as_secs_f64();
    if report.status == Status::Converged {
        report.message = if floor {
            format!(
                "converged in {iter} iterations to the round-off floor of forces ({:.2e} N)",
                model.roundoff_force(x)
            )
        } else {
            format!("converged in {iter} iterations")
        };
    }
}

/// Whether the equilibrium `x` is a minimum of the model's energy: the exact Hessian over the free
/// coordinates (held components decoupled; every contact pair's whole curvature, the distance's own
/// κ b′∇²d included), shifted by 1e-10 of its mean diagonal for neutral directions, has a Cholesky
/// factorization. False at a saddle or a maximum (an unstable equilibrium, e.g. a flat sheet under
/// compression). Newton's Hessian, which keeps only a pair's curvature along its normal, called
/// the 0.8 m cotton sheet's stacked folds on the sphere a saddle where the exact one is definite.
pub fn is_minimum(model: &Model, x: &[Vector3<f64>]) -> bool {
    let mut h = HessianBlocks::default();
    model.hessian(x, &mut h, HessianMode::Exact);
    !matches!(
        super::EquilibriumFactor::of(model, h),
        Err(super::NoFactor::NotAMinimum)
    )
}
