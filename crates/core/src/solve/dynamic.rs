//! Dynamic integrators, all stopping at equilibrium (largest residual force and largest speed below
//! tolerance) or at a maximum simulated time:
//! - explicit (forward) Euler as in seed 000: x ← x + Δt v, v ← v + Δt F/m with the damping force
//!   −c v (Eq. 4), then Provot's position correction of springs stretched beyond the elongation rate;
//! - symplectic (semi-implicit) Euler: v ← v + Δt F/m, x ← x + Δt v;
//! - implicit Euler as an optimisation (the default implicit integrator; [`super::incremental`]): each
//!   step minimises the incremental potential with the static solver's Newton, adaptive steps, contact
//!   kept outside by the line search's bound;
//! - implicit Euler after Baraff & Witkin (1998): (M + Δt c + Δt² K) Δv = Δt (f − Δt K v), one
//!   linearised step solved by conjugate gradients with a block-Jacobi preconditioner (kept for
//!   comparison: it is cheaper per step but takes fixed steps and cuts them short at contact).
//!
//! The explicit integrators stop with [`StopReason::ContactTooStiff`] the first time a step would
//! carry a particle into an obstacle: their step cannot resolve the barrier there.

use super::dynamic_options::DynamicOptions;
use super::executor::{Budget, Verdict};
use super::implicit_euler::{Settle, integrate_implicit, observe_start};
use super::incremental::ImplicitSettings;
use super::kind::Integrator;
use super::stability::{kinetic_energy, stability_limit_dt};
use super::time_step::Stepper;
use super::{DivergenceReason, Observer, SolveReport, StateEvent, StopReason};
use crate::physics::{Contacts, Model};
use nalgebra::Vector3;
use std::time::Instant;

/// Integrates from rest at `x` (updated in place) until equilibrium, divergence or the time limit.
/// `v` holds the velocities (in: initial, out: final).
pub fn solve_dynamic(
    model: &mut Model,
    integrator: Integrator,
    x: &mut [Vector3<f64>],
    v: &mut [Vector3<f64>],
    opts: &DynamicOptions,
    observer: &mut dyn Observer,
) -> SolveReport {
    if integrator == Integrator::ImplicitEuler {
        return solve_implicit(model, x, v, opts, observer);
    }
    let model = &*model;
    let start = Instant::now();
    let n = model.len();
    let c = viscous_damping(model, opts);
    let dt = fixed_dt(model, x, integrator, c, opts);
    let free: Vec<bool> = model.fixed.iter().map(|f| !f).collect();
    let w_ref = model.reference_weight();
    let mut report = SolveReport {
        stop: StopReason::SimulatedTime,
        sim_time_s: Some(0.0),
        dt_s: Some(dt),
        ..SolveReport::unsolved(integrator.into())
    };
    if !free.iter().any(|&f| f) || !w_ref.is_finite() || dt.is_nan() || dt <= 0.0 {
        report.stop_with(
            StopReason::Invalid,
            "nothing free to integrate, or a non-positive time step",
        );
        return report;
    }
    let limits = Limits::new(model, x, v, opts, dt);
    hold_fixed(model, v);
    let mut run = ExplicitRun {
        stepper: Stepper::new(model, integrator, x, c, dt, free),
        model,
        x,
        v,
        limits,
        g: Vec::with_capacity(n),
        contacts: Contacts::default(),
        check: opts.check_every.max(1),
        step: 0,
        cg_tol_rel: opts.cg_tol_rel,
        integrator,
        report: &mut report,
    };
    let budget = Budget {
        iterations: usize::MAX,
        wall_s: opts.max_wall_time_s,
    };
    let verdict = super::executor::run(&mut run, budget, observer);
    let ExplicitRun {
        x, step, stepper, ..
    } = run;
    let cut_steps = stepper.cut_steps;
    super::executor::conclude(verdict, step, &mut report);
    finish(model, x, step, dt, start, &mut report);
    if cut_steps > 0 && integrator == Integrator::BaraffWitkin {
        report.contact_cut_steps = cut_steps;
        report.message = format!(
            "{} ({} steps cut short by contact)",
            report.message, cut_steps
        );
    }
    report
}

