//! The clock of an implicit integration (its time, steps and frames) and its step-size control:
//! steps grow with few Newton iterations, halve on a rejected step, land on frame times.

use crate::physics::Model;
use nalgebra::Vector3;

/// Where an integration is: its time, steps, the largest and the last step, and the frames.
pub(super) struct Clock {
    pub(super) t: f64,
    pub(super) steps: usize,
    pub(super) largest: f64,
    pub(super) last_dt: f64,
    /// The number of the next frame (1 first).
    pub(super) frame: usize,
    /// Whether the state is at a frame time (t = 0 is one).
    pub(super) at_frame: bool,
}

impl Default for Clock {
    fn default() -> Self {
        Self {
            t: 0.0,
            steps: 0,
            largest: 0.0,
            last_dt: 0.0,
            frame: 1,
            at_frame: true,
        }
    }
}

impl Clock {
    /// An accepted step of `dt`: the time landed on the next frame time `next_frame` when it is
    /// within round-off of it.
    pub(super) fn accept(&mut self, dt: f64, next_frame: Option<f64>) {
        self.steps += 1;
        self.last_dt = dt;
        self.largest = self.largest.max(dt);
        (self.t, self.at_frame) = advance(self.t, dt, next_frame, &mut self.frame);
    }

    /// The message of a settled state with largest residual `r` (N) and speed (m/s).
    pub(super) fn settled(&self, model: &Model, v: &[Vector3<f64>], r: f64, speed: f64) -> String {
        format!(
            "settled at t = {:.4} s after {} steps (largest residual {r:.2e} N, largest speed {speed:.2e} m/s, kinetic energy {:.2e} J; largest step {:.1e} s)",
            self.t,
            self.steps,
            super::kinetic_energy(model, v),
            self.largest
        )
    }
}

/// The time after an accepted step of `dt` from `t`, landed on the next frame time `next_frame`
/// (counted in `frame`) when it is within round-off of it; and whether it landed.
fn advance(t: f64, dt: f64, next_frame: Option<f64>, frame: &mut usize) -> (f64, bool) {
    let t = t + dt;
    match next_frame {
        Some(tf) if (tf - t).abs() <= 1e-9 * tf.max(1.0) => {
            *frame += 1;
            (tf, true)
        }
        _ => (t, false),
    }
}

/// The next step after an accepted step of `dt` that took `iterations` Newton iterations: a step
/// shortened to land on a frame does not set the next one, and while `cooldown` lasts (after a
/// rejected step) the step does not grow.
pub(super) fn grown(
    h: f64,
    dt: f64,
    iterations: usize,
    cooldown: usize,
    bounds: StepBounds,
) -> f64 {
    if dt < h * (1.0 - 1e-12) {
        return h;
    }
    next_dt(h, iterations, bounds).min(if cooldown > 0 { h } else { f64::INFINITY })
}

/// The next step after one that took `iterations` Newton iterations (chord steps not counted: they
/// factorize nothing): doubled when Newton converged within 6, kept up to 12, halved beyond.
fn next_dt(h: f64, iterations: usize, s: StepBounds) -> f64 {
    if !s.adaptive {
        return h;
    }
    let f = match iterations {
        0..=6 => 2.0,
        7..=12 => 1.0,
        _ => 0.5,
    };
    (h * f).clamp(s.min_dt_s, s.max_dt_s)
}

/// What bounds an adaptive step: whether it adapts at all, and its smallest and largest length, s.
#[derive(Clone, Copy)]
pub(super) struct StepBounds {
    pub(super) adaptive: bool,
    pub(super) min_dt_s: f64,
    pub(super) max_dt_s: f64,
}
