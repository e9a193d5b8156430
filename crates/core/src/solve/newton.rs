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

use super::linear::{DofMap, SparseSpd};
use super::{
    DivergenceReason, Globalization, Observer, SolveReport, StateEvent, Status, StopReason,
};
use crate::physics::{HessianBlocks, Model};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// Options of the static solver.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StaticOptions {
    /// Convergence when the largest residual force on a free particle is below this fraction of the
    /// lightest free particle's weight. Default 1e-8.
    #[serde(default = "default_tol")]
    pub residual_tol_rel: f64,
    /// Newton iterations allowed over all load steps. Default 500.
    #[serde(default = "default_max_iter")]
    pub max_iterations: usize,
    /// Number of equal load increments (1 = full load at once). Default 1.
    #[serde(default = "default_steps")]
    pub load_steps: usize,
    /// Initial Levenberg–Marquardt damping relative to the mean Hessian diagonal. Default 1e-3.
    #[serde(default = "default_lm")]
    pub lm_damping_initial: f64,
    /// A strain (relative elongation) beyond which the solve is reported as diverged. Default 10.
    #[serde(default = "default_strain")]
    pub strain_bound: f64,
    /// Start from the interpolated solution on the grid with every other line (nested iteration),
    /// where that grid exists. Default true.
    #[serde(default = "default_true")]
    pub coarse_start: bool,
    /// Without a coarse start and without obstacles, start Newton from the sheet folded down about
    /// the line of its pins when they lie on one ([`super::folded_start`]: the fold angle that
    /// minimises the energy), else from the sagged sheet ([`super::sagged_start`]: the membrane's
    /// sag shape at the depth that minimises the energy), instead of the flat one. Default true.
    #[serde(default = "default_true")]
    pub sag_start: bool,
    /// Follow the curved path x + α dx + ½ α² a, a the step's geodesic acceleration, where a is at
    /// most twice the step in length and the Hessian is the exact one. Default true.
    #[serde(default = "default_true")]
    pub curvilinear: bool,
    /// The largest shift of an indefinite exact Hessian, relative to its mean diagonal, tried
    /// (tenfold from 1e-8) before the projected Hessian is used. Default 1e-5.
    #[serde(default = "default_shift_max")]
    pub shift_max_rel: f64,
    /// Carry the shift that made an indefinite exact Hessian positive definite on as the damping,
    /// projecting once it reaches 1e-3 of the diagonal (drapelab's first schedule: a quasi-static
    /// path of short steps after every indefinite point; the Cusick drape keeps it, its fold counts
    /// converge with the mesh on that path). False: the shift is the iteration's own. Default false.
    #[serde(default)]
    pub carried_damping: bool,
    /// Reuse the last factorization while Newton converges: after a whole step that cut the largest
    /// residual force at least in half, the next step is the chord step −H₀⁻¹ g with the factor
    /// already at hand (no Hessian, no factorization), taken whole when it lowers the energy; the
    /// Hessian is factorized afresh as soon as one does not, or the residual falls by less than half
    /// (Shamanskii's modified Newton). The same equilibrium to the tolerance, fewer factorizations,
    /// possibly more iterations. Default false (the calibration's warm-started solves and each step
    /// of implicit Euler turn it on).
    #[serde(default)]
    pub reuse_factorization: bool,
}

fn default_shift_max() -> f64 {
    1e-5
}

fn default_true() -> bool {
    true
}

fn default_tol() -> f64 {
    1e-8
}
fn default_max_iter() -> usize {
    500
}
fn default_steps() -> usize {
    1
}
fn default_lm() -> f64 {
    1e-3
}
fn default_strain() -> f64 {
    10.0
}

impl Default for StaticOptions {
    fn default() -> Self {
        Self {
            residual_tol_rel: default_tol(),
            max_iterations: default_max_iter(),
            load_steps: default_steps(),
            lm_damping_initial: default_lm(),
            strain_bound: default_strain(),
            coarse_start: true,
            sag_start: true,
            curvilinear: true,
            carried_damping: false,
            shift_max_rel: default_shift_max(),
            reuse_factorization: false,
        }
    }
}

