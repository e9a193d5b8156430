//! One interface for the optimisers of a calibration (argmin's habit: problem, solver and report
//! apart, and why a solver stopped is an enum): ICA (seed 000), the CMA-ES baseline and the
//! Nelder–Mead polish (argmin's) all minimise a cost over the unit box and return an
//! [`OptimReport`].

use super::{Ica, cmaes};

/// A cost over the unit box, evaluated in parallel by population methods.
pub type Cost<'a> = &'a (dyn Fn(&[f64]) -> f64 + Sync);

/// Why an optimiser stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OptimStop {
    /// Its iteration (decade, generation) or evaluation budget ran out.
    Budget,
    /// Its own convergence test held (one empire left; the simplex's spread below tolerance).
    Converged,
    /// It could not run (an invalid start); the start is returned.
    Failed,
}

/// What every optimiser returns.
#[derive(Debug, Clone, PartialEq)]
pub struct OptimReport {
    /// "ica", "cma-es" or "nelder-mead".
    pub optimizer: &'static str,
    /// Best point found, in the unit box.
    pub best_x: Vec<f64>,
    /// Its cost.
    pub best_cost: f64,
    /// Cost evaluations spent.
    pub evaluations: usize,
    /// Best cost after each iteration (decade, generation).
    pub history: Vec<f64>,
    /// Why it stopped.
    pub stop: OptimStop,
}

/// Minimises a cost over [0, 1]^dim from an optional start.
pub trait Minimizer {
    /// Runs the optimiser.
    fn minimize(&self, cost: Cost<'_>, start: Option<&[f64]>) -> OptimReport;
}

impl Minimizer for Ica {
    /// ICA ignores the start: its empires are drawn from the seed.
    fn minimize(&self, cost: Cost<'_>, _start: Option<&[f64]>) -> OptimReport {
        let r = self.run(cost, |_| {});
        OptimReport {
            optimizer: "ica",
            stop: if r.decades < self.settings.decades {
                OptimStop::Converged
            } else {
                OptimStop::Budget
            },
            best_x: r.best_x,
            best_cost: r.best_cost,
            evaluations: r.evaluations,
            history: r.history,
        }
    }
}

/// CMA-ES from the box centre within an evaluation budget ([`cmaes`]).
#[derive(Debug, Clone, Copy)]
pub struct Cmaes {
    /// Dimension of the box.
    pub dim: usize,
    /// Cost evaluations allowed.
    pub budget: usize,
    /// Seed of the draws.
    pub seed: u64,
}

impl Minimizer for Cmaes {
    fn minimize(&self, cost: Cost<'_>, _start: Option<&[f64]>) -> OptimReport {
        let r = cmaes(cost, self.dim, self.budget, self.seed);
        OptimReport {
            optimizer: "cma-es",
            best_x: r.best_x,
            best_cost: r.best_cost,
            evaluations: r.evaluations,
            history: r.history,
            stop: OptimStop::Budget,
        }
    }
}

/// Nelder–Mead (argmin's) from a start, with a simplex of `step` along each axis (towards the inside
/// of the box), stopping at `max_iters` iterations or when the simplex's costs spread less than
/// `sd_tolerance`. The best point is returned only when it improves on the start.
#[derive(Debug, Clone, Copy)]
pub struct NelderMead {
    /// Iterations allowed.
    pub max_iters: u64,
    /// Initial simplex size along each axis.
    pub step: f64,
    /// Standard deviation of the simplex's costs at which it stops.
    pub sd_tolerance: f64,
}

/// A cost closure as argmin's problem, counting its evaluations.
struct Closure<'a>(Cost<'a>, &'a std::sync::atomic::AtomicUsize);

impl argmin::core::CostFunction for Closure<'_> {
    type Param = Vec<f64>;
    type Output = f64;
    fn cost(&self, v: &Self::Param) -> Result<f64, argmin::core::Error> {
        self.1.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        Ok((self.0)(v))
    }
}