/// The fixed step of an explicit or Baraff–Witkin integration: `auto_dt_fraction` of the stability
/// limit at `x` when asked and known, else `dt_s`.
fn fixed_dt(
    model: &Model,
    x: &[Vector3<f64>],
    integrator: Integrator,
    c: f64,
    opts: &DynamicOptions,
) -> f64 {
    match (
        opts.auto_dt_fraction > 0.0,
        stability_limit_dt(model, x, integrator, c),
    ) {
        (true, Some(lim)) if lim > 0.0 && lim.is_finite() => opts.auto_dt_fraction * lim,
        _ => opts.dt_s,
    }
}

/// The report's final state after `steps` steps of `dt`: residual, energy, times.
fn finish(
    model: &Model,
    x: &[Vector3<f64>],
    steps: usize,
    dt: f64,
    start: Instant,
    report: &mut SolveReport,
) {
    report.iterations = steps;
    report.sim_time_s = Some(steps as f64 * dt);
    final_state(model, x, start, report);
}

/// The report's final residual, energy and wall time at `x`.
fn final_state(model: &Model, x: &[Vector3<f64>], start: Instant, report: &mut SolveReport) {
    let (mut g, contacts) = (Vec::with_capacity(model.len()), model.contacts(x));
    model.gradient_on(x, &contacts, 1.0, &mut g);
    report.max_residual_N = model.max_residual(&g);
    report.max_residual_rel = report.max_residual_N / model.reference_weight();
    report.energy_J = model.energy_on(x, &contacts, 1.0);
    report.wall_time_s = start.elapsed().as_secs_f64();
}

/// The viscous damping coefficient c of the integration, N·s/m (0 without damping).
fn viscous_damping(model: &Model, opts: &DynamicOptions) -> f64 {
    if opts.damping {
        model.damping_Ns_per_m
    } else {
        0.0
    }
}

/// Zero velocity on the fixed particles.
fn hold_fixed(model: &Model, v: &mut [Vector3<f64>]) {
    for (vi, f) in v.iter_mut().zip(&model.fixed) {
        if *f {
            *vi = Vector3::zeros();
        }
    }
}

/// Implicit Euler as an optimisation ([`integrate_implicit`]) with the options' steps, damping and
/// settle criterion (the same as the other integrators': residual force and speed), and the report's
/// final numbers.
fn solve_implicit(
    model: &mut Model,
    x: &mut [Vector3<f64>],
    v: &mut [Vector3<f64>],
    opts: &DynamicOptions,
    observer: &mut dyn Observer,
) -> SolveReport {
    let start = Instant::now();
    let w_ref = model.reference_weight();
    let mut report = SolveReport {
        stop: StopReason::SimulatedTime,
        sim_time_s: Some(0.0),
        dt_s: Some(opts.dt_s),
        ..SolveReport::unsolved(super::SolverKind::ImplicitEuler)
    };
    let free = model.fixed.iter().any(|f| !f);
    let steps_ok = opts.dt_s > 0.0 && opts.min_dt_s > 0.0 && opts.max_dt_s >= opts.min_dt_s;
    if !free || !w_ref.is_finite() || !steps_ok {
        report.stop_with(StopReason::Invalid, "nothing free to integrate, or time steps that are not 0 < min_dt_s ≤ max_dt_s, dt_s > 0");
        return report;
    }
    hold_fixed(model, v);
    let settings = ImplicitSettings::of(opts, viscous_damping(model, opts));
    let settle = Settle {
        residual_N: opts.residual_tol_rel * w_ref,
        speed_m_per_s: opts.speed_tol_m_per_s,
        extent_m: extent_m(x),
    };
    let frame_s = observer.frame_interval_s();
    if let Err(e) = observe_start(model, x, v, frame_s, observer) {
        report.stop_with(
            StopReason::Observer,
            format!("an observer failed at t = 0: {e:#}"),
        );
        return report;
    }
    integrate_implicit(
        model,
        x,
        v,
        &settings,
        &settle,
        (opts.max_time_s, opts.max_wall_time_s),
        frame_s,
        observer,
        &mut report,
    );
    final_state(model, x, start, &mut report);
    report
}

