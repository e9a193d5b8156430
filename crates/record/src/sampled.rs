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
    last_index: Option<usize>,
}

impl<S: StateSink> Sampled<S> {
    /// Records every `every`-th state (at least every state when `every` is 0 or 1) into `sink`.
    pub fn new(sink: S, every: usize) -> Self {
        Self {
            sink,
            every: every.max(1),
            last_index: None,
        }
    }
}

impl<S: StateSink> Observer for Sampled<S> {
    fn wants(&self, index: usize) -> bool {
        index.is_multiple_of(self.every)
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
