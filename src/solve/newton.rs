//! Static equilibrium: Newton's method on the total potential energy with Levenberg–Marquardt
//! damping and a backtracking (Armijo) line search, as seed 003 §10.2 recommends; optionally with
//! incremental loading (the external loads raised in `load_steps` equal steps, §10.3.3).
//!
//! A flat net has no transverse stiffness at the start, so its Hessian is singular: the damping
//! `μ` (added on the diagonal, scaled by the mean diagonal) keeps every system positive definite,
//! grows when a factorization or line search fails and shrinks after each accepted step, so the
//! last iterations are plain Newton with quadratic convergence.

use super::linear::{DofMap, SparseSpd};
use super::{Divergence, Observer, SolveReport, StateEvent, Status};
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
    /// Without a coarse start and without obstacles, start Newton from the sagged sheet
    /// ([`super::sagged_start`]: the membrane's sag shape at the depth that minimises the energy)
    /// instead of the flat one. Default true.
    #[serde(default = "default_true")]
    pub sag_start: bool,
    /// How the Levenberg–Marquardt damping moves. Default "auto" (= "cautious", measured the faster
    /// of the two on hang4 at 81² and as fast on the slack nets).
    #[serde(default)]
    pub lm_schedule: LmSchedule,
}

/// How the static solver's Levenberg–Marquardt damping moves between iterations.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LmSchedule {
    /// "cautious" (resolved by [`StaticOptions::resolved`]). The adaptive schedule was measured
    /// against it: hang4 at 81² 41 iterations and 50 factorizations (1.56 s) against 40 and 41
    /// (1.28 s), the slack nets and hang2 alike; it stays as an option.
    #[default]
    Auto,
    /// Divided by 10 after each full step, raised tenfold from 1e-6 while the exact Hessian is
    /// indefinite or the line search cuts the step below 1/8, the projected Hessian for three
    /// iterations once the shift would exceed 1e-3: few iterations where the equilibrium is unique.
    Adaptive,
    /// Divided by 4 after each full step, raised tenfold from 1e-8, the projected Hessian only for
    /// the iteration that needed it (drapelab's schedule before issue 14): small steps, so a drape
    /// whose equilibrium depends on its path (folds on a pedestal, a sheet rolling off a rod,
    /// sticky contact) follows a quasi-static path.
    Cautious,
}

impl StaticOptions {
    /// The options with `lm_schedule = "auto"` resolved (cautious).
    pub fn resolved(&self) -> Self {
        let mut o = self.clone();
        if o.lm_schedule == LmSchedule::Auto {
            o.lm_schedule = LmSchedule::Cautious;
        }
        o
    }
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
            lm_schedule: LmSchedule::Auto,
        }
    }
}

fn free_max_residual(model: &Model, g: &[Vector3<f64>]) -> f64 {
    model.max_residual(g)
}

/// Mean of the Hessian's diagonal over the free DOFs (the scale of the damping), 1 if empty.
fn mean_free_diagonal(h: &HessianBlocks, dofs: &DofMap, n: usize) -> f64 {
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
/// iteration), the Levenberg–Marquardt damping and which Hessian to use.
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
    shift: Vec<f64>,
    /// Levenberg–Marquardt damping relative to the mean free diagonal of the Hessian.
    mu: f64,
    /// Whether the next iteration uses the exact Hessian (else the projected one).
    exact: bool,
    /// Iterations left before the exact Hessian is tried again after it proved indefinite.
    cooldown: usize,
    /// The damping schedule (never `Auto` here).
    schedule: LmSchedule,
    /// The damping's initial value (the cautious schedule returns to it on projecting).
    mu_initial: f64,
}

/// The stretch a straight Newton step may add to a spring before the adaptive schedule's line
/// search pulls it back (relative to the longer of its rest and previous length).
const STRETCH_TOL: f64 = 1e-3;

