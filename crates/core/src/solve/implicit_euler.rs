//! Implicit Euler's loop of time steps (each an optimisation of the incremental potential,
//! [`super::incremental`]) under the executor ([`super::executor`]): until the drape settles, a
//! budget is spent, a step diverges or the step size falls below its minimum.

use super::clock::{Clock, grown};
use super::executor::{Budget, Verdict};
use super::incremental::{Attempt, Carried, ImplicitSettings, step};
use super::{DivergenceReason, Observer, SolveReport, StateEvent, StopReason};
use crate::physics::{Contacts, Model};
use nalgebra::Vector3;

/// What a settled (or stopped) integration is checked against, and where it stands.
pub struct Settle {
    /// Largest residual force of W (without inertia) allowed, N.
    pub residual_N: f64,
    /// Largest speed allowed, m/s.
    pub speed_m_per_s: f64,
    /// Size of the drape (its bounding box's diagonal), m.
    pub extent_m: f64,
}

/// Integrates from (`x`, `v`) (updated in place) until settled, stopped or out of time: each step
/// minimises the incremental potential ([`Inertia`] + the model). `frame_s`: land a step on every
/// multiple of it and hand that state to `observer` (stamped with the exact frame time).
/// Newton's Hessian is that of a time step: pinned contact pairs carry their distance's
/// curvature ([`crate::physics::PairCurvature::Pinned`]).
#[allow(clippy::too_many_arguments)]
pub fn integrate_implicit(
    model: &mut Model,
    x: &mut [Vector3<f64>],
    v: &mut [Vector3<f64>],
    s: &ImplicitSettings,
    settle: &Settle,
    budget: (f64, Option<f64>),
    frame_s: Option<f64>,
    observer: &mut dyn Observer,
    report: &mut SolveReport,
) {
    let mut run = ImplicitRun {
        model,
        x,
        v,
        s,
        settle,
        budget,
        frame_s,
        report,
        h: s.dt_s,
        cooldown: 0,
        g: Vec::new(),
        carried: Carried::default(),
        clock: Clock::default(),
        r: f64::NAN,
        pending: None,
    };
    let budget = Budget {
        iterations: usize::MAX,
        wall_s: budget.1,
    };
    let verdict = super::executor::run(&mut run, budget, observer);
    let (steps, t, largest) = (run.clock.steps, run.clock.t, run.clock.largest);
    super::executor::conclude(verdict, steps, report);
    report.iterations = steps;
    report.sim_time_s = Some(t);
    report.dt_s = Some(if steps > 0 { largest } else { s.dt_s });
}

/// Implicit Euler's steps as an iterative solver ([`super::executor`]): the state, its step size
/// and clock, and the observation an accepted step owes.
struct ImplicitRun<'a> {
    model: &'a mut Model,
    x: &'a mut [Vector3<f64>],
    v: &'a mut [Vector3<f64>],
    s: &'a ImplicitSettings,
    settle: &'a Settle,
    /// The simulated-time and wall-time budgets, s (the executor spends the wall time).
    budget: (f64, Option<f64>),
    frame_s: Option<f64>,
    report: &'a mut SolveReport,
    /// The next step's size, s.
    h: f64,
    /// Steps left before the step may grow again after a rejected one.
    cooldown: usize,
    g: Vec<Vector3<f64>>,
    /// The last step's factor (the next step's preconditioner) and the candidate set contact is
    /// measured over.
    carried: Carried,
    clock: Clock,
    /// The largest residual force at the current state, N.
    r: f64,
    /// The state after an accepted step, which the observer sees if it lands on a frame or the
    /// observer wants its step: (step, time s, residual N, on a frame).
    pending: Option<(usize, f64, f64, bool)>,
}

