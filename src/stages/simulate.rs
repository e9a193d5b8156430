//! `simulate`: one scene (the stage's single input) with overrides, into the folder of its outputs.

use super::StageContext;
use crate::scene::Scene;
use crate::solve::{NoObserver, Status};
use anyhow::{Result, bail};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// Parameters of a simulate stage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct SimulateParams {
    /// Scene keys to override by dotted path, e.g. { "cloth.nx" = 21 }.
    #[serde(default)]
    pub set: BTreeMap<String, toml::Value>,
}

/// Runs the stage.
pub fn run(ctx: &StageContext<'_>, p: &SimulateParams) -> Result<()> {
    let [scene_file] = ctx.inputs.as_slice() else {
        bail!(
            "a simulate stage takes exactly one scene file as input, got {}",
            ctx.inputs.len()
        );
    };
    let dir = ctx.outputs[0]
        .parent()
        .expect("output has a folder")
        .to_path_buf();
    if ctx
        .outputs
        .iter()
        .any(|o| o.parent() != Some(dir.as_path()))
    {
        bail!("all outputs of a simulate stage must lie in one folder");
    }
    let overrides: Vec<(String, toml::Value)> =
        p.set.iter().map(|(k, v)| (k.clone(), v.clone())).collect();
    let loaded = Scene::load(scene_file, &overrides)?;
    ctx.progress.stage_started(&ctx.stage.name, 1);
    let report = crate::simulate::simulate_to_dir(&loaded, &dir, &mut NoObserver)?;
    ctx.progress.item_done(&ctx.stage.name);
    if report.status != Status::Converged {
        bail!(
            "{}: {} ({})",
            loaded.scene.name,
            report.status.as_str(),
            report.message
        );
    }
    Ok(())
}
