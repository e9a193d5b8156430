//! Runs that cannot corrupt each other and outputs that never contradict themselves (issue 33): a
//! second `drapelab run` of a pipeline is refused while the first holds its run folder, a killed
//! run's lock is taken over, a failed `simulate` leaves no stale result, a disc sheet's particles
//! say which are fabric, and bad flags and files are refused with one line and exit code 2.

use crate::pipeline::{SLOW_PIPELINE, project};
use crate::support::{assert_bad_input, drapelab, root};
use std::path::Path;
use std::time::{Duration, Instant};

/// Spawns `drapelab run FILE` and waits until it holds the run folder (its lock file names it).
fn start_run(file: &Path, lock: &Path) -> std::process::Child {
    let child = drapelab()
        .arg("run")
        .arg(file)
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let t = Instant::now();
    while std::fs::read_to_string(lock).map_or(true, |s| !s.contains(&child.id().to_string())) {
        assert!(
            t.elapsed() < Duration::from_secs(60),
            "the run never took the lock"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    child
}

#[test]
fn a_second_run_of_a_pipeline_is_refused_naming_the_holder_and_nothing_is_lost() {
    let (tmp, file) = project(SLOW_PIPELINE);
    let lock = tmp.path().join("runs/t/.lock");
    let mut first = start_run(&file, &lock);
    let second = drapelab().arg("run").arg(&file).output().unwrap();
    let err = String::from_utf8_lossy(&second.stderr);
    assert_eq!(second.status.code(), Some(2), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(
        err.contains(&format!("process {}", first.id())) && err.contains(".lock"),
        "{err}"
    );
    assert!(first.wait().unwrap().success(), "the first run failed");
    // Every stage the first run completed is up to date: the refused run wrote nothing.
    let status = drapelab()
        .args(["status", "--check"])
        .arg(&file)
        .output()
        .unwrap();
    assert!(
        status.status.success(),
        "{}",
        String::from_utf8_lossy(&status.stdout)
    );
    // With --wait, a second run waits for the first instead, then finds everything done.
    let mut again = start_run(&file, &lock);
    let waited = drapelab()
        .args(["run", "--wait"])
        .arg(&file)
        .output()
        .unwrap();
    assert!(again.wait().unwrap().success());
    assert!(
        waited.status.success(),
        "{}",
        String::from_utf8_lossy(&waited.stderr)
    );
    assert!(String::from_utf8_lossy(&waited.stderr).contains("0 ran, 3 up to date"));
}

#[test]
fn the_lock_of_a_killed_run_is_taken_over() {
    let (tmp, file) = project(SLOW_PIPELINE);
    let lock = tmp.path().join("runs/t/.lock");
    let mut child = start_run(&file, &lock);
    let pid = child.id();
    child.kill().unwrap(); // SIGKILL: no chance to release anything
    child.wait().unwrap();
    assert!(
        std::fs::read_to_string(&lock)
            .unwrap()
            .contains(&pid.to_string())
    );
    let out = drapelab().arg("run").arg(&file).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("taking over the lock") && err.contains(&format!("process {pid}")),
        "{err}"
    );
    // Released cleanly now: the next run says nothing of a lock.
    let next = drapelab().arg("run").arg(&file).output().unwrap();
    assert!(!String::from_utf8_lossy(&next.stderr).contains("taking over"));
}

#[test]
fn a_failed_simulate_into_an_old_folder_leaves_no_stale_result() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("hang2");
    std::fs::write(tmp.path().join("keep.txt"), "not drapelab's").unwrap();
    let scene = root().join("datasets/scenes/hang2.toml");
    let ok = drapelab()
        .arg("simulate")
        .arg(&scene)
        .arg("--out")
        .arg(&out)
        .args(["--set", "cloth.nx=11", "--set", "cloth.ny=11"])
        .output()
        .unwrap();
    assert!(ok.status.success());
    assert!(out.join("particles.parquet").exists());
    let failed = drapelab()
        .arg("simulate")
        .arg(&scene)
        .arg("--out")
        .arg(&out)
        .args(["--set", "cloth.nx=11", "--set", "cloth.ny=11"])
        .args(["--set", "solver.static.max_iterations=1"])
        .output()
        .unwrap();
    assert_eq!(failed.status.code(), Some(1));
    let run: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("run.json")).unwrap()).unwrap();
    assert_eq!(run["status"], "max-iterations");
    assert!(
        !out.join("particles.parquet").exists(),
        "an old result sits beside a run.json that says the solve did not converge"
    );
    assert!(out.join("last_state.parquet").exists());
    let names: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .collect();
    assert!(names.iter().all(|n| !n.starts_with('.')), "{names:?}");
    assert!(tmp.path().join("keep.txt").exists());
}