impl Minimizer for NelderMead {
    fn minimize(&self, cost: Cost<'_>, start: Option<&[f64]>) -> OptimReport {
        use argmin::core::{Executor, State, TerminationReason, TerminationStatus};
        let v0 = start.map(<[f64]>::to_vec).unwrap_or_default();
        let start_cost = cost(&v0);
        let unchanged = |stop| OptimReport {
            optimizer: "nelder-mead",
            best_x: v0.clone(),
            best_cost: start_cost,
            evaluations: 1,
            history: vec![start_cost],
            stop,
        };
        if self.max_iters == 0 || v0.is_empty() {
            return unchanged(OptimStop::Budget);
        }
        let mut simplex = vec![v0.clone()];
        for k in 0..v0.len() {
            let mut v = v0.clone();
            v[k] += if v[k] + self.step <= 1.0 {
                self.step
            } else {
                -self.step
            };
            simplex.push(v);
        }
        let Ok(solver) = argmin::solver::neldermead::NelderMead::new(simplex)
            .with_sd_tolerance(self.sd_tolerance)
        else {
            return unchanged(OptimStop::Failed);
        };
        let count = std::sync::atomic::AtomicUsize::new(0);
        let Ok(res) = Executor::new(Closure(cost, &count), solver)
            .configure(|s| s.max_iters(self.max_iters))
            .run()
        else {
            return unchanged(OptimStop::Failed);
        };
        let state = res.state();
        let stop = match state.get_termination_status() {
            TerminationStatus::Terminated(TerminationReason::SolverConverged) => {
                OptimStop::Converged
            }
            _ => OptimStop::Budget,
        };
        match state.get_best_param() {
            Some(v) if state.get_best_cost() < start_cost => OptimReport {
                optimizer: "nelder-mead",
                best_x: v.clone(),
                best_cost: state.get_best_cost(),
                evaluations: 1 + count.load(std::sync::atomic::Ordering::Relaxed),
                history: vec![start_cost, state.get_best_cost()],
                stop,
            },
            _ => unchanged(stop),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optim::IcaSettings;

    /// A bowl with its minimum 0 at (0.3, 0.7, 0.2) inside the box.
    fn bowl(x: &[f64]) -> f64 {
        [0.3, 0.7, 0.2]
            .iter()
            .zip(x)
            .map(|(c, v)| (v - c).powi(2))
            .sum()
    }

    #[test]
    fn every_optimizer_finds_the_bottom_of_a_bowl_and_says_why_it_stopped() {
        let ica = Ica {
            settings: IcaSettings {
                decades: 60,
                countries: 40,
                imperialists: 4,
                beta: 2.0,
                gamma: 0.5,
                revolution_rate: 0.3,
                xi: 0.1,
                seed: 3,
            },
            dim: 3,
        };
        let cm = Cmaes {
            dim: 3,
            budget: 2000,
            seed: 3,
        };
        let nm = NelderMead {
            max_iters: 400,
            step: 0.1,
            sd_tolerance: 1e-14,
        };
        let runs: [(&dyn Minimizer, Option<&[f64]>, f64); 3] = [
            (&ica, None, 1e-3),
            (&cm, None, 1e-8),
            (&nm, Some(&[0.5, 0.5, 0.5]), 1e-8),
        ];
        for (opt, start, tol) in runs {
            let r = opt.minimize(&bowl, start);
            assert!(r.best_cost < tol, "{}: {}", r.optimizer, r.best_cost);
            assert!(
                (bowl(&r.best_x) - r.best_cost).abs() < 1e-15,
                "{}",
                r.optimizer
            );
            assert!(r.evaluations > 1, "{}", r.optimizer);
            assert!(
                r.history.windows(2).all(|w| w[1] <= w[0]),
                "{}: best cost never rises",
                r.optimizer
            );
        }
        assert_eq!(cm.minimize(&bowl, None).stop, OptimStop::Budget);
        assert_eq!(
            nm.minimize(&bowl, Some(&[0.5, 0.5, 0.5])).stop,
            OptimStop::Converged
        );
        // A start already at the bottom is kept.
        let at = nm.minimize(&bowl, Some(&[0.3, 0.7, 0.2]));
        assert_eq!(at.best_x, vec![0.3, 0.7, 0.2]);
        assert_eq!(at.best_cost, 0.0);
    }
}
