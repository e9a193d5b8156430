//! `seed003-solve`: seed 003's drape scenes, each solved at its own grid and at twice its resolution
//! (run times, grid-convergence gap, drape coefficient, folds, penetration, the drapes themselves),
//! and the studies set beside the seed's tables: the quarter table's edge points (Table 10.2), the
//! rod's corners under every contact treatment with their grid study (Table 10.4), the cantilever's
//! free end against the grid (Table 10.1) and its load–displacement curve (§10.3.3). Writes tables
//! only; the `seed003-report` stage reads them.

use crate::job::Job;
use crate::seed003::studies::{
    Solved, cantilever_rows, load, load_steps, rod_grid_rows, rod_rows, solve_pair, table_edge_rows,
};
use crate::seed003::tables::{DrapeParticleRow, Seed003SceneRow};
use anyhow::{Result, bail};
use drapelab_core::measure::drape_measures;
use drapelab_core::obstacle::Obstacle;
use drapelab_core::scene::Scene;
use drapelab_record::{Table, write_table};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// Parameters of a seed003-solve stage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Seed003SolveParams {
    /// Load increments of the cantilever's load–displacement curve. Default 50 (the seed's); more
    /// for a smoother curve.
    #[serde(default = "default_steps")]
    pub load_steps: usize,
}

impl Default for Seed003SolveParams {
    fn default() -> Self {
        Self {
            load_steps: default_steps(),
        }
    }
}

/// Default of `load_steps`: 50 load increments (the seed's).
pub fn default_steps() -> usize {
    50
}

/// The files a seed003-solve stage reads.
pub struct Seed003SolveInputs {
    /// Scene TOMLs, each solved at its grid and at twice its resolution.
    pub scenes: Vec<PathBuf>,
    /// The quarter table scene (one of `scenes`) compared with Table 10.2.
    pub quarter_table: Option<PathBuf>,
    /// Table 10.2's edge points (fvm_table_drape_edges.csv): the material points put.
    pub table_reference: Option<PathBuf>,
    /// The rod scene (one of `scenes`) compared with Table 10.4.
    pub rod: Option<PathBuf>,
    /// The cantilever of §10.3.3 and Table 10.1.
    pub cantilever: Option<PathBuf>,
}

/// A solved scene's row: its two solves and, when it converged, its drape measures.
pub fn scene_row(s: &Solved) -> Seed003SceneRow {
    let r = &s.coarse.report;
    let m = r
        .is_converged()
        .then(|| drape_measures(&s.scene, &s.coarse.x));
    Seed003SceneRow {
        scene: s.scene.name.clone(),
        nx: s.scene.cloth.nx as u32,
        ny: s.scene.cloth.ny as u32,
        contact: (!s.scene.obstacles.is_empty()).then_some(s.scene.contact.method),
        status: r.status,
        iterations: r.iterations as u64,
        wall_time_s: r.wall_time_s,
        fine_status: s.fine.report.status,
        fine_wall_time_s: s.fine.report.wall_time_s,
        grid_gap_m: s.gap_m.is_finite().then_some(s.gap_m),
        drape_coefficient_pct: m.as_ref().and_then(|m| m.drape_coefficient_pct),
        folds: m.as_ref().and_then(|m| m.folds).map(|f| f as u32),
        max_penetration_m: m.map(|m| m.max_penetration_m),
        from_above: s
            .scene
            .obstacles
            .iter()
            .any(|o| matches!(o, Obstacle::Box { .. } | Obstacle::Pedestal { .. })),
    }
}

/// A solved scene's drape at its grid, one row per particle in grid order.
pub fn drape_rows(s: &Solved) -> Vec<DrapeParticleRow> {
    let g = &s.coarse.grid;
    let present = drapelab_core::build::present_particles(&s.scene);
    s.coarse
        .grid_positions()
        .iter()
        .enumerate()
        .map(|(k, q)| {
            let (i, j) = g.ij(k);
            DrapeParticleRow {
                scene: s.scene.name.clone(),
                i: i as u32,
                j: j as u32,
                u_m: g.xs[i],
                v_m: g.ys[j],
                x_m: q.x,
                y_m: q.y,
                z_m: q.z,
                present: present.get(k).copied().unwrap_or(true),
            }
        })
        .collect()
}

