//! Bad input at the command line: one line naming the file and the key, exit code 2, nothing
//! written. A failure here means a user gets a panic, a vague message or a half-written folder.

use crate::support::{drapelab, root};
use std::path::Path;

/// Runs `simulate` on a scene text (or a path) and returns (exit code, stderr, whether DIR has files).
fn simulate_text(text: Option<&str>, extra: &[&str]) -> (i32, String, bool, std::path::PathBuf) {
    let tmp = tempfile::tempdir().unwrap();
    let scene = tmp.path().join("scene.toml");
    if let Some(t) = text {
        std::fs::write(&scene, t).unwrap();
    }
    let out = tmp.path().join("out");
    let o = drapelab()
        .arg("simulate")
        .arg(&scene)
        .arg("--out")
        .arg(&out)
        .args(extra)
        .output()
        .unwrap();
    let has_files = out.exists() && std::fs::read_dir(&out).unwrap().next().is_some();
    (
        o.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&o.stderr).to_string(),
        has_files,
        scene,
    )
}

fn hang4() -> String {
    std::fs::read_to_string(root().join("datasets/scenes/hang4.toml")).unwrap()
}

fn assert_bad(text: Option<&str>, extra: &[&str], key: &str) {
    let (code, err, has_files, scene) = simulate_text(text, extra);
    assert_eq!(code, 2, "exit code for {key}: stderr {err}");
    let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "one line expected: {err}");
    assert!(
        lines[0].contains(&scene.display().to_string())
            || lines[0].contains(Path::new(&scene).file_name().unwrap().to_str().unwrap()),
        "file not named: {err}"
    );
    assert!(lines[0].contains(key), "key `{key}` not named: {err}");
    assert!(!has_files, "files left in DIR for {key}");
}

#[test]
fn unknown_key_is_refused_with_its_path() {
    let t = hang4().replace(
        "stiffness_N_per_m = 1000.0",
        "stiffness_N_per_m = 1000.0\nstifness = 3",
    );
    assert_bad(Some(&t), &[], "material.mass_spring.stifness");
}

#[test]
fn negative_stiffness_is_refused() {
    let t = hang4().replace("stiffness_N_per_m = 1000.0", "stiffness_N_per_m = -5.0");
    assert_bad(Some(&t), &[], "material.mass_spring.stiffness_N_per_m");
}

/// Issue 78: a mass-spring scene without its stiffness was run with 1000 N/m; it is refused naming
/// the key (no stiffness is a fabric's by default).
#[test]
fn a_missing_stiffness_is_refused_naming_the_key() {
    let t = hang4().replace("stiffness_N_per_m = 1000.0", "");
    assert_bad(Some(&t), &[], "stiffness_N_per_m");
}

#[test]
fn nan_is_refused() {
    let t = hang4().replace(
        "areal_density_kg_per_m2 = 0.045",
        "areal_density_kg_per_m2 = nan",
    );
    assert_bad(Some(&t), &[], "cloth.areal_density_kg_per_m2");
    assert_bad(
        Some(&hang4()),
        &["--set", "solver.dynamic.dt_s=inf"],
        "solver.dynamic.dt_s",
    );
}

#[test]
fn pin_outside_the_grid_is_refused() {
    let t = hang4().replace("[boundary]", "[boundary]\npin_particles = [[3, 11]]");
    assert_bad(Some(&t), &[], "boundary.pin_particles.0");
}

#[test]
fn missing_file_and_malformed_toml_are_refused() {
    let (code, err, has, _) = simulate_text(None, &[]);
    assert_eq!(code, 2);
    assert!(
        err.contains("scene.toml") && err.contains("cannot read"),
        "{err}"
    );
    assert!(!has);
    let (code, err, _, _) = simulate_text(Some("name = \"x\"\n[cloth\nnx = 3"), &[]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("malformed TOML"), "{err}");
}

