//! The one executor of static continuations (argmin's habit: the executor owns the loop). A
//! continuation is a sequence of Newton stages of one model whose set-up changes between them: the
//! external loads raised in increments (seed 003 §10.3.3, [`super::LoadRamp`]), obstacles'
//! contact sets refreshed (§10.7.1's vertical gap), friction anchors lagged one solve behind. The
//! [`Continuation`] says what the next stage is; [`execute`] runs the Newton runs, hands the
//! observer the first run, stops at the first stage that does not reach its goal, and merges the
//! runs' reports ([`SolveReport::merge`]).

use super::executor::{Budget, Verdict};
use super::newton::{Goal, NewtonRun};
use super::warm::WarmData;
use super::{NoObserver, Observer, Part, SolveReport, StaticOptions, StopReason};
use crate::physics::{CandidateSet, Model};
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
    /// Whether `max_iterations` bounds the Newton iterations of all its stages together (a
    /// continuation whose stages need not end, as lagged friction's updates), rather than each
    /// stage's run. Default false.
    fn shares_budget(&self) -> bool {
        false
    }
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

/// Runs `continuation` on `model` from `x` (updated in place) with Newton under `opts`, its
/// stages under the executor ([`super::executor::run`]): the observer sees the runs until the
/// first one reaches the tolerance; a stage that does not reach its goal ends it with that run's
/// status. The work of every run adds up in the report.
pub fn execute(
    model: &mut Model,
    x: &mut [Vector3<f64>],
    opts: &StaticOptions,
    warm: WarmData<'_>,
    continuation: &mut dyn Continuation,
    observer: &mut dyn Observer,
) -> SolveReport {
    let mut staged = Staged {
        model,
        x,
        opts,
        warm,
        continuation,
        observer,
        total: None,
        run: None,
        candidates: warm.candidates.cloned().unwrap_or_default(),
        solved: false,
        next: (1.0, Goal::Tolerance),
        stages: 0,
    };
    let verdict =
        super::executor::run(&mut staged, Budget::iterations(usize::MAX), &mut NoObserver);
    let mut total = staged
        .total
        .take()
        .unwrap_or_else(|| SolveReport::unsolved(super::SolverKind::Static));
    let iterations = total.iterations;
    super::executor::conclude(verdict, iterations, &mut total);
    total
}

/// A continuation's stages as an iterative solver ([`super::executor`]): the model and state, the
/// Newton run an increment carries on, and the reports of the runs so far.
struct Staged<'a> {
    model: &'a mut Model,
    x: &'a mut [Vector3<f64>],
    opts: &'a StaticOptions,
    warm: WarmData<'a>,
    continuation: &'a mut dyn Continuation,
    /// Sees the runs until the first one reaches the tolerance.
    observer: &'a mut dyn Observer,
    /// The runs' reports so far, merged; at the end, the whole solve's.
    total: Option<SolveReport>,
    /// The run an increment leaves open for the next stage.
    run: Option<NewtonRun>,
    /// The candidate set the last closed run ended with (or the neighbour's): the next run's.
    candidates: CandidateSet,
    /// Whether a stage has reached its goal.
    solved: bool,
    /// The next stage's load factor and goal.
    next: (f64, Goal),
    stages: usize,
}

impl Staged<'_> {
    /// Ends the open run, if any, and merges its report into the total.
    fn close(&mut self) {
        if let Some(r) = self.run.take() {
            let (report, candidates) = r.finish(self.model, self.x);
            self.candidates = candidates;
            self.total = Some(merged(self.total.take(), report));
        }
    }
}

impl super::executor::Iterative for Staged<'_> {
    fn iterations(&self) -> usize {
        self.stages
    }

    /// Asks the continuation for the next stage: done or stopped ends the loop.
    fn terminate(&mut self, _observer: &mut dyn Observer) -> Option<Verdict> {
        let next = self.continuation.next(self.model, self.x, self.solved);
        let spent = self.total.as_ref().map_or(0, |t| t.iterations);
        if self.continuation.shares_budget()
            && matches!(next, Stage::Solve(_) | Stage::Increment(_))
            && spent >= self.opts.max_iterations
        {
            // `max_iterations` is the whole continuation's budget, over every stage.
            self.close();
            let m = format!(
                "{spent} Newton iterations over {} stages without finishing them (max_iterations {})",
                self.stages, self.opts.max_iterations
            );
            return Some(Verdict::Stopped(StopReason::Iterations, m));
        }
        match next {
            Stage::Solve(load) => self.next = (load, Goal::Tolerance),
            Stage::Increment(load) => self.next = (load, Goal::Increment),
            Stage::Done(note) => {
                let staged = self.total.is_some();
                self.close();
                let t = self
                    .total
                    .get_or_insert_with(|| SolveReport::unsolved(super::SolverKind::Static));
                if staged {
                    t.message = whole_count(&t.message, t.iterations);
                }
                t.message += &note;
                return Some(Verdict::Reached(None, None));
            }
            Stage::Stop(reason, message) => {
                self.close();
                return Some(Verdict::Stopped(reason, message));
            }
        }
        None
    }

    /// Runs the next stage: the open run carried on, or a fresh one.
    fn next_iter(&mut self) -> Result<(), Verdict> {
        self.stages += 1;
        let (load, goal) = self.next;
        let mut current = match self.run.take() {
            Some(r) => r,
            None => match NewtonRun::new(
                self.model,
                self.x,
                self.opts,
                (self.warm.factor, std::mem::take(&mut self.candidates)),
            ) {
                Ok(r) => r,
                Err(invalid) => {
                    self.total = Some(merged(self.total.take(), *invalid));
                    return Err(Verdict::PartFailed);
                }
            },
        };
        let obs: &mut dyn Observer = match self.total {
            None => &mut *self.observer,
            Some(_) => &mut NoObserver,
        };
        let reached = current.stage(self.model, self.x, self.opts, (load, goal), obs);
        self.run = Some(current);
        if !reached {
            self.close();
            return Err(Verdict::PartFailed);
        }
        if goal == Goal::Tolerance {
            self.close();
        }
        self.solved = true;
        Ok(())
    }

    fn out_of_iterations(&self, budget: usize) -> String {
        format!("{budget} continuation stages")
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