fn free_max_residual(model: &Model, g: &[Vector3<f64>]) -> f64 {
    model.max_residual(g)
}

/// Mean of the Hessian's diagonal over the free DOFs (the scale of the damping), 1 if empty.
pub(super) fn mean_free_diagonal(h: &HessianBlocks, dofs: &DofMap, n: usize) -> f64 {
    let diag = h.diagonal(n);
    let (mut sum, mut cnt) = (0.0, 0usize);
    for (p, d) in diag.iter().enumerate() {
        if dofs.dof(p).is_some() {
            sum += d.trace();
            cnt += 3;
        }
    }
    if cnt > 0 && sum > 0.0 {
        sum / cnt as f64
    } else {
        1.0
    }
}

/// Solves for the static equilibrium starting from `x` (updated in place), the external loads raised
/// in `opts.load_steps` equal steps.
pub fn solve_static(
    model: &Model,
    x: &mut [Vector3<f64>],
    opts: &StaticOptions,
    observer: &mut dyn Observer,
) -> SolveReport {
    let steps = opts.load_steps.max(1);
    let loads: Vec<f64> = (1..=steps).map(|s| s as f64 / steps as f64).collect();
    solve_static_loads(model, x, opts, &loads, observer)
}

/// What the Newton loop carries between iterations: the buffers (nothing is allocated per
/// iteration) and the Levenberg–Marquardt damping.
struct Workspace {
    dofs: DofMap,
    held: Vec<(usize, usize)>,
    spd: SparseSpd,
    g: Vec<Vector3<f64>>,
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
    /// The largest shift of the exact Hessian ([`StaticOptions::shift_max_rel`]).
    shift_max: f64,
    /// Whether to take curved steps ([`StaticOptions::curvilinear`]).
    curvilinear: bool,
    /// Whether the shift is carried on as damping ([`StaticOptions::carried_damping`]).
    carried: bool,
    /// The damping's initial value (where a carried damping returns when the Hessian is projected).
    mu_initial: f64,
    /// Whether the last factorization was of the projected Hessian (see [`Workspace::top_fails`]).
    was_projected: bool,
    /// Whether to reuse the factorization ([`StaticOptions::reuse_factorization`]).
    reuse: bool,
    /// The largest residual force at the start of the previous iteration, N.
    r_prev: f64,
    /// Whether the previous iteration's step was taken whole (from a factorization still at hand).
    whole_prev: bool,
    /// What the globalization did so far.
    stats: Globalization,
}

/// The largest geodesic acceleration taken, relative to the step: |½ a| ≤ |dx|.
const ACCELERATION_MAX: f64 = 1.0;
/// The finite-difference step (in units of dx) of the acceleration's second derivative.
const ACCELERATION_FD: f64 = 0.1;

/// The line search's acceptance of a trial energy `et` from `e` at step length `alpha` along a
/// direction of directional derivative `slope`: (sufficient decrease, Armijo with 1e-4; flat to
/// round-off, a change below 1e-11 of the energy).
fn armijo(et: f64, e: f64, alpha: f64, slope: f64) -> (bool, bool) {
    (
        et <= e + ARMIJO_DECREASE * alpha * slope,
        (et - e).abs() <= ENERGY_FLAT_REL * e.abs().max(1e-300),
    )
}

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

/// The damping above which [`StaticOptions::carried_damping`] switches to the projected Hessian.
pub const CARRIED_DAMPING_MAX: f64 = 1e-3;

/// A chord step is tried while the largest residual force falls at least by this factor per
/// iteration ([`StaticOptions::reuse_factorization`]).
const CHORD_CONTRACTION: f64 = 0.5;

