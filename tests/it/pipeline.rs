//! Make-style pipelines: the cache, forced reruns, staleness reasons, atomicity under kill -9, bad
//! pipeline files, and a real client reading the sweep dataset. A failure here means stale results
//! are served as fresh, or a killed run leaves a wrong artifact.

use crate::support::{drapelab, run_python, temp_project};
use drapelab::pipeline::{
    LogProgress, RunOptions, StageState, StaleReason, load_plan, run_pipeline, stage_states,
};
use std::path::{Path, PathBuf};

const PIPELINE: &str = r#"
name = "t"
[stages.a4]
kind = "simulate"
inputs.scene = "datasets/scenes/hang4.toml"
outputs.particles = "{run}/a4/particles.parquet"
outputs.run = "{run}/a4/run.json"
params.set = { "cloth.nx" = 9, "cloth.ny" = 9 }

[stages.a2]
kind = "simulate"
inputs.scene = "datasets/scenes/hang2.toml"
outputs.particles = "{run}/a2/particles.parquet"
outputs.run = "{run}/a2/run.json"
params.set = { "cloth.nx" = 9, "cloth.ny" = 9 }

[stages.sweep2]
kind = "sweep"
inputs.scenes = ["datasets/scenes/hang2.toml"]
outputs.table = "{run}/sweep2/sweep.parquet"
params.axes = { "material.mass_spring.stiffness_N_per_m" = [600.0, 1100.0], "cloth.nx,cloth.ny" = [7, 9] }

[stages.report]
kind = "report"
inputs.tables = ["{run}/sweep2/*.parquet"]
outputs.markdown = "reports/t.md"
outputs.plot = "reports/t.svg"
params = { title = "t", x = "material.mass_spring.stiffness_N_per_m", group_by = ["scene", "cloth.nx"] }
"#;

/// A temporary project with the bundled scenes and a pipeline file.
pub(crate) fn project(pipeline: &str) -> (tempfile::TempDir, PathBuf) {
    temp_project(
        &["datasets/scenes/hang4.toml", "datasets/scenes/hang2.toml"],
        "t.toml",
        pipeline,
    )
}

fn run(file: &Path, opts: RunOptions) -> drapelab::pipeline::RunSummary {
    let plan = load_plan(file, &drapelab::stages::registry()).unwrap();
    run_pipeline(
        &plan,
        &RunOptions { jobs: 2, ..opts },
        &LogProgress::default(),
    )
    .unwrap()
}

fn sorted(mut v: Vec<String>) -> Vec<String> {
    v.sort();
    v
}

#[test]
fn second_run_skips_everything_and_a_changed_input_reruns_only_its_dependents() {
    let (tmp, file) = project(PIPELINE);
    let first = run(&file, RunOptions::default());
    assert!(first.failed.is_empty(), "{:?}", first.failed);
    assert_eq!(sorted(first.ran), ["a2", "a4", "report", "sweep2"]);
    let second = run(&file, RunOptions::default());
    assert!(second.ran.is_empty(), "{:?}", second.ran);
    assert_eq!(second.skipped.len(), 4);
    // Change hang2's scene: a2, sweep2 and report rerun, a4 does not.
    let h2 = tmp.path().join("datasets/scenes/hang2.toml");
    let text = std::fs::read_to_string(&h2)
        .unwrap()
        .replace("stiffness_N_per_m = 1000.0", "stiffness_N_per_m = 900.0");
    std::fs::write(&h2, text).unwrap();
    let plan = load_plan(&file, &drapelab::stages::registry()).unwrap();
    let states = stage_states(&plan);
    let why = |n: &str| states.iter().find(|(s, _)| s == n).unwrap().1.clone();
    assert_eq!(why("a4"), StageState::UpToDate);
    assert!(matches!(
        why("a2"),
        StageState::Stale(StaleReason::InputChanged(w)) if w.contains("hang2.toml")
    ));
    let third = run(&file, RunOptions::default());
    assert_eq!(sorted(third.ran), ["a2", "report", "sweep2"]);
    assert_eq!(third.skipped, ["a4"]);
}