/// The diagonal of the particles' bounding box, m (at least 1 mm): the drape's size.
fn extent_m(x: &[Vector3<f64>]) -> f64 {
    let (lo, hi) = x.iter().fold(
        (
            Vector3::repeat(f64::INFINITY),
            Vector3::repeat(f64::NEG_INFINITY),
        ),
        |(lo, hi), p| (lo.inf(p), hi.sup(p)),
    );
    (hi - lo).norm().max(1e-3)
}

/// Why the time loop stops.
enum Stop {
    Reason(StopReason),
    Diverged(DivergenceReason),
}

/// The budgets and divergence thresholds of one integration.
struct Limits {
    dt: f64,
    max_steps: usize,
    w_ref: f64,
    e0: f64,
    blowup: f64,
    residual_tol_rel: f64,
    speed_tol: f64,
    strain_bound: f64,
    max_time_s: f64,
}

impl Limits {
    fn new(
        model: &Model,
        x: &[Vector3<f64>],
        v: &[Vector3<f64>],
        opts: &DynamicOptions,
        dt: f64,
    ) -> Self {
        let total_weight: f64 = model.masses.iter().sum::<f64>() * model.gravity_m_per_s2.max(1.0);
        let extent = extent_m(x);
        let e0 = model.energy(x, 1.0) + kinetic_energy(model, v);
        Self {
            dt,
            max_steps: (opts.max_time_s / dt).ceil() as usize,
            w_ref: model.reference_weight(),
            e0,
            blowup: 100.0 * total_weight * extent + 100.0 * e0.abs(),
            residual_tol_rel: opts.residual_tol_rel,
            speed_tol: opts.speed_tol_m_per_s,
            strain_bound: opts.strain_bound,
            max_time_s: opts.max_time_s,
        }
    }

    /// Hands the state at `step` (residual `r` N, total energy `etot` J) to `obs`; a stop when it
    /// fails.
    fn event(
        &self,
        obs: &mut dyn Observer,
        x: &[Vector3<f64>],
        (step, r, etot): (usize, f64, f64),
    ) -> Option<(Stop, String)> {
        let event = StateEvent {
            index: step,
            time_s: Some(step as f64 * self.dt),
            x,
            max_residual_N: r,
            energy_J: etot,
            step: None,
        };
        obs.observe(&event).err().map(|err| {
            let msg = format!("an observer failed at step {step}: {err:#}");
            (Stop::Reason(StopReason::Observer), msg)
        })
    }

    /// The state at `step` handed to `observer` between the checks of [`Limits::check`]; a stop
    /// only when the observer fails.
    fn observe(
        &self,
        model: &Model,
        (x, contacts): (&[Vector3<f64>], &Contacts),
        v: &[Vector3<f64>],
        g: &[Vector3<f64>],
        step: usize,
        observer: &mut dyn Observer,
    ) -> Option<(Stop, String)> {
        let etot = model.energy_on(x, contacts, 1.0) + kinetic_energy(model, v);
        self.event(observer, x, (step, model.max_residual(g), etot))
    }

    /// Whether to stop at `step` (the gradient `g` is current), and why, in words too; the observer,
    /// when given, sees the state first.
    fn check(
        &self,
        model: &Model,
        (x, contacts): (&[Vector3<f64>], &Contacts),
        v: &[Vector3<f64>],
        g: &[Vector3<f64>],
        step: usize,
        observer: Option<&mut dyn Observer>,
    ) -> Option<(Stop, String)> {
        let dt = self.dt;
        let r = model.max_residual(g);
        let vmax = v.iter().map(|vi| vi.norm()).fold(0.0, f64::max);
        let etot = model.energy_on(x, contacts, 1.0) + kinetic_energy(model, v);
        let time = step as f64 * dt;
        if let Some(obs) = observer
            && let Some(failed) = self.event(obs, x, (step, r, etot))
        {
            return Some(failed);
        }
        let divergence = if !etot.is_finite() || !r.is_finite() {
            Some(DivergenceReason::NonFinite)
        } else if etot - self.e0 > self.blowup {
            Some(DivergenceReason::EnergyBlowUp {
                energy_J: etot,
                initial_J: self.e0,
            })
        } else {
            let s = model.max_strain(x);
            (s > self.strain_bound).then_some(DivergenceReason::StrainBeyondBound {
                strain: s,
                bound: self.strain_bound,
            })
        };
        if let Some(d) = divergence {
            let msg = format!("diverged at step {step} (dt = {dt:e} s): {d}");
            return Some((Stop::Diverged(d), msg));
        }
        if r <= (self.residual_tol_rel * self.w_ref).max(model.roundoff_force(x))
            && vmax <= self.speed_tol
        {
            let msg = format!("equilibrium at t = {time:.4} s after {step} steps");
            return Some((Stop::Reason(StopReason::Converged), msg));
        }
        if step >= self.max_steps {
            let msg = format!(
                "no equilibrium within {} s (residual {r:.3e} N, speed {vmax:.3e} m/s)",
                self.max_time_s
            );
            return Some((Stop::Reason(StopReason::SimulatedTime), msg));
        }
        None
    }
}

