//! Progress of a pipeline run: the runner talks to the [`Progress`] trait, never to the terminal.
//! On a terminal, an indicatif MultiProgress with one bar per running stage; otherwise log lines
//! through `tracing` (level info; `-q` or `RUST_LOG=warn` silences them).

use crate::outcome::StageOutcome;
use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::collections::HashMap;
use std::io::IsTerminal;
use std::sync::Mutex;
use std::time::Instant;

/// Receives the events of a pipeline run.
pub trait Progress: Sync {
    /// A stage starts, with its number of items (samples, sweep points).
    fn stage_started(&self, stage: &str, items: u64);
    /// One item of a stage finished.
    fn item_done(&self, stage: &str);
    /// A stage finished, after `wall_s` seconds.
    fn stage_finished(&self, stage: &str, outcome: &StageOutcome, wall_s: f64);
    /// A stage was skipped, and why.
    fn stage_skipped(&self, stage: &str, why: &str);
}

/// Plain log lines on stderr (for pipes, files and CI logs).
pub struct LogProgress {
    counts: Mutex<HashMap<String, (u64, u64, Instant)>>,
}

impl Default for LogProgress {
    fn default() -> Self {
        Self {
            counts: Mutex::new(HashMap::new()),
        }
    }
}

impl Progress for LogProgress {
    fn stage_started(&self, stage: &str, items: u64) {
        tracing::info!("[{stage}] started: {items} item(s)");
        self.counts
            .lock()
            .expect("lock")
            .insert(stage.into(), (0, items, Instant::now()));
    }
    fn item_done(&self, stage: &str) {
        let mut c = self.counts.lock().expect("lock");
        if let Some((done, total, t0)) = c.get_mut(stage) {
            *done += 1;
            // A line per tenth of the items, at most.
            let step = (*total / 10).max(1);
            if *done % step == 0 || *done == *total {
                let el = t0.elapsed().as_secs_f64();
                let eta = if *done > 0 {
                    el / *done as f64 * (*total - *done) as f64
                } else {
                    0.0
                };
                tracing::info!("[{stage}] {done}/{total} done, {el:.1} s elapsed, ETA {eta:.1} s");
            }
        }
    }
    fn stage_finished(&self, stage: &str, outcome: &StageOutcome, wall_s: f64) {
        if outcome.is_ok() {
            tracing::info!("[{stage}] {outcome} in {wall_s:.2} s");
        } else {
            tracing::error!("[{stage}] {outcome} in {wall_s:.2} s");
        }
    }
    fn stage_skipped(&self, stage: &str, why: &str) {
        tracing::info!("[{stage}] skipped: {why}");
    }
}

/// One indicatif bar per running stage.
pub struct MultiBarProgress {
    multi: MultiProgress,
    bars: Mutex<HashMap<String, ProgressBar>>,
}

impl Default for MultiBarProgress {
    fn default() -> Self {
        Self {
            multi: MultiProgress::with_draw_target(ProgressDrawTarget::stderr()),
            bars: Mutex::new(HashMap::new()),
        }
    }
}

impl Progress for MultiBarProgress {
    fn stage_started(&self, stage: &str, items: u64) {
        let bar = self.multi.add(ProgressBar::new(items));
        bar.set_style(
            ProgressStyle::with_template(
                "{prefix:>14} [{bar:30}] {pos}/{len} {elapsed_precise} ETA {eta}",
            )
            .expect("template")
            .progress_chars("=> "),
        );
        bar.set_prefix(stage.to_string());
        self.bars.lock().expect("lock").insert(stage.into(), bar);
    }
    fn item_done(&self, stage: &str) {
        if let Some(b) = self.bars.lock().expect("lock").get(stage) {
            b.inc(1);
        }
    }
    fn stage_finished(&self, stage: &str, outcome: &StageOutcome, wall_s: f64) {
        if let Some(b) = self.bars.lock().expect("lock").remove(stage) {
            b.finish_and_clear();
        }
        self.multi
            .println(format!("[{stage}] {outcome} in {wall_s:.2} s"))
            .ok();
    }
    fn stage_skipped(&self, stage: &str, why: &str) {
        self.multi.println(format!("[{stage}] skipped: {why}")).ok();
    }
}

/// Bars on a terminal, log lines otherwise.
pub fn progress_for_terminal() -> Box<dyn Progress> {
    if std::io::stderr().is_terminal() {
        Box::new(MultiBarProgress::default())
    } else {
        Box::new(LogProgress::default())
    }
}