#[test]
fn force_reruns_the_stage_and_its_dependents_and_a_changed_parameter_is_reported() {
    let (_tmp, file) = project(PIPELINE);
    run(&file, RunOptions::default());
    let dry = run(
        &file,
        RunOptions {
            force: vec!["sweep2".into()],
            dry_run: true,
            ..Default::default()
        },
    );
    assert!(dry.ran.is_empty());
    assert_eq!(
        sorted(dry.would_run.iter().map(|(n, _)| n.clone()).collect()),
        ["report", "sweep2"]
    );
    let forced = run(
        &file,
        RunOptions {
            force: vec!["sweep2".into()],
            ..Default::default()
        },
    );
    assert_eq!(sorted(forced.ran), ["report", "sweep2"]);
    let until = run(
        &file,
        RunOptions {
            force: vec!["a4".into()],
            until: Some("a4".into()),
            ..Default::default()
        },
    );
    assert_eq!(until.ran, ["a4"]);
    // The stages ran inside this test's binary: the drapelab binary is another build, for which
    // every stage is stale until it has run them itself.
    let out = drapelab().arg("status").arg(&file).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("a4: stale (drapelab was rebuilt"), "{text}");
    let out = drapelab().arg("run").arg(&file).output().unwrap();
    assert!(out.status.success());
    // A parameter change makes the stage stale, and status says which.
    std::fs::write(
        &file,
        PIPELINE.replace(
            r#""cloth.nx" = 9, "cloth.ny" = 9 }
"#,
            r#""cloth.nx" = 7, "cloth.ny" = 9 }
"#,
        ),
    )
    .unwrap();
    let plan = load_plan(&file, &drapelab::stages::registry()).unwrap();
    let states = stage_states(&plan);
    let a4 = &states.iter().find(|(s, _)| s == "a4").unwrap().1;
    assert!(
        matches!(a4, StageState::Stale(StaleReason::ParamsChanged(k)) if k == &["set"]),
        "{a4:?}"
    );
    let out = drapelab().arg("status").arg(&file).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("a4: stale (parameter changed: set)"),
        "{text}"
    );
    assert!(text.contains("sweep2: up to date"), "{text}");
}

/// Heavier than PIPELINE (about 2 s on 2 cores) so that kills land inside stages.
pub(crate) const SLOW_PIPELINE: &str = r#"
name = "t"
[stages.a4]
kind = "simulate"
inputs.scene = "datasets/scenes/hang4.toml"
outputs.particles = "{run}/a4/particles.parquet"
outputs.run = "{run}/a4/run.json"
outputs.timeline = "{run}/a4/timeline.mcap"
params.set = { "cloth.nx" = 41, "cloth.ny" = 41, "record.timeline" = true }

[stages.sweep2]
kind = "sweep"
inputs.scenes = ["datasets/scenes/hang2.toml"]
outputs.table = "{run}/sweep2/sweep.parquet"
params.axes = { "material.mass_spring.stiffness_N_per_m" = [600.0, 900.0, 1200.0], "cloth.nx,cloth.ny" = [21, 41] }

[stages.report]
kind = "report"
inputs.tables = ["{run}/sweep2/*.parquet"]
outputs.markdown = "reports/t.md"
outputs.plot = "reports/t.svg"
params = { title = "t", x = "material.mass_spring.stiffness_N_per_m", group_by = ["scene", "cloth.nx"] }
"#;

