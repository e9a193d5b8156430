//! What a workflow gets to run: its typed input files, its outputs by name, where to report
//! progress, and how to name a bad parameter. A plain value that a pipeline stage, the command line, a test or the Python package
//! builds; a workflow sees nothing of the engine.

use anyhow::Result;
use drapelab_core::error::InputError;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Receives a workflow's progress.
pub trait Progress: Sync {
    /// The workflow has `items` items of work.
    fn started(&self, items: usize);
    /// One item is done.
    fn item_done(&self);
}

/// A progress that says nothing.
pub struct Quiet;

impl Progress for Quiet {
    fn started(&self, _: usize) {}
    fn item_done(&self) {}
}

/// A workflow's files and surroundings; `I` is the workflow's typed inputs (its `…Inputs` struct,
/// built by the stage adapter from the declared slots).
pub struct Job<'a, I = ()> {
    /// Its name (the stage's name in a pipeline), for messages.
    pub stage: String,
    /// Where its parameters come from (the pipeline file), for provenance lines and errors.
    pub source: PathBuf,
    /// The folder paths in tables and reports are written relative to.
    pub root: PathBuf,
    /// The workflow's input files, absolute.
    pub inputs: I,
    /// Output files by name, absolute.
    pub outputs: BTreeMap<String, PathBuf>,
    /// Where progress goes.
    pub progress: Box<dyn Progress + 'a>,
}

impl<I> Job<'_, I> {
    /// "Made by `drapelab run SOURCE` (drapelab VERSION)": the provenance line of every report.
    pub fn made_by(&self) -> String {
        format!(
            "Made by `drapelab run {}` (drapelab {})",
            self.source.display(),
            drapelab_core::VERSION
        )
    }
    /// Reports `items` items of work.
    pub fn started(&self, items: usize) {
        self.progress.started(items);
    }
    /// Reports one item done.
    pub fn item_done(&self) {
        self.progress.item_done();
    }
    /// `path` relative to the root, for tables and reports.
    pub fn relative<'p>(&self, path: &'p Path) -> &'p Path {
        path.strip_prefix(&self.root).unwrap_or(path)
    }
    /// A bad value of parameter `key` (found when the workflow runs): an input error naming the
    /// source and `stages.STAGE.params.KEY` (exit 2).
    pub fn param_error(&self, key: &str, message: impl Into<String>) -> InputError {
        InputError::new(
            self.root.join(&self.source),
            format!("stages.{}.params.{key}", self.stage),
            message,
        )
    }
    /// The path of output `name`.
    pub fn output(&self, name: &str) -> Result<&Path> {
        self.optional_output(name).ok_or_else(|| {
            anyhow::anyhow!(
                "`{}` needs output `{name}`: add `outputs.{name} = \"PATH\"`",
                self.stage
            )
        })
    }
    /// The path of an optional output, if given.
    pub fn optional_output(&self, name: &str) -> Option<&Path> {
        self.outputs.get(name).map(PathBuf::as_path)
    }
    /// Loads scene `file` with overrides from this job's parameters; an error an override causes
    /// names the source, the stage and the parameter (`param_key` of the override's scene key).
    pub fn load_scene(
        &self,
        file: &Path,
        overrides: &[(String, toml::Value)],
        param_key: impl Fn(&str) -> String,
    ) -> Result<drapelab_core::scene::LoadedScene> {
        drapelab_core::scene::Scene::load(file, overrides).map_err(|e| {
            let culprit = drapelab_core::config::override_culprit(&e.key, overrides);
            // An error in another file (a fabric, a mesh) names that file.
            match culprit.filter(|_| e.file == file) {
                Some(i) => self
                    .param_error(
                        &param_key(&overrides[i].0),
                        format!("{} (scene {}, key `{}`)", e.message, file.display(), e.key),
                    )
                    .into(),
                None => e.into(),
            }
        })
    }
}
