//! Shared helpers: scene loading with overrides, paths, the binary, the Python of the test venv.

use drapelab::scene::{Scene, parse_override};
use std::path::{Path, PathBuf};

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
}

/// The drapelab binary built for these tests.
pub fn drapelab() -> std::process::Command {
    std::process::Command::new(env!("CARGO_BIN_EXE_drapelab"))
}

/// The Python interpreter with the readers installed (`.venv/`, made by `.ci/run`), or $DRAPELAB_PYTHON.
pub fn python() -> PathBuf {
    if let Ok(p) = std::env::var("DRAPELAB_PYTHON") {
        return PathBuf::from(p);
    }
    let venv = root().join(".venv/bin/python");
    assert!(
        venv.exists(),
        "no Python readers: run `bash .ci/run` once (it creates .venv with mcap, rerun-sdk, pyarrow, polars)"
    );
    venv
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
