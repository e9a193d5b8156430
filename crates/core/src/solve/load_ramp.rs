//! Incremental loading (seed 003 §10.3.3): the static solve's external loads raised through load
//! factors as a continuation ([`LoadRamp`]) of one Newton run under the executor
//! ([`super::execute`]).

use super::continuation::{Continuation, Stage, execute};
use super::static_options::StaticOptions;
use super::warm::WarmData;
use super::{Observer, SolveReport};
use crate::physics::Model;
use nalgebra::Vector3;

/// Solves for the static equilibrium starting from `x` (updated in place), the external loads raised
/// in `opts.load_steps` equal steps.
pub fn solve_static(
    model: &mut Model,
    x: &mut [Vector3<f64>],
    opts: &StaticOptions,
    observer: &mut dyn Observer,
) -> SolveReport {
    solve_static_warm(model, x, opts, WarmData::default(), observer)
}

/// [`solve_static`] through the given load factors (increasing; the last one is solved to the
/// tolerance and reported, the others only roughly), one Newton run through the executor
/// ([`execute`] of a [`LoadRamp`]).
pub fn solve_static_loads(
    model: &mut Model,
    x: &mut [Vector3<f64>],
    opts: &StaticOptions,
    loads: &[f64],
    observer: &mut dyn Observer,
) -> SolveReport {
    let ramp = &mut LoadRamp::new(loads);
    execute(model, x, opts, WarmData::default(), ramp, observer)
}

/// [`solve_static`] from a neighbouring solve's data (`warm`: its factor; candidate sets are
/// seeded into the model by whoever builds it).
pub fn solve_static_warm(
    model: &mut Model,
    x: &mut [Vector3<f64>],
    opts: &StaticOptions,
    warm: WarmData<'_>,
    observer: &mut dyn Observer,
) -> SolveReport {
    let steps = opts.load_steps.max(1);
    let loads: Vec<f64> = (1..=steps).map(|s| s as f64 / steps as f64).collect();
    execute(model, x, opts, warm, &mut LoadRamp::new(&loads), observer)
}

/// Incremental loading (seed 003 §10.3.3) as a continuation: the external loads raised through the
/// given factors within one Newton run, the last solved to the tolerance.
pub struct LoadRamp {
    loads: Vec<f64>,
    next: usize,
}

impl LoadRamp {
    /// The ramp through `loads` (full load at once when empty).
    pub fn new(loads: &[f64]) -> Self {
        let loads = if loads.is_empty() {
            vec![1.0]
        } else {
            loads.to_vec()
        };
        Self { loads, next: 0 }
    }
}

impl Continuation for LoadRamp {
    fn next(&mut self, _model: &mut Model, _x: &mut [Vector3<f64>], _solved: bool) -> Stage {
        let k = self.next;
        self.next += 1;
        match self.loads.get(k) {
            Some(&load) if k + 1 == self.loads.len() => Stage::Solve(load),
            Some(&load) => Stage::Increment(load),
            None => Stage::Done(String::new()),
        }
    }
}