/// Smallest damping used once damping is needed (relative to the mean diagonal): a compressed
/// spring's negative transverse stiffness is its strain times k, rarely below 1e-6 k.
const MU_MIN: f64 = 1e-6;

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
            shift: vec![0.0; n],
            mu: opts.lm_damping_initial,
            exact: true,
            cooldown: 0,
            schedule: match opts.lm_schedule {
                LmSchedule::Adaptive => LmSchedule::Adaptive,
                _ => LmSchedule::Cautious,
            },
            mu_initial: opts.lm_damping_initial,
        }
    }

    /// Factorizes the Hessian at `x`, shifted by the damping: the exact Hessian (quadratic
    /// convergence; projected Newton stalls on a hanging net whose compressed springs' transverse
    /// stiffness it drops), its damping raised tenfold while it is indefinite, and the projected
    /// Hessian (every term's indefinite part clamped) for three iterations once the shift would have
    /// to exceed 1e-3 of the diagonal. False when no damping helps.
    fn factorize(
        &mut self,
        model: &Model,
        x: &[Vector3<f64>],
        projected: &mut bool,
        scale: f64,
        report: &mut SolveReport,
    ) -> bool {
        let cautious = self.schedule == LmSchedule::Cautious;
        for _ in 0..40 {
            self.shift.iter_mut().for_each(|s| *s = self.mu * scale);
            // Held components (symmetry planes): a diagonal far above the rest decouples them,
            // and their step is set to zero.
            for &(d, c) in &self.held {
                self.shift[d + c] += 1e12 * scale.max(1e-300);
            }
            let ok = self.spd.factorize(&self.dofs, &self.h, &self.shift);
            report.factorizations += 1;
            if ok {
                report.linear_solves += 1;
                return true;
            }
            // Indefinite: shift the exact Hessian (Levenberg–Marquardt) first; only when a large
            // shift would be needed, use the projected Hessian.
            if !*projected && self.mu >= 1e-3 {
                *projected = true;
                model.hessian(x, &mut self.h, true);
                if cautious {
                    self.mu = self.mu_initial.min(self.mu);
                } else {
                    self.cooldown = 3;
                }
            } else {
                self.mu = (self.mu * 10.0).max(if cautious { 1e-8 } else { MU_MIN });
            }
        }
        false
    }

    /// The Newton step −(H + μD)⁻¹ g into `dx` (zero on fixed particles and held components), and
    /// the directional derivative gᵀdx.
    fn step(&mut self, x_len: usize) -> f64 {
        for (p, gp) in self.g.iter().enumerate() {
            if let Some(d) = self.dofs.dof(p) {
                self.rhs[d] = -gp.x;
                self.rhs[d + 1] = -gp.y;
                self.rhs[d + 2] = -gp.z;
            }
        }
        for &(d, c) in &self.held {
            self.rhs[d + c] = 0.0;
        }
        self.spd.solve_in_place(&mut self.rhs);
        for &(d, c) in &self.held {
            self.rhs[d + c] = 0.0;
        }
        let mut slope = 0.0;
        for p in 0..x_len {
            self.dx[p] = match self.dofs.dof(p) {
                Some(d) => Vector3::new(self.rhs[d], self.rhs[d + 1], self.rhs[d + 2]),
                None => Vector3::zeros(),
            };
            slope += self.g[p].dot(&self.dx[p]);
        }
        slope
    }

    /// Backtracking (Armijo) line search along `dx`, bounded by the terms' largest step (contact).
    /// Near the solution the energy change falls below round-off: there a step that lowers the
    /// largest residual force is accepted instead. Returns the accepted step length, if any.
    fn line_search(
        &mut self,
        model: &Model,
        x: &mut [Vector3<f64>],
        load: f64,
        e: &mut f64,
        r: f64,
        slope: f64,
    ) -> Option<f64> {
        let mut alpha = model.max_step(x, &self.dx).min(1.0);
        let cautious = self.schedule == LmSchedule::Cautious;
        let halvings = if cautious { 30 } else { 40 };
        for _ in 0..halvings {
            for (p, xp) in x.iter().enumerate() {
                self.trial[p] = xp + self.dx[p] * alpha;
            }
            if !cautious {
                // A straight step rotates stiff springs and stretches them at second order, which
                // the energy punishes with a tiny step: pull back what the step stretched by more
                // than 1e-3 (a curvilinear step; near the solution nothing is pulled back).
                model.limit_stretch(x, &mut self.trial, STRETCH_TOL);
            }
            let et = model.energy(&self.trial, load);
            let flat = (et - *e).abs() <= 1e-11 * e.abs().max(1e-300);
            let lowers_residual = flat && {
                model.gradient(&self.trial, load, &mut self.g_trial);
                free_max_residual(model, &self.g_trial) < r
            };
            if et.is_finite() && (et <= *e + 1e-4 * alpha * slope || lowers_residual) {
                x.copy_from_slice(&self.trial);
                *e = et;
                return Some(alpha);
            }
            alpha *= 0.5;
        }
        None
    }

    /// One damped Newton iteration from `x`: factorize, step, line search, then adapt the damping
    /// (divided by 10 after a full step, multiplied by 10 when the line search had to cut the step
    /// below 1/8) and re-enable the exact Hessian after a full projected step. False when no step
    /// lowers the energy.
    fn iterate(
        &mut self,
        model: &Model,
        x: &mut [Vector3<f64>],
        load: f64,
        e: &mut f64,
        (r, tol): (f64, f64),
        report: &mut SolveReport,
    ) -> bool {
        self.cooldown = self.cooldown.saturating_sub(1);
        let cautious = self.schedule == LmSchedule::Cautious;
        let mut projected = !(self.exact && self.cooldown == 0);
        model.hessian(x, &mut self.h, projected);
        // The damping's scale: the mean diagonal of this iteration's first Hessian.
        let scale = mean_free_diagonal(&self.h, &self.dofs, model.len());
        for _ in 0..20 {
            if !self.factorize(model, x, &mut projected, scale, report) {
                return false;
            }
            let slope = self.step(x.len());
            let full = model.max_step(x, &self.dx) >= 1.0;
            match self.line_search(model, x, load, e, r, slope) {
                Some(alpha) => {
                    if cautious {
                        if alpha == 1.0 && full {
                            self.mu = if self.mu < 1e-12 { 0.0 } else { self.mu / 4.0 };
                        }
                    } else if alpha == 1.0 {
                        self.mu = if self.mu < 1e-10 { 0.0 } else { self.mu / 10.0 };
                    } else if alpha < 0.125 {
                        self.mu = (self.mu * 10.0).max(MU_MIN);
                    }
                    return true;
                }
                // A step that does not decrease the energy: near the solution, round-off.
                None if cautious && r <= 10.0 * tol => return false,
                None => {
                    self.mu = (self.mu * 10.0).max(if cautious { 1e-8 } else { MU_MIN });
                }
            }
        }
        false
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
    let mut report = SolveReport {
        solver: "static-newton".into(),
        status: Status::MaxIterations,
        iterations: 0,
        linear_solves: 0,
        inner_iterations: 0,
        factorizations: 0,
        factor_time_s: 0.0,
        max_residual_N: f64::NAN,
        max_residual_rel: f64::NAN,
        energy_J: f64::NAN,
        sim_time_s: None,
        dt_s: None,
        wall_time_s: 0.0,
        divergence: None,
        message: String::new(),
        minimum: None,
    };
    let mut ws = Workspace::new(model, x, opts);
    if ws.dofs.n == 0 || !w_ref.is_finite() {
        report.status = Status::Invalid;
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
                report.status = Status::Diverged;
                report.divergence = Some(Divergence {
                    step: iter,
                    dt_s: None,
                    reason: "non-finite".into(),
                });
                break 'load;
            }
            if observer.wants(iter) {
                observer.observe(&StateEvent {
                    index: iter,
                    time_s: None,
                    x,
                    max_residual_N: r,
                    energy_J: e,
                });
            }
            if r <= tol && last {
                report.status = Status::Converged;
                break 'load;
            }
            // Round-off floor: the residual cannot fall below ~16 ε k |x| (see Model::roundoff_force);
            // reaching it after the tolerance proved unreachable is convergence, said in the message.
            if last && r <= model.roundoff_force(x) && r <= 1e3 * tol {
                report.status = Status::Converged;
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
                    report.status = Status::Converged;
                } else {
                    report.message =
                        format!("line search failed at iteration {iter} with residual {r:.3e} N");
                }
                break 'load;
            }
            let strain = model.max_strain(x);
            if strain > opts.strain_bound {
                report.status = Status::Diverged;
                report.divergence = Some(Divergence {
                    step: iter,
                    dt_s: None,
                    reason: format!("strain {strain:.3e} beyond bound"),
                });
                break 'load;
            }
        }
    }
    let final_load = loads.last().copied().unwrap_or(1.0);
    model.gradient(x, final_load, &mut ws.g);
    report.iterations = iter;
    report.factor_time_s = ws.spd.factor_time_s;
    report.max_residual_N = free_max_residual(model, &ws.g);
    report.max_residual_rel = report.max_residual_N / w_ref;
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
    report
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
    let dofs = DofMap::new(&model.fixed);
    if dofs.n == 0 {
        return true;
    }
    let mut h = HessianBlocks::default();
    model.hessian(x, &mut h, false);
    let scale = mean_free_diagonal(&h, &dofs, model.len());
    let mut shift = vec![1e-10 * scale; dofs.n];
    for (d, c) in held_dofs(model, &dofs) {
        shift[d + c] += 1e12 * scale.max(1e-300);
    }
    SparseSpd::new().factorize(&dofs, &h, &shift)
}
