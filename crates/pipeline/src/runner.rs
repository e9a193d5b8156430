//! Running a plan make-style: a stage runs when it is stale (or forced), otherwise it is skipped
//! in milliseconds. Outputs are written atomically by the stages; the manifest is written last.

use crate::executor::{ExecutorKind, ExecutorSettings};
use crate::manifest::{Manifest, build_id, hash_file, stage_key};
use crate::plan::{Plan, PlannedStage};
use crate::progress::Progress;
use crate::stage::StageContext;
use anyhow::Result;
use drapelab_core::error::InputError;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Options of `drapelab run`.
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    /// Run only this stage and what it depends on.
    pub until: Option<String>,
    /// Rerun these stages and their dependents even when up to date.
    pub force: Vec<String>,
    /// Threads for the items of a stage (0 = all cores).
    pub jobs: usize,
    /// Say what would run, run nothing.
    pub dry_run: bool,
    /// The executor of items, overriding the pipeline's `[executor]` kind (`--executor`).
    pub executor: Option<ExecutorKind>,
}

/// Whether a stage is up to date, and if not, why.
#[derive(Debug, Clone, PartialEq)]
pub enum StageState {
    /// Inputs, parameters, version and outputs match the manifest.
    UpToDate,
    /// Must run; the reason in words.
    Stale(String),
}

/// What a run did.
#[derive(Debug, Clone, Default)]
pub struct RunSummary {
    /// Stages that ran successfully.
    pub ran: Vec<String>,
    /// Stages skipped as up to date.
    pub skipped: Vec<String>,
    /// Stages that failed, with why.
    pub failed: Vec<(String, String)>,
    /// Stages that would run (dry run).
    pub would_run: Vec<(String, String)>,
}

fn rel(root: &Path, p: &Path) -> String {
    p.strip_prefix(root)
        .unwrap_or(p)
        .to_string_lossy()
        .replace('\\', "/")
}

/// The manifest path of a stage.
pub fn manifest_path(plan: &Plan, stage: &str) -> PathBuf {
    plan.run_dir()
        .join(".manifests")
        .join(format!("{stage}.json"))
}

