//! Reading a pipeline file into a validated plan: stages, resolved paths, the dependency graph and
//! a topological order. Cycles, unknown kinds, keys or slots, missing slots and inputs, and two
//! stages writing one output are refused with an [`InputError`] naming the file, the stage and the
//! slot or key.

use crate::executor::ExecutorSettings;
use crate::files::rel;
use crate::stage::{Registry, Stage};
use drapelab_core::config::{from_table, read_toml_table};
use drapelab_core::error::InputError;
use serde::{Deserialize, Serialize};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// A stage as written in the pipeline file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StageSpec {
    /// The stage kind: simulate, sweep, report, … (`drapelab kinds` lists them).
    pub kind: String,
    /// Input files or globs by slot, relative to the project root; `{run}` = `runs/<pipeline>`.
    #[serde(default)]
    pub inputs: BTreeMap<String, Paths>,
    /// Output files by slot, relative to the project root.
    #[serde(default)]
    pub outputs: BTreeMap<String, String>,
    /// Parameters of the kind (checked by the kind).
    #[serde(default)]
    pub params: toml::Table,
}

/// One path or glob, or a list of them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Paths {
    /// One path or glob.
    One(String),
    /// A list.
    Many(Vec<String>),
}

impl Paths {
    /// The paths as a list.
    pub fn as_slice(&self) -> &[String] {
        match self {
            Paths::One(s) => std::slice::from_ref(s),
            Paths::Many(v) => v,
        }
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct PipelineFile {
    name: String,
    #[serde(default)]
    description: String,
    stages: BTreeMap<String, StageSpec>,
    #[serde(default)]
    executor: ExecutorSettings,
}

/// A stage with resolved paths and its dependencies.
#[derive(Clone)]
pub struct PlannedStage {
    /// Stage name.
    pub name: String,
    /// The spec as written.
    pub spec: StageSpec,
    /// The kind.
    pub kind: Arc<dyn Stage>,
    /// The parameters with defaults filled in, as JSON (part of the up-to-date key).
    pub params: serde_json::Value,
    /// Input patterns by slot with `{run}` expanded, relative to the root.
    pub input_patterns: BTreeMap<String, Vec<String>>,
    /// Output paths by slot, relative to the root.
    pub outputs: BTreeMap<String, PathBuf>,
    /// Names of the stages this one reads from.
    pub deps: BTreeSet<String>,
}

impl std::fmt::Debug for PlannedStage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PlannedStage")
            .field("name", &self.name)
            .field("kind", &self.kind.kind())
            .field("outputs", &self.outputs)
            .field("deps", &self.deps)
            .finish()
    }
}

/// A validated pipeline.
#[derive(Debug, Clone)]
pub struct Plan {
    /// Pipeline name.
    pub name: String,
    /// What it does.
    pub description: String,
    /// The file it came from.
    pub file: PathBuf,
    /// Project root that paths are relative to.
    pub root: PathBuf,
    /// Stages in topological order (ties by name).
    pub stages: Vec<PlannedStage>,
    /// Where items run (the `[executor]` table; `drapelab run --executor` overrides its kind).
    pub executor: ExecutorSettings,
}

impl Plan {
    /// The run folder `runs/<pipeline>` (absolute).
    pub fn run_dir(&self) -> PathBuf {
        self.root.join("runs").join(&self.name)
    }
    /// A stage by name.
    pub fn stage(&self, name: &str) -> Option<&PlannedStage> {
        self.stages.iter().find(|s| s.name == name)
    }
    /// `name` and every stage downstream of it.
    pub fn descendants(&self, name: &str) -> BTreeSet<String> {
        let mut set = BTreeSet::from([name.to_string()]);
        for s in &self.stages {
            if s.deps.iter().any(|d| set.contains(d)) {
                set.insert(s.name.clone());
            }
        }
        set
    }
    /// `name` and every stage upstream of it.
    pub fn ancestors(&self, name: &str) -> BTreeSet<String> {
        let mut set = BTreeSet::from([name.to_string()]);
        for s in self.stages.iter().rev() {
            if set.contains(&s.name) {
                set.extend(s.deps.iter().cloned());
            }
        }
        set
    }
}

