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
    const ROW: &'static str = "One Newton iteration (static) or time step (dynamic) of a `simulate` run, as its observers see them: the first Newton run of a continuation (its load steps included; later contact rounds and friction updates are counted in run.json), or every step of a dynamic solve.";
}

/// An observer that keeps every iteration's residual and energy.
#[derive(Default)]
pub struct History {
    /// The rows so far.
    pub rows: Vec<IterationRow>,
}

impl Observer for History {
    fn wants(&self, _index: usize) -> bool {
        true
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
    /// Writes `iterations.parquet` at `path`.
    pub fn write(&self, path: &Path) -> Result<()> {
        write_table(path, &self.rows)
    }
}