/// Smallest damping used once damping is needed (relative to the mean diagonal).
const MU_MIN: f64 = 1e-8;

impl Workspace {
    fn new(model: &Model, x: &[Vector3<f64>], opts: &StaticOptions) -> Self {
        let dofs = DofMap::new(&model.fixed);
        let held = held_dofs(model, &dofs);
        let n = dofs.n;
        Self {
            dofs,
            held,
            spd: SparseSpd::new(),
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
            shift_max: opts.shift_max_rel,
            curvilinear: opts.curvilinear,
            carried: opts.carried_damping,
            mu_initial: opts.lm_damping_initial,
            was_projected: false,
            reuse: opts.reuse_factorization,
            r_prev: f64::INFINITY,
            whole_prev: false,
            stats: Globalization::default(),
        }
    }

    /// Factorizes the Hessian in `h` (computed at `x`), shifted by the damping: the exact Hessian
    /// (quadratic convergence; projected Newton stalls on a hanging net whose compressed springs'
    /// transverse stiffness it drops), shifted further tenfold while it is indefinite up to
    /// `shift_max` of the diagonal (for this iteration only), then the projected Hessian (every
    /// term's indefinite part clamped) with the damping, raised tenfold while it fails. False when no
    /// damping helps.
    fn factorize(
        &mut self,
        model: &Model,
        x: &[Vector3<f64>],
        projected: &mut bool,
        scale: f64,
        report: &mut SolveReport,
    ) -> bool {
        let mut shift = self.mu;
        for attempt in 0..FACTORIZE_ATTEMPTS {
            if self.try_shift(shift, scale, report) {
                report.linear_solves += 1;
                self.was_projected = *projected;
                return true;
            }
            if self.carried {
                self.carry_shift(model, x, projected);
                shift = self.mu;
            } else if attempt == 0
                && !*projected
                && self.was_projected
                && self.top_fails(shift, scale, report)
            {
                *projected = true;
                model.hessian(x, &mut self.h, true);
            } else if !*projected && shift * DAMPING_GROWTH <= self.shift_max {
                shift = (shift * DAMPING_GROWTH).max(MU_MIN);
            } else if !*projected {
                *projected = true;
                model.hessian(x, &mut self.h, true);
                shift = self.mu;
            } else {
                shift = (shift * DAMPING_GROWTH).max(MU_MIN);
                self.mu = shift;
            }
        }
        false
    }

    /// Factorizes the Hessian in `h` shifted by `shift` × `scale` on the diagonal (held components
    /// decoupled); counts it. False when that is not positive definite.
    fn try_shift(&mut self, shift: f64, scale: f64, report: &mut SolveReport) -> bool {
        self.shift.iter_mut().for_each(|s| *s = shift * scale);
        // Held components (symmetry planes): a diagonal far above the rest decouples them, and
        // their step is set to zero.
        for &(d, c) in &self.held {
            self.shift[d + c] += super::equilibrium::HELD_SHIFT_REL * scale.max(1e-300);
        }
        report.factorizations += 1;
        self.spd.factorize(&self.dofs, &self.h, &self.shift)
    }

    /// After the damping `shift` alone failed, where the iteration before ended on the projected
    /// Hessian: whether the top of the ladder of shifts fails too. Positive definiteness only grows
    /// with a diagonal shift, so then every shift in between fails as well and the ladder can be
    /// skipped — the same step as climbing it, in one factorization instead of each rung's.
    fn top_fails(&mut self, shift: f64, scale: f64, report: &mut SolveReport) -> bool {
        let mut top = shift;
        while top * DAMPING_GROWTH <= self.shift_max {
            top = (top * DAMPING_GROWTH).max(MU_MIN);
        }
        if top == shift {
            return false;
        }
        let fails = !self.try_shift(top, scale, report);
        self.stats.skipped_shifts += usize::from(fails);
        fails
    }