/// The project root of a pipeline file: the folder above `pipelines/`, else the file's folder. A
/// file named from inside `pipelines/` (`cd pipelines && drapelab status main.toml`) finds it too.
pub fn project_root(file: &Path) -> PathBuf {
    let dir = file.parent().map(Path::to_path_buf).unwrap_or_default();
    let dir = if dir.as_os_str().is_empty() {
        PathBuf::from(".")
    } else {
        dir
    };
    let is_pipelines = |d: &Path| d.file_name().is_some_and(|n| n == "pipelines");
    if is_pipelines(&dir) {
        return dir
            .parent()
            .map(Path::to_path_buf)
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or_else(|| PathBuf::from("."));
    }
    match dir.canonicalize() {
        Ok(abs) if is_pipelines(&abs) => abs.parent().map_or(dir, Path::to_path_buf),
        _ => dir,
    }
}

/// Reads and validates a pipeline file against the kinds of `registry`.
pub fn load_plan(file: &Path, registry: &Registry) -> Result<Plan, InputError> {
    let table = read_toml_table(file)?;
    let pf: PipelineFile = from_table(file, "", table)?;
    if pf.name.is_empty()
        || !pf
            .name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
    {
        return Err(InputError::new(
            file,
            "name",
            "must be a non-empty word of letters, digits, '-' or '_'",
        ));
    }
    pf.executor.check(file)?;
    let root = project_root(file);
    let run = format!("runs/{}", pf.name);
    let mut stages = Vec::new();
    let mut writer: BTreeMap<PathBuf, String> = BTreeMap::new();
    for (name, spec) in &pf.stages {
        stages.push(plan_stage(file, registry, &run, name, spec, &mut writer)?);
    }
    for s in stages.iter_mut() {
        link_inputs(file, &root, s, &writer)?;
    }
    Ok(Plan {
        name: pf.name,
        description: pf.description,
        file: file.to_path_buf(),
        root,
        stages: topological(file, stages)?,
        executor: pf.executor,
    })
}

/// Checks one stage against its kind: known kind, valid parameters, every slot known, every required
/// slot given, one path for a single slot, outputs inside the project with one writer each.
fn plan_stage(
    file: &Path,
    registry: &Registry,
    run: &str,
    name: &str,
    spec: &StageSpec,
    writer: &mut BTreeMap<PathBuf, String>,
) -> Result<PlannedStage, InputError> {
    let key = |k: &str| format!("stages.{name}.{k}");
    let expand = |s: &str| s.replace("{run}", run);
    let kind = registry.get(&spec.kind).ok_or_else(|| {
        InputError::new(
            file,
            key("kind"),
            format!(
                "unknown stage kind `{}` (known: {})",
                spec.kind,
                registry.names()
            ),
        )
    })?;
    let params = kind
        .resolve(&spec.params)
        .map_err(|e| InputError::new(file, key(&format!("params.{}", e.key)), e.message))?;
    let given_inputs: BTreeMap<&str, usize> = spec
        .inputs
        .iter()
        .map(|(k, v)| (k.as_str(), v.as_slice().len()))
        .collect();
    let given_outputs: BTreeMap<&str, usize> =
        spec.outputs.keys().map(|k| (k.as_str(), 1)).collect();
    check_slots(file, name, kind, "inputs", kind.inputs(), &given_inputs)?;
    check_slots(file, name, kind, "outputs", kind.outputs(), &given_outputs)?;
    let mut outputs = BTreeMap::new();
    for (slot, o) in &spec.outputs {
        let p = PathBuf::from(expand(o));
        if p.is_absolute()
            || p.components()
                .any(|c| matches!(c, std::path::Component::ParentDir))
        {
            return Err(InputError::new(
                file,
                key(&format!("outputs.{slot}")),
                format!("`{o}` must be a relative path inside the project"),
            ));
        }
        if let Some(other) = writer.insert(p.clone(), name.to_string()) {
            return Err(InputError::new(
                file,
                key(&format!("outputs.{slot}")),
                format!("`{o}` is also written by stage `{other}`: give each output one writer"),
            ));
        }
        outputs.insert(slot.clone(), p);
    }
    Ok(PlannedStage {
        name: name.to_string(),
        spec: spec.clone(),
        kind: registry.shared(&spec.kind).expect("kind checked above"),
        params,
        input_patterns: spec
            .inputs
            .iter()
            .map(|(k, v)| (k.clone(), v.as_slice().iter().map(|i| expand(i)).collect()))
            .collect(),
        outputs,
        deps: BTreeSet::new(),
    })
}

