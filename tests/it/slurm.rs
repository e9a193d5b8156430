//! Items that survive and the Slurm executor (issue 18), on a real one-machine Slurm cluster that
//! `tests/slurm/up.sh` installs (Debian's slurm-wlm and munge) and starts once per test process:
//! a sweep and a calibration give the same tables through Slurm as locally, a cancelled array task
//! is resubmitted, a killed run computes only its missing parts, bad executor settings exit 2.

use crate::support::{drapelab, root, run_python, temp_project};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

/// Starts the one-machine cluster once (the script is idempotent: a cluster left running by an
/// earlier run is reused).
fn slurm_up() {
    static UP: OnceLock<()> = OnceLock::new();
    UP.get_or_init(|| {
        let o = std::process::Command::new("bash")
            .arg(root().join("tests/slurm/up.sh"))
            .output()
            .unwrap();
        assert!(
            o.status.success(),
            "tests/slurm/up.sh failed: {}{}",
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        );
    });
}

/// A 24-point sweep of the 4-corner hang (6 stiffnesses × 4 grid sizes) with an executor table.
fn sweep_pipeline(executor: &str) -> String {
    format!(
        r#"
name = "s"
[executor]
{executor}
[stages.sweep]
kind = "sweep"
inputs.scenes = ["datasets/scenes/hang4.toml"]
outputs.table = "{{run}}/sweep/sweep.parquet"
[stages.sweep.params]
axes."material.mass_spring.stiffness_N_per_m" = [500.0, 650.0, 800.0, 950.0, 1100.0, 1250.0]
axes."cloth.nx,cloth.ny" = [5, 7, 9, 11]
"#
    )
}

/// Runs `drapelab run FILE ARGS…` and asserts success.
fn run_cli(file: &Path, args: &[&str]) {
    let o = drapelab().arg("run").arg(file).args(args).output().unwrap();
    assert!(
        o.status.success(),
        "drapelab run {} {args:?}: {}",
        file.display(),
        String::from_utf8_lossy(&o.stderr)
    );
}

/// Asserts that two Parquet tables hold the same rows and column types, timing columns aside.
fn assert_same_table(a: &Path, b: &Path) {
    let code = r#"
import sys, polars as pl
a, b = pl.read_parquet(sys.argv[1]), pl.read_parquet(sys.argv[2])
assert a.schema == b.schema, (a.schema, b.schema)
timing = [c for c in a.columns if "time_s" in c]
assert a.height == b.height and a.height > 0, (a.height, b.height)
assert a.drop(timing).equals(b.drop(timing)), (a, b)
print(a.height, "rows equal; timing columns left out:", timing)
"#;
    run_python(code, &[a, b]);
}

fn sweep_table(tmp: &Path) -> PathBuf {
    tmp.join("runs/s/sweep/sweep.parquet")
}

#[test]
fn a_24_point_sweep_through_slurm_equals_the_local_one() {
    slurm_up();
    let (local, lf) = temp_project(
        &["datasets/scenes/hang4.toml"],
        "s.toml",
        &sweep_pipeline(""),
    );
    run_cli(&lf, &["--executor", "local"]);
    let (cluster, cf) = temp_project(
        &["datasets/scenes/hang4.toml"],
        "s.toml",
        &sweep_pipeline("items_per_task = 3\npoll_interval_s = 0.5"),
    );
    run_cli(&cf, &["--executor", "slurm"]);
    // One part per item, eight array tasks of three.
    let parts = cluster.path().join("runs/s/parts/sweep");
    assert_eq!(count_parts(&parts), 24);
    let tasks = std::fs::read_to_string(parts.join("slurm/tasks-0.txt")).unwrap();
    assert_eq!(tasks.lines().count(), 8, "{tasks}");
    assert_same_table(&sweep_table(local.path()), &sweep_table(cluster.path()));
}

/// The main parts (`part-NNNNN.parquet`) in a parts folder.
fn count_parts(dir: &Path) -> usize {
    std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .filter(|e| {
            let n = e.file_name().to_string_lossy().to_string();
            n.starts_with("part-") && n.ends_with(".parquet") && n.matches('.').count() == 1
        })
        .count()
}

