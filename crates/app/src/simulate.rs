//! `simulate`: one scene with overrides, solved into the folder of its outputs.

use crate::job::Job;
use anyhow::{Result, bail};
use drapelab_core::solve::{NoObserver, SolveReport, Status};
use drapelab_record::simulate_to_dir;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::PathBuf;

/// Parameters of a simulate stage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct SimulateParams {
    /// Scene keys to override by dotted path, e.g. { "cloth.nx" = 21 }.
    #[serde(default)]
    pub set: BTreeMap<String, toml::Value>,
}

/// The input of a simulate stage.
pub struct SimulateInputs {
    /// The scene TOML.
    pub scene: PathBuf,
}

/// The `run` of the stage kind over this workflow.
pub fn run(ctx: &Job<'_, SimulateInputs>, p: &SimulateParams) -> Result<SolveReport> {
    let dir = ctx
        .output("run")?
        .parent()
        .expect("output has a folder")
        .to_path_buf();
    if ctx
        .outputs
        .values()
        .any(|o| o.parent() != Some(dir.as_path()))
    {
        bail!("all outputs of a simulate stage must lie in one folder");
    }
    let overrides: Vec<(String, toml::Value)> =
        p.set.iter().map(|(k, v)| (k.clone(), v.clone())).collect();
    let loaded = ctx.load_scene(&ctx.inputs.scene, &overrides, |k| format!("set.{k}"))?;
    ctx.started(1);
    let report = simulate_to_dir(&loaded, &dir, &mut NoObserver)?;
    ctx.item_done();
    if report.status != Status::Converged {
        bail!(
            "{}: {} ({})",
            loaded.scene.name,
            report.status.as_str(),
            report.message
        );
    }
    Ok(report)
}
