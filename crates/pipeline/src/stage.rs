//! One shape for every stage (n2's habit: the engine knows a stage only through one small interface).
//!
//! A kind is a [`StageKind`]: its typed parameters (checked when the plan loads), its named input and
//! output slots (checked when the plan loads, looked up by name when it runs) and `run`. The engine
//! sees kinds as `dyn` [`Stage`] through a [`Registry`]; adding a kind is one file and one line in the
//! registry that the binary builds.

use crate::progress::Progress;
use anyhow::Result;
use serde::Serialize;
use serde::de::DeserializeOwned;
use std::collections::BTreeMap;
use std::marker::PhantomData;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// A named input or output of a stage kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Slot {
    /// The slot's name, the key under `inputs.` or `outputs.` in a pipeline file.
    pub name: &'static str,
    /// Whether a pipeline must give it.
    pub required: bool,
    /// Whether it takes a list of paths or globs (otherwise exactly one path).
    pub many: bool,
    /// What goes there, for `--help` and errors.
    pub doc: &'static str,
}

impl Slot {
    /// A required slot of one path.
    pub const fn one(name: &'static str, doc: &'static str) -> Self {
        Self {
            name,
            required: true,
            many: false,
            doc,
        }
    }
    /// An optional slot of one path.
    pub const fn optional(name: &'static str, doc: &'static str) -> Self {
        Self {
            name,
            required: false,
            many: false,
            doc,
        }
    }
    /// A required slot of one or more paths or globs.
    pub const fn many(name: &'static str, doc: &'static str) -> Self {
        Self {
            name,
            required: true,
            many: true,
            doc,
        }
    }
    /// An optional slot of paths or globs.
    pub const fn optional_many(name: &'static str, doc: &'static str) -> Self {
        Self {
            name,
            required: false,
            many: true,
            doc,
        }
    }
}

pub use drapelab_core::error::KeyError;

/// The interface the engine knows a stage kind by (object safe).
pub trait Stage: Send + Sync {
    /// The kind's name in pipeline files (`simulate`, `fit-edges`, …).
    fn kind(&self) -> &'static str;
    /// One line on what the kind does.
    fn summary(&self) -> &'static str;
    /// The input slots.
    fn inputs(&self) -> &'static [Slot];
    /// The output slots.
    fn outputs(&self) -> &'static [Slot];
    /// Checks a params table; the resolved parameters (defaults filled in) as JSON, part of the
    /// up-to-date key.
    fn resolve(&self, params: &toml::Table) -> Result<serde_json::Value, KeyError>;
    /// Checks the parameters against the stage's input files, when the plan loads and every
    /// input already exists (a scene's overrides against the scene): an [`InputError`] refuses the
    /// plan in `status`, `run --dry-run` and `run` alike, before any work.
    ///
    /// [`InputError`]: drapelab_core::error::InputError
    fn precheck(&self, _ctx: &StageContext<'_>) -> Result<()> {
        Ok(())
    }
    /// Runs the stage (a stage with items runs through [`Stage::items`] instead).
    fn run(&self, ctx: &StageContext<'_>) -> Result<()>;
    /// How many independent items the stage has, when it runs by items (parts and executors,
    /// [`ItemKind`]); None: it runs as one piece through [`Stage::run`].
    fn items(&self, _ctx: &StageContext<'_>) -> Result<Option<usize>> {
        Ok(None)
    }
    /// Computes item `item` and writes its part at `part` (last, atomically; side files beside it).
    fn compute_item(&self, ctx: &StageContext<'_>, item: usize, part: &Path) -> Result<()> {
        let _ = (item, part);
        anyhow::bail!("stage `{}` does not run by items", ctx.stage)
    }
    /// Writes the stage's outputs from the parts of every item, in item order.
    fn gather(&self, ctx: &StageContext<'_>, parts: &[PathBuf]) -> Result<()> {
        let _ = parts;
        anyhow::bail!("stage `{}` does not run by items", ctx.stage)
    }
}

/// A stage kind with typed parameters: implement this, register it with [`Registry::with`].
pub trait StageKind: Send + Sync + 'static {
    /// The parameters (`params.*` in a pipeline file); unknown keys should be refused.
    type Params: DeserializeOwned + Serialize;
    /// The kind's name.
    const KIND: &'static str;
    /// One line on what it does.
    const SUMMARY: &'static str;
    /// Input slots.
    const INPUTS: &'static [Slot];
    /// Output slots.
    const OUTPUTS: &'static [Slot];
    /// Checks beyond the types (ranges, consistency).
    fn check(_params: &Self::Params) -> Result<(), KeyError> {
        Ok(())
    }
    /// [`Stage::precheck`] with the typed parameters. Default: nothing to check.
    fn precheck(_ctx: &StageContext<'_>, _params: &Self::Params) -> Result<()> {
        Ok(())
    }
    /// Runs the stage with its parameters (not called for an [`ItemKind`]).
    fn run(ctx: &StageContext<'_>, _params: &Self::Params) -> Result<()> {
        anyhow::bail!("stage `{}` of kind {} runs by items", ctx.stage, Self::KIND)
    }
}