#[test]
fn a_disc_sheet_flags_the_particles_outside_its_circle() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("disc");
    let ok = drapelab()
        .arg("simulate")
        .arg(root().join("datasets/scenes/pedestal_wool.toml"))
        .arg("--out")
        .arg(&out)
        .args(["--set", "cloth.nx=21", "--set", "cloth.ny=21"])
        .output()
        .unwrap();
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
    let code = r#"
import sys, math, pyarrow.parquet as pq
t = pq.read_table(sys.argv[1]).to_pydict()
n = len(t["i"])
absent = [k for k in range(n) if not t["present"][k]]
present = [k for k in range(n) if t["present"][k]]
assert 0 < len(absent) < n, len(absent)
# Absent particles lie outside the disc's circle (the corners of the 21 x 21 grid) ...
c = 10
for k in absent:
    assert math.hypot(t["i"][k] - c, t["j"][k] - c) > 9.9, (t["i"][k], t["j"][k])
# ... and stay near their flat start, while the fabric hangs well below it.
top = max(t["z_m"][k] for k in absent)
assert min(t["z_m"][k] for k in absent) > top - 1e-3
assert min(t["z_m"][k] for k in present) < top - 0.01
print(len(absent))
"#;
    let absent: usize = crate::support::run_python(code, &[&out.join("particles.parquet")])
        .trim()
        .parse()
        .unwrap();
    assert!(absent > 0);
}

#[test]
fn the_drape_is_written_as_a_mesh_over_present_particles_only() {
    // A grid sheet and a disc cut from one: triangles.parquet's rows index particles.parquet, two
    // per cell where all four corners are present, none touching an absent particle; --obj writes
    // the same faces over every particle as a vertex.
    let tmp = tempfile::tempdir().unwrap();
    let code = r#"
import sys, pyarrow.parquet as pq
p = pq.read_table(sys.argv[1] + "/particles.parquet").to_pydict()
t = pq.read_table(sys.argv[1] + "/triangles.parquet")
assert [f.name for f in t.schema] == ["a", "b", "c"], t.schema
assert all(str(f.type) == "int32" for f in t.schema), t.schema
t = t.to_pydict()
n = len(p["i"])
tris = list(zip(t["a"], t["b"], t["c"]))
assert all(0 <= v < n and p["present"][v] for tri in tris for v in tri)
# Each triangle is half a grid cell; a cell with four corners present gives two, one with three
# at most one, others none.
nx, ny = max(p["i"]) + 1, max(p["j"]) + 1
at = {(p["i"][k], p["j"][k]): k for k in range(n)}
assert all(max(p["i"][v] for v in t) - min(p["i"][v] for v in t) == 1 and
           max(p["j"][v] for v in t) - min(p["j"][v] for v in t) == 1 for t in tris)
corners = [sum(p["present"][at[(i + a, j + b)]] for a in (0, 1) for b in (0, 1))
           for i in range(nx - 1) for j in range(ny - 1)]
full, three = corners.count(4), corners.count(3)
assert 2 * full <= len(tris) <= 2 * full + three, (len(tris), full, three)
print(len(tris), sum(p["present"]), n)
"#;
    for (scene, obj) in [("hang4", true), ("pedestal_wool", false)] {
        let out = tmp.path().join(scene);
        let mut cmd = drapelab();
        cmd.arg("simulate")
            .arg(root().join(format!("datasets/scenes/{scene}.toml")))
            .arg("--out")
            .arg(&out)
            .args(["--set", "cloth.nx=15", "--set", "cloth.ny=15"]);
        if obj {
            cmd.arg("--obj");
        }
        let ok = cmd.output().unwrap();
        assert!(
            ok.status.success(),
            "{}",
            String::from_utf8_lossy(&ok.stderr)
        );
        let said = crate::support::run_python(code, &[&out]);
        let counts: Vec<usize> = said
            .split_whitespace()
            .map(|v| v.parse().unwrap())
            .collect();
        if scene == "hang4" {
            assert_eq!(counts, vec![2 * 14 * 14, 225, 225], "{said}");
        } else {
            assert!(counts[1] < counts[2] && counts[0] > 0, "{said}");
        }
        assert_eq!(out.join("drape.obj").exists(), obj);
        if obj {
            let text = std::fs::read_to_string(out.join("drape.obj")).unwrap();
            let v = text.lines().filter(|l| l.starts_with("v ")).count();
            let f: Vec<&str> = text.lines().filter(|l| l.starts_with("f ")).collect();
            assert_eq!((v, f.len()), (225, 2 * 14 * 14));
            assert!(f.iter().all(|l| {
                l.split_whitespace()
                    .skip(1)
                    .all(|k| (1..=225).contains(&k.parse::<usize>().unwrap()))
            }));
        }
    }
}

