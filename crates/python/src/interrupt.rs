//! Ctrl-C during a long solve, and a pipeline's progress as lines on standard error.

use drapelab_core::solve::{Observer, StateEvent};
use pyo3::{PyErr, Python};
use std::time::{Duration, Instant};

/// How often a solve asks Python whether a signal arrived.
const EVERY: Duration = Duration::from_millis(50);

/// An observer that stops a solve when Python has a signal pending (SIGINT: `KeyboardInterrupt`),
/// asked at most every 50 ms between iterations; it keeps Python's exception to raise.
pub struct Interrupt {
    last: Instant,
    error: Option<PyErr>,
}

impl Interrupt {
    pub fn new() -> Self {
        Interrupt {
            last: Instant::now(),
            error: None,
        }
    }
    /// The exception a signal handler raised, if one did.
    pub fn into_error(self) -> Option<PyErr> {
        self.error
    }
}

impl Observer for Interrupt {
    fn wants(&self, _index: usize) -> bool {
        self.last.elapsed() >= EVERY
    }
    fn observe(&mut self, _event: &StateEvent<'_>) -> anyhow::Result<()> {
        self.last = Instant::now();
        if let Err(e) = Python::attach(|py| py.check_signals()) {
            self.error = Some(e);
            anyhow::bail!("interrupted from Python (a signal handler raised)");
        }
        Ok(())
    }
}

/// A pipeline's progress as one line per stage on standard error.
pub struct StageLines;

impl drapelab_pipeline::Progress for StageLines {
    fn stage_started(&self, stage: &str, items: u64) {
        eprintln!("[{stage}] started: {items} item(s)");
    }
    fn item_done(&self, _: &str) {}
    fn stage_finished(&self, stage: &str, outcome: &drapelab_pipeline::StageOutcome, wall_s: f64) {
        eprintln!("[{stage}] {outcome} in {wall_s:.1} s");
    }
    fn stage_skipped(&self, stage: &str, why: &str) {
        eprintln!("[{stage}] skipped: {why}");
    }
}
