//! The indicatif implementation of progress for long solves; hidden when stderr is not a terminal.
//! With `-v` the solve also logs every tenth Newton iteration or time step (residual, energy) and
//! its work at the end; with `-vv` every one.

use crate::solve::{Observer, SolveReport, StateEvent};
use indicatif::{ProgressBar, ProgressStyle};
use std::time::Duration;

/// A spinner that shows the iteration, simulated time and residual of a running solve.
pub struct SolveProgress {
    bar: ProgressBar,
}

impl SolveProgress {
    /// A spinner labelled `name` (drawn only on a terminal).
    pub fn new(name: &str) -> Self {
        let bar = ProgressBar::new_spinner();
        bar.set_style(
            ProgressStyle::with_template("{spinner} {prefix} [{elapsed_precise}] {msg}")
                .expect("valid template"),
        );
        bar.set_prefix(name.to_string());
        bar.enable_steady_tick(Duration::from_millis(120));
        Self { bar }
    }
    /// Clears the spinner; with `-v`, logs the solve's work.
    pub fn done(&self, r: &SolveReport) {
        self.bar.finish_and_clear();
        tracing::debug!(
            "{}: {} iterations, {} factorizations ({} sparsity analyses), {} linear solves, \
{:.3} s factorizing; {}",
            r.solver.report_name(),
            r.iterations,
            r.factorizations,
            r.analyses,
            r.linear_solves,
            r.factor_time_s,
            r.message
        );
    }
}

/// Every how many iterations or steps `-v` logs one.
const LOG_EVERY: usize = 10;

impl Observer for SolveProgress {
    fn wants(&self, index: usize) -> bool {
        (!self.bar.is_hidden() && index.is_multiple_of(100))
            || tracing::enabled!(tracing::Level::TRACE)
            || (tracing::enabled!(tracing::Level::DEBUG) && index.is_multiple_of(LOG_EVERY))
    }
    fn observe(&mut self, ev: &StateEvent<'_>) -> anyhow::Result<()> {
        let t = ev
            .time_s
            .map(|t| format!(" t = {t:.4} s"))
            .unwrap_or_default();
        if tracing::enabled!(tracing::Level::TRACE) || ev.index.is_multiple_of(LOG_EVERY) {
            tracing::debug!(
                "step {}{t}: residual {:.3e} N, energy {:.6e} J",
                ev.index,
                ev.max_residual_N,
                ev.energy_J
            );
        }
        self.bar.set_message(format!(
            "step {}{t}, residual {:.3e} N",
            ev.index, ev.max_residual_N
        ));
        Ok(())
    }
}