/// A stage kind whose work is independent items (sweep points, samples): each item writes one part,
/// `{run}/parts/<stage>/part-00017.parquet` (atomically), and the outputs are the gather of the
/// parts, so a killed run keeps its finished items and an executor (local threads, Slurm array
/// tasks) can spread them. Register it with [`Registry::with_items`].
pub trait ItemKind: StageKind {
    /// The number of items (read from the inputs and parameters; cheap).
    fn count(ctx: &StageContext<'_>, params: &Self::Params) -> Result<usize>;
    /// Computes item `item` (0-based) and writes its part at `part`, last and atomically; side files
    /// go beside it as `part-00017.NAME`. Must not depend on which other items ran in this process.
    fn compute(
        ctx: &StageContext<'_>,
        params: &Self::Params,
        item: usize,
        part: &Path,
    ) -> Result<()>;
    /// Writes the stage's outputs from every item's part, in item order.
    fn gather(ctx: &StageContext<'_>, params: &Self::Params, parts: &[PathBuf]) -> Result<()>;
}

/// Deserializes a params table into `T`, naming the bad key.
pub fn typed_params<T: DeserializeOwned>(params: &toml::Table) -> Result<T, KeyError> {
    serde_path_to_error::deserialize(toml::Value::Table(params.clone())).map_err(|e| {
        let path = e.path().to_string();
        KeyError::new(
            if path == "." { String::new() } else { path },
            e.into_inner()
                .to_string()
                .lines()
                .next()
                .unwrap_or("invalid")
                .to_string(),
        )
    })
}

struct Typed<K>(PhantomData<K>);

struct ItemTyped<K>(PhantomData<K>);

/// The parameters of the stage in `ctx`, typed.
fn params_of<K: StageKind>(ctx: &StageContext<'_>) -> Result<K::Params> {
    typed_params(&ctx.params).map_err(|e| anyhow::anyhow!("params.{}: {}", e.key, e.message))
}

/// The [`Stage`] methods every typed kind shares: its metadata, its parameters and `run`.
macro_rules! typed_stage_methods {
    () => {
        fn kind(&self) -> &'static str {
            K::KIND
        }
        fn summary(&self) -> &'static str {
            K::SUMMARY
        }
        fn inputs(&self) -> &'static [Slot] {
            K::INPUTS
        }
        fn outputs(&self) -> &'static [Slot] {
            K::OUTPUTS
        }
        fn resolve(&self, params: &toml::Table) -> Result<serde_json::Value, KeyError> {
            let p: K::Params = typed_params(params)?;
            K::check(&p)?;
            serde_json::to_value(&p).map_err(|e| KeyError::new("", e.to_string()))
        }
        fn precheck(&self, ctx: &StageContext<'_>) -> Result<()> {
            K::precheck(ctx, &params_of::<K>(ctx)?)
        }
        fn run(&self, ctx: &StageContext<'_>) -> Result<()> {
            K::run(ctx, &params_of::<K>(ctx)?)
        }
    };
}

impl<K: StageKind> Stage for Typed<K> {
    typed_stage_methods!();
}

impl<K: ItemKind> Stage for ItemTyped<K> {
    typed_stage_methods!();
    fn items(&self, ctx: &StageContext<'_>) -> Result<Option<usize>> {
        K::count(ctx, &params_of::<K>(ctx)?).map(Some)
    }
    fn compute_item(&self, ctx: &StageContext<'_>, item: usize, part: &Path) -> Result<()> {
        K::compute(ctx, &params_of::<K>(ctx)?, item, part)
    }
    fn gather(&self, ctx: &StageContext<'_>, parts: &[PathBuf]) -> Result<()> {
        K::gather(ctx, &params_of::<K>(ctx)?, parts)
    }
}

