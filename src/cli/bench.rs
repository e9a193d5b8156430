//! `drapelab bench`: prints the engine benchmark table (see [`crate::benchmark`]).

use crate::benchmark::{hang4_rows, markdown_table};
use crate::scene::Scene;
use anyhow::Result;
use std::path::Path;

/// Runs the hang4 benchmark and prints its Markdown table to stdout.
pub fn run_bench(
    scene: &Path,
    sizes: &[usize],
    max_explicit_size: usize,
    max_implicit_size: usize,
    tol: f64,
) -> Result<()> {
    let loaded = Scene::load(scene, &[])?;
    let rows = hang4_rows(
        &loaded.scene,
        sizes,
        max_explicit_size,
        max_implicit_size,
        tol,
        |msg| eprintln!("{msg}"),
    );
    println!("{}", markdown_table(&rows));
    Ok(())
}
