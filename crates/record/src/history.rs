//! `iterations.parquet`: how a solve went, one row per Newton iteration (static) or time step
//! (dynamic) that the solve's observers see: the residual and the energy, for a convergence plot.

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
        self.rows.push(IterationRow {
            index: ev.index as u64,
            time_s: ev.time_s,
            max_residual_N: ev.max_residual_N,
            energy_J: ev.energy_J,
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