/// The stage kinds a plan may use, by name.
#[derive(Default)]
pub struct Registry {
    kinds: BTreeMap<&'static str, Arc<dyn Stage>>,
}

impl Registry {
    /// An empty registry.
    pub fn new() -> Self {
        Self::default()
    }
    /// Adds a typed kind.
    pub fn with<K: StageKind>(mut self) -> Self {
        self.kinds
            .insert(K::KIND, Arc::new(Typed::<K>(PhantomData)));
        self
    }
    /// Adds a kind that runs by items ([`ItemKind`]).
    pub fn with_items<K: ItemKind>(mut self) -> Self {
        self.kinds
            .insert(K::KIND, Arc::new(ItemTyped::<K>(PhantomData)));
        self
    }
    /// The kind called `name`, shared.
    pub fn shared(&self, name: &str) -> Option<Arc<dyn Stage>> {
        self.kinds.get(name).cloned()
    }
    /// The kind called `name`.
    pub fn get(&self, name: &str) -> Option<&dyn Stage> {
        self.kinds.get(name).map(|b| b.as_ref())
    }
    /// Every kind, by name.
    pub fn kinds(&self) -> impl Iterator<Item = &dyn Stage> {
        self.kinds.values().map(|b| b.as_ref())
    }
    /// The kinds' names, comma separated.
    pub fn names(&self) -> String {
        self.kinds.keys().copied().collect::<Vec<_>>().join(", ")
    }
}

/// What a stage gets to run, as plain data: where it is, its parameters as written, its files by
/// slot (absolute) and where to report progress. A stage sees nothing of the plan but this, so
/// everything it reads is a declared input. Stage kinds hand it to their workflow as a
/// `drapelab_app::Job` (the files' accessors live there).
pub struct StageContext<'a> {
    /// The pipeline's name.
    pub pipeline: String,
    /// The pipeline file, relative to the root where it lies inside it.
    pub pipeline_file: PathBuf,
    /// The stage's name.
    pub stage: String,
    /// The project root (absolute or as given) that the pipeline's paths are relative to.
    pub root: PathBuf,
    /// The run folder, `runs/<pipeline>` under the root.
    pub run_dir: PathBuf,
    /// The `params` table as written (defaults are filled in by the kind's typed parameters).
    pub params: toml::Table,
    /// Input files of each given slot, absolute, sorted within a slot (globs expanded).
    pub inputs: BTreeMap<String, Vec<PathBuf>>,
    /// Output files of each given slot, absolute.
    pub outputs: BTreeMap<String, PathBuf>,
    /// Where to report items.
    pub progress: &'a dyn Progress,
}

impl StageContext<'_> {
    /// Reports that the stage has `items` items of work.
    pub fn started(&self, items: usize) {
        self.progress.stage_started(&self.stage, items as u64);
    }
    /// Reports one item done.
    pub fn item_done(&self) {
        self.progress.item_done(&self.stage);
    }
    /// The one file of input `slot`.
    pub fn file(&self, slot: &Slot) -> anyhow::Result<PathBuf> {
        self.optional_file(slot)?.ok_or_else(|| {
            anyhow::anyhow!(
                "`{}` needs input `{}`: add `inputs.{} = \"PATH\"`",
                self.stage,
                slot.name,
                slot.name
            )
        })
    }
    /// The file of optional input `slot`, if given.
    pub fn optional_file(&self, slot: &Slot) -> anyhow::Result<Option<PathBuf>> {
        match self.inputs.get(slot.name).map(Vec::as_slice) {
            None => Ok(None),
            Some([one]) => Ok(Some(one.clone())),
            Some(many) => anyhow::bail!(
                "input `{}` of `{}` matched {} files; it takes one",
                slot.name,
                self.stage,
                many.len()
            ),
        }
    }
    /// The files of input `slot` (empty when not given), sorted.
    pub fn files(&self, slot: &Slot) -> Vec<PathBuf> {
        self.inputs.get(slot.name).cloned().unwrap_or_default()
    }
}