#[test]
fn bad_flags_and_files_are_refused_with_one_line_naming_them() {
    let tmp = tempfile::tempdir().unwrap();
    let hang4 = root().join("datasets/scenes/hang4.toml");
    let out = tmp.path().join("r");
    let render = |flag: &[&str]| {
        let mut a = vec![
            "render".to_string(),
            hang4.display().to_string(),
            "--out".into(),
            out.display().to_string(),
        ];
        a.extend(flag.iter().map(|s| s.to_string()));
        a
    };
    for (flag, name) in [
        (&["--px-per-cm", "1e9"][..], "--px-per-cm"),
        (&["--noise=-0.5"][..], "--noise"),
        (&["--noise", "-0.5"][..], "--noise"),
        (&["--jpeg-quality", "0"][..], "--jpeg-quality"),
        (&["--rotate-deg", "nan"][..], "--rotate-deg"),
        (&["--blur-px", "inf"][..], "--blur-px"),
    ] {
        assert_bad_input(render(flag), &[name]);
        assert!(
            !out.exists(),
            "{name}: a refused render left {}",
            out.display()
        );
    }
    // A scene render cannot view (a table drape) is refused after --out was made: nothing left.
    let nested = tmp.path().join("new/render");
    assert_bad_input(
        [
            Path::new("render"),
            &root().join("datasets/scenes/table_wool.toml"),
            Path::new("--out"),
            &nested,
        ],
        &["boundary.pin_corners"],
    );
    assert!(
        !tmp.path().join("new").exists(),
        "a refused render left its folder"
    );
    assert_bad_input(["bench", "--sizes", "1"], &["--sizes"]);
    assert_bad_input(["bench", "--tol", "0"], &["--tol"]);
    assert_bad_input(
        ["fit-edges", "x.png", "--out", "o", "--degree", "9"],
        &["--degree"],
    );
    // An --out that cannot be written, and a file that is not Parquet.
    let blocker = tmp.path().join("file");
    std::fs::write(&blocker, "a file, not a folder").unwrap();
    let unwritable = blocker.join("out");
    assert_bad_input(
        [
            Path::new("simulate"),
            &hang4,
            Path::new("--out"),
            &unwritable,
        ],
        &["--out", "file/out"],
    );
    let junk = tmp.path().join("edges.parquet");
    std::fs::write(&junk, "PAR1 not really").unwrap();
    assert_bad_input(
        [Path::new("score"), &junk, &junk],
        &["edges.parquet", "Parquet"],
    );
}

#[test]
fn status_finds_the_project_from_inside_pipelines() {
    // `cd pipelines && drapelab status t.toml`: the project root is the folder above.
    let (_tmp, file) = project(&one_stage(
        "simulate",
        "inputs.scene = \"datasets/scenes/hang2.toml\"\noutputs.particles = \"{run}/p.parquet\"\n\
         outputs.run = \"{run}/run.json\"",
    ));
    let o = drapelab()
        .current_dir(file.parent().unwrap())
        .args(["status", "t.toml"])
        .output()
        .unwrap();
    let said = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(said.contains("s: stale"), "{said}");
}

