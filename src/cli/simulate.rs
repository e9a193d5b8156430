//! `drapelab simulate`: solve one scene and record it (optionally from a saved drape, with
//! sensitivities and an OBJ).

use super::progress::SolveProgress;
use super::{args, load_scene};
use crate::error::{EXIT_FAILED, EXIT_OK};
use anyhow::Result;
use std::path::{Path, PathBuf};

/// The flags of `drapelab simulate`.
#[derive(Debug, clap::Args)]
pub struct SimulateArgs {
    /// The scene file, e.g. datasets/scenes/hang4.toml.
    pub scene: PathBuf,
    /// Output folder (created; files are written atomically).
    #[arg(long)]
    pub out: PathBuf,
    /// Override any scene key by its dotted path, e.g. --set cloth.nx=41 --set solver.kind=implicit-euler
    /// --set record.timeline=true. Repeatable.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Also write sensitivity.parquet: how every particle of the converged drape moves per unit
    /// of this continuous scene key (dx*/dθ = −H⁻¹ ∂g/∂θ, from the factor of the exact Hessian
    /// at the equilibrium; one back-substitution per key), e.g. --sensitivity
    /// material.mass_spring.stiffness_N_per_m. Repeatable. A state that did not converge or is
    /// no minimum gets none, and run.json says why.
    #[arg(long = "sensitivity", value_name = "KEY")]
    pub sensitivity: Vec<String>,
    /// Start the solve from a saved drape (a particles.parquet or last_state.parquet of the same
    /// scene and grid) instead of the scene's own start: a restart, which takes up what the run
    /// that wrote it adapted (the self-contact κ growth, in the file's metadata) and so continues
    /// that run: a converged drape at the same parameters comes back in 0 iterations. A table
    /// written elsewhere starts the model as built; run.json's `start` says which.
    #[arg(long, value_name = "FILE")]
    pub start: Option<PathBuf>,
    /// Drape the scene in this fabric: its material (and its areal density, where the file gives
    /// one) from a fabric file as a calibration writes it, in place of the scene's [material].
    /// The same as `[material] fabric = "FILE"` in the scene.
    #[arg(long, value_name = "FILE")]
    pub fabric: Option<PathBuf>,
    /// Also write the converged drape as drape.obj (Wavefront OBJ, metres; every particle a
    /// vertex in particles.parquet's order) for Blender, MeshLab or a CAD tool.
    /// triangles.parquet (the same faces as row indices) is written beside every state.
    #[arg(long)]
    pub obj: bool,
}

/// `drapelab simulate`.
pub fn run(a: SimulateArgs, quiet: bool) -> Result<i32> {
    simulate(
        &a.scene,
        &a.out,
        (&a.set, a.fabric.as_deref()),
        (&a.sensitivity, a.start.as_deref(), a.obj),
        quiet,
    )
}

/// `drapelab simulate`: the result line on stdout (none with `-q`).
fn simulate(
    scene: &Path,
    out: &Path,
    (set, fabric): (&[String], Option<&Path>),
    (sensitivity, start, obj): (&[String], Option<&Path>, bool),
    quiet: bool,
) -> Result<i32> {
    let loaded = match fabric {
        Some(f) => super::load_scene_in_fabric(scene, set, f)?,
        None => load_scene(scene, set)?,
    };
    crate::build::check_something_free(&loaded)?;
    for key in sensitivity {
        crate::sensitivity::check_key(&loaded.scene, key, "--sensitivity")?;
    }
    let extras = crate::io::SimulateExtras {
        sensitivity_keys: sensitivity.to_vec(),
        start: start
            .map(|f| crate::io::read_start(f, &loaded.scene, "--start"))
            .transpose()?,
        obj,
    };
    let _out = args::out_dir(out)?;
    let mut progress = SolveProgress::new(&loaded.scene.name);
    let report = crate::io::simulate_to_dir_with(&loaded, out, &mut progress, &extras)?.report;
    progress.done(&report);
    if !quiet {
        // Why a solve did not converge, on the line itself (run.json has the numbers).
        let why = match (&report.divergence, report.is_converged()) {
            (Some(d), _) => format!(" ({} at step {})", d.reason, d.step),
            (None, false) if !report.message.is_empty() => format!(" ({})", report.message),
            _ => String::new(),
        };
        println!(
            "{}: {}{why} by {} in {} iterations, largest residual {:.3e} N ({:.2e} of a particle's weight), {:.3} s → {}",
            loaded.scene.name,
            report.status.as_str(),
            report.solver.report_name(),
            report.iterations,
            report.max_residual_N,
            report.max_residual_rel,
            report.wall_time_s,
            out.display()
        );
    }
    Ok(if report.is_converged() {
        EXIT_OK
    } else {
        EXIT_FAILED
    })
}
