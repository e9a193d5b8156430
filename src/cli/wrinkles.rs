//! `drapelab wrinkles`: seed 002's tension-field wrinkles of every case of a config.

use super::args;
use crate::error::{EXIT_FAILED, EXIT_OK};
use anyhow::Result;
use std::path::{Path, PathBuf};

/// The flags of `drapelab wrinkles`.
#[derive(Debug, clap::Args)]
pub struct WrinklesArgs {
    /// The cases, e.g. datasets/wrinkles/seed_tables.toml.
    pub config: PathBuf,
    /// Output folder (created; files are written atomically).
    #[arg(long)]
    pub out: PathBuf,
    /// Points per row and rows of the deformed grid.
    #[arg(long, num_args = 2, value_names = ["NX", "NY"], default_values_t = [41, 81], value_parser = args::mesh_side())]
    pub mesh: Vec<usize>,
}

/// `drapelab wrinkles`.
pub fn run(a: WrinklesArgs) -> Result<i32> {
    wrinkles(&a.config, &a.out, &a.mesh)
}

/// `drapelab wrinkles`.
fn wrinkles(config: &Path, out: &Path, mesh: &[usize]) -> Result<i32> {
    let cfg = crate::wrinkles::load_config(config)?;
    let _out = args::out_dir(out)?;
    let outputs = crate::app::wrinkles::WrinkleOutputs {
        table: Some(out.join("wrinkles.parquet")),
        mesh: Some(out.join("mesh.parquet")),
        recording: Some(out.join("wrinkles.rrd")),
        markdown: Some(out.join("wrinkles.md")),
    };
    let params = crate::app::wrinkles::WrinklesParams {
        mesh_nx: mesh[0],
        mesh_ny: mesh[1],
    };
    let solved = crate::app::wrinkles::write_wrinkles(&cfg, &outputs, &params)?;
    print!("{}", crate::app::wrinkles::report_markdown(&cfg, &solved));
    Ok(if solved.iter().all(|s| s.result.converged) {
        EXIT_OK
    } else {
        EXIT_FAILED
    })
}