#[test]
fn set_overrides_reach_the_solve_and_outputs_are_written() {
    let (code, err, has, _) = simulate_text(
        Some(&hang4()),
        &["--set", "cloth.nx=7", "--set", "cloth.ny=5"],
    );
    assert_eq!(code, 0, "{err}");
    assert!(has);
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("o");
    let o = drapelab()
        .arg("simulate")
        .arg(root().join("datasets/scenes/hang4.toml"))
        .arg("--out")
        .arg(&out)
        .args(["--set", "cloth.nx=7", "--set", "cloth.ny=5"])
        .output()
        .unwrap();
    assert!(o.status.success());
    let rows = drapelab::io::read_particles(&out.join("particles.parquet")).unwrap();
    assert_eq!(rows.len(), 35);
    assert!(rows.iter().any(|r| r.0 == 6 && r.1 == 4));
    let run: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("run.json")).unwrap()).unwrap();
    assert_eq!(run["status"], "converged");
    assert_eq!(run["scene"]["cloth"]["nx"], 7);
    // How the solve went, an iteration a row: as many rows as iterations plus the start, the
    // residual at the last one the report's.
    let history: Vec<drapelab::io::IterationRow> =
        drapelab::io::read_table(&out.join("iterations.parquet")).unwrap();
    let iterations = run["report"]["iterations"].as_u64().unwrap();
    assert_eq!(history.len() as u64, iterations + 1);
    assert!(history.iter().enumerate().all(|(k, r)| r.index == k as u64));
    let last = history.last().unwrap().max_residual_N;
    let reported = run["report"]["max_residual_N"].as_f64().unwrap();
    assert!(
        (last - reported).abs() <= 1e-9 * reported.max(1e-300),
        "{last} {reported}"
    );
    // No temporary files are left behind.
    for e in std::fs::read_dir(&out).unwrap() {
        let name = e.unwrap().file_name().to_string_lossy().to_string();
        assert!(!name.ends_with(".partial"), "{name}");
    }
}

#[test]
fn a_diverged_run_writes_its_status_and_no_particles() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("o");
    let o = drapelab()
        .arg("simulate")
        .arg(root().join("datasets/scenes/hang4.toml"))
        .arg("--out")
        .arg(&out)
        .args([
            "--set",
            "solver.kind=explicit-euler",
            "--set",
            "solver.dynamic.dt_s=2e-4",
            "--set",
            "solver.dynamic.max_time_s=5",
        ])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    let run: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("run.json")).unwrap()).unwrap();
    assert_eq!(run["status"], "diverged");
    assert!(run["report"]["divergence"]["step"].as_u64().is_some());
    assert!(!out.join("particles.parquet").exists());
    // The result line says why; a finite last state is kept for looking at, labelled diverged.
    let line = String::from_utf8_lossy(&o.stdout);
    let kind = run["report"]["divergence"]["reason"]["kind"]
        .as_str()
        .unwrap();
    assert!(
        line.contains("diverged (") && line.contains("at step"),
        "{line}"
    );
    assert_eq!(
        out.join("last_state.parquet").exists(),
        kind != "non-finite",
        "{kind}"
    );
    assert!(run["host"].as_str().is_some_and(|h| !h.is_empty()));
    assert!(
        run["finished_utc"]
            .as_str()
            .is_some_and(|t| t.ends_with('Z'))
    );
    assert_eq!(run["build_id"].as_str().map(str::len), Some(16));
}

