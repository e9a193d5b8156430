//! The loop of an iterative solver, owned in one place (argmin's executor): the solver says
//! whether its current state ends the loop ([`Iterative::terminate`]) and takes one iteration
//! ([`Iterative::next_iter`]); [`run`] owns the loop, the iteration and wall-time budgets
//! ([`Budget`]) and the observer, and [`conclude`] writes why the loop ended into the report,
//! always one [`StopReason`].

use super::{DivergenceReason, Observer, SolveReport, StopReason};
use std::time::Instant;

/// What a loop may spend: iterations, and wall time from the moment [`run`] is called.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Budget {
    /// Iterations (or time steps) at most.
    pub iterations: usize,
    /// Wall time at most, s (none: no limit).
    pub wall_s: Option<f64>,
}

impl Budget {
    /// `n` iterations and no wall-time limit.
    pub(super) fn iterations(n: usize) -> Self {
        Self {
            iterations: n,
            wall_s: None,
        }
    }
}

/// How an iterative loop ends.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Verdict {
    /// The goal is met, for a reason (converged, the round-off floor) and in words where the
    /// solver has them; no reason for a goal short of the solve's own (a load increment reached),
    /// which leaves the report's reason as it is.
    Reached(Option<StopReason>, Option<String>),
    /// The loop cannot go on, for a reason said in words.
    Stopped(StopReason, String),
    /// The state diverged: why, at which time step (dynamics), and in words where the solver has
    /// them.
    Diverged {
        /// Why.
        reason: DivergenceReason,
        /// The time step that diverged, s (none in a static solve).
        dt_s: Option<f64>,
        /// The solver's words, where it has them.
        message: Option<String>,
    },
    /// A part of the solve (a continuation's stage) did not reach its goal; its own verdict is
    /// written in its report, which the whole's report has taken over ([`super::Part::Stage`]).
    PartFailed,
}

/// An iterative solver over its own state: its checks and its iteration.
pub(super) trait Iterative {
    /// Iterations taken so far.
    fn iterations(&self) -> usize;
    /// Whether the current state ends the loop, checked before every iteration (the observer
    /// sees the state first).
    fn terminate(&mut self, observer: &mut dyn Observer) -> Option<Verdict>;
    /// One iteration; the verdict that ends the loop where it cannot be taken or finishes it.
    fn next_iter(&mut self) -> Result<(), Verdict>;
    /// What running out of `budget` iterations means, in words.
    fn out_of_iterations(&self, budget: usize) -> String;
    /// What spending the wall-time budget of `budget_s` seconds means, in words.
    fn out_of_wall_time(&self, budget_s: f64) -> String {
        format!(
            "wall-time budget of {budget_s} s spent after {} iterations",
            self.iterations()
        )
    }
}

/// Runs `solver` until its state ends the loop, an iteration ends it, or it has spent its
/// `budget` (checked after the state's own tests, before each iteration); the verdict.
pub(super) fn run(
    solver: &mut impl Iterative,
    budget: Budget,
    observer: &mut dyn Observer,
) -> Verdict {
    let start = Instant::now();
    loop {
        if let Some(v) = solver.terminate(observer) {
            return v;
        }
        if solver.iterations() >= budget.iterations {
            let words = solver.out_of_iterations(budget.iterations);
            return Verdict::Stopped(StopReason::Iterations, words);
        }
        if let Some(wall) = budget.wall_s
            && start.elapsed().as_secs_f64() > wall
        {
            return Verdict::Stopped(StopReason::WallTime, solver.out_of_wall_time(wall));
        }
        if let Err(v) = solver.next_iter() {
            return v;
        }
    }
}

