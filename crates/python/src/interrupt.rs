//! Ctrl-C during a long solve, and a pipeline's progress as lines on standard error and, when
//! given, calls of a Python callback.

use drapelab_core::solve::{Observer, StateEvent};
use pyo3::PyErr;
use pyo3::prelude::*;
use std::collections::HashMap;
use std::sync::Mutex;
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

/// A pipeline's progress as one line per stage on standard error and, when given, a callback
/// `callback(stage, event, done, total)` (event `"started"`, `"item"`, `"finished"` or `"skipped"`;
/// `done` of `total` items). An exception the callback raises is kept and raised when the run ends.
#[derive(Default)]
pub struct StageLines {
    callback: Option<Py<PyAny>>,
    /// Items done and in all, per stage.
    counts: Mutex<HashMap<String, (u64, u64)>>,
    error: Mutex<Option<PyErr>>,
}

impl StageLines {
    /// Lines, and calls of `callback` when given.
    pub fn with(callback: Option<Py<PyAny>>) -> Self {
        Self {
            callback,
            ..Self::default()
        }
    }
    /// The exception the callback raised first, if any.
    pub fn into_error(self) -> Option<PyErr> {
        self.error.into_inner().unwrap_or_else(|e| e.into_inner())
    }
    fn call(&self, stage: &str, event: &str, (done, total): (u64, u64)) {
        let Some(cb) = &self.callback else { return };
        let mut error = self.error.lock().unwrap_or_else(|e| e.into_inner());
        if error.is_some() {
            return;
        }
        if let Err(e) = Python::attach(|py| cb.call1(py, (stage, event, done, total)).map(drop)) {
            *error = Some(e);
        }
    }
}

impl drapelab_pipeline::Progress for StageLines {
    fn stage_started(&self, stage: &str, items: u64) {
        eprintln!("[{stage}] started: {items} item(s)");
        let mut c = self.counts.lock().unwrap_or_else(|e| e.into_inner());
        c.insert(stage.to_string(), (0, items));
        drop(c);
        self.call(stage, "started", (0, items));
    }
    fn item_done(&self, stage: &str) {
        let mut c = self.counts.lock().unwrap_or_else(|e| e.into_inner());
        let n = c.entry(stage.to_string()).or_insert((0, 0));
        n.0 += 1;
        let n = *n;
        drop(c);
        self.call(stage, "item", n);
    }
    fn stage_finished(&self, stage: &str, outcome: &drapelab_pipeline::StageOutcome, wall_s: f64) {
        eprintln!("[{stage}] {outcome} in {wall_s:.1} s");
        let c = self.counts.lock().unwrap_or_else(|e| e.into_inner());
        let n = c.get(stage).copied().unwrap_or((0, 0));
        drop(c);
        self.call(stage, "finished", n);
    }
    fn stage_skipped(&self, stage: &str, why: &str) {
        eprintln!("[{stage}] skipped: {why}");
        self.call(stage, "skipped", (0, 0));
    }
}
