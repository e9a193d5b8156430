//! Whether a stage is up to date (n2's rule): the hashes of its inputs, parameters, version and
//! outputs against its manifest, and if not, why.

use crate::files::rel;
use crate::manifest::{Manifest, build_id, hash_file, stage_key};
use crate::outcome::{StageOutcome, StaleReason};
use crate::plan::{Plan, PlannedStage};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Whether a stage is up to date, and if not, why.
#[derive(Debug, Clone, PartialEq)]
pub enum StageState {
    /// Inputs, parameters, version and outputs match the manifest.
    UpToDate,
    /// Must run, and why.
    Stale(StaleReason),
}

/// The manifest path of a stage.
pub fn manifest_path(plan: &Plan, stage: &str) -> PathBuf {
    plan.run_dir()
        .join(".manifests")
        .join(format!("{stage}.json"))
}

/// The input files of a stage now, by slot: globs expanded, outputs of other stages included even
/// when missing; each slot's files sorted by path relative to the root.
pub(crate) fn slot_inputs(plan: &Plan, s: &PlannedStage) -> BTreeMap<String, BTreeSet<String>> {
    let produced: Vec<&PathBuf> = plan
        .stages
        .iter()
        .filter(|o| s.deps.contains(&o.name))
        .flat_map(|o| o.outputs.values())
        .collect();
    let mut slots = BTreeMap::new();
    for (slot, pats) in &s.input_patterns {
        let mut files = BTreeSet::new();
        for pat in pats {
            let g = glob::Pattern::new(pat).ok();
            for out in &produced {
                if out.as_path() == Path::new(pat)
                    || g.as_ref().is_some_and(|g| g.matches_path(out))
                {
                    files.insert(out.to_string_lossy().to_string());
                }
            }
            if let Ok(paths) = glob::glob(&plan.root.join(pat).to_string_lossy()) {
                for p in paths.flatten() {
                    if p.is_file() {
                        files.insert(rel(&plan.root, &p));
                    }
                }
            }
        }
        slots.insert(slot.clone(), files);
    }
    slots
}

/// Every input file of a stage now with its content hash (None when missing).
fn current_inputs(plan: &Plan, s: &PlannedStage) -> BTreeMap<String, Option<String>> {
    hashed(plan, &slot_inputs(plan, s))
}

/// The files of every slot with their content hashes (None when missing), and the files they
/// name: a scene's mesh files (`cloth.mesh`, mesh obstacles) are read with it, so they are inputs too.
pub(crate) fn hashed(
    plan: &Plan,
    slots: &BTreeMap<String, BTreeSet<String>>,
) -> BTreeMap<String, Option<String>> {
    let named = slots.values().flatten().flat_map(|p| {
        let path = plan.root.join(p);
        let meshes = match path.extension().is_some_and(|e| e == "toml") {
            true => drapelab_core::scene::mesh_files_of(&path),
            false => Vec::new(),
        };
        meshes.into_iter().map(|m| rel(&plan.root, &m))
    });
    let files: BTreeSet<String> = slots.values().flatten().cloned().chain(named).collect();
    files
        .into_iter()
        .map(|p| {
            let h = hash_file(&plan.root.join(&p)).ok();
            (p, h)
        })
        .collect()
}

/// Why stage `s` must run, if it must: upstream stages that will run, then its manifest against
/// its parameters, inputs, outputs and build.
pub(crate) fn check(
    plan: &Plan,
    s: &PlannedStage,
    upstream_stale: &BTreeSet<String>,
) -> StageState {
    if let Some(d) = s.deps.iter().find(|d| upstream_stale.contains(*d)) {
        return StageState::Stale(StaleReason::UpstreamWillRun(d.clone()));
    }
    let Some(m) = Manifest::read(&manifest_path(plan, &s.name)) else {
        return StageState::Stale(StaleReason::NeverRun);
    };
    match stale_reason(plan, s, &m) {
        Some(r) => StageState::Stale(r),
        None => StageState::UpToDate,
    }
}

/// Why the manifest `m` of stage `s` no longer holds, if it does not.
fn stale_reason(plan: &Plan, s: &PlannedStage, m: &Manifest) -> Option<StaleReason> {
    if let StageOutcome::Failed { message, .. } = &m.status {
        return Some(StaleReason::LastRunFailed(message.clone()));
    }
    if m.drapelab_version != drapelab_core::VERSION {
        return Some(StaleReason::VersionChanged {
            from: m.drapelab_version.clone(),
            to: drapelab_core::VERSION.into(),
        });
    }
    if m.params != s.params {
        let mut changed = Vec::new();
        if let (Some(a), Some(b)) = (m.params.as_object(), s.params.as_object()) {
            for k in a.keys().chain(b.keys()).collect::<BTreeSet<_>>() {
                if a.get(k) != b.get(k) {
                    changed.push(k.clone());
                }
            }
        }
        return Some(StaleReason::ParamsChanged(changed));
    }
    let now = current_inputs(plan, s);
    for (p, h) in &now {
        match (h, m.inputs.get(p)) {
            (None, _) => return Some(StaleReason::InputMissing(p.clone())),
            (Some(_), None) => return Some(StaleReason::InputAdded(p.clone())),
            (Some(a), Some(b)) if a != b => return Some(StaleReason::InputChanged(p.clone())),
            _ => {}
        }
    }
    if let Some(p) = m.inputs.keys().find(|p| !now.contains_key(*p)) {
        return Some(StaleReason::InputRemoved(p.clone()));
    }
    for o in s.outputs.values() {
        let size = std::fs::metadata(plan.root.join(o)).map(|m| m.len()).ok();
        if size.is_none() || size != m.outputs.get(&o.to_string_lossy().to_string()).copied() {
            return Some(StaleReason::OutputAltered(o.display().to_string()));
        }
    }
    if m.key != stage_key(s.kind.kind(), &s.params, &m.inputs) {
        return Some(StaleReason::KeyMismatch);
    }
    if m.build != build_id() {
        return Some(StaleReason::Rebuilt {
            from: if m.build.is_empty() {
                "unknown".into()
            } else {
                m.build.clone()
            },
            to: build_id().into(),
        });
    }
    None
}

/// The state of every stage, as `drapelab status` prints it (stale stages make their dependents stale).
pub fn stage_states(plan: &Plan) -> Vec<(String, StageState)> {
    let mut stale = BTreeSet::new();
    let mut out = Vec::new();
    for s in &plan.stages {
        let st = check(plan, s, &stale);
        if st != StageState::UpToDate {
            stale.insert(s.name.clone());
        }
        out.push((s.name.clone(), st));
    }
    out
}
