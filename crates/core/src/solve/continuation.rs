//! The one executor of static continuations (argmin's habit: the executor owns the loop). A
//! continuation is a sequence of Newton solves of one model whose set-up changes between them: a
//! load raised in increments with obstacles' contact sets refreshed (seed 003 §10.7.1's vertical
//! gap), friction anchors lagged one solve behind, a start from a coarser grid. The
//! [`Continuation`] says what the next stage is; [`execute`] runs the solves, hands the observer
//! the first stage, stops at the first stage that does not converge, and merges the reports
//! ([`SolveReport::merge`]).

use super::{
    NoObserver, Observer, Part, SolveReport, StaticOptions, StopReason, solve_static_loads,
};
use crate::physics::Model;
use nalgebra::Vector3;

/// What a continuation does next.
#[derive(Debug, Clone, PartialEq)]
pub enum Stage {
    /// Solve the model at this load factor (1 = full load), from the positions as they are.
    Solve(f64),
    /// Done: the last stage's outcome is the result; this note is added to its message.
    Done(String),
    /// Stopped short of a result, for this reason, with this message.
    Stop(StopReason, String),
}

/// A static continuation: the set-up of each stage of [`execute`].
pub trait Continuation {
    /// The next stage. Called before the first solve with `solved` false, then after each stage
    /// that converged with `solved` true; it may change the model (fixed particles, terms) and the
    /// positions (a contact pull-back, a rejected increment rolled back) first.
    fn next(&mut self, model: &mut Model, x: &mut [Vector3<f64>], solved: bool) -> Stage;
}

/// Runs `continuation` on `model` from `x` (updated in place) with Newton under `opts`: the
/// observer sees the first stage's iterations; a stage that does not converge ends it with that
/// stage's status. The work of every stage adds up in the report.
pub fn execute(
    model: &mut Model,
    x: &mut [Vector3<f64>],
    opts: &StaticOptions,
    continuation: &mut dyn Continuation,
    observer: &mut dyn Observer,
) -> SolveReport {
    let mut total: Option<SolveReport> = None;
    loop {
        match continuation.next(model, x, total.is_some()) {
            Stage::Solve(load) => {
                let obs: &mut dyn Observer = match total {
                    None => &mut *observer,
                    Some(_) => &mut NoObserver,
                };
                let stage = solve_static_loads(model, x, opts, &[load], obs);
                let converged = stage.is_converged();
                match &mut total {
                    None => total = Some(stage),
                    Some(t) => t.merge(&stage, Part::Stage),
                }
                if !converged {
                    return total.expect("a stage was solved");
                }
            }
            Stage::Done(note) => {
                let mut t = total.unwrap_or_else(|| SolveReport::unsolved("static-newton"));
                t.message += &note;
                return t;
            }
            Stage::Stop(reason, message) => {
                let mut t = total.unwrap_or_else(|| SolveReport::unsolved("static-newton"));
                t.stop_for(reason);
                t.message = message;
                return t;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::{Gravity, SpringFamily, Springs};

    /// A load ramp: stages at ¼, ½, ¾ and 1, then done.
    struct Ramp(usize);

    impl Continuation for Ramp {
        fn next(&mut self, _m: &mut Model, _x: &mut [Vector3<f64>], _solved: bool) -> Stage {
            self.0 += 1;
            match self.0 {
                k @ 1..=4 => Stage::Solve(k as f64 / 4.0),
                _ => Stage::Done(" (ramped)".into()),
            }
        }
    }

    #[test]
    fn a_ramp_of_stages_ends_at_the_full_load_with_the_work_of_all_stages() {
        // A particle hanging from a pinned one by a spring (k = 100 N/m, L0 = 0.1 m, m = 0.1 kg):
        // at full load the spring stretches by m g / k.
        let k = 100.0;
        let mut model = Model {
            masses: vec![0.0, 0.1],
            fixed: vec![true, false],
            held_components: vec![],
            n_grid: 2,
            terms: vec![
                Box::new(Springs::new(
                    SpringFamily::Structural,
                    vec![(0, 1)],
                    vec![0.1],
                    vec![k],
                )),
                Box::new(Gravity::new(vec![0.0, 0.1], 9.81)),
            ],
            gravity_m_per_s2: 9.81,
            damping_Ns_per_m: 0.0,
            elongation_rate: None,
        };
        let mut x = vec![Vector3::zeros(), Vector3::new(0.0, 0.0, -0.1)];
        let opts = StaticOptions::default();
        let r = execute(&mut model, &mut x, &opts, &mut Ramp(0), &mut NoObserver);
        assert!(r.is_converged(), "{}", r.message);
        assert!(r.message.ends_with(" (ramped)"));
        assert!((x[1].z + 0.1 + 0.1 * 9.81 / k).abs() < 1e-9, "{}", x[1].z);
        // Four stages' work: at least one iteration each.
        assert!(r.iterations >= 4, "{}", r.iterations);
    }
}