#[test]
fn a_run_killed_mid_stage_completes_to_the_same_artifacts() {
    let (clean, clean_file) = project(SLOW_PIPELINE);
    assert!(
        drapelab()
            .arg("run")
            .arg(&clean_file)
            .output()
            .unwrap()
            .status
            .success()
    );
    let (tmp, file) = project(SLOW_PIPELINE);
    // Kill (SIGKILL) at several moments; each rerun resumes, finishing only what is missing.
    let mut interrupted = 0;
    for delay_ms in [250u64, 700, 1200] {
        let mut child = drapelab()
            .arg("run")
            .arg(&file)
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(std::time::Duration::from_millis(delay_ms));
        child.kill().unwrap();
        child.wait().unwrap();
        let plan = load_plan(&file, &drapelab::stages::registry()).unwrap();
        if stage_states(&plan)
            .iter()
            .any(|(_, s)| *s != StageState::UpToDate)
        {
            interrupted += 1;
        }
        // Nothing that looks finished is unfinished: every stage with a manifest has all its outputs.
        for s in &plan.stages {
            let m = tmp
                .path()
                .join(format!("runs/t/.manifests/{}.json", s.name));
            if m.exists() {
                for o in s.outputs.values() {
                    assert!(
                        tmp.path().join(o).exists(),
                        "{} has a manifest but no {}",
                        s.name,
                        o.display()
                    );
                }
            }
        }
    }
    assert!(
        interrupted >= 1,
        "no kill landed before the pipeline finished: the test proves nothing"
    );
    let out = drapelab().arg("run").arg(&file).output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let again = drapelab().arg("run").arg(&file).output().unwrap();
    assert!(
        String::from_utf8_lossy(&again.stderr).contains("0 ran, 3 up to date"),
        "{}",
        String::from_utf8_lossy(&again.stderr)
    );
    // Deterministic artifacts are identical byte for byte; no temporary file is left in an output folder.
    let p = "runs/t/a4/particles.parquet";
    assert_eq!(
        std::fs::read(tmp.path().join(p)).unwrap(),
        std::fs::read(clean.path().join(p)).unwrap(),
        "{p} differs"
    );
    for dir in ["runs/t/a4", "runs/t/sweep2", "reports"] {
        for e in std::fs::read_dir(tmp.path().join(dir)).unwrap() {
            let name = e.unwrap().file_name().to_string_lossy().to_string();
            assert!(!name.ends_with(".partial"), "{dir}/{name} left behind");
        }
    }
    // The sweep is deterministic but for its wall times.
    let code = r#"
import sys, pyarrow.parquet as pq
a, b = (pq.read_table(p).drop(["wall_time_s"]) for p in sys.argv[1:3])
assert a.equals(b), (a, b)
"#;
    run_python(
        code,
        &[
            &tmp.path().join("runs/t/sweep2/sweep.parquet"),
            &clean.path().join("runs/t/sweep2/sweep.parquet"),
        ],
    );
}

fn assert_bad_pipeline(text: &str, stage: &str, what: &str) {
    let (_tmp, file) = project(text);
    let out = drapelab().arg("run").arg(&file).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{what}: {err}");
    let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "{what}: {err}");
    assert!(
        lines[0].contains("t.toml") && lines[0].contains(stage),
        "{what}: {err}"
    );
}

#[test]
fn bad_pipeline_files_are_refused_naming_file_and_stage() {
    let cycle = r#"
name = "t"
[stages.x]
kind = "report"
inputs.tables = ["{run}/y.parquet"]
outputs.plot = "{run}/x.parquet"
outputs.markdown = "reports/x.md"
params = { title = "x", x = "a" }
[stages.y]
kind = "report"
inputs.tables = ["{run}/x.parquet"]
outputs.plot = "{run}/y.parquet"
outputs.markdown = "reports/y.md"
params = { title = "y", x = "a" }
"#;
    assert_bad_pipeline(cycle, "stages.x", "cycle");
    // A stage that reads its own output: a cycle of one, refused at load naming its input slot.
    let own = r#"
name = "t"
[stages.x]
kind = "report"
inputs.tables = ["{run}/x.parquet"]
outputs.plot = "{run}/x.parquet"
outputs.markdown = "reports/x.md"
params = { title = "x", x = "iterations" }
"#;
    assert_bad_pipeline(own, "stages.x.inputs.tables", "own output");
    assert_bad_pipeline(
        &PIPELINE.replace("kind = \"sweep\"", "kind = \"swep\""),
        "stages.sweep2.kind",
        "unknown kind",
    );
    assert_bad_pipeline(
        &PIPELINE.replace("datasets/scenes/hang4.toml", "datasets/scenes/nope.toml"),
        "stages.a4.inputs",
        "missing input",
    );
    assert_bad_pipeline(
        &PIPELINE.replace(
            "params = { title = \"t\",",
            "params = { titel = \"t\", title = \"t\",",
        ),
        "stages.report.params.titel",
        "unknown key",
    );
    assert_bad_pipeline(
        &PIPELINE.replace("{run}/a2/particles.parquet", "{run}/a4/particles.parquet"),
        "stages.a4.outputs",
        "two writers",
    );
}

