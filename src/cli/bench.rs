//! `drapelab bench`: prints the engine benchmark table (see [`crate::benchmark`]).

use super::args;
use crate::benchmark::{hang4_rows, markdown_table, population_table, slack_net_population};
use crate::error::EXIT_OK;
use crate::scene::Scene;
use anyhow::Result;
use std::path::{Path, PathBuf};

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

/// The flags of `drapelab bench`.
#[derive(Debug, clap::Args)]
pub struct BenchArgs {
    /// The hang4 scene to benchmark.
    #[arg(long, default_value = "datasets/scenes/hang4.toml")]
    pub scene: PathBuf,
    /// Particles per side to run (comma-separated, each 3..=1001).
    #[arg(long, value_delimiter = ',', default_value = "11,21,41,81", value_parser = args::grid_side())]
    pub sizes: Vec<usize>,
    /// Largest size at which the explicit and symplectic integrators are run (they are slow).
    #[arg(long, default_value_t = 21)]
    pub max_explicit_size: usize,
    /// Largest size at which implicit Euler is run.
    #[arg(long, default_value_t = 41)]
    pub max_implicit_size: usize,
    /// Force tolerance of every solver, relative to the lightest particle's weight (> 0).
    #[arg(long, default_value_t = 1e-6, value_parser = args::positive)]
    pub tol: f64,
    /// Static solves of seed 000's slack-net population (14 × 14 over Table 3's box) to run
    /// after the hang4 table, for its iterations and factorizations per solve (0: none).
    #[arg(long, default_value_t = 50)]
    pub population: usize,
    /// Run the whole benchmark pipeline instead (pipelines/benchmark.toml: every reference scene,
    /// solver, size and tolerance, the scipy/numpy peers, the skips, reports/benchmark.md; only
    /// stale stages run).
    #[arg(long)]
    pub all: bool,
}

/// `drapelab bench`: the hang4 table, or the whole benchmark pipeline with `--all`.
pub fn run(a: BenchArgs) -> Result<i32> {
    if a.all {
        return super::pipeline::run_pipeline_command(
            Path::new("pipelines/benchmark.toml"),
            false,
            Default::default(),
        );
    }
    run_bench(
        &a.scene,
        &a.sizes,
        (a.max_explicit_size, a.max_implicit_size),
        a.tol,
        a.population,
    )?;
    Ok(EXIT_OK)
}