/// The explicit, symplectic and Baraff–Witkin integrators' fixed steps as an iterative solver
/// ([`super::executor`]): the state, its stepper and the checks of [`Limits`].
struct ExplicitRun<'a, 'r> {
    model: &'a Model,
    x: &'a mut [Vector3<f64>],
    v: &'a mut [Vector3<f64>],
    limits: Limits,
    stepper: Stepper,
    /// The gradient at the current state.
    g: Vec<Vector3<f64>>,
    /// The contact set at the current state.
    contacts: Contacts,
    /// The stopping criteria are checked every `check` steps.
    check: usize,
    step: usize,
    cg_tol_rel: f64,
    integrator: Integrator,
    report: &'r mut SolveReport,
}

impl super::executor::Iterative for ExplicitRun<'_, '_> {
    fn iterations(&self) -> usize {
        self.step
    }

    /// The stopping criteria, checked every `check_every` steps whether or not anyone watches: an
    /// observer sees states between them without moving where the run stops.
    fn terminate(&mut self, observer: &mut dyn Observer) -> Option<Verdict> {
        let (model, x, v, step) = (self.model, &*self.x, &*self.v, self.step);
        let want = observer.wants(step);
        self.contacts = self.stepper.contacts(model, x);
        model.gradient_on(x, &self.contacts, 1.0, &mut self.g);
        let at = (x, &self.contacts);
        let g = &self.g;
        let stop = if step.is_multiple_of(self.check) || step == self.limits.max_steps {
            self.limits
                .check(model, at, v, g, step, want.then_some(observer))
        } else if want {
            self.limits.observe(model, at, v, g, step, observer)
        } else {
            None
        };
        stop.map(|(stop, message)| match stop {
            Stop::Diverged(reason) => Verdict::Diverged {
                reason,
                dt_s: Some(self.limits.dt),
                message: Some(message),
            },
            Stop::Reason(StopReason::Converged) => {
                Verdict::Reached(Some(StopReason::Converged), Some(message))
            }
            Stop::Reason(reason) => Verdict::Stopped(reason, message),
        })
    }

    fn next_iter(&mut self) -> Result<(), Verdict> {
        let (model, g) = (self.model, &self.g);
        let tol = self.cg_tol_rel;
        let at = (&mut *self.x, &self.contacts);
        self.stepper.step(model, at, self.v, g, tol, self.report);
        self.step += 1;
        if self.stepper.cut_steps > 0 && self.integrator != Integrator::BaraffWitkin {
            let message = format!(
                "contact too stiff for an explicit step: at t = {:.4} s a step of {:e} s would carry a particle into an obstacle; use implicit-euler",
                self.step as f64 * self.limits.dt,
                self.limits.dt
            );
            return Err(Verdict::Stopped(StopReason::ContactTooStiff, message));
        }
        Ok(())
    }

    fn out_of_iterations(&self, budget: usize) -> String {
        format!("{budget} time steps")
    }

    fn out_of_wall_time(&self, budget_s: f64) -> String {
        let time = self.step as f64 * self.limits.dt;
        let r = self.model.max_residual(&self.g);
        let vmax = self.v.iter().map(|vi| vi.norm()).fold(0.0, f64::max);
        format!(
            "wall-time budget of {budget_s} s spent at t = {time:.4} s (residual {r:.3e} N, speed {vmax:.3e} m/s)"
        )
    }
}