/// A calibration of two samples of the bundled photos (one small ICA run each).
fn calibration_pipeline(executor: &str) -> String {
    format!(
        r#"
name = "c"
[executor]
{executor}
[stages.fit4]
kind = "fit-edges"
inputs.photos = ["datasets/knitted/sample_0[38]/hang4/photo.png"]
inputs.cameras = ["datasets/knitted/sample_0[38]/hang4/camera.json"]
outputs.edges = "{{run}}/fit4/edges.parquet"
[stages.calibrate]
kind = "calibrate"
inputs.edges = "{{run}}/fit4/edges.parquet"
inputs.samples = "datasets/knitted/knitted_samples.csv"
inputs.scene = "datasets/scenes/hang4.toml"
outputs.results = "{{run}}/calibrate/results.parquet"
outputs.evaluations = "{{run}}/calibrate/evaluations.parquet"
outputs.recording = "{{run}}/calibrate/calibration.rrd"
[stages.calibrate.params]
runs = 1
polish_iterations = 10
ica = {{ decades = 3, countries = 8, imperialists = 2, beta = 2.0, gamma = 0.3, revolution_rate = 0.2, xi = 0.1, seed = 4 }}
"#
    )
}

#[test]
fn a_calibration_of_two_samples_through_slurm_equals_the_local_one() {
    slurm_up();
    let files = [
        "datasets/knitted/sample_0[38]/hang4/*",
        "datasets/knitted/knitted_samples.csv",
        "datasets/scenes/hang4.toml",
    ];
    let (local, lf) = temp_project(&files, "c.toml", &calibration_pipeline(""));
    run_cli(&lf, &[]);
    let (cluster, cf) = temp_project(
        &files,
        "c.toml",
        &calibration_pipeline("kind = \"slurm\"\npoll_interval_s = 0.5"),
    );
    run_cli(&cf, &[]);
    let dir = |t: &Path| t.join("runs/c/calibrate");
    for table in ["results.parquet", "evaluations.parquet"] {
        assert_same_table(
            &dir(local.path()).join(table),
            &dir(cluster.path()).join(table),
        );
    }
    // The recording gathers both samples' parts.
    let code = r#"
import sys
from rerun.experimental import RrdReader
paths = {c.entity_path for c in RrdReader(sys.argv[1]).stream().to_chunks()}
for s in ["sample_03", "sample_08"]:
    assert any(s in p and p.endswith("/cost/best_pct") for p in paths), (s, sorted(paths))
"#;
    run_python(code, &[&dir(cluster.path()).join("calibration.rrd")]);
}

