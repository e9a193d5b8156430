//! The command line: clap arguments become one validated configuration, once (ripgrep's habit);
//! [`run`] returns the process exit code.

mod bench;
mod progress;

pub use progress::SolveProgress;

use crate::error::{EXIT_FAILED, EXIT_OK, InputError};
use crate::scene::{Scene, parse_override};
use anyhow::Result;
use clap::{Parser, Subcommand};
use std::path::PathBuf;

/// drapelab: simulate how fabric drapes, measure drape, calibrate and validate models, record every run.
///
/// Units are SI inside and named in every key (`stiffness_N_per_m`, `x_m`). Exit codes: 0 success,
/// 1 a solve or stage failed (its status is written into the outputs), 2 bad input.
#[derive(Debug, Parser)]
#[command(name = "drapelab", version, about, long_about)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

/// Subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Solve one scene (TOML) and write particles.parquet, run.json and, when the scene's [record]
    /// asks, timeline.mcap (Foxglove) and drape.rrd (rerun) into DIR.
    ///
    /// Example: drapelab simulate datasets/scenes/hang4.toml --out runs/hang4 --set cloth.nx=41 --set cloth.ny=41
    Simulate {
        /// The scene file, e.g. datasets/scenes/hang4.toml.
        scene: PathBuf,
        /// Output folder (created; files are written atomically).
        #[arg(long)]
        out: PathBuf,
        /// Override any scene key by its dotted path, e.g. --set cloth.nx=41 --set solver.kind=implicit-euler
        /// --set record.timeline=true. Repeatable.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
    },
    /// Run a pipeline make-style: only stale stages run (inputs' content, parameters or the drapelab
    /// version changed since the stage's manifest), items in parallel, artifacts under runs/<pipeline>/.
    ///
    /// Example: drapelab run pipelines/main.toml --jobs 2
    Run {
        /// The pipeline file, e.g. pipelines/main.toml.
        pipeline: PathBuf,
        /// Run only this stage and the stages it depends on.
        #[arg(long, value_name = "STAGE")]
        until: Option<String>,
        /// Rerun this stage and everything downstream of it even if up to date. Repeatable.
        #[arg(long, value_name = "STAGE")]
        force: Vec<String>,
        /// Threads for the items of a stage (0 = all cores).
        #[arg(long, default_value_t = 0)]
        jobs: usize,
        /// Print what would run and why; run nothing.
        #[arg(long)]
        dry_run: bool,
    },
    /// List each stage of a pipeline as up to date or stale, and why (which input or parameter changed).
    Status {
        /// The pipeline file.
        pipeline: PathBuf,
    },
    /// Benchmark: time to equilibrium of hang4 at several resolutions with every solver, and each
    /// result's distance to the finest static solution. Prints a Markdown table.
    Bench {
        /// The hang4 scene to benchmark.
        #[arg(long, default_value = "datasets/scenes/hang4.toml")]
        scene: PathBuf,
        /// Particles per side to run (comma-separated).
        #[arg(long, value_delimiter = ',', default_value = "11,21,41,81")]
        sizes: Vec<usize>,
        /// Largest size at which the explicit and symplectic integrators are run (they are slow).
        #[arg(long, default_value_t = 21)]
        max_explicit_size: usize,
        /// Largest size at which implicit Euler is run.
        #[arg(long, default_value_t = 41)]
        max_implicit_size: usize,
        /// Force tolerance of every solver, relative to the lightest particle's weight.
        #[arg(long, default_value_t = 1e-6)]
        tol: f64,
    },
}

/// Runs the parsed command line; returns the exit code.
pub fn run(cli: Cli) -> Result<i32> {
    match cli.command {
        Command::Simulate { scene, out, set } => {
            let overrides = set
                .iter()
                .map(|s| parse_override(s))
                .collect::<Result<Vec<_>, InputError>>()?;
            let loaded = Scene::load(&scene, &overrides)?;
            let mut progress = SolveProgress::new(&loaded.scene.name);
            let report = crate::simulate::simulate_to_dir(&loaded, &out, &mut progress)?;
            progress.finish(&report);
            eprintln!(
                "{}: {} by {} in {} iterations, largest residual {:.3e} N ({:.2e} of a particle's weight), {:.3} s → {}",
                loaded.scene.name,
                report.status.as_str(),
                report.solver,
                report.iterations,
                report.max_residual_N,
                report.max_residual_rel,
                report.wall_time_s,
                out.display()
            );
            Ok(if report.is_converged() {
                EXIT_OK
            } else {
                EXIT_FAILED
            })
        }
        Command::Run {
            pipeline,
            until,
            force,
            jobs,
            dry_run,
        } => {
            let plan = crate::pipeline::load_plan(&pipeline)?;
            let progress = crate::pipeline::progress_for_terminal();
            let opts = crate::pipeline::RunOptions {
                until,
                force,
                jobs,
                dry_run,
            };
            let summary = crate::pipeline::run_pipeline(&plan, &opts, progress.as_ref())?;
            for (name, why) in &summary.would_run {
                println!("would run {name}: {why}");
            }
            eprintln!(
                "{}: {} ran, {} up to date, {} failed{}",
                plan.name,
                summary.ran.len(),
                summary.skipped.len(),
                summary.failed.len(),
                if opts.dry_run { " (dry run)" } else { "" }
            );
            for (name, why) in &summary.failed {
                eprintln!("  {name}: {why}");
            }
            Ok(if summary.failed.is_empty() {
                EXIT_OK
            } else {
                EXIT_FAILED
            })
        }
        Command::Status { pipeline } => {
            let plan = crate::pipeline::load_plan(&pipeline)?;
            for (name, state) in crate::pipeline::stage_states(&plan) {
                match state {
                    crate::pipeline::StageState::UpToDate => println!("{name}: up to date"),
                    crate::pipeline::StageState::Stale(why) => println!("{name}: stale ({why})"),
                }
            }
            Ok(EXIT_OK)
        }
        Command::Bench {
            scene,
            sizes,
            max_explicit_size,
            max_implicit_size,
            tol,
        } => {
            bench::run_bench(&scene, &sizes, max_explicit_size, max_implicit_size, tol)?;
            Ok(EXIT_OK)
        }
    }
}