/// A pipeline with one stage of `kind` and the given inputs, outputs and params.
fn one_stage(kind: &str, rest: &str) -> String {
    format!("name = \"t\"\n[stages.s]\nkind = \"{kind}\"\n{rest}\n")
}

#[test]
fn a_bad_set_in_a_pipeline_names_the_pipeline_and_stage_and_a_bad_report_column_is_refused_before_work()
 {
    let (_tmp, file) = project(&one_stage(
        "simulate",
        "inputs.scene = \"datasets/scenes/hang2.toml\"\noutputs.particles = \"{run}/p.parquet\"\n\
         outputs.run = \"{run}/run.json\"\nparams.set = { \"cloth.nx\" = -3 }",
    ));
    // Refused alike by status, a dry run and a run, and the run leaves no lock and no folder.
    let refused_everywhere = |file: &Path, names: &[&str]| {
        for cmd in [&["status"][..], &["run", "--dry-run"], &["run"]] {
            let mut a: Vec<&Path> = cmd.iter().map(Path::new).collect();
            a.push(file);
            assert_bad_input(a, names);
        }
        let runs = file.parent().unwrap().parent().unwrap().join("runs");
        assert!(
            !runs.join("t").exists(),
            "a refused run left {}",
            runs.display()
        );
    };
    refused_everywhere(
        &file,
        &["t.toml", "stages.s.params.set.cloth.nx", "hang2.toml"],
    );
    let (_tmp, file) = project(&one_stage(
        "sweep",
        "inputs.scenes = [\"datasets/scenes/hang2.toml\"]\noutputs.table = \"{run}/sweep.parquet\"\n\
         params.axes = { \"material.mass_spring.stiffness_N_per_m\" = [-1.0, 2.0] }",
    ));
    refused_everywhere(
        &file,
        &["t.toml", "stages.s.params.axes", "stiffness_N_per_m"],
    );
    let (_tmp, file) = project(
        r#"
name = "t"
[stages.sweep]
kind = "sweep"
inputs.scenes = ["datasets/scenes/hang2.toml"]
outputs.table = "{run}/sweep.parquet"
params.axes = { "cloth.nx,cloth.ny" = [5] }
[stages.r]
kind = "report"
inputs.tables = ["{run}/sweep.parquet"]
outputs.markdown = "r.md"
outputs.plot = "r.svg"
params = { title = "t", x = "cloth.nx", y = "centre_height_m" }
"#,
    );
    let line = assert_bad_input(
        [Path::new("-q"), Path::new("run"), &file],
        &[
            "t.toml",
            "stages.r.params.y",
            "centre_height_m",
            "centre_z_m",
        ],
    );
    assert!(line.len() < 2000, "{line}");
}

/// Two `simulate` runs into one `--out`, the second started while the first solves: both finish
/// with their status (the later no longer removes the earlier's staging folder, which left the
/// earlier with exit 1 and no status), the folder holds one whole result and no staging.
#[test]
fn two_simulate_runs_into_one_folder_both_finish() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let scene = crate::support::root().join("datasets/scenes/sphere_wool.toml");
    let start = || {
        crate::support::drapelab()
            .arg("-q")
            .arg("simulate")
            .arg(&scene)
            .arg("--out")
            .arg(&out)
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap()
    };
    let first = start();
    std::thread::sleep(std::time::Duration::from_millis(300));
    let second = start();
    for (k, child) in [first, second].into_iter().enumerate() {
        let o = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(0), "run {k}: {err}");
    }
    let run: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).unwrap()).unwrap();
    assert_eq!(run["report"]["status"], "converged");
    assert!(out.join("particles.parquet").exists());
    for e in std::fs::read_dir(&out).unwrap().flatten() {
        let name = e.file_name().to_string_lossy().to_string();
        assert!(!name.ends_with(".partial"), "{name} left behind");
    }
}