#[test]
fn a_bad_set_value_names_the_flag() {
    let tmp = tempfile::tempdir().unwrap();
    let o = drapelab()
        .arg("simulate")
        .arg(root().join("datasets/scenes/hang4.toml"))
        .arg("--out")
        .arg(tmp.path().join("out"))
        .args(["--set", "cloth.nx=1"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "{err}");
    assert!(
        lines[0].contains("--set cloth.nx=1") && lines[0].contains("cloth.nx"),
        "{err}"
    );
    assert!(!tmp.path().join("out").exists());
}

#[test]
fn a_grid_override_moves_index_pins_to_the_same_material_points() {
    // The rod scene pins particles by index on its 33 × 33 grid; on 17 × 17 (and 65 × 65) they must
    // stay at the same points of the sheet, not at the old indices.
    let path = root().join("datasets/scenes/rod_polyester.toml");
    let base = drapelab::scene::Scene::load(&path, &[]).unwrap().scene;
    let at = |s: &drapelab::scene::Scene, p: [usize; 2]| {
        (
            p[0] as f64 / (s.cloth.nx - 1) as f64 * s.cloth.size_x_m,
            p[1] as f64 / (s.cloth.ny - 1) as f64 * s.cloth.size_y_m,
        )
    };
    for n in [17i64, 65] {
        let sets = [
            ("cloth.nx".to_string(), toml::Value::Integer(n)),
            ("cloth.ny".to_string(), toml::Value::Integer(n)),
        ];
        let s = drapelab::scene::Scene::load(&path, &sets).unwrap().scene;
        assert_eq!(s.cloth.nx, n as usize);
        assert_eq!(
            s.boundary.pin_particles.len(),
            base.boundary.pin_particles.len()
        );
        for (a, b) in base
            .boundary
            .pin_particles
            .iter()
            .zip(&s.boundary.pin_particles)
        {
            let (pa, pb) = (at(&base, *a), at(&s, *b));
            assert!(
                (pa.0 - pb.0).abs() < 1e-12 && (pa.1 - pb.1).abs() < 1e-12,
                "n = {n}: pin {a:?} → {b:?}"
            );
        }
    }
    // Pins given with the grid override are taken as indices of the new grid.
    let sets = [
        ("cloth.nx".to_string(), toml::Value::Integer(17)),
        ("cloth.ny".to_string(), toml::Value::Integer(17)),
        (
            "boundary.pin_particles".to_string(),
            toml::Value::Array(vec![toml::Value::Array(vec![
                toml::Value::Integer(3),
                toml::Value::Integer(5),
            ])]),
        ),
    ];
    let s = drapelab::scene::Scene::load(&path, &sets).unwrap().scene;
    assert_eq!(s.boundary.pin_particles, vec![[3, 5]]);
}

#[test]
fn drapelab_tables_lists_the_documented_columns() {
    let out = drapelab().arg("tables").output().expect("run");
    assert!(out.status.success());
    let listing = String::from_utf8(out.stdout).expect("utf-8");
    for (file, column) in [
        ("particles.parquet", "`z_m` | Float64 | no"),
        ("bench.parquet", "`error_m` | Float64 | yes"),
        ("results.parquet", "`topology` | Utf8 | no"),
        ("sweep.parquet", "`max_residual_N` | Float64 | yes"),
        ("wrinkles.parquet", "`converged` | Boolean | no"),
    ] {
        let section = listing
            .split("#### ")
            .find(|s| s.starts_with(&format!("`{file}`")) && s.contains(column));
        assert!(section.is_some(), "{file}: no column {column}");
    }
}

#[test]
fn a_missing_argument_is_named_on_the_one_line() {
    for (args, names) in [
        (vec!["simulate"], vec!["<SCENE>", "--out"]),
        (vec!["simulate", "x.toml"], vec!["--out"]),
        (vec!["run"], vec!["<PIPELINE>"]),
    ] {
        crate::support::assert_bad_input(&args, &names);
    }
}

#[test]
fn the_result_line_is_on_stdout_and_quiet_means_errors_only() {
    let tmp = tempfile::tempdir().unwrap();
    let scene = root().join("datasets/scenes/hang4.toml");
    let run = |extra: &[&str], out: &str| {
        drapelab()
            .args(extra)
            .arg("simulate")
            .arg(&scene)
            .arg("--out")
            .arg(tmp.path().join(out))
            .output()
            .unwrap()
    };
    let o = run(&[], "a");
    assert!(o.status.success());
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("hang4: converged by"), "stdout: {stdout}");
    let o = run(&["-q"], "b");
    assert!(o.status.success());
    assert!(o.stdout.is_empty() && o.stderr.is_empty(), "{o:?}");
    assert!(tmp.path().join("b/particles.parquet").exists());
    // Errors still reach stderr with -q.
    let o = drapelab()
        .args(["-q", "simulate", "missing.toml", "--out"])
        .arg(tmp.path().join("c"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(!o.stderr.is_empty());
}

#[test]
fn a_sheet_with_nothing_free_is_bad_input_and_leaves_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("o");
    let scene = root().join("datasets/scenes/hang4.toml");
    crate::support::assert_bad_input(
        [
            "simulate",
            scene.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--set",
            "cloth.nx=2",
            "--set",
            "cloth.ny=2",
        ],
        &["hang4.toml", "boundary", "no free particle"],
    );
    assert!(!out.exists());
}

#[test]
fn every_physical_number_out_of_range_is_refused_naming_its_key() {
    // A property test over the bundled scenes: each continuous key set to a value no fabric has
    // (infinite, NaN, ±1e300, 1e-300) is refused naming that key; through the command line it is
    // exit 2 with one line and nothing written, for a sample of them.
    use drapelab::params::{continuous_keys, with_value};
    use drapelab::scene::Scene;
    let bad = [f64::NAN, f64::INFINITY, 1e300, -1e300, 1e-300];
    let mut refused = 0;
    let mut sample = Vec::new();
    let dir = root().join("datasets/scenes");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    for file in &files {
        let scene = Scene::load(file, &[]).unwrap().scene.into_inner();
        for key in continuous_keys(&scene) {
            for v in bad {
                match with_value(&scene, &key, v, "mutated") {
                    Ok(_) => panic!("{}: {key} = {v} was accepted", file.display()),
                    Err(e) => {
                        assert_eq!(e.key, named(&key), "{}: {key} = {v}: {e}", file.display())
                    }
                }
                refused += 1;
            }
            if sample.len() < 12 && refused % 37 == 0 {
                sample.push((file.clone(), key.clone()));
            }
        }
    }
    assert!(refused > 500, "{refused}");
    let tmp = tempfile::tempdir().unwrap();
    for (k, (file, key)) in sample.iter().enumerate() {
        let out = tmp.path().join(format!("o{k}"));
        crate::support::assert_bad_input(
            [
                Path::new("simulate"),
                file,
                Path::new("--out"),
                &out,
                Path::new("--set"),
                Path::new(&format!("{key}=1e300")),
            ],
            &[named(key).as_str()],
        );
        assert!(!out.exists(), "{key}: a refused run left {}", out.display());
    }
}

/// A dotted `--set` key as scene errors name it: the same spelling (`loads.0.magnitude_N`), a list
/// of numbers as a whole (`cloth.origin_m.1` → `cloth.origin_m`).
fn named(key: &str) -> String {
    let parts: Vec<&str> = key.split('.').collect();
    let numeric = |p: &str| p.parse::<usize>().is_ok();
    let mut out: Vec<&str> = Vec::new();
    for (k, p) in parts.iter().enumerate() {
        if numeric(p) && parts.get(k + 1).is_none_or(|n| numeric(n)) {
            break;
        }
        out.push(p);
    }
    out.join(".")
}

#[test]
fn verbose_simulate_logs_the_iterations_and_the_work() {
    let tmp = tempfile::tempdir().unwrap();
    let scene = root().join("datasets/scenes/hang4.toml");
    let run = |flags: &[&str], out: &str| {
        let o = drapelab()
            .args(flags)
            .arg("simulate")
            .arg(&scene)
            .arg("--out")
            .arg(tmp.path().join(out))
            .env_remove("RUST_LOG")
            .output()
            .unwrap();
        assert!(o.status.success());
        String::from_utf8_lossy(&o.stderr).to_string()
    };
    let (plain, v, vv) = (run(&[], "a"), run(&["-v"], "b"), run(&["-vv"], "c"));
    let steps = |s: &str| {
        s.lines()
            .filter(|l| l.contains("residual") && l.contains("step "))
            .count()
    };
    assert_eq!(steps(&plain), 0, "{plain}");
    assert!(v.contains("step 0:") && v.contains("factorizations"), "{v}");
    // hang4 converges in 11 iterations: -v logs steps 0 and 10, -vv every one.
    assert_eq!(steps(&v), 2, "{v}");
    assert!(steps(&vv) >= 11, "{vv}");
}

/// Issue 52: the solver options are checked beside their types (`StaticOptions::check`,
/// `DynamicOptions::check`), the ones that were never checked included; each bad value exits 2
/// naming the file and its key.
#[test]
fn every_solver_option_is_checked_and_a_bad_one_names_its_key() {
    for (set, key) in [
        (
            "solver.static.shift_max_rel=0",
            "solver.static.shift_max_rel",
        ),
        (
            "solver.static.max_iterations=0",
            "solver.static.max_iterations",
        ),
        ("solver.static.load_steps=0", "solver.static.load_steps"),
        (
            "solver.static.residual_tol_rel=1e300",
            "solver.static.residual_tol_rel",
        ),
        (
            "solver.dynamic.residual_tol_rel=1",
            "solver.dynamic.residual_tol_rel",
        ),
        ("solver.dynamic.min_dt_s=200", "solver.dynamic.min_dt_s"),
        (
            "solver.dynamic.newton_iterations=0",
            "solver.dynamic.newton_iterations",
        ),
        (
            "solver.dynamic.rayleigh_mass_per_s=-1",
            "solver.dynamic.rayleigh_mass_per_s",
        ),
        (
            "solver.dynamic.rayleigh_stiffness_s=nan",
            "solver.dynamic.rayleigh_stiffness_s",
        ),
        ("solver.dynamic.max_dt_s=0", "solver.dynamic.max_dt_s"),
        ("solver.dynamic.check_every=0", "solver.dynamic.check_every"),
        (
            "solver.dynamic.auto_dt_fraction=200",
            "solver.dynamic.auto_dt_fraction",
        ),
    ] {
        assert_bad(Some(&hang4()), &["--set", set], key);
    }
}

/// A grid sheet without `cloth.nx` is refused naming the key and saying it is missing (it said
/// "got 0"), one line, exit 2, nothing written.
#[test]
fn a_missing_grid_count_is_named_as_missing() {
    let text: String = hang4()
        .lines()
        .filter(|l| !l.trim_start().starts_with("nx"))
        .map(|l| format!("{l}\n"))
        .collect();
    assert_bad(Some(&text), &[], "cloth.nx");
    let (_, err, _, _) = simulate_text(Some(&text), &[]);
    assert!(err.contains("missing") && !err.contains("got 0"), "{err}");
}
