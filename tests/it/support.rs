//! Shared helpers: scene loading with overrides, paths, the binary, the Python of the test venv.

use drapelab::config::parse_override;
use drapelab::scene::Scene;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The repository root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Loads a bundled scene with `--set`-style overrides.
pub fn scene(name: &str, sets: &[&str]) -> Scene {
    let overrides: Vec<_> = sets
        .iter()
        .map(|s| parse_override(s).expect("override"))
        .collect();
    Scene::load(&root().join("datasets/scenes").join(name), &overrides)
        .expect("valid scene")
        .scene
        .into_inner()
}

/// `drapelab -q simulate SCENE --out OUT EXTRA…`, asserted to exit 0 (a converged drape).
pub fn simulate_ok(scene: &Path, out: &Path, extra: &[&str]) {
    let o = drapelab()
        .args(["-q", "simulate"])
        .arg(scene)
        .arg("--out")
        .arg(out)
        .args(extra)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// A run folder's run.json, parsed.
pub fn run_json(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("run.json")).unwrap()).unwrap()
}

/// The drapelab binary built for these tests.
pub fn drapelab() -> std::process::Command {
    std::process::Command::new(env!("CARGO_BIN_EXE_drapelab"))
}

/// `drapelab simulate SCENE --out OUT` with both recordings asked (the MCAP timeline and the rerun
/// file) and `extra` arguments.
pub fn simulate_recorded(scene: &Path, out: &Path, extra: &[&str]) -> std::process::Output {
    drapelab()
        .arg("simulate")
        .arg(scene)
        .arg("--out")
        .arg(out)
        .args([
            "--set",
            "record.timeline=true",
            "--set",
            "record.rerun=true",
        ])
        .args(extra)
        .output()
        .unwrap()
}

/// The Python interpreter with the readers installed: $DRAPELAB_PYTHON, or `.venv/` in the
/// repository, created on first use from `tests/requirements.txt` (mcap, rerun-sdk, pyarrow, polars).
pub fn python() -> PathBuf {
    static PY: OnceLock<PathBuf> = OnceLock::new();
    PY.get_or_init(|| {
        if let Ok(p) = std::env::var("DRAPELAB_PYTHON") {
            return PathBuf::from(p);
        }
        let venv = root().join(".venv");
        let py = venv.join("bin/python");
        let ready = |py: &Path| {
            py.exists()
                && std::process::Command::new(py)
                    .args(["-c", "import mcap, rerun, pyarrow, polars, pygltflib"])
                    .output()
                    .is_ok_and(|o| o.status.success())
        };
        if !ready(&py) {
            let ok = std::process::Command::new("python3")
                .arg("-m")
                .arg("venv")
                .arg(&venv)
                .status()
                .is_ok_and(|s| s.success());
            assert!(
                ok,
                "python3 -m venv failed: the tests need Python 3 with venv"
            );
            let ok = std::process::Command::new(&py)
                .args([
                    "-m",
                    "pip",
                    "install",
                    "--quiet",
                    "--disable-pip-version-check",
                    "-r",
                ])
                .arg(root().join("tests/requirements.txt"))
                .status()
                .is_ok_and(|s| s.success());
            assert!(
                ok && ready(&py),
                "installing tests/requirements.txt into .venv failed"
            );
        }
        py
    })
    .clone()
}

/// Runs a Python snippet with arguments; panics with its output if it fails.
pub fn run_python(code: &str, args: &[&Path]) -> String {
    let out = std::process::Command::new(python())
        .arg("-c")
        .arg(code)
        .args(args)
        .output()
        .expect("python runs");
    let stdout = String::from_utf8_lossy(&out.stdout).to_string();
    assert!(
        out.status.success(),
        "python failed:\n{}\n{}",
        stdout,
        String::from_utf8_lossy(&out.stderr)
    );
    stdout
}