/// The scene of `file` among the solved ones (by its name), if the file is given.
fn named<'s>(solved: &'s [Solved], file: &Option<PathBuf>) -> Result<Option<&'s Solved>> {
    let Some(f) = file else {
        return Ok(None);
    };
    let name = load(f)?.name;
    match solved.iter().find(|s| s.scene.name == name) {
        Some(s) => Ok(Some(s)),
        None => bail!(
            "{}: scene `{name}` is not among the stage's `scenes`",
            f.display()
        ),
    }
}

/// Computes the rows of output `slot` and writes them, when the stage has that output.
fn write_if<T: Table, I>(
    ctx: &Job<'_, I>,
    slot: &str,
    rows: impl FnOnce() -> Result<Vec<T>>,
) -> Result<()> {
    match ctx.optional_output(slot) {
        Some(path) => write_table(path, &rows()?),
        None => Ok(()),
    }
}

/// Refuses an output whose inputs are not given (it would be left unwritten): an input error naming
/// the pipeline and `stages.STAGE.outputs.NAME` (exit 2).
pub fn check_outputs(ctx: &Job<'_, Seed003SolveInputs>) -> Result<()> {
    let f = &ctx.inputs;
    let table = f.quarter_table.is_some() && f.table_reference.is_some();
    for (out, given, needs) in [
        (
            "table_edges",
            table,
            "quarter_table` and `inputs.table_reference",
        ),
        ("rod", f.rod.is_some(), "rod"),
        ("rod_grid", f.rod.is_some(), "rod"),
        ("load_displacement", f.cantilever.is_some(), "cantilever"),
        ("cantilever_grid", f.cantilever.is_some(), "cantilever"),
    ] {
        if ctx.optional_output(out).is_some() && !given {
            return Err(drapelab_core::error::InputError::new(
                ctx.root.join(&ctx.source),
                format!("stages.{}.outputs.{out}", ctx.stage),
                format!("is written only with `inputs.{needs}`: add it, or drop the output"),
            )
            .into());
        }
    }
    Ok(())
}

/// The `run` of the stage kind over this workflow.
pub fn run(ctx: &Job<'_, Seed003SolveInputs>, p: &Seed003SolveParams) -> Result<()> {
    check_outputs(ctx)?;
    let files = &ctx.inputs;
    let scenes: Vec<Scene> = files
        .scenes
        .iter()
        .map(|f| load(f))
        .collect::<Result<_>>()?;
    if scenes.is_empty() {
        bail!("input `scenes` matched no scene file");
    }
    ctx.started(scenes.len() + 1);
    let solved: Vec<Solved> = scenes
        .par_iter()
        .map(|s| {
            let r = solve_pair(s);
            ctx.item_done();
            r
        })
        .collect();
    let rows: Vec<Seed003SceneRow> = solved.iter().map(scene_row).collect();
    write_table(ctx.output("scenes")?, &rows)?;
    let drapes: Vec<DrapeParticleRow> = solved.iter().flat_map(drape_rows).collect();
    write_table(ctx.output("drapes")?, &drapes)?;
    if let (Some(q), Some(file)) = (
        named(&solved, &files.quarter_table)?,
        &files.table_reference,
    ) {
        write_if(ctx, "table_edges", || table_edge_rows(q, file))?;
    }
    if let Some(r) = named(&solved, &files.rod)? {
        write_if(ctx, "rod", || Ok(rod_rows(r)))?;
        write_if(ctx, "rod_grid", || Ok(rod_grid_rows(&r.scene)))?;
    }
    if let Some(c) = files.cantilever.as_deref().map(load).transpose()? {
        write_if(ctx, "load_displacement", || load_steps(&c, p.load_steps))?;
        write_if(ctx, "cantilever_grid", || Ok(cantilever_rows(&c)))?;
    }
    ctx.item_done();
    Ok(())
}
