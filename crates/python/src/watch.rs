//! What a notebook sees of a running solve: a progress callback (called at most every 50 ms with the
//! iteration or step, the simulated time, the residual and the energy; an exception it raises stops
//! the solve and is raised again) and the solve's frames (every state, thinned to at most a given
//! number by keeping every second one whenever the buffer fills).

use drapelab_core::solve::{Observer, StateEvent};
use pyo3::prelude::*;
use std::time::{Duration, Instant};

/// How often the callback is called at most.
const EVERY: Duration = Duration::from_millis(50);

/// One kept state: its iteration or step, its simulated time (dynamics) and the grid positions.
pub type Frame = (usize, Option<f64>, Vec<f64>);

/// The frames and the callback of one solve.
pub struct Watch {
    callback: Option<Py<PyAny>>,
    last: Instant,
    /// The most frames to keep (0: none).
    max_frames: usize,
    /// Keep the states whose index is a multiple of this.
    stride: usize,
    /// How many grid particles a frame holds.
    n: usize,
    /// The frames kept.
    pub frames: Vec<Frame>,
    /// The exception the callback raised, if it did.
    pub error: Option<PyErr>,
}

impl Watch {
    /// A watch calling `callback` and keeping up to `max_frames` frames of the first `n` particles.
    pub fn new(callback: Option<Py<PyAny>>, max_frames: usize, n: usize) -> Self {
        Self {
            callback,
            last: Instant::now() - EVERY,
            max_frames,
            stride: 1,
            n,
            frames: Vec::new(),
            error: None,
        }
    }

    fn keep(&mut self, ev: &StateEvent<'_>) {
        let xyz = ev.x[..self.n.min(ev.x.len())]
            .iter()
            .flat_map(|p| [p.x, p.y, p.z])
            .collect();
        self.frames.push((ev.index, ev.time_s, xyz));
        if self.frames.len() > self.max_frames {
            // Thin to every second kept index: the frames stay evenly spaced.
            self.stride *= 2;
            let stride = self.stride;
            self.frames.retain(|f| f.0.is_multiple_of(stride));
        }
    }
}

impl Observer for Watch {
    fn wants(&self, index: usize) -> bool {
        (self.max_frames > 0 && index.is_multiple_of(self.stride))
            || (self.callback.is_some() && self.last.elapsed() >= EVERY)
    }
    fn observe(&mut self, ev: &StateEvent<'_>) -> anyhow::Result<()> {
        if self.max_frames > 0 && ev.index.is_multiple_of(self.stride) {
            self.keep(ev);
        }
        let Some(cb) = &self.callback else {
            return Ok(());
        };
        if self.last.elapsed() < EVERY {
            return Ok(());
        }
        self.last = Instant::now();
        let called = Python::attach(|py| {
            cb.call1(py, (ev.index, ev.time_s, ev.max_residual_N, ev.energy_J))
                .map(drop)
        });
        if let Err(e) = called {
            self.error = Some(e);
            anyhow::bail!("stopped by the progress callback (it raised)");
        }
        Ok(())
    }
}
