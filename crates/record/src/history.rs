//! `iterations.parquet`: how a solve went, one row per Newton iteration (static) or time step
//! (dynamic) that the solve's observers see: the residual and the energy, for a convergence plot,
//! and how each Newton iteration stepped (its length, the contact bound, line-search trials,
//! factorizations, active contact pairs): where a long path's iterations go.

use crate::table::{Table, write_table};
use anyhow::Result;
use drapelab_core::solve::{Observer, StateEvent};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// One iteration or time step of a solve.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct IterationRow {
    /// Newton iteration (static) or time step (dynamic), from 0.
    pub index: u64,
    /// Simulated time, s (dynamic solves; null for a static one).
    pub time_s: Option<f64>,
    /// Largest residual force on a free particle, N.
    pub max_residual_N: f64,
    /// Total energy (potential, plus kinetic in dynamics), J.
    pub energy_J: f64,
    /// The step the Newton iteration took, as a fraction of its Newton step (1: whole); null for
    /// a start or a time step.
    pub step_fraction: Option<f64>,
    /// The collision-free bound on that step (contact: no pair closes more than 90 % of its gap),
    /// as a fraction of the Newton step; null where no term bounded it.
    pub contact_bound_fraction: Option<f64>,
    /// Whether the contact bound cut the step (it stopped at the bound).
    pub contact_bound_cut: Option<bool>,
    /// Line-search trials of the iteration (the accepted one and those rejected).
    pub line_search_trials: Option<u32>,
    /// Factorizations the iteration made (0: it reused a factor: a chord or Krylov step).
    pub factorizations: Option<u32>,
    /// Self-contact pairs within the activation distance at the new state.
    pub active_contact_pairs: Option<u64>,
    /// The largest distance a particle moved in the iteration, m.
    pub max_move_m: Option<f64>,
}

impl Table for IterationRow {
    const FILE: &'static str = "iterations.parquet";
    const ROW: &'static str = "One Newton iteration (static) or time step (dynamic) of a `simulate` run, as its observers see them: every iteration of the first Newton run of a continuation (its load steps included; later contact rounds and friction updates are counted in run.json), or every `solver.dynamic.check_every`-th step of a dynamic solve (where it checks its state anyway).";
}

/// An observer that keeps every `every`-th iteration's residual and energy.
pub struct History {
    every: usize,
    /// The rows so far.
    pub rows: Vec<IterationRow>,
}

impl Observer for History {
    fn wants(&self, index: usize) -> bool {
        index.is_multiple_of(self.every)
    }
    fn observe(&mut self, ev: &StateEvent<'_>) -> anyhow::Result<()> {
        let s = ev.step;
        self.rows.push(IterationRow {
            index: ev.index as u64,
            time_s: ev.time_s,
            max_residual_N: ev.max_residual_N,
            energy_J: ev.energy_J,
            step_fraction: s.map(|s| s.alpha),
            contact_bound_fraction: s.and_then(|s| s.bound.is_finite().then_some(s.bound)),
            contact_bound_cut: s.map(|s| s.bound_cut),
            line_search_trials: s.map(|s| s.trials as u32),
            factorizations: s.map(|s| s.factorizations as u32),
            active_contact_pairs: s.map(|s| s.active_pairs as u64),
            max_move_m: s.map(|s| s.max_move_m),
        });
        Ok(())
    }
}

impl History {
    /// Every `every`-th iteration or step (at least every one): a static solve's every iteration
    /// costs nothing more (its residual and energy are at hand), a dynamic one's would cost an
    /// energy per step, so it keeps the steps its solver checks.
    pub fn every(every: usize) -> Self {
        Self {
            every: every.max(1),
            rows: Vec::new(),
        }
    }
    /// Writes `iterations.parquet` at `path`.
    pub fn write(&self, path: &Path) -> Result<()> {
        write_table(path, &self.rows)
    }
}
