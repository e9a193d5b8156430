//! `drape.rrd`: a rerun recording with the cloth as a mesh over an `iteration` (Newton) or `sim_time`
//! (dynamics) timeline, the pinned points, and the residual and energy as scalars.

use crate::Staged;
use crate::rerun;
use crate::sampled::{Sampled, StateSink};
use anyhow::Result;
use drapelab_core::solve::StateEvent;
use std::path::Path;

/// An observer writing a rerun recording.
pub struct RerunRecorder {
    rec: Option<rerun::RecordingStream>,
    staged: Option<Staged>,
    n_grid: usize,
}

impl RerunRecorder {
    /// Starts a recording at `path` of the sheet's `particles` first particles and its
    /// `triangles`; `pins` are its fixed particles.
    pub fn new(
        path: &Path,
        app: &str,
        (particles, triangles): (usize, &[[u32; 3]]),
        x0: &[nalgebra::Vector3<f64>],
        pins: &[usize],
        every: usize,
    ) -> Result<Sampled<Self>> {
        let staged = Staged::new(path)?;
        let rec = rerun::RecordingStreamBuilder::new(rerun::ApplicationId::new_or_unknown(
            format!("drapelab_{app}"),
        ))
        .save(staged.path())?;
        let tris = triangles;
        // Z is up in drapelab (gravity along −z).
        rec.log_static("/", &rerun::ViewCoordinates::RIGHT_HAND_Z_UP())?;
        // The mesh topology is static; only the positions change over time.
        rec.log_static(
            "cloth/mesh",
            &rerun::Mesh3D::update_fields().with_triangle_indices(tris.iter().copied()),
        )?;
        rec.log_static(
            "cloth/rest",
            &rerun::Mesh3D::new(
                x0[..particles]
                    .iter()
                    .map(|p| [p.x as f32, p.y as f32, p.z as f32]),
            )
            .with_triangle_indices(tris.iter().copied()),
        )?;
        rec.log_static(
            "cloth/pins",
            &rerun::Points3D::new(
                pins.iter()
                    .map(|&p| [x0[p].x as f32, x0[p].y as f32, x0[p].z as f32]),
            )
            .with_radii([0.004f32]),
        )?;
        Ok(Sampled::new(
            Self {
                rec: Some(rec),
                staged: Some(staged),
                n_grid: particles,
            },
            every,
        ))
    }

    fn log_state(&mut self, ev: &StateEvent<'_>) -> Result<()> {
        let rec = self
            .rec
            .as_ref()
            .ok_or_else(|| anyhow::anyhow!("the rerun recording is already closed"))?;
        match ev.time_s {
            Some(t) => rec.set_duration_secs("sim_time", t),
            None => rec.set_time_sequence("iteration", ev.index as i64),
        }
        let verts: Vec<[f32; 3]> = ev.x[..self.n_grid]
            .iter()
            .map(|p| [p.x as f32, p.y as f32, p.z as f32])
            .collect();
        rec.log(
            "cloth/mesh",
            &rerun::Mesh3D::update_fields().with_vertex_positions(verts),
        )?;
        rec.log(
            "stats/max_residual_N",
            &rerun::Scalars::single(ev.max_residual_N),
        )?;
        rec.log("stats/energy_J", &rerun::Scalars::single(ev.energy_J))?;
        Ok(())
    }
}

impl Sampled<RerunRecorder> {
    /// Logs a sewn garment's stages before its drape: the unsewn pieces (`sewing/pieces`) at the
    /// arranged start and after each stage on a `sewing_stage` timeline, with the stage's seam
    /// stiffness and largest gap as scalars.
    pub fn log_sewing(&mut self, sewing: &drapelab_core::sewing::sew::SewReport) -> Result<()> {
        let rec = self
            .sink_mut()
            .rec
            .as_ref()
            .ok_or_else(|| anyhow::anyhow!("the rerun recording is already closed"))?;
        rec.log_static(
            "sewing/pieces",
            &rerun::Mesh3D::update_fields().with_triangle_indices(sewing.pieces.iter().copied()),
        )?;
        for (i, x) in sewing.stage_positions.iter().enumerate() {
            rec.set_time_sequence("sewing_stage", i as i64);
            rec.log(
                "sewing/pieces",
                &rerun::Mesh3D::update_fields().with_vertex_positions(x.iter().copied()),
            )?;
            if let Some(&(k, gap)) = i.checked_sub(1).and_then(|s| sewing.stages.get(s)) {
                rec.log("sewing/seam_stiffness_N_per_m", &rerun::Scalars::single(k))?;
                rec.log("sewing/largest_gap_m", &rerun::Scalars::single(gap))?;
            }
        }
        rec.reset_time();
        Ok(())
    }
}

impl StateSink for RerunRecorder {
    fn write(&mut self, ev: &StateEvent<'_>) -> Result<()> {
        self.log_state(ev)
    }
    fn close(&mut self) -> Result<()> {
        if let (Some(rec), Some(staged)) = (self.rec.take(), self.staged.take()) {
            rec.flush_blocking()?;
            drop(rec);
            staged.commit()?;
        }
        Ok(())
    }
}