#[test]
fn pyarrow_and_polars_read_the_sweep_dataset_with_documented_columns() {
    let (tmp, file) = project(PIPELINE);
    run(
        &file,
        RunOptions {
            until: Some("sweep2".into()),
            ..Default::default()
        },
    );
    let code = r#"
import sys, pyarrow as pa, pyarrow.parquet as pq, polars as pl
t = pq.read_table(sys.argv[1])
want = {"scene": pa.string(), "point": pa.uint32(), "material.mass_spring.stiffness_N_per_m": pa.float64(),
        "cloth.nx": pa.int64(), "particles": pa.uint32(), "solver": pa.string(), "status": pa.string(),
        "iterations": pa.uint64(), "linear_solves": pa.uint64(), "wall_time_s": pa.float64(),
        "max_residual_N": pa.float64(), "centre_z_m": pa.float64(), "min_z_m": pa.float64(),
        "corner_xmin_ymin_z_m": pa.float64()}
for k, ty in want.items():
    assert t.schema.field(k).type == ty, (k, t.schema.field(k).type)
assert t.num_rows == 4
# The run's metadata: which drapelab made it, where and when.
meta = {k.decode(): v.decode() for k, v in t.schema.metadata.items()}
assert {"drapelab_version", "build_id", "host", "finished_utc"} <= set(meta), meta
assert len(meta["build_id"]) == 16 and meta["finished_utc"].endswith("Z"), meta
df = pl.read_parquet(sys.argv[1])
assert (df["status"] == "converged").all()
# Stiffer springs sag less: the centre hangs higher at 1100 N/m than at 600 N/m.
s = df.filter(pl.col("cloth.nx") == 9).sort("material.mass_spring.stiffness_N_per_m")
assert s["centre_z_m"][0] < s["centre_z_m"][1] < 0, s
print("ok")
"#;
    run_python(code, &[&tmp.path().join("runs/t/sweep2/sweep.parquet")]);
}

#[test]
fn a_missing_or_unknown_slot_is_refused_at_load_naming_stage_and_slot() {
    // A required output left out.
    assert_bad_pipeline(
        &PIPELINE.replace("outputs.run = \"{run}/a4/run.json\"\n", ""),
        "stages.a4.outputs.run",
        "missing output slot",
    );
    // An output the kind does not have.
    assert_bad_pipeline(
        &PIPELINE.replace(
            "outputs.run = \"{run}/a4/run.json\"\n",
            "outputs.run = \"{run}/a4/run.json\"\noutputs.extra = \"{run}/a4/extra.json\"\n",
        ),
        "stages.a4.outputs.extra",
        "unknown output slot",
    );
    // An input slot the kind does not have, and a required input left out.
    assert_bad_pipeline(
        &PIPELINE.replace(
            "inputs.scene = \"datasets/scenes/hang2.toml\"",
            "inputs.scenes = \"datasets/scenes/hang2.toml\"",
        ),
        "stages.a2.inputs.scenes",
        "unknown input slot",
    );
    // Nothing ran and nothing was written.
    let (tmp, file) = project(&PIPELINE.replace("outputs.run = \"{run}/a4/run.json\"\n", ""));
    assert!(load_plan(&file, &drapelab::stages::registry()).is_err());
    assert!(!tmp.path().join("runs").exists());
}

/// A stage kind that panics, registered beside drapelab's own (a new kind is one type and one line).
struct Panics;