/// The input files of a stage now, by slot: globs expanded, outputs of other stages included even
/// when missing; each slot's files sorted by path relative to the root.
fn slot_inputs(plan: &Plan, s: &PlannedStage) -> BTreeMap<String, BTreeSet<String>> {
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

/// The files of every slot with their content hashes (None when missing).
fn hashed(
    plan: &Plan,
    slots: &BTreeMap<String, BTreeSet<String>>,
) -> BTreeMap<String, Option<String>> {
    slots
        .values()
        .flatten()
        .cloned()
        .map(|p| {
            let h = hash_file(&plan.root.join(&p)).ok();
            (p, h)
        })
        .collect()
}

fn check(plan: &Plan, s: &PlannedStage, upstream_stale: &BTreeSet<String>) -> StageState {
    if let Some(d) = s.deps.iter().find(|d| upstream_stale.contains(*d)) {
        return StageState::Stale(format!("upstream stage `{d}` will run"));
    }
    let Some(m) = Manifest::read(&manifest_path(plan, &s.name)) else {
        return StageState::Stale("never completed (no manifest)".into());
    };
    if m.status != "ok" {
        return StageState::Stale(format!("last run {}", m.status));
    }
    if m.drapelab_version != drapelab_core::VERSION {
        return StageState::Stale(format!(
            "drapelab version changed ({} → {})",
            m.drapelab_version,
            drapelab_core::VERSION
        ));
    }
    let params = &s.params;
    if m.params != *params {
        let mut changed = Vec::new();
        if let (Some(a), Some(b)) = (m.params.as_object(), params.as_object()) {
            for k in a.keys().chain(b.keys()).collect::<BTreeSet<_>>() {
                if a.get(k) != b.get(k) {
                    changed.push(k.clone());
                }
            }
        }
        return StageState::Stale(format!("parameter changed: {}", changed.join(", ")));
    }
    let now = current_inputs(plan, s);
    for (p, h) in &now {
        match (h, m.inputs.get(p)) {
            (None, _) => return StageState::Stale(format!("input `{p}` is missing")),
            (Some(_), None) => return StageState::Stale(format!("new input `{p}`")),
            (Some(a), Some(b)) if a != b => {
                return StageState::Stale(format!("input `{p}` changed"));
            }
            _ => {}
        }
    }
    if let Some(p) = m.inputs.keys().find(|p| !now.contains_key(*p)) {
        return StageState::Stale(format!("input `{p}` removed"));
    }
    for o in s.outputs.values() {
        let size = std::fs::metadata(plan.root.join(o)).map(|m| m.len()).ok();
        if size.is_none() || size != m.outputs.get(&o.to_string_lossy().to_string()).copied() {
            return StageState::Stale(format!("output `{}` missing or altered", o.display()));
        }
    }
    if m.key != stage_key(s.kind.kind(), params, &m.inputs) {
        return StageState::Stale("manifest key mismatch".into());
    }
    if m.build != build_id() {
        return StageState::Stale(format!(
            "drapelab was rebuilt (build {} → {})",
            if m.build.is_empty() {
                "unknown"
            } else {
                &m.build
            },
            build_id()
        ));
    }
    StageState::UpToDate
}

/// Removes temporary files left in `dir` by a killed run (`.NAME.*.partial`).
pub(crate) fn remove_partials(dir: &Path) {
    if let Ok(entries) = std::fs::read_dir(dir) {
        for e in entries.flatten() {
            let name = e.file_name().to_string_lossy().to_string();
            if name.starts_with('.') && name.ends_with(".partial") {
                std::fs::remove_file(e.path()).ok();
            }
        }
    }
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

/// Runs the plan; stage failures are in the summary, bad input is an error.
pub fn run_pipeline(plan: &Plan, opts: &RunOptions, progress: &dyn Progress) -> Result<RunSummary> {
    for name in opts.until.iter().chain(&opts.force) {
        if plan.stage(name).is_none() {
            let known: Vec<&str> = plan.stages.iter().map(|s| s.name.as_str()).collect();
            return Err(InputError::new(
                &plan.file,
                "stages",
                format!("no stage named `{name}` (stages: {})", known.join(", ")),
            )
            .into());
        }
    }
    let mut executor = plan.executor.clone();
    if let Some(kind) = opts.executor {
        executor.kind = kind;
    }
    if executor.kind == ExecutorKind::Slurm && !opts.dry_run {
        crate::slurm::preflight(&executor, &plan.file)?;
    }
    let selected: BTreeSet<String> = match &opts.until {
        Some(u) => plan.ancestors(u),
        None => plan.stages.iter().map(|s| s.name.clone()).collect(),
    };
    let forced: BTreeSet<String> = opts
        .force
        .iter()
        .flat_map(|f| plan.descendants(f))
        .collect();
    let mut summary = RunSummary::default();
    let mut will_run: BTreeSet<String> = BTreeSet::new();
    let mut failed: BTreeSet<String> = BTreeSet::new();
    let jobs = if opts.jobs == 0 {
        std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(1)
    } else {
        opts.jobs
    };
    let pool = rayon::ThreadPoolBuilder::new().num_threads(jobs).build()?;
    for s in &plan.stages {
        if !selected.contains(&s.name) {
            continue;
        }
        if let Some(d) = s.deps.iter().find(|d| failed.contains(*d)) {
            let why = format!("upstream stage `{d}` failed");
            progress.stage_skipped(&s.name, &why);
            failed.insert(s.name.clone());
            summary.failed.push((s.name.clone(), why));
            continue;
        }
        let upstream = if opts.dry_run {
            will_run.clone()
        } else {
            BTreeSet::new()
        };
        let state = if forced.contains(&s.name) {
            StageState::Stale("forced".into())
        } else {
            check(plan, s, &upstream)
        };
        tracing::debug!(stage = %s.name, kind = s.kind.kind(), state = ?state, "checked");
        let StageState::Stale(why) = state else {
            progress.stage_skipped(&s.name, "up to date");
            summary.skipped.push(s.name.clone());
            continue;
        };
        will_run.insert(s.name.clone());
        if opts.dry_run {
            summary.would_run.push((s.name.clone(), why));
            continue;
        }
        if forced.contains(&s.name) {
            // Forced: computed afresh, parts included.
            let parts = crate::items::parts_dir(&plan.run_dir(), &s.name);
            if parts.exists() {
                std::fs::remove_dir_all(&parts)?;
            }
        }
        let status = run_stage(plan, s, &pool, &executor, progress)?;
        if status == "ok" {
            summary.ran.push(s.name.clone());
        } else {
            failed.insert(s.name.clone());
            summary.failed.push((s.name.clone(), status));
        }
    }
    Ok(summary)
}

/// The context of stage `s` now (its input files by slot, its outputs) and its input hashes.
fn stage_context<'a>(
    plan: &'a Plan,
    s: &'a PlannedStage,
    progress: &'a dyn Progress,
) -> (StageContext<'a>, BTreeMap<String, String>) {
    let slots = slot_inputs(plan, s);
    let inputs: BTreeMap<String, String> = hashed(plan, &slots)
        .into_iter()
        .map(|(p, h)| (p, h.unwrap_or_default()))
        .collect();
    let ctx = StageContext {
        plan,
        stage: s,
        inputs: slots
            .into_iter()
            .map(|(k, files)| (k, files.iter().map(|p| plan.root.join(p)).collect()))
            .collect(),
        outputs: s
            .outputs
            .iter()
            .map(|(k, o)| (k.clone(), plan.root.join(o)))
            .collect(),
        progress,
    };
    (ctx, inputs)
}

/// The key of a stage's parts: its up-to-date key and the build (parts of another build are
/// recomputed).
fn parts_key(s: &PlannedStage, inputs: &BTreeMap<String, String>) -> String {
    format!(
        "{}-{}",
        stage_key(s.kind.kind(), &s.params, inputs),
        build_id()
    )
}

/// Runs a stage: by items through the executor when its kind has items, else in one piece.
fn run_whole_or_items(
    ctx: &StageContext<'_>,
    inputs: &BTreeMap<String, String>,
    executor: &ExecutorSettings,
) -> Result<()> {
    match ctx.stage.kind.items(ctx)? {
        Some(n) => crate::items::run_by_items(ctx, n, &parts_key(ctx.stage, inputs), executor),
        None => ctx.stage.kind.run(ctx),
    }
}

/// `drapelab worker`: computes `items` of stage `stage` of `plan` (those without a part), on this
/// process's threads, as one Slurm array task does. The parts folder must have been prepared for
/// the stage's current inputs and parameters by `drapelab run` (else the inputs changed since).
pub fn run_worker(plan: &Plan, stage: &str, items: &[usize]) -> Result<()> {
    let s = plan.stage(stage).ok_or_else(|| {
        InputError::new(&plan.file, "stages", format!("no stage named `{stage}`"))
    })?;
    let progress = crate::progress::LogProgress::default();
    let (ctx, inputs) = stage_context(plan, s, &progress);
    let dir = crate::items::parts_dir(&plan.run_dir(), stage);
    if !crate::items::parts_match(&dir, &parts_key(s, &inputs)) {
        anyhow::bail!(
            "{}: the parts folder is not that of stage `{stage}` with its current inputs,              parameters and build (they changed since `drapelab run` submitted the work); run it again",
            dir.display()
        );
    }
    let todo = crate::items::without_part(&dir, items.iter().copied());
    crate::items::compute_local(&ctx, &todo, &dir)
}

/// Runs one stale stage in `pool` and writes its manifest: its status, "ok" or "failed: …" (an
/// error, a panic, or an output not written). Bad input is returned as an error.
fn run_stage(
    plan: &Plan,
    s: &PlannedStage,
    pool: &rayon::ThreadPool,
    executor: &ExecutorSettings,
    progress: &dyn Progress,
) -> Result<String> {
    let start = Instant::now();
    let (ctx, inputs) = stage_context(plan, s, progress);
    for o in ctx.outputs.values() {
        if let Some(d) = o.parent() {
            std::fs::create_dir_all(d)?;
            remove_partials(d);
        }
    }
    let outputs = ctx.outputs.clone();
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        pool.install(|| run_whole_or_items(&ctx, &inputs, executor))
    }));
    let status = match result {
        Ok(Ok(())) => match outputs.values().find(|o| !o.exists()) {
            Some(o) => format!("failed: did not write {}", rel(&plan.root, o)),
            None => "ok".to_string(),
        },
        Ok(Err(e)) if e.chain().any(|c| c.is::<InputError>()) => return Err(e),
        Ok(Err(e)) => format!("failed: {}", format!("{e:#}").replace('\n', " ")),
        Err(panic) => format!(
            "failed: the stage panicked ({}); this is a bug in drapelab, please report it",
            panic_message(panic.as_ref())
        ),
    };
    let wall = start.elapsed().as_secs_f64();
    let manifest = Manifest {
        stage: s.name.clone(),
        kind: s.kind.kind().into(),
        key: stage_key(s.kind.kind(), &s.params, &inputs),
        inputs,
        params: s.params.clone(),
        outputs: s
            .outputs
            .values()
            .map(|o| {
                (
                    o.to_string_lossy().to_string(),
                    std::fs::metadata(plan.root.join(o))
                        .map(|m| m.len())
                        .unwrap_or(0),
                )
            })
            .collect(),
        status: status.clone(),
        wall_time_s: wall,
        command_line: std::env::args().collect(),
        drapelab_version: drapelab_core::VERSION.into(),
        build: build_id().into(),
    };
    manifest.write(&manifest_path(plan, &s.name))?;
    progress.stage_finished(&s.name, &status, wall);
    Ok(status)
}

/// The message of a panic payload.
fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "no message".into())
}