/// Writes `verdict`, reached at iteration `iter`, into `report`: true when the goal was met.
pub(super) fn conclude(verdict: Verdict, iter: usize, report: &mut SolveReport) -> bool {
    match verdict {
        Verdict::Reached(reason, message) => {
            if let Some(r) = reason {
                report.stop_for(r);
            }
            if let Some(m) = message {
                report.message = m;
            }
            true
        }
        Verdict::Stopped(reason, message) => {
            report.stop_with(reason, message);
            false
        }
        Verdict::Diverged {
            reason,
            dt_s,
            message,
        } => {
            report.diverge(iter, dt_s, reason);
            if let Some(m) = message {
                report.message = m;
            }
            false
        }
        Verdict::PartFailed => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solve::{NoObserver, SolverKind, Status};

    /// Newton's method for √2 from `x`, each iterate checked: reached below `tol`, diverged when
    /// not finite.
    struct Root {
        x: f64,
        iterations: usize,
        tol: f64,
    }

    impl Iterative for Root {
        fn iterations(&self) -> usize {
            self.iterations
        }
        fn terminate(&mut self, _observer: &mut dyn Observer) -> Option<Verdict> {
            let r = (self.x * self.x - 2.0).abs();
            if !r.is_finite() {
                let reason = DivergenceReason::NonFinite;
                return Some(Verdict::Diverged {
                    reason,
                    dt_s: None,
                    message: None,
                });
            }
            (r <= self.tol).then_some(Verdict::Reached(Some(StopReason::Converged), None))
        }
        fn next_iter(&mut self) -> Result<(), Verdict> {
            self.iterations += 1;
            self.x -= (self.x * self.x - 2.0) / (2.0 * self.x);
            Ok(())
        }
        fn out_of_iterations(&self, budget: usize) -> String {
            format!("{budget} iterations")
        }
    }

    #[test]
    fn the_executor_ends_each_loop_for_one_reason_written_in_one_place() {
        let fresh = || SolveReport::unsolved(SolverKind::Static);
        // Converges quadratically: 1e-12 in 5 iterations from 1.
        let mut root = Root {
            x: 1.0,
            iterations: 0,
            tol: 1e-12,
        };
        let mut report = fresh();
        let v = run(&mut root, Budget::iterations(50), &mut NoObserver);
        assert!(conclude(v, root.iterations, &mut report));
        assert_eq!(
            (report.stop, report.status),
            (StopReason::Converged, Status::Converged)
        );
        assert!((root.x - 2f64.sqrt()).abs() < 1e-12 && root.iterations == 5);
        // The same with a budget of 2: the budget's reason and words, not a default.
        let mut short = Root {
            x: 1.0,
            iterations: 0,
            tol: 1e-12,
        };
        let mut report = fresh();
        let v = run(&mut short, Budget::iterations(2), &mut NoObserver);
        assert!(!conclude(v, short.iterations, &mut report));
        assert_eq!(
            (report.stop, report.message.as_str()),
            (StopReason::Iterations, "2 iterations")
        );
        // From 0 the first step is not finite: diverged at the iteration it was found.
        let mut zero = Root {
            x: 0.0,
            iterations: 0,
            tol: 1e-12,
        };
        let mut report = fresh();
        let v = run(&mut zero, Budget::iterations(50), &mut NoObserver);
        assert!(!conclude(v, zero.iterations, &mut report));
        assert_eq!(report.stop, StopReason::Diverged);
        assert_eq!(report.divergence.as_ref().map(|d| d.step), Some(1));
    }

    /// A solver that never reaches its goal and takes a millisecond an iteration.
    struct Slow(usize);

    impl Iterative for Slow {
        fn iterations(&self) -> usize {
            self.0
        }
        fn terminate(&mut self, _observer: &mut dyn Observer) -> Option<Verdict> {
            None
        }
        fn next_iter(&mut self) -> Result<(), Verdict> {
            std::thread::sleep(std::time::Duration::from_millis(1));
            self.0 += 1;
            Ok(())
        }
        fn out_of_iterations(&self, budget: usize) -> String {
            format!("{budget} iterations")
        }
    }

    #[test]
    fn the_executor_spends_a_wall_time_budget_and_says_so() {
        // 2,000 iterations of at least a millisecond: the wall time, not the count, ends it.
        let budget = Budget {
            iterations: 2000,
            wall_s: Some(0.02),
        };
        let mut slow = Slow(0);
        let mut report = SolveReport::unsolved(SolverKind::Static);
        let start = std::time::Instant::now();
        let v = run(&mut slow, budget, &mut NoObserver);
        let spent = start.elapsed().as_secs_f64();
        assert!(!conclude(v, slow.0, &mut report));
        assert_eq!(report.stop, StopReason::WallTime);
        // It ran until the 20 ms were spent and stopped soon after, far short of its 2,000
        // iterations (a loaded machine may stretch a millisecond's sleep).
        let n = slow.0;
        assert!(spent >= 0.02 && n >= 1, "{spent} s, {n} iterations");
        assert!(spent < 1.0 && n < 1000, "{spent} s, {n} iterations");
        assert!(report.message.contains("0.02 s"), "{}", report.message);
        // The iteration budget, when smaller, ends it first.
        let mut slow = Slow(0);
        let budget = Budget {
            iterations: 3,
            wall_s: Some(60.0),
        };
        let v = run(&mut slow, budget, &mut NoObserver);
        assert!(matches!(v, Verdict::Stopped(StopReason::Iterations, _)));
        assert_eq!(slow.0, 3);
    }
}
