//! The one executor of static continuations (argmin's habit: the executor owns the loop). A
//! continuation is a sequence of Newton stages of one model whose set-up changes between them: the
//! external loads raised in increments (seed 003 §10.3.3, [`super::LoadRamp`]), obstacles'
//! contact sets refreshed (§10.7.1's vertical gap), friction anchors lagged one solve behind. The
//! [`Continuation`] says what the next stage is; [`execute`] runs the Newton runs, hands the
//! observer the first run, stops at the first stage that does not reach its goal, and merges the
//! runs' reports ([`SolveReport::merge`]).

use super::newton::{Goal, NewtonRun};
use super::warm::WarmData;
use super::{NoObserver, Observer, Part, SolveReport, StaticOptions, StopReason};
use crate::physics::Model;
use nalgebra::Vector3;

/// What a continuation does next.
#[derive(Debug, Clone, PartialEq)]
pub enum Stage {
    /// Solve the model at this load factor (1 = full load), from the positions as they are, to the
    /// tolerance: the end of the current Newton run if an increment began it, else a fresh run (the
    /// continuation may have changed the model since the last one).
    Solve(f64),
    /// Raise the load to this factor within the current Newton run (its damping, factor and
    /// iteration budget carried on), solved only roughly: an increment of incremental loading. The
    /// model must not change until the run ends with a [`Stage::Solve`].
    Increment(f64),
    /// Done: the last stage's outcome is the result; this note is added to its message.
    Done(String),
    /// Stopped short of a result, for this reason, with this message.
    Stop(StopReason, String),
}

/// A static continuation: the set-up of each stage of [`execute`].
pub trait Continuation {
    /// The next stage. Called before the first stage with `solved` false, then after each stage
    /// that reached its goal with `solved` true; it may change the model (fixed particles, terms) and
    /// the positions (a contact pull-back, a rejected increment rolled back) before a
    /// [`Stage::Solve`] that starts a fresh run.
    fn next(&mut self, model: &mut Model, x: &mut [Vector3<f64>], solved: bool) -> Stage;
}

/// The reports of the runs so far, merged ([`Part::Stage`]).
fn merged(total: Option<SolveReport>, run: SolveReport) -> SolveReport {
    match total {
        None => run,
        Some(mut t) => {
            t.merge(&run, Part::Stage);
            t
        }
    }
}

/// A message that counts the last stage's iterations ("converged in 10 iterations …") restated
/// with the whole run's `total`, the last stage's count kept in brackets: a run of many stages
/// must not read as converged in its last stage's few.
fn whole_count(message: &str, total: usize) -> String {
    let counted = message
        .strip_prefix("converged in ")
        .and_then(|rest| rest.split_once(" iterations"))
        .and_then(|(n, rest)| n.parse::<usize>().ok().map(|n| (n, rest)));
    match counted {
        Some((last, rest)) if last != total => {
            format!("converged in {total} iterations ({last} in the last stage){rest}")
        }
        _ => message.to_string(),
    }
}

/// Runs `continuation` on `model` from `x` (updated in place) with Newton under `opts`: the
/// observer sees the first run's iterations; a stage that does not reach its goal ends it with that
/// run's status. The work of every run adds up in the report.
pub fn execute(
    model: &mut Model,
    x: &mut [Vector3<f64>],
    opts: &StaticOptions,
    warm: WarmData<'_>,
    continuation: &mut dyn Continuation,
    observer: &mut dyn Observer,
) -> SolveReport {
    let mut total: Option<SolveReport> = None;
    let mut run: Option<NewtonRun> = None;
    let mut solved = false;
    loop {
        let (load, goal) =
            match continuation.next(model, x, solved) {
                Stage::Solve(load) => (load, Goal::Tolerance),
                Stage::Increment(load) => (load, Goal::Increment),
                Stage::Done(note) => {
                    let staged = total.is_some();
                    let mut t = match run.take() {
                        Some(r) => merged(total, r.finish(model, x)),
                        None => total
                            .unwrap_or_else(|| SolveReport::unsolved(super::SolverKind::Static)),
                    };
                    if staged {
                        t.message = whole_count(&t.message, t.iterations);
                    }
                    t.message += &note;
                    return t;
                }
                Stage::Stop(reason, message) => {
                    let mut t = match run.take() {
                        Some(r) => merged(total, r.finish(model, x)),
                        None => total
                            .unwrap_or_else(|| SolveReport::unsolved(super::SolverKind::Static)),
                    };
                    t.stop_with(reason, message);
                    return t;
                }
            };
        let mut current = match run.take() {
            Some(r) => r,
            None => match NewtonRun::new(model, x, opts, warm.factor) {
                Ok(r) => r,
                Err(invalid) => return merged(total, *invalid),
            },
        };
        let obs: &mut dyn Observer = match total {
            None => &mut *observer,
            Some(_) => &mut NoObserver,
        };
        let reached = current.stage(model, x, opts, (load, goal), obs);
        if !reached {
            return merged(total, current.finish(model, x));
        }
        match goal {
            Goal::Increment => run = Some(current),
            Goal::Tolerance => total = Some(merged(total, current.finish(model, x))),
        }
        solved = true;
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
        let (mut model, mut x) = hung(k);
        let opts = StaticOptions::default();
        let r = execute(
            &mut model,
            &mut x,
            &opts,
            WarmData::default(),
            &mut Ramp(0),
            &mut NoObserver,
        );
        assert!(r.is_converged(), "{}", r.message);
        assert!(r.message.ends_with(" (ramped)"));
        // The message counts every stage's iterations, as the report does.
        let counted = format!("converged in {} iterations", r.iterations);
        assert!(r.message.starts_with(&counted), "{}", r.message);
        assert!((x[1].z + 0.1 + 0.1 * 9.81 / k).abs() < 1e-9, "{}", x[1].z);
        // Four stages' work: at least one iteration each.
        assert!(r.iterations >= 4, "{}", r.iterations);
    }

    /// The spring-hung particle of the test above.
    fn hung(k: f64) -> (Model, Vec<Vector3<f64>>) {
        let model = Model {
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
            constant_hessian: Default::default(),
        };
        (model, vec![Vector3::zeros(), Vector3::new(0.0, 0.0, -0.1)])
    }

    #[test]
    fn a_load_ramp_is_one_newton_run_through_its_increments() {
        let k = 100.0;
        let (mut model, mut x) = hung(k);
        let opts = StaticOptions {
            load_steps: 5,
            ..StaticOptions::default()
        };
        let r = super::super::solve_static(&mut model, &mut x, &opts, &mut NoObserver);
        assert!(r.is_converged(), "{}", r.message);
        assert!((x[1].z + 0.1 + 0.1 * 9.81 / k).abs() < 1e-9, "{}", x[1].z);
        // One run: its iterations share one budget, and one too small for all five increments
        // stops it.
        let (mut model, mut x) = hung(k);
        let tight = StaticOptions {
            max_iterations: r.iterations - 1,
            ..opts
        };
        let short = super::super::solve_static(&mut model, &mut x, &tight, &mut NoObserver);
        assert!(!short.is_converged(), "{}", short.message);
        assert!(
            short.message.contains("Newton iterations"),
            "{}",
            short.message
        );
    }
}