impl drapelab::pipeline::StageKind for Panics {
    type Params = toml::Table;
    const KIND: &'static str = "panics";
    const SUMMARY: &'static str = "panics (a test of the runner)";
    const INPUTS: &'static [drapelab::pipeline::Slot] = &[];
    const OUTPUTS: &'static [drapelab::pipeline::Slot] =
        &[drapelab::pipeline::Slot::one("out", "never written")];
    fn run(_: &drapelab::pipeline::StageContext<'_>, _: &toml::Table) -> anyhow::Result<()> {
        panic!("index out of bounds in a buggy stage")
    }
}

#[test]
fn a_panicking_stage_fails_alone_and_the_run_exits_1() {
    let text = PIPELINE.to_string()
        + "\n[stages.bad]\nkind = \"panics\"\noutputs.out = \"{run}/bad/out.json\"\n\
           \n[stages.after_bad]\nkind = \"report\"\ninputs.tables = [\"{run}/bad/out.json\"]\n\
           outputs.markdown = \"reports/ab.md\"\noutputs.plot = \"reports/ab.svg\"\n\
           params = { title = \"t\", x = \"cloth.nx\" }\n";
    let (tmp, file) = project(&text);
    let registry = drapelab::stages::registry().with::<Panics>();
    let code = drapelab::cli::run_pipeline_with(
        &file,
        RunOptions {
            jobs: 2,
            ..Default::default()
        },
        &registry,
    )
    .unwrap();
    assert_eq!(code, 1, "a failed stage makes the run exit 1");
    let manifest: serde_json::Value = serde_json::from_slice(
        &std::fs::read(tmp.path().join("runs/t/.manifests/bad.json")).unwrap(),
    )
    .unwrap();
    let status = &manifest["status"];
    assert_eq!(status["outcome"], "failed", "{status}");
    assert_eq!(status["cause"], "panic", "{status}");
    let message = status["message"].as_str().unwrap();
    assert!(
        message.contains("panicked") && message.contains("buggy"),
        "{message}"
    );
    // The stages that do not depend on it ran; its dependent did not.
    for done in ["a4", "a2", "sweep2", "report"] {
        let m: serde_json::Value = serde_json::from_slice(
            &std::fs::read(tmp.path().join(format!("runs/t/.manifests/{done}.json"))).unwrap(),
        )
        .unwrap();
        assert_eq!(m["status"]["outcome"], "ok", "{done}");
    }
    assert!(!tmp.path().join("reports/ab.md").exists());
}

/// A mesh scene's OBJ (`cloth.mesh`) is an input of every stage that reads the scene: a changed
/// pattern makes the stage stale and names the file, an unchanged one does not.
#[test]
fn a_changed_mesh_file_makes_the_stage_that_reads_its_scene_stale() {
    let (tmp, file) = temp_project(
        &[
            "datasets/patterns/l_panel_table.toml",
            "datasets/patterns/l_panel.obj",
        ],
        "t.toml",
        r#"
name = "t"
[stages.panel]
kind = "simulate"
inputs.scene = "datasets/patterns/l_panel_table.toml"
outputs.particles = "{run}/panel/particles.parquet"
outputs.run = "{run}/panel/run.json"
"#,
    );
    let first = run(&file, RunOptions::default());
    assert!(first.failed.is_empty(), "{:?}", first.failed);
    let plan = load_plan(&file, &drapelab::stages::registry()).unwrap();
    assert_eq!(stage_states(&plan)[0].1, StageState::UpToDate);
    // Move one vertex of the pattern by 1 mm.
    let obj = tmp.path().join("datasets/patterns/l_panel.obj");
    let text = std::fs::read_to_string(&obj).unwrap();
    let moved = text.replacen("v 0.015000 0.000000 0", "v 0.016000 0.000000 0", 1);
    assert_ne!(moved, text);
    std::fs::write(&obj, moved).unwrap();
    let plan = load_plan(&file, &drapelab::stages::registry()).unwrap();
    assert!(matches!(
        &stage_states(&plan)[0].1,
        StageState::Stale(StaleReason::InputChanged(w)) if w.contains("l_panel.obj")
    ));
    let second = run(&file, RunOptions::default());
    assert_eq!(second.ran, ["panel"]);
}
