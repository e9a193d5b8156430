//! Running a plan make-style: a stage runs when it is stale (or forced), otherwise it is skipped
//! in milliseconds. Outputs are written atomically by the stages; the manifest is written last.

use crate::executor::ExecutorKind;
use crate::files::{rel, remove_partials};
use crate::items::{Executor, Local, parts_dir, run_by_items};
use crate::lock::{LockWait, RunLock};
use crate::manifest::{Manifest, build_id, stage_key};
use crate::outcome::{FailureCause, StageOutcome, StaleReason};
use crate::plan::{Plan, PlannedStage};
use crate::progress::Progress;
use crate::slurm::Slurm;
use crate::stage::StageContext;
use crate::stale::{StageState, check, hashed, manifest_path, slot_inputs};
use anyhow::Result;
use drapelab_core::error::InputError;
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;
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
    /// Whether to wait for a run folder that another run holds (`--wait`) or refuse at once.
    pub wait: LockWait,
}

impl RunOptions {
    /// The stages' worker threads: `jobs`, or every core when 0.
    fn threads(&self) -> usize {
        match self.jobs {
            0 => std::thread::available_parallelism().map_or(1, |n| n.get()),
            n => n,
        }
    }
}

/// What a run did.
#[derive(Debug, Clone, Default)]
pub struct RunSummary {
    /// Stages that ran successfully.
    pub ran: Vec<String>,
    /// Stages skipped as up to date.
    pub skipped: Vec<String>,
    /// Stages that failed, with how.
    pub failed: Vec<(String, StageOutcome)>,
    /// Stages that would run (dry run), with why.
    pub would_run: Vec<(String, StaleReason)>,
}

/// Refuses `--until`/`--force` names that are not stages of the plan.
fn check_stage_names(plan: &Plan, opts: &RunOptions) -> Result<(), InputError> {
    for name in opts.until.iter().chain(&opts.force) {
        if plan.stage(name).is_none() {
            let known: Vec<&str> = plan.stages.iter().map(|s| s.name.as_str()).collect();
            return Err(InputError::new(
                &plan.file,
                "stages",
                format!("no stage named `{name}` (stages: {})", known.join(", ")),
            ));
        }
    }
    Ok(())
}

/// Runs the plan; stage failures are in the summary, bad input is an error. A real run holds the
/// run folder's lock ([`RunLock`]) throughout: a second run of the pipeline is refused (or waits).
pub fn run_pipeline(plan: &Plan, opts: &RunOptions, progress: &dyn Progress) -> Result<RunSummary> {
    check_stage_names(plan, opts)?;
    let mut settings = plan.executor.clone();
    settings.kind = opts.executor.unwrap_or(settings.kind);
    if settings.kind == ExecutorKind::Slurm && !opts.dry_run {
        crate::slurm::preflight(&settings, &plan.file)?;
    }
    let _lock = if opts.dry_run {
        None
    } else {
        Some(RunLock::acquire(&plan.run_dir(), opts.wait)?)
    };
    let executor: Box<dyn Executor> = match settings.kind {
        ExecutorKind::Local => Box::new(Local),
        ExecutorKind::Slurm => Box::new(Slurm(&settings)),
    };
    let selected: BTreeSet<String> = match &opts.until {
        Some(u) => plan.ancestors(u),
        None => plan.stages.iter().map(|s| s.name.clone()).collect(),
    };
    let forced: BTreeSet<String> = opts
        .force
        .iter()
        .flat_map(|f| plan.descendants(f))
        .collect();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.threads())
        .build()?;
    let mut summary = RunSummary::default();
    let mut will_run: BTreeSet<String> = BTreeSet::new();
    for s in plan.stages.iter().filter(|s| selected.contains(&s.name)) {
        if let Some(d) = s.deps.iter().find(|d| summary.has_failed(d)) {
            let outcome = StageOutcome::failed(
                FailureCause::Upstream,
                format!("upstream stage `{d}` failed"),
            );
            progress.stage_skipped(&s.name, &outcome.to_string());
            summary.failed.push((s.name.clone(), outcome));
            continue;
        }
        let upstream = if opts.dry_run {
            will_run.clone()
        } else {
            BTreeSet::new()
        };
        let state = if forced.contains(&s.name) {
            StageState::Stale(StaleReason::Forced)
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
            let parts = parts_dir(&plan.run_dir(), &s.name);
            if parts.exists() {
                std::fs::remove_dir_all(&parts)?;
            }
        }
        match run_stage(plan, s, &pool, executor.as_ref(), progress)? {
            StageOutcome::Ok => summary.ran.push(s.name.clone()),
            failed => summary.failed.push((s.name.clone(), failed)),
        }
    }
    Ok(summary)
}

impl RunSummary {
    /// Whether stage `name` failed (or did not run because one above it failed).
    pub fn has_failed(&self, name: &str) -> bool {
        self.failed.iter().any(|(s, _)| s == name)
    }
}