/// Refuses a slot the kind does not have, a required slot left out, and several paths in a slot of
/// one; the error names the stage and the slot.
fn check_slots(
    file: &Path,
    stage: &str,
    kind: &dyn Stage,
    side: &str,
    slots: &[crate::stage::Slot],
    given: &BTreeMap<&str, usize>,
) -> Result<(), InputError> {
    let names = || {
        slots
            .iter()
            .map(|s| {
                if s.required {
                    s.name.to_string()
                } else {
                    format!("{} (optional)", s.name)
                }
            })
            .collect::<Vec<_>>()
            .join(", ")
    };
    for (&g, &n) in given {
        let Some(slot) = slots.iter().find(|s| s.name == g) else {
            return Err(InputError::new(
                file,
                format!("stages.{stage}.{side}.{g}"),
                format!(
                    "stage kind `{}` has no {side} slot `{g}` (its {side}: {})",
                    kind.kind(),
                    names()
                ),
            ));
        };
        if !slot.many && n != 1 {
            return Err(InputError::new(
                file,
                format!("stages.{stage}.{side}.{g}"),
                format!("slot `{g}` takes one path ({}), {n} given", slot.doc),
            ));
        }
    }
    if let Some(missing) = slots
        .iter()
        .find(|s| s.required && !given.contains_key(s.name))
    {
        return Err(InputError::new(
            file,
            format!("stages.{stage}.{side}.{}", missing.name),
            format!(
                "missing {side} slot `{}` of stage kind `{}`: {} (its {side}: {})",
                missing.name,
                kind.kind(),
                missing.doc,
                names()
            ),
        ));
    }
    Ok(())
}

/// Dependencies: inputs equal to, or globs matching, another stage's outputs; an input that no stage
/// writes must exist.
fn link_inputs(
    file: &Path,
    root: &Path,
    s: &mut PlannedStage,
    writer: &BTreeMap<PathBuf, String>,
) -> Result<(), InputError> {
    for (slot, pats) in &s.input_patterns {
        let key = format!("stages.{}.inputs.{slot}", s.name);
        for pat in pats {
            let glob = glob::Pattern::new(pat)
                .map_err(|e| InputError::new(file, &key, format!("bad glob `{pat}`: {e}")))?;
            let mut produced = false;
            for (out, w) in writer {
                if out == Path::new(pat) || glob.matches_path(out) {
                    if w == &s.name {
                        return Err(InputError::new(
                            file,
                            &key,
                            format!(
                                "`{pat}` is this stage's own output `{}`: a stage cannot read what \
                                 it writes (a dependency cycle of one stage); read a file or \
                                 another stage's output",
                                out.display()
                            ),
                        ));
                    }
                    produced = true;
                    s.deps.insert(w.clone());
                }
            }
            if !produced {
                let matches: Vec<PathBuf> = glob::glob(&root.join(pat).to_string_lossy())
                    .map(|g| g.flatten().collect())
                    .unwrap_or_default();
                if matches.is_empty() {
                    return Err(InputError::new(
                        file,
                        &key,
                        format!("missing input `{pat}`: no such file, and no stage writes it"),
                    ));
                }
                // A stage reads files: a folder (or a pipe) named as an input fails only when it runs.
                if let Some(m) = matches.iter().find(|m| !m.is_file()) {
                    let what = if m.is_dir() {
                        "a folder"
                    } else {
                        "not a regular file"
                    };
                    return Err(InputError::new(
                        file,
                        &key,
                        format!(
                            "input `{}` is {what}: name the file (or a glob of files) inside it",
                            rel(root, m)
                        ),
                    ));
                }
            }
        }
    }
    Ok(())
}

/// Topological order (Kahn), ties by name; a leftover means a cycle.
fn topological(file: &Path, stages: Vec<PlannedStage>) -> Result<Vec<PlannedStage>, InputError> {
    let mut order = Vec::new();
    let mut done: BTreeSet<String> = BTreeSet::new();
    let mut left: Vec<PlannedStage> = stages;
    while !left.is_empty() {
        let pos = left
            .iter()
            .position(|s| s.deps.iter().all(|d| done.contains(d)));
        match pos {
            Some(i) => {
                let s = left.remove(i);
                done.insert(s.name.clone());
                order.push(s);
            }
            None => {
                let names: Vec<&str> = left.iter().map(|s| s.name.as_str()).collect();
                return Err(InputError::new(
                    file,
                    format!("stages.{}", names[0]),
                    format!("dependency cycle among stages {}", names.join(", ")),
                ));
            }
        }
    }
    Ok(order)
}