/// Polls `squeue` until an array job named for stage `sweep` of pipeline `s` is queued; its id.
fn wait_for_job(name: &str) -> String {
    let t0 = Instant::now();
    while t0.elapsed() < Duration::from_secs(60) {
        let o = std::process::Command::new("squeue")
            .args(["-h", "-n", name, "-o", "%F"])
            .output()
            .unwrap();
        let out = String::from_utf8_lossy(&o.stdout).to_string();
        if let Some(id) = out.split_whitespace().next() {
            return id.to_string();
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    panic!("no job {name} in squeue after 60 s");
}

#[test]
fn a_cancelled_array_task_is_resubmitted_and_nothing_is_lost_or_doubled() {
    slurm_up();
    // One task at a time, so that the last task is still pending when it is cancelled.
    let (cluster, cf) = temp_project(
        &["datasets/scenes/hang4.toml"],
        "s.toml",
        &sweep_pipeline(
            "kind = \"slurm\"\nitems_per_task = 4\nmax_concurrent_tasks = 1\npoll_interval_s = 0.5",
        )
        .replace("name = \"s\"", "name = \"cancel\""),
    );
    let child = drapelab()
        .arg("run")
        .arg(&cf)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let job = wait_for_job("drapelab-cancel-sweep");
    let o = std::process::Command::new("scancel")
        .arg(format!("{job}_5"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    let parts = cluster.path().join("runs/cancel/parts/sweep");
    // The second submission holds exactly the cancelled task's four items.
    let again = std::fs::read_to_string(parts.join("slurm/tasks-1.txt")).unwrap();
    assert_eq!(again.trim(), "20 21 22 23", "{err}");
    let code = r#"
import sys, polars as pl
t = pl.read_parquet(sys.argv[1])
assert t.height == 24, t.height
assert t.select("point").n_unique() == 24, t["point"].to_list()
assert (t["status"] == "converged").all(), t["status"].to_list()
"#;
    run_python(
        code,
        &[&cluster.path().join("runs/cancel/sweep/sweep.parquet")],
    );
}

#[test]
fn a_run_killed_mid_stage_computes_only_the_missing_parts_when_rerun() {
    // Local executor, one thread; larger nets so that the stage lasts a few seconds.
    let pipeline = sweep_pipeline("").replace("[5, 7, 9, 11]", "[15, 19, 23, 27]");
    let (tmp, file) = temp_project(&["datasets/scenes/hang4.toml"], "s.toml", &pipeline);
    let parts = tmp.path().join("runs/s/parts/sweep");
    let mut child = drapelab()
        .arg("run")
        .arg(&file)
        .args(["--jobs", "1"])
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let t0 = Instant::now();
    while !(parts.exists() && count_parts(&parts) >= 4) {
        assert!(
            t0.elapsed() < Duration::from_secs(120),
            "no parts after 120 s"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    child.kill().unwrap(); // SIGKILL
    child.wait().unwrap();
    let before: Vec<(String, std::time::SystemTime)> = part_times(&parts);
    assert!(
        before.len() >= 4 && before.len() < 24,
        "{} parts",
        before.len()
    );
    assert!(!sweep_table(tmp.path()).exists());
    run_cli(&file, &["--jobs", "1"]);
    let after = part_times(&parts);
    assert_eq!(after.len(), 24);
    // The parts of the killed run are kept as they were; only the others were computed.
    for (name, t) in &before {
        let now = after.iter().find(|(n, _)| n == name).unwrap();
        assert_eq!(&now.1, t, "{name} was recomputed");
    }
    let code = r#"
import sys, polars as pl
t = pl.read_parquet(sys.argv[1])
assert t.height == 24 and t.select("point").n_unique() == 24, t
"#;
    run_python(code, &[&sweep_table(tmp.path())]);
}

/// The main parts of a folder with their modification times, by name.
fn part_times(dir: &Path) -> Vec<(String, std::time::SystemTime)> {
    let mut v: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .filter_map(|e| {
            let n = e.file_name().to_string_lossy().to_string();
            (n.starts_with("part-") && n.ends_with(".parquet"))
                .then(|| (n, e.metadata().unwrap().modified().unwrap()))
        })
        .collect();
    v.sort();
    v
}

#[test]
fn bad_executor_settings_exit_2_with_one_line_that_says_what_to_do() {
    // A zero time limit: refused when the pipeline loads, naming the file and the key.
    let (_t, file) = temp_project(
        &["datasets/scenes/hang4.toml"],
        "s.toml",
        &sweep_pipeline("kind = \"slurm\"\ntime_limit_min = 0"),
    );
    crate::support::assert_bad_input(
        [Path::new("run"), &file],
        &["s.toml", "executor.time_limit_min"],
    );
    // No sbatch on PATH.
    let (_t, file) = temp_project(
        &["datasets/scenes/hang4.toml"],
        "s.toml",
        &sweep_pipeline(""),
    );
    let empty = tempfile::tempdir().unwrap();
    let o = drapelab()
        .env("PATH", empty.path())
        .arg("run")
        .arg(&file)
        .args(["--executor", "slurm"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(
        err.contains("--executor slurm") && err.contains("sbatch") && err.contains("PATH"),
        "{err}"
    );
    assert!(!tmp_has_runs(&file), "a refused run wrote files");
    // An unknown partition, checked against the cluster's sinfo.
    slurm_up();
    let (_t, file) = temp_project(
        &["datasets/scenes/hang4.toml"],
        "s.toml",
        &sweep_pipeline("kind = \"slurm\"\npartition = \"gpu-huge\""),
    );
    let line = crate::support::assert_bad_input(
        [Path::new("run"), &file],
        &["s.toml", "executor.partition", "gpu-huge"],
    );
    assert!(
        line.contains("debug"),
        "names the partitions there are: {line}"
    );
    assert!(!tmp_has_runs(&file));
}

/// Whether the project of pipeline `file` has a `runs/` folder.
fn tmp_has_runs(file: &Path) -> bool {
    file.parent()
        .unwrap()
        .parent()
        .unwrap()
        .join("runs")
        .exists()
}
