//! `drapelab bench`: prints the engine benchmark table (see [`crate::benchmark`]).

use crate::benchmark::{hang4_rows, markdown_table, population_table, slack_net_population};
use crate::scene::Scene;
use anyhow::Result;
use std::path::Path;

/// Runs the hang4 benchmark and prints its Markdown table to stdout, then the iterations and
/// factorizations per solve of `population` solves of seed 000's slack net.
pub fn run_bench(
    scene: &Path,
    sizes: &[usize],
    (max_explicit_size, max_implicit_size): (usize, usize),
    tol: f64,
    population: usize,
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
    if population > 0 {
        let rows = slack_net_population(&loaded.scene, population, 8);
        println!(
            "\nSeed 000's slack net (14 × 14, Table 3's box), static solves from the sagged start:\n\n{}",
            population_table(&rows)
        );
        let (rows, lattice_s) =
            crate::benchmark::warm_start_population(&loaded.scene, population, 9);
        println!(
            "\nThe same net as a calibration solves it, from its warm-start lattice's nearest drape \
(the lattice itself: {lattice_s:.2} s):\n\n{}",
            population_table(&rows)
        );
    }
    Ok(())
}
