//! Recording a solve: every `every`-th state and the final one, into a file format (a [`StateSink`]:
//! the MCAP timeline, the rerun recording). The observer side (which states, the final call) is here
//! once; a sink only writes a state and closes its file.

use anyhow::Result;
use drapelab_core::solve::{Observer, StateEvent};

/// A file that states are written to and that is closed (renamed into place) at the end.
pub trait StateSink {
    /// Writes one state.
    fn write(&mut self, ev: &StateEvent<'_>) -> Result<()>;
    /// Closes the file and renames it into place.
    fn close(&mut self) -> Result<()>;
}

/// Every `every`-th state of a solve and its final state, written to a sink.
pub struct Sampled<S> {
    sink: S,
    every: usize,
    /// Dynamics: frames at this interval of simulated time instead of every k-th step.
    frame_interval_s: Option<f64>,
    last_index: Option<usize>,
}

impl<S: StateSink> Sampled<S> {
    /// The sink, for what it writes outside the sampled states.
    pub(crate) fn sink_mut(&mut self) -> &mut S {
        &mut self.sink
    }

    /// Records every `every`-th state (at least every state when `every` is 0 or 1) into `sink`.
    pub fn new(sink: S, every: usize) -> Self {
        Self {
            sink,
            every: every.max(1),
            frame_interval_s: None,
            last_index: None,
        }
    }
    /// Records dynamics as frames at `hz` of simulated time (the solver hands over exactly those
    /// states); None keeps every k-th step.
    pub fn at_frame_rate(mut self, hz: Option<f64>) -> Self {
        self.frame_interval_s = hz.filter(|h| *h > 0.0).map(|h| 1.0 / h);
        self
    }
}

impl<S: StateSink> Observer for Sampled<S> {
    fn wants(&self, index: usize) -> bool {
        // In frame mode the solver hands over exactly the frames (static solves: every iteration).
        self.frame_interval_s.is_some() || index.is_multiple_of(self.every)
    }
    fn frame_interval_s(&self) -> Option<f64> {
        self.frame_interval_s
    }
    fn observe(&mut self, ev: &StateEvent<'_>) -> Result<()> {
        self.sink.write(ev)?;
        self.last_index = Some(ev.index);
        Ok(())
    }
    /// Records the final state (when it was not the last one recorded) and closes the file.
    fn finish(&mut self, final_state: Option<&StateEvent<'_>>) -> Result<()> {
        if let Some(ev) = final_state
            && self.last_index != Some(ev.index)
        {
            self.observe(ev)?;
        }
        self.sink.close()
    }
}