/// A temporary project holding copies of the repository files matched by `globs` (relative to the
/// root) and the pipeline text as `pipelines/<name>`; returns the folder and the pipeline file.
pub fn temp_project(globs: &[&str], name: &str, pipeline: &str) -> (tempfile::TempDir, PathBuf) {
    let tmp = tempfile::tempdir().unwrap();
    for g in globs {
        for entry in glob::glob(&root().join(g).to_string_lossy()).unwrap() {
            let src = entry.unwrap();
            let dst = tmp.path().join(src.strip_prefix(root()).unwrap());
            std::fs::create_dir_all(dst.parent().unwrap()).unwrap();
            std::fs::copy(&src, &dst).unwrap();
        }
    }
    std::fs::create_dir_all(tmp.path().join("pipelines")).unwrap();
    let file = tmp.path().join("pipelines").join(name);
    std::fs::write(&file, pipeline).unwrap();
    (tmp, file)
}

/// Runs the pipeline `file` in this process and asserts that no stage failed.
pub fn run_plan(file: &Path) -> drapelab::pipeline::RunSummary {
    let plan = drapelab::pipeline::load_plan(file, &drapelab::stages::registry()).unwrap();
    let s = drapelab::pipeline::run_pipeline(
        &plan,
        &Default::default(),
        &drapelab::pipeline::LogProgress::default(),
    )
    .unwrap();
    assert!(s.failed.is_empty(), "{:?}", s.failed);
    s
}

/// Runs drapelab with `args` and asserts bad input: exit code 2 and one line on stderr that names
/// every string of `names` (the file, the key). Returns that line.
pub fn assert_bad_input<I, S>(args: I, names: &[&str]) -> String
where
    I: IntoIterator<Item = S>,
    S: AsRef<std::ffi::OsStr>,
{
    let o = drapelab().args(args).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert_eq!(o.status.code(), Some(2), "{names:?}: {err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    for n in names {
        assert!(err.contains(n), "{n} not named: {err}");
    }
    err
}

/// `drapelab simulate SCENE --set SET` is refused as bad input in one line naming `names`.
pub fn assert_bad_set(scene: &Path, set: &str, names: &[&str]) -> String {
    let out = tempfile::tempdir().unwrap();
    let out = out.path().join("o");
    let args = [Path::new("simulate"), scene, Path::new("--out"), &out];
    let err = assert_bad_input(
        args.iter()
            .map(|p| p.as_os_str())
            .chain([std::ffi::OsStr::new("--set"), std::ffi::OsStr::new(set)]),
        names,
    );
    assert!(!out.exists(), "{set}: {} left behind", out.display());
    err
}

/// For each `(from, to, key)`: the bundled file `path` (relative to the repository) with its first
/// `from` replaced by `to`, given to `drapelab COMMAND FILE --out DIR`, is refused as bad input
/// naming `key` and the file, and leaves nothing in DIR.
pub fn assert_bad_edits(command: &str, path: &str, edits: &[(&str, &str, &str)]) {
    let base = std::fs::read_to_string(root().join(path)).unwrap();
    let name = Path::new(path)
        .file_name()
        .unwrap()
        .to_string_lossy()
        .to_string();
    for (from, to, key) in edits {
        assert!(base.contains(from), "{from}");
        let tmp = tempfile::tempdir().unwrap();
        let file = tmp.path().join(&name);
        std::fs::write(&file, base.replacen(from, to, 1)).unwrap();
        let out = tmp.path().join("out");
        let args = [Path::new(command), &file, Path::new("--out"), &out];
        assert_bad_input(args, &[key, &name]);
        let written = std::fs::read_dir(&out).map_or(0, |d| d.count());
        assert_eq!(
            written,
            0,
            "{key}: bad input left {written} files in {}",
            out.display()
        );
    }
}

/// Builds a scene's model (the builder takes only a checked scene).
pub fn built(s: &Scene) -> drapelab::build::BuiltScene {
    drapelab::build::build_scene(&s.clone().validated().expect("valid scene"))
}
