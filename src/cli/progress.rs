//! The indicatif implementation of progress for long solves; hidden when stderr is not a terminal.

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
    /// Clears the spinner.
    pub fn done(&self, _report: &SolveReport) {
        self.bar.finish_and_clear();
    }
}

impl Observer for SolveProgress {
    fn wants(&self, index: usize) -> bool {
        !self.bar.is_hidden() && index.is_multiple_of(100)
    }
    fn observe(&mut self, ev: &StateEvent<'_>) -> anyhow::Result<()> {
        let t = ev
            .time_s
            .map(|t| format!(" t = {t:.4} s"))
            .unwrap_or_default();
        self.bar.set_message(format!(
            "step {}{t}, residual {:.3e} N",
            ev.index, ev.max_residual_N
        ));
        Ok(())
    }
}
