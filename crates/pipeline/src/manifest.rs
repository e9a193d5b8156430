//! Stage manifests: what a finished stage read, with which parameters, what it wrote and how it
//! ended. Written last and atomically, so a stage without a matching manifest is not finished.

use crate::outcome::StageOutcome;
use anyhow::Result;
use drapelab_core::atomic::write_atomic;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

/// The record of one finished stage, `runs/<pipeline>/.manifests/<stage>.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// Stage name.
    pub stage: String,
    /// Stage kind.
    pub kind: String,
    /// The hash that decides whether the stage is up to date (inputs, parameters, version).
    pub key: String,
    /// blake3 of each input file's content, by path relative to the root.
    pub inputs: BTreeMap<String, String>,
    /// The resolved parameters as JSON.
    pub params: serde_json::Value,
    /// Each output's size in bytes, by path.
    pub outputs: BTreeMap<String, u64>,
    /// How the stage ended.
    pub status: StageOutcome,
    /// Wall time of the stage in s.
    pub wall_time_s: f64,
    /// The command line that ran it.
    pub command_line: Vec<String>,
    /// drapelab version.
    pub drapelab_version: String,
    /// The build that ran the stage ([`build_id`]); empty in manifests written before it was kept.
    #[serde(default)]
    pub build: String,
}

pub use drapelab_core::provenance::build_id;

impl Manifest {
    /// Reads a manifest; None when absent or unreadable (then the stage is stale).
    pub fn read(path: &Path) -> Option<Self> {
        serde_json::from_slice(&std::fs::read(path).ok()?).ok()
    }
    /// Writes the manifest atomically.
    pub fn write(&self, path: &Path) -> Result<()> {
        if let Some(d) = path.parent() {
            std::fs::create_dir_all(d)?;
        }
        let json = serde_json::to_vec_pretty(self)?;
        write_atomic(path, |f| {
            use std::io::Write;
            f.write_all(&json)?;
            Ok(())
        })?;
        Ok(())
    }
}

/// blake3 of a file's content, hex.
pub fn hash_file(path: &Path) -> std::io::Result<String> {
    let mut h = blake3::Hasher::new();
    let mut f = std::fs::File::open(path)?;
    std::io::copy(&mut f, &mut h)?;
    Ok(h.finalize().to_hex().to_string())
}

/// The up-to-date key of a stage.
pub fn stage_key(
    kind: &str,
    params: &serde_json::Value,
    inputs: &BTreeMap<String, String>,
) -> String {
    let mut h = blake3::Hasher::new();
    h.update(drapelab_core::VERSION.as_bytes());
    h.update(b"\0");
    h.update(kind.as_bytes());
    h.update(b"\0");
    h.update(params.to_string().as_bytes());
    for (p, d) in inputs {
        h.update(b"\0");
        h.update(p.as_bytes());
        h.update(b"=");
        h.update(d.as_bytes());
    }
    h.finalize().to_hex().to_string()
}