    /// [`StaticOptions::carried_damping`]: the damping raised tenfold, or the projected Hessian
    /// with the damping back at its initial value once it reaches 1e-3.
    fn carry_shift(&mut self, model: &Model, x: &[Vector3<f64>], projected: &mut bool) {
        if !*projected && self.mu >= CARRIED_DAMPING_MAX {
            *projected = true;
            model.hessian(x, &mut self.h, true);
            self.mu = self.mu_initial.min(self.mu);
        } else {
            self.mu = (self.mu * DAMPING_GROWTH).max(MU_MIN);
        }
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

    /// The step's geodesic acceleration into `acc` (Transtrum & Sethna 2012): a = −(H + μD)⁻¹ T, T
    /// the second derivative of the gradient along dx by central differences, so that the path
    /// x + α dx + ½ α² a also cancels the gradient's second-order change. False when that is not
    /// finite or |½ a| > [`ACCELERATION_MAX`] |dx|.
    fn acceleration(&mut self, model: &Model, x: &[Vector3<f64>], load: f64) -> bool {
        let h = ACCELERATION_FD;
        for (p, xp) in x.iter().enumerate() {
            self.trial[p] = xp + self.dx[p] * h;
        }
        model.gradient(&self.trial, load, &mut self.g_trial);
        for (p, xp) in x.iter().enumerate() {
            self.trial[p] = xp - self.dx[p] * h;
        }
        model.gradient(&self.trial, load, &mut self.g_back);
        // T into g_trial (its buffer, so nothing is allocated per iteration).
        for ((t, g), b) in self.g_trial.iter_mut().zip(&self.g).zip(&self.g_back) {
            *t = (*t - g * 2.0 + b) / (h * h);
        }
        let (t, mut acc) = (
            std::mem::take(&mut self.g_trial),
            std::mem::take(&mut self.acc),
        );
        self.solve_for(&t, &mut acc);
        (self.g_trial, self.acc) = (t, acc);
        let norm = |v: &[Vector3<f64>]| v.iter().map(|a| a.norm_squared()).sum::<f64>().sqrt();
        let na = norm(&self.acc);
        na.is_finite() && 0.5 * na <= ACCELERATION_MAX * norm(&self.dx)
    }

    /// Backtracking (Armijo) line search along `dx` from the step length `alpha` (below 1 where a
    /// term bounds the step: contact). Near the solution the energy change falls below round-off:
    /// there a step that lowers the largest residual force is accepted instead. Returns the accepted
    /// step length, if any.
    fn line_search(
        &mut self,
        model: &Model,
        x: &mut [Vector3<f64>],
        load: f64,
        (e, r): (&mut f64, f64),
        (mut alpha, slope): (f64, f64),
    ) -> Option<f64> {
        for _ in 0..LINE_SEARCH_HALVINGS {
            let half = 0.5 * alpha * alpha;
            for (p, xp) in x.iter().enumerate() {
                self.trial[p] = xp + self.dx[p] * alpha + self.acc[p] * half;
            }
            let et = model.energy(&self.trial, load);
            let (decreases, flat) = armijo(et, *e, alpha, slope);
            let lowers_residual = flat && {
                model.gradient(&self.trial, load, &mut self.g_trial);
                free_max_residual(model, &self.g_trial) < r
            };
            if et.is_finite() && (decreases || lowers_residual) {
                x.copy_from_slice(&self.trial);
                *e = et;
                return Some(alpha);
            }
            self.stats.rejected_trials += 1;
            alpha *= 0.5;
        }
        None
    }

    /// One damped Newton iteration from `x`: factorize, step (curved where the acceleration is
    /// small), line search, then adapt the damping (divided by 4 after a whole step, raised tenfold
    /// from 1e-8 when no step lowers the energy). False when no step lowers the energy.
    fn iterate(
        &mut self,
        model: &Model,
        x: &mut [Vector3<f64>],
        load: f64,
        e: &mut f64,
        (r, tol): (f64, f64),
        report: &mut SolveReport,
    ) -> bool {
        // Shamanskii: while whole steps halve the residual, the factor at hand serves again.
        let chord = self.reuse && self.whole_prev && r <= CHORD_CONTRACTION * self.r_prev;
        self.r_prev = r;
        self.whole_prev = chord && self.chord_step(model, x, load, e, report);
        if self.whole_prev {
            return true;
        }
        let mut projected = false;
        model.hessian(x, &mut self.h, projected);
        // The damping's scale: the mean diagonal of this iteration's exact Hessian.
        let scale = mean_free_diagonal(&self.h, &self.dofs, model.len());
        for _ in 0..DAMPED_ROUNDS {
            if !self.factorize(model, x, &mut projected, scale, report) {
                return false;
            }
            let slope = self.step(x.len());
            let mut bound = model.max_step(x, &self.dx);
            let curved = self.curvilinear && !projected && self.acceleration(model, x, load);
            if curved {
                // The bound of the chord to the curve's end as well as of the tangent (the chord
                // into g_back, free until the next acceleration).
                for ((c, d), a) in self.g_back.iter_mut().zip(&self.dx).zip(&self.acc) {
                    *c = d + a * 0.5;
                }
                bound = bound.min(model.max_step(x, &self.g_back));
            } else {
                self.acc.iter_mut().for_each(|a| *a = Vector3::zeros());
            }
            match self.line_search(model, x, load, (e, r), (bound.min(1.0), slope)) {
                Some(alpha) => {
                    self.count(alpha, bound, (curved, projected));
                    self.whole_prev = alpha == 1.0 && bound >= 1.0;
                    if self.whole_prev {
                        self.mu = if self.mu < 1e-12 {
                            0.0
                        } else {
                            self.mu / DAMPING_DECREASE
                        };
                    }
                    return true;
                }
                // A step that does not decrease the energy: near the solution, round-off.
                None if r <= 10.0 * tol => return false,
                None => self.mu = (self.mu * DAMPING_GROWTH).max(MU_MIN),
            }
        }
        false
    }

    /// The chord step −H₀⁻¹ g with the factorization at hand, taken whole when no term bounds it and
    /// it lowers the energy enough (Armijo) or leaves it flat to round-off. False (and `x` as it was)
    /// otherwise.
    fn chord_step(
        &mut self,
        model: &Model,
        x: &mut [Vector3<f64>],
        load: f64,
        e: &mut f64,
        report: &mut SolveReport,
    ) -> bool {
        let slope = self.step(x.len());
        report.linear_solves += 1;
        if slope.is_nan() || slope >= 0.0 || model.max_step(x, &self.dx) < 1.0 {
            return false;
        }
        for (p, xp) in x.iter().enumerate() {
            self.trial[p] = xp + self.dx[p];
        }
        let et = model.energy(&self.trial, load);
        let (decreases, flat) = armijo(et, *e, 1.0, slope);
        if !(et.is_finite() && (decreases || flat)) {
            self.stats.rejected_trials += 1;
            return false;
        }
        x.copy_from_slice(&self.trial);
        *e = et;
        self.stats.full_steps += 1;
        self.stats.chord_steps += 1;
        true
    }

    /// Counts an accepted step of length `alpha` under the terms' `bound`.
    fn count(&mut self, alpha: f64, bound: f64, (curved, projected): (bool, bool)) {
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

/// [`solve_static`] through the given load factors (increasing; the last one is solved to the
/// tolerance and reported, the others only roughly).
pub fn solve_static_loads(
    model: &Model,
    x: &mut [Vector3<f64>],
    opts: &StaticOptions,
    loads: &[f64],
    observer: &mut dyn Observer,
) -> SolveReport {
    let start = Instant::now();
    let w_ref = model.reference_weight();
    let tol = opts.residual_tol_rel * w_ref;
    let mut report = SolveReport::unsolved("static-newton");
    let mut ws = Workspace::new(model, x, opts);
    if ws.dofs.n == 0 || !w_ref.is_finite() {
        report.stop_for(StopReason::Invalid);
        report.message = "no free particle with mass: nothing to solve".into();
        return report;
    }
    let steps = loads.len().max(1);
    let mut iter = 0usize;
    let mut floor = false;
    'load: for step in 1..=steps {
        let load = loads.get(step - 1).copied().unwrap_or(1.0);
        let last = step == steps;
        let mut e = model.energy(x, load);
        loop {
            model.gradient(x, load, &mut ws.g);
            let r = free_max_residual(model, &ws.g);
            if !r.is_finite() || !e.is_finite() {
                report.diverge(iter, None, DivergenceReason::NonFinite);
                break 'load;
            }
            if let Err(err) = observe_iterate(observer, iter, x, (r, e)) {
                report.stop_for(StopReason::Observer);
                report.message = format!("an observer failed at iteration {iter}: {err:#}");
                break 'load;
            }
            if r <= tol && last {
                report.stop_for(StopReason::Converged);
                break 'load;
            }
            // Round-off floor: the residual cannot fall below ~16 ε k |x| (see Model::roundoff_force);
            // reaching it after the tolerance proved unreachable is convergence, said in the message.
            if last && r <= model.roundoff_force(x) && r <= 1e3 * tol {
                report.stop_for(StopReason::RoundoffFloor);
                floor = true;
                break 'load;
            }
            if r <= tol.max(1e-6 * w_ref) && !last {
                continue 'load;
            }
            if iter >= opts.max_iterations {
                report.message = format!(
                    "{} Newton iterations without reaching the tolerance",
                    opts.max_iterations
                );
                break 'load;
            }
            iter += 1;
            if !ws.iterate(model, x, load, &mut e, (r, tol), &mut report) {
                // A step that does not decrease the energy: near the solution, round-off.
                model.gradient(x, load, &mut ws.g);
                let r = free_max_residual(model, &ws.g);
                if r <= tol && last {
                    report.stop_for(StopReason::Converged);
                } else {
                    report.stop_for(StopReason::LineSearch);
                    report.message =
                        format!("line search failed at iteration {iter} with residual {r:.3e} N");
                }
                break 'load;
            }
            let strain = model.max_strain(x);
            if strain > opts.strain_bound {
                let bound = opts.strain_bound;
                report.diverge(
                    iter,
                    None,
                    DivergenceReason::StrainBeyondBound { strain, bound },
                );
                break 'load;
            }
        }
    }
    let final_load = loads.last().copied().unwrap_or(1.0);
    finish_report(
        model,
        x,
        final_load,
        &mut ws,
        (iter, floor, start),
        &mut report,
    );
    report
}

/// Hands Newton iterate `iter` (residual `r` N, energy `e` J) to `observer` when it wants it.
fn observe_iterate(
    observer: &mut dyn Observer,
    iter: usize,
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
    })
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
    model.gradient(x, final_load, &mut ws.g);
    report.iterations = iter;
    report.globalization = ws.stats;
    report.factor_time_s = ws.spd.factor_time_s;
    report.max_residual_N = free_max_residual(model, &ws.g);
    report.max_residual_rel = report.max_residual_N / model.reference_weight();
    report.energy_J = model.energy(x, final_load);
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

/// Whether the equilibrium `x` is a minimum of the model's energy: the exact Hessian over the free
/// coordinates (held components decoupled), shifted by 1e-10 of its mean diagonal for neutral
/// directions, has a Cholesky factorization. False at a saddle or a maximum (an unstable
/// equilibrium, e.g. a flat sheet under compression).
pub fn is_minimum(model: &Model, x: &[Vector3<f64>]) -> bool {
    let mut h = HessianBlocks::default();
    model.hessian(x, &mut h, false);
    !matches!(
        super::EquilibriumFactor::of(model, h),
        Err(super::NoFactor::NotAMinimum)
    )
}