impl super::executor::Iterative for ImplicitRun<'_> {
    fn iterations(&self) -> usize {
        self.clock.steps
    }

    fn terminate(&mut self, observer: &mut dyn Observer) -> Option<Verdict> {
        let contacts = (self.model).contacts_with(self.x, &mut self.carried.candidates);
        if let Some((steps, t, r, at_frame)) = self.pending.take()
            && (at_frame || (self.frame_s.is_none() && observer.wants(steps)))
            && let Err(e) = observe_state(
                observer,
                (self.model, &contacts),
                self.x,
                self.v,
                (steps, t, r),
            )
        {
            let message = format!("an observer failed at t = {t:.4} s: {e:#}");
            return Some(Verdict::Stopped(StopReason::Observer, message));
        }
        (self.model).gradient_on(self.x, &contacts, 1.0, &mut self.g);
        let r = self.model.max_residual(&self.g);
        self.r = r;
        let speed = self.v.iter().map(|p| p.norm()).fold(0.0, f64::max);
        if !r.is_finite() {
            let (reason, dt_s) = (DivergenceReason::NonFinite, Some(self.h));
            return Some(Verdict::Diverged {
                reason,
                dt_s,
                message: None,
            });
        }
        // Recording frames, the state is judged on frame times only (the last one recorded is the
        // final state).
        let c = &self.clock;
        let on_frame = self.frame_s.is_none() || c.at_frame;
        if on_frame && settled(self.model, self.x, self.settle, (r, speed, c.last_dt)) {
            let message = c.settled(self.model, self.v, r, speed);
            return Some(Verdict::Reached(Some(StopReason::Converged), Some(message)));
        }
        let max_time_s = self.budget.0;
        (c.t >= max_time_s * (1.0 - 1e-12)).then(|| {
            let message = format!(
                "not settled within {max_time_s} s (residual {r:.3e} N, speed {speed:.3e} m/s)"
            );
            Verdict::Stopped(StopReason::SimulatedTime, message)
        })
    }

    fn next_iter(&mut self) -> Result<(), Verdict> {
        // The step: capped by the time budget and, when recording frames, landing on the next one.
        let (t, next_frame) = (
            self.clock.t,
            self.frame_s.map(|f| f * self.clock.frame as f64),
        );
        let dt = next_frame
            .map_or(self.h, |tf| self.h.min(tf - t))
            .min(self.budget.0 - t);
        let (model, s) = (&mut *self.model, self.s);
        match step(model, self.x, self.v, dt, s, &mut self.carried, self.report) {
            Attempt::Accepted(iterations) => {
                self.clock.accept(dt, next_frame);
                let c = &self.clock;
                self.pending = Some((c.steps, c.t, self.r, c.at_frame));
                // A step shortened to land on a frame does not set the next one, and for three
                // steps after a rejected one the step does not grow.
                self.cooldown = self.cooldown.saturating_sub(1);
                self.h = grown(self.h, dt, iterations, self.cooldown, s.bounds());
                Ok(())
            }
            Attempt::Diverged(reason) => {
                let message = Some(format!(
                    "diverged at t = {t:.4} s (step {dt:e} s): {reason}"
                ));
                Err(Verdict::Diverged {
                    reason,
                    dt_s: Some(dt),
                    message,
                })
            }
            Attempt::Rejected => {
                (self.h, self.cooldown) = (dt * 0.5, 3);
                if self.h >= s.min_dt_s {
                    return Ok(());
                }
                let message = format!(
                    "Newton failed at every step down to {:.1e} s at t = {t:.4} s",
                    s.min_dt_s
                );
                Err(Verdict::Stopped(StopReason::StepTooSmall, message))
            }
        }
    }

    fn out_of_iterations(&self, budget: usize) -> String {
        format!("{budget} time steps")
    }

    fn out_of_wall_time(&self, _budget_s: f64) -> String {
        let (t, r) = (self.clock.t, self.r);
        format!("wall-time budget spent at t = {t:.4} s (residual {r:.3e} N)")
    }
}

/// Whether a state with largest residual `r` N and speed m/s after a step of `last_dt` s has
/// settled: forces and speed below the criterion. Near the round-off floor of forces a soft mode
/// keeps moving by floor/stiffness per step: there the speed criterion becomes "no particle moved
/// more than 1e-7 of the drape's size". (Each step's Newton stops within 100 times the floor of
/// its own, inertia-stiffened forces.)
fn settled(
    model: &Model,
    x: &[Vector3<f64>],
    settle: &Settle,
    (r, speed, last_dt): (f64, f64, f64),
) -> bool {
    let floor = 100.0 * model.roundoff_force(x);
    let still =
        speed <= settle.speed_m_per_s || (r <= floor && speed * last_dt <= 1e-7 * settle.extent_m);
    r <= settle.residual_N.max(floor) && still
}

/// Hands the state after step `steps` (time `t`, residual `r` N) to `observer`, with its total
/// (potential and kinetic) energy (`contacts` the contact set at `x`).
fn observe_state(
    observer: &mut dyn Observer,
    (model, contacts): (&Model, &Contacts),
    x: &[Vector3<f64>],
    v: &[Vector3<f64>],
    (steps, t, r): (usize, f64, f64),
) -> anyhow::Result<()> {
    observer.observe(&StateEvent {
        index: steps,
        time_s: Some(t),
        x,
        max_residual_N: r,
        energy_J: model.energy_on(x, contacts, 1.0) + super::kinetic_energy(model, v),
        step: None,
    })
}

/// Hands the initial state (t = 0) to `observer` when it records frames or wants step 0.
pub fn observe_start(
    model: &Model,
    x: &[Vector3<f64>],
    v: &[Vector3<f64>],
    frame_s: Option<f64>,
    observer: &mut dyn Observer,
) -> anyhow::Result<()> {
    if frame_s.is_some() || observer.wants(0) {
        let (mut g, contacts) = (Vec::new(), model.contacts(x));
        model.gradient_on(x, &contacts, 1.0, &mut g);
        let r = model.max_residual(&g);
        observe_state(observer, (model, &contacts), x, v, (0, 0.0, r))?;
    }
    Ok(())
}
