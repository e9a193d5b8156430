//! `timeline.mcap`: particle states over Newton iterations or time, as Foxglove's well-known
//! `foxglove.SceneUpdate` schema in JSON encoding (topic `/drapelab/cloth`, a triangle mesh), and a
//! `drapelab.Stats` channel with residual and energy (topic `/drapelab/stats`). Foxglove's 3D panel
//! replays the first; any MCAP reader decodes both as JSON.

use crate::Staged;
use crate::sampled::{Sampled, StateSink};
use anyhow::Result;
use drapelab_core::solve::StateEvent;
use mcap::records::MessageHeader;
use serde_json::json;
use std::collections::BTreeMap;
use std::io::BufWriter;
use std::path::Path;

/// JSON schema of the subset of `foxglove.SceneUpdate` that drapelab writes.
const SCENE_UPDATE_SCHEMA: &str = r#"{"title":"foxglove.SceneUpdate","type":"object","properties":{"deletions":{"type":"array","items":{"type":"object"}},"entities":{"type":"array","items":{"type":"object","properties":{"timestamp":{"type":"object","properties":{"sec":{"type":"integer"},"nsec":{"type":"integer"}}},"frame_id":{"type":"string"},"id":{"type":"string"},"lifetime":{"type":"object","properties":{"sec":{"type":"integer"},"nsec":{"type":"integer"}}},"frame_locked":{"type":"boolean"},"metadata":{"type":"array"},"arrows":{"type":"array"},"cubes":{"type":"array"},"spheres":{"type":"array"},"cylinders":{"type":"array"},"lines":{"type":"array"},"triangles":{"type":"array","items":{"type":"object","properties":{"pose":{"type":"object"},"points":{"type":"array","items":{"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"}}}},"color":{"type":"object"},"colors":{"type":"array"},"indices":{"type":"array","items":{"type":"integer"}}}}},"texts":{"type":"array"},"models":{"type":"array"}}}}}}"#;

const STATS_SCHEMA: &str = r#"{"title":"drapelab.Stats","type":"object","properties":{"index":{"type":"integer"},"time_s":{"type":["number","null"]},"max_residual_N":{"type":"number"},"energy_J":{"type":"number"}}}"#;

/// An observer writing `timeline.mcap`.
pub struct TimelineRecorder {
    writer: Option<mcap::Writer<BufWriter<std::fs::File>>>,
    staged: Option<Staged>,
    cloth: u16,
    stats: u16,
    seq: u32,
    n_grid: usize,
    indices: Vec<u32>,
}

impl TimelineRecorder {
    /// Starts recording to `path` the sheet's `particles` first particles and its `triangles`
    /// ([`drapelab_core::build::scene_triangles`]), keeping every `every`-th state.
    pub fn new(
        path: &Path,
        (particles, triangles): (usize, &[[u32; 3]]),
        every: usize,
    ) -> Result<Sampled<Self>> {
        let staged = Staged::new(path)?;
        let file = staged.path().to_path_buf();
        let f = std::fs::OpenOptions::new()
            .write(true)
            .truncate(true)
            .open(&file)?;
        let opts = mcap::WriteOptions::new()
            .compression(Some(mcap::Compression::Zstd))
            .profile("drapelab");
        let mut writer = opts.create(BufWriter::new(f))?;
        let s1 = writer.add_schema(
            "foxglove.SceneUpdate",
            "jsonschema",
            SCENE_UPDATE_SCHEMA.as_bytes(),
        )?;
        let cloth = writer.add_channel(s1, "/drapelab/cloth", "json", &BTreeMap::new())?;
        let s2 = writer.add_schema("drapelab.Stats", "jsonschema", STATS_SCHEMA.as_bytes())?;
        let stats = writer.add_channel(s2, "/drapelab/stats", "json", &BTreeMap::new())?;
        Ok(Sampled::new(
            Self {
                writer: Some(writer),
                staged: Some(staged),
                cloth,
                stats,
                seq: 0,
                n_grid: particles,
                indices: triangles.iter().flatten().copied().collect(),
            },
            every,
        ))
    }

    fn log_state(&mut self, ev: &StateEvent<'_>) -> Result<()> {
        // Log time: simulated time for dynamics, the iteration as milliseconds for Newton.
        let t_ns = match ev.time_s {
            Some(t) => (t * 1e9).round() as u64,
            None => ev.index as u64 * 1_000_000,
        };
        let stamp = json!({"sec": t_ns / 1_000_000_000, "nsec": t_ns % 1_000_000_000});
        let points: Vec<_> = ev.x[..self.n_grid]
            .iter()
            .map(|p| json!({"x": p.x, "y": p.y, "z": p.z}))
            .collect();
        let msg = json!({
            "deletions": [],
            "entities": [{
                "timestamp": stamp, "frame_id": "world", "id": "cloth",
                "lifetime": {"sec": 0, "nsec": 0}, "frame_locked": false, "metadata": [],
                "arrows": [], "cubes": [], "spheres": [], "cylinders": [], "lines": [], "texts": [], "models": [],
                "triangles": [{
                    "pose": {"position": {"x": 0.0, "y": 0.0, "z": 0.0}, "orientation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0}},
                    "points": points,
                    "color": {"r": 0.85, "g": 0.35, "b": 0.2, "a": 1.0},
                    "colors": [],
                    "indices": self.indices,
                }]
            }]
        });
        let stats = json!({"index": ev.index, "time_s": ev.time_s, "max_residual_N": ev.max_residual_N, "energy_J": ev.energy_J});
        let w = self
            .writer
            .as_mut()
            .ok_or_else(|| anyhow::anyhow!("the timeline is already closed"))?;
        for (ch, body) in [(self.cloth, msg), (self.stats, stats)] {
            self.seq += 1;
            let header = MessageHeader {
                channel_id: ch,
                sequence: self.seq,
                log_time: t_ns,
                publish_time: t_ns,
            };
            w.write_to_known_channel(&header, serde_json::to_string(&body)?.as_bytes())?;
        }
        Ok(())
    }
}

impl StateSink for TimelineRecorder {
    fn write(&mut self, ev: &StateEvent<'_>) -> Result<()> {
        self.log_state(ev)
    }
    fn close(&mut self) -> Result<()> {
        if let (Some(mut w), Some(staged)) = (self.writer.take(), self.staged.take()) {
            w.finish()?;
            drop(w);
            staged.commit()?;
        }
        Ok(())
    }
}