/// The context of stage `s` now (its input files by slot, its outputs) and its input hashes.
/// Reads and validates a pipeline file ([`load_plan`](crate::load_plan)), then checks each stage
/// whose inputs all exist against them ([`Stage::precheck`](crate::Stage::precheck): a scene's
/// overrides, a sweep's axes): bad input is refused here, in `status` and `--dry-run` as in `run`.
pub fn load_checked_plan(file: &Path, registry: &crate::Registry) -> Result<Plan> {
    let plan = crate::load_plan(file, registry)?;
    let silent = Silent;
    for s in &plan.stages {
        let ctx = context(&plan, s, slot_inputs(&plan, s), &silent);
        let all_there = s.input_patterns.keys().all(|k| {
            ctx.inputs
                .get(k)
                .is_some_and(|f| !f.is_empty() && f.iter().all(|p| p.is_file()))
        });
        if !all_there {
            continue;
        }
        // Only bad input refuses the plan; another failure (an unreadable file) is the run's.
        match s.kind.precheck(&ctx) {
            Err(e) if e.chain().any(|c| c.is::<InputError>()) => return Err(e),
            _ => {}
        }
    }
    Ok(plan)
}

/// A progress that says nothing (the checks of [`load_checked_plan`]).
struct Silent;

impl Progress for Silent {
    fn stage_started(&self, _stage: &str, _items: u64) {}
    fn item_done(&self, _stage: &str) {}
    fn stage_finished(&self, _stage: &str, _outcome: &StageOutcome, _wall_s: f64) {}
    fn stage_skipped(&self, _stage: &str, _why: &str) {}
}

fn stage_context<'a>(
    plan: &Plan,
    s: &PlannedStage,
    progress: &'a dyn Progress,
) -> (StageContext<'a>, BTreeMap<String, String>) {
    let slots = slot_inputs(plan, s);
    let inputs: BTreeMap<String, String> = hashed(plan, &slots)
        .into_iter()
        .map(|(p, h)| (p, h.unwrap_or_default()))
        .collect();
    (context(plan, s, slots, progress), inputs)
}

/// The context of stage `s` over its input files `slots` (paths relative to the root), without
/// hashing them.
fn context<'a>(
    plan: &Plan,
    s: &PlannedStage,
    slots: BTreeMap<String, BTreeSet<String>>,
    progress: &'a dyn Progress,
) -> StageContext<'a> {
    StageContext {
        pipeline: plan.name.clone(),
        pipeline_file: plan
            .file
            .strip_prefix(&plan.root)
            .unwrap_or(&plan.file)
            .to_path_buf(),
        stage: s.name.clone(),
        root: plan.root.clone(),
        run_dir: plan.run_dir(),
        params: s.spec.params.clone(),
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
    }
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
    s: &PlannedStage,
    ctx: &StageContext<'_>,
    inputs: &BTreeMap<String, String>,
    executor: &dyn Executor,
) -> Result<()> {
    let kind = s.kind.as_ref();
    match kind.items(ctx)? {
        Some(n) => run_by_items(kind, ctx, n, &parts_key(s, inputs), executor),
        None => kind.run(ctx),
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
    let dir = parts_dir(&plan.run_dir(), stage);
    if !crate::items::parts_match(&dir, &parts_key(s, &inputs)) {
        anyhow::bail!(
            "{}: the parts folder is not that of stage `{stage}` with its current inputs, \
             parameters and build (they changed since `drapelab run` submitted the work); run it again",
            dir.display()
        );
    }
    let todo = crate::items::without_part(&dir, items.iter().copied());
    Local.compute(s.kind.as_ref(), &ctx, &todo, &dir)
}

/// Runs one stale stage in `pool` and writes its manifest: its outcome (an error, a panic, or an
/// output not written is a failure). Bad input is returned as an error.
fn run_stage(
    plan: &Plan,
    s: &PlannedStage,
    pool: &rayon::ThreadPool,
    executor: &dyn Executor,
    progress: &dyn Progress,
) -> Result<StageOutcome> {
    let start = Instant::now();
    let (ctx, inputs) = stage_context(plan, s, progress);
    // Output folders this stage makes: removed again if it fails leaving them empty.
    let mut _made = Vec::new();
    for o in ctx.outputs.values() {
        if let Some(d) = o.parent() {
            _made.push(drapelab_core::atomic::MadeDirs::create(d)?);
            remove_partials(d);
        }
    }
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        pool.install(|| run_whole_or_items(s, &ctx, &inputs, executor))
    }));
    let status = match result {
        Ok(Ok(())) => match ctx.outputs.values().find(|o| !o.exists()) {
            Some(o) => StageOutcome::failed(
                FailureCause::MissingOutput,
                format!("did not write {}", rel(&plan.root, o)),
            ),
            None => StageOutcome::Ok,
        },
        Ok(Err(e)) if e.chain().any(|c| c.is::<InputError>()) => return Err(e),
        Ok(Err(e)) => StageOutcome::failed(FailureCause::Error, format!("{e:#}")),
        Err(panic) => StageOutcome::failed(
            FailureCause::Panic,
            format!(
                "the stage panicked ({}); this is a bug in drapelab, please report it",
                panic_message(panic.as_ref())
            ),
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
                let size = std::fs::metadata(plan.root.join(o)).map_or(0, |m| m.len());
                (o.to_string_lossy().to_string(), size)
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
