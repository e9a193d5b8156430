//! Reading a pipeline file into a validated plan: stages, resolved paths, the dependency graph and
//! a topological order. Cycles, unknown kinds or keys, missing inputs and two stages writing one
//! output are refused with an [`InputError`] naming the file and the stage.

use crate::error::InputError;
use crate::scene::{from_table, read_toml_table};
use crate::stages::StageKind;
use serde::{Deserialize, Serialize};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// A stage as written in the pipeline file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StageSpec {
    /// The stage kind: simulate, sweep, report.
    pub kind: String,
    /// Input files or globs, relative to the project root; `{run}` = `runs/<pipeline>`.
    #[serde(default)]
    pub inputs: Vec<String>,
    /// Output files the stage writes, relative to the project root.
    pub outputs: Vec<String>,
    /// Parameters of the kind (checked by the kind).
    #[serde(default)]
    pub params: toml::Table,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct PipelineFile {
    name: String,
    #[serde(default)]
    description: String,
    stages: BTreeMap<String, StageSpec>,
}

/// A stage with resolved paths and its dependencies.
#[derive(Debug, Clone)]
pub struct PlannedStage {
    /// Stage name.
    pub name: String,
    /// The spec as written.
    pub spec: StageSpec,
    /// The kind.
    pub kind: StageKind,
    /// Input patterns with `{run}` expanded, relative to the root.
    pub input_patterns: Vec<String>,
    /// Output paths, relative to the root.
    pub outputs: Vec<PathBuf>,
    /// Names of the stages this one reads from.
    pub deps: BTreeSet<String>,
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

/// The project root of a pipeline file: the folder above `pipelines/`, else the file's folder.
pub fn project_root(file: &Path) -> PathBuf {
    let dir = file.parent().map(Path::to_path_buf).unwrap_or_default();
    let dir = if dir.as_os_str().is_empty() {
        PathBuf::from(".")
    } else {
        dir
    };
    if dir.file_name().is_some_and(|n| n == "pipelines") {
        dir.parent()
            .map(Path::to_path_buf)
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or_else(|| PathBuf::from("."))
    } else {
        dir
    }
}

/// Reads and validates a pipeline file.
pub fn load_plan(file: &Path) -> Result<Plan, InputError> {
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
    let root = project_root(file);
    let run = format!("runs/{}", pf.name);
    let expand = |s: &str| s.replace("{run}", &run);
    let mut stages = Vec::new();
    let mut writer: BTreeMap<PathBuf, String> = BTreeMap::new();
    for (name, spec) in &pf.stages {
        let key = |k: &str| format!("stages.{name}.{k}");
        let kind = StageKind::parse(&spec.kind).ok_or_else(|| {
            InputError::new(
                file,
                key("kind"),
                format!(
                    "unknown stage kind `{}` (known: {})",
                    spec.kind,
                    StageKind::ALL.join(", ")
                ),
            )
        })?;
        kind.check_params(&spec.params)
            .map_err(|(k, m)| InputError::new(file, key(&format!("params.{k}")), m))?;
        if spec.outputs.is_empty() {
            return Err(InputError::new(
                file,
                key("outputs"),
                "a stage must declare at least one output",
            ));
        }
        let mut outputs = Vec::new();
        for o in &spec.outputs {
            let p = PathBuf::from(expand(o));
            if p.is_absolute()
                || p.components()
                    .any(|c| matches!(c, std::path::Component::ParentDir))
            {
                return Err(InputError::new(
                    file,
                    key("outputs"),
                    format!("`{o}` must be a relative path inside the project"),
                ));
            }
            if let Some(other) = writer.insert(p.clone(), name.clone()) {
                return Err(InputError::new(
                    file,
                    key("outputs"),
                    format!(
                        "`{o}` is also written by stage `{other}`: give each output one writer"
                    ),
                ));
            }
            outputs.push(p);
        }
        stages.push(PlannedStage {
            name: name.clone(),
            spec: spec.clone(),
            kind,
            input_patterns: spec.inputs.iter().map(|i| expand(i)).collect(),
            outputs,
            deps: BTreeSet::new(),
        });
    }
    // Dependencies: inputs equal to, or globs matching, another stage's outputs.
    for s in stages.iter_mut() {
        for pat in &s.input_patterns {
            let glob = glob::Pattern::new(pat).map_err(|e| {
                InputError::new(
                    file,
                    format!("stages.{}.inputs", s.name),
                    format!("bad glob `{pat}`: {e}"),
                )
            })?;
            let mut produced = false;
            for (out, w) in &writer {
                if out == Path::new(pat) || glob.matches_path(out) {
                    produced = true;
                    if w != &s.name {
                        s.deps.insert(w.clone());
                    }
                }
            }
            if !produced {
                let found = glob::glob(&root.join(pat).to_string_lossy())
                    .map(|mut g| g.next().is_some())
                    .unwrap_or(false);
                if !found {
                    return Err(InputError::new(
                        file,
                        format!("stages.{}.inputs", s.name),
                        format!("missing input `{pat}`: no such file, and no stage writes it"),
                    ));
                }
            }
        }
    }
    // Topological order (Kahn), ties by name; a leftover means a cycle.
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
    Ok(Plan {
        name: pf.name,
        description: pf.description,
        file: file.to_path_buf(),
        root,
        stages: order,
    })
}
