//! `wrinkles`: seed 002's tension-field wrinkles for every case of a config (`drapelab wrinkles` and the
//! pipeline stage kind). Outputs: `wrinkles.parquet` (one row per case), the deformed grids as a
//! Parquet table, a `.rrd` (each grid as a rerun mesh) and a `.md` report with the seed's results
//! beside drapelab's.

pub mod full;
pub mod params;
pub mod points;
pub mod tables;

use crate::job::Job;
use anyhow::Result;
use drapelab_core::wrinkles::{
    WrinkleConfig, WrinkleMesh, WrinkleResult, load_config, solve, wrinkle_mesh,
};
use drapelab_record::{Table, write_text};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Parameters of a wrinkles stage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WrinklesParams {
    /// Points per row of the deformed grid. Default 41.
    #[serde(default = "default_nx")]
    pub mesh_nx: usize,
    /// Rows of the deformed grid. Default 81.
    #[serde(default = "default_ny")]
    pub mesh_ny: usize,
}

/// Default of `mesh_nx`: 41 points per row.
pub fn default_nx() -> usize {
    41
}
/// Default of `mesh_ny`.
pub fn default_ny() -> usize {
    81
}

impl Default for WrinklesParams {
    fn default() -> Self {
        Self {
            mesh_nx: default_nx(),
            mesh_ny: default_ny(),
        }
    }
}

/// One solved case.
pub struct SolvedCase {
    /// Index in the config.
    pub index: usize,
    /// The solver's result.
    pub result: WrinkleResult,
}

/// Where the outputs of [`write_wrinkles`] go; each is optional.
#[derive(Debug, Clone, Default)]
pub struct WrinkleOutputs {
    /// One row per case (Parquet).
    pub table: Option<PathBuf>,
    /// The deformed grids (Parquet).
    pub mesh: Option<PathBuf>,
    /// Each grid as a rerun mesh (.rrd).
    pub recording: Option<PathBuf>,
    /// The Markdown report.
    pub markdown: Option<PathBuf>,
}

/// Solves every case of `cfg` (in parallel) and writes the outputs asked for.
pub fn write_wrinkles(
    cfg: &WrinkleConfig,
    outputs: &WrinkleOutputs,
    p: &WrinklesParams,
) -> Result<Vec<SolvedCase>> {
    let solved: Vec<SolvedCase> = cfg
        .cases
        .par_iter()
        .enumerate()
        .map(|(index, c)| SolvedCase {
            index,
            result: solve(&c.inputs(&cfg.defaults)),
        })
        .collect();
    if let Some(out) = &outputs.mesh {
        write_mesh(out, cfg, &solved, p)?;
    }
    if let Some(out) = &outputs.table {
        write_table(out, cfg, &solved)?;
    }
    if let Some(out) = &outputs.recording {
        write_rrd(out, cfg, &solved, p)?;
    }
    if let Some(out) = &outputs.markdown {
        let body = report_markdown(cfg, &solved);
        write_text(out, &format!("{REPORT_HEAD}{body}{REPORT_TAIL}"))?;
    }
    Ok(solved)
}

/// One seed 002 case: its inputs and the tension-field solution (Eqs. 5–7).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct WrinkleRow {
    /// Case name.
    pub case: String,
    /// Horizontal length of the sheet L, m.
    pub length_m: f64,
    /// Height of the sheet h, m.
    pub height_m: f64,
    /// Thickness t, m.
    pub thickness_m: f64,
    /// Young's modulus E, Pa.
    pub youngs_modulus_Pa: f64,
    /// Poisson's ratio ν.
    pub poisson_ratio: f64,
    /// Weight per area w, N/m².
    pub weight_N_per_m2: f64,
    /// Inward displacement d of each support, m.
    pub support_displacement_m: f64,
    /// Load constant c of Eq. 7.
    pub buckling_constant: f64,
    /// The fabric's bending length of Eq. 7, m (none: the seed's plate reading, E t³).
    pub bending_length_m: Option<f64>,
    /// Number of wrinkles.
    pub n: u32,
    /// Ratio of consecutive amplitudes (Eq. 5).
    pub q: f64,
    /// Critical ratio (Eq. 7).
    pub q_critical: f64,
    /// Largest out-of-plane displacement, cm.
    pub zmax_cm: f64,
    /// Iterations made.
    pub iterations: u64,
    /// Whether |L' − L| ≤ tolerance · L with n settled.
    pub converged: bool,
    /// Relative tolerance on L' against L.
    pub tolerance_rel: f64,
    /// |L' − L| / L at the last iteration.
    pub length_error_rel: f64,
    /// Why the iteration ended.
    pub message: String,
}

impl Table for WrinkleRow {
    const FILE: &'static str = "wrinkles.parquet";
    const ROW: &'static str =
        "One hung sheet of seed 002: inputs, wrinkle count and amplitudes' ratio.";
}

/// One point of a case's wrinkled surface (seed 002 Eq. 4 on a grid).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct WrinkleMeshRow {
    /// Case name.
    pub case: String,
    /// Grid column.
    pub column: u32,
    /// Grid row.
    pub row: u32,
    /// Horizontal position, m.
    pub x_m: f64,
    /// Depth below the top edge, m.
    pub y_down_m: f64,
    /// Out-of-plane displacement, m.
    pub z_out_of_plane_m: f64,
}

impl Table for WrinkleMeshRow {
    const FILE: &'static str = "mesh.parquet";
    const ROW: &'static str = "One grid point of a seed 002 case's wrinkled surface.";
}

/// Writes `wrinkles.parquet`: one row per solved case.
pub fn write_table(out: &Path, cfg: &WrinkleConfig, solved: &[SolvedCase]) -> Result<()> {
    let rows: Vec<WrinkleRow> = solved
        .iter()
        .map(|s| {
            let c = &cfg.cases[s.index];
            let i = c.inputs(&cfg.defaults);
            let r = &s.result;
            WrinkleRow {
                case: c.case.clone(),
                length_m: i.length_m,
                height_m: i.height_m,
                thickness_m: i.thickness_m,
                youngs_modulus_Pa: i.youngs_modulus_Pa,
                poisson_ratio: i.poisson_ratio,
                weight_N_per_m2: i.weight_N_per_m2,
                support_displacement_m: i.support_displacement_m,
                buckling_constant: i.buckling_constant,
                bending_length_m: i.bending_length_m,
                n: r.n as u32,
                q: r.q,
                q_critical: r.q_critical,
                zmax_cm: 100.0 * r.zmax_m,
                iterations: r.iterations as u64,
                converged: r.converged,
                tolerance_rel: i.tolerance_rel,
                length_error_rel: r.length_error_rel,
                message: r.message.clone(),
            }
        })
        .collect();
    drapelab_record::write_table(out, &rows)
}

/// Writes `mesh.parquet`: each case's wrinkled surface on a grid.
pub fn write_mesh(
    out: &Path,
    cfg: &WrinkleConfig,
    solved: &[SolvedCase],
    p: &WrinklesParams,
) -> Result<()> {
    let mut rows = Vec::new();
    for s in solved {
        let c = &cfg.cases[s.index];
        let m = wrinkle_mesh(&c.inputs(&cfg.defaults), &s.result, p.mesh_nx, p.mesh_ny);
        rows.extend(m.points.iter().enumerate().map(|(k, pt)| WrinkleMeshRow {
            case: c.case.clone(),
            column: (k % m.nx) as u32,
            row: (k / m.nx) as u32,
            x_m: pt[0],
            y_down_m: pt[1],
            z_out_of_plane_m: pt[2],
        }));
    }
    drapelab_record::write_table(out, &rows)
}

/// Each case's deformed grid as a rerun mesh at `cases/NAME/mesh` (z up: (x, z_out, −y_down)).
pub fn write_rrd(
    out: &Path,
    cfg: &WrinkleConfig,
    solved: &[SolvedCase],
    p: &WrinklesParams,
) -> Result<()> {
    let meshes: Vec<(String, WrinkleMesh)> = solved
        .iter()
        .map(|s| {
            let c = &cfg.cases[s.index];
            (
                c.case.clone(),
                wrinkle_mesh(&c.inputs(&cfg.defaults), &s.result, p.mesh_nx, p.mesh_ny),
            )
        })
        .collect();
    drapelab_record::write_wrinkle_meshes(out, &meshes)
}

/// The head of the tension-field report.
pub const REPORT_HEAD: &str = "# Tension-field wrinkles (seed 002, Tables I–IV)\n\nMade by the `wrinkles` stage \
(`drapelab wrinkles datasets/wrinkles/seed_tables.toml --out DIR` gives the same). drapelab's values first, \
the seed's in brackets; Q_c is the critical ratio of Eq. 7, Q = (a₀/a_n)^(1/n) the ratio of Eq. 5 after \
rounding n; L error is |L' − L|/L at convergence (tolerance 5 %, the seed's).\n\n";

/// The tail of the tension-field report: where drapelab and the seed differ.
pub const REPORT_TAIL: &str = "\n## Where drapelab and the seed differ, and why\n\n\
- Read as the seed's plate with c = 135, the trends agree (n grows with h and w and falls with t and E; Q \
falls with w and rises with t), the numbers only roughly (z_max within a factor of 1.5 where both have wrinkles; n off by up to a factor of 2).\n\
- The seed's equations are garbled in its text and it gives neither Poisson's ratio nor the load constant c \
of Eq. 7: drapelab reads Eq. 7 as plate buckling, σ_c = c E t²/(l²(1 − ν²)), with ν = 0.3 and c = 135 \
chosen so that Table I's middle row has the seed's Q = 1.29. The bundled config reads it for a fabric \
instead (`bending_length_m`: E t³/(1 − ν²) becomes 12 w c_b³, c = 7197, the reading that full simulations of \
the sheets as fabric support: reports/wrinkles.md); then s = 12 c c_b³/(h l²) no longer depends on w, t or \
E, and n rises with h alone.\n\
- With the plate's reading Q_c depends on t³ E/(w h): Table III's thickness range (0.09–0.40 mm, a factor of 88 \
in t³) spans Q_c from 1.08 to no wrinkling at all (s ≥ 1 at 0.40 mm), where the seed, whose Q moves only \
from 1.33 to 2.60, still finds 2 wrinkles. The seed's own Q values do not follow any single power of t, E, \
w or h (Table I's Q is not even monotone in h), so no choice of c reproduces all twelve cases: its Q \
evidently carries the rounding of n and iteration details that the text does not give.\n\
- The reading of Eqs. 8 and 9 (the upper boundary takes up the length L − l; the centre fibre keeps the \
height h across n strips, with a₀ = h) is stated in `crates/core/src/wrinkles/mod.rs`; the seed's a₀ = 1.0h and \
a_n = 0.01h start values and z_max = 0.014 m tentative value are used as given.\n";

/// The seed's n, z_max and Q beside drapelab's, with the deviations.
pub fn report_markdown(cfg: &WrinkleConfig, solved: &[SolvedCase]) -> String {
    let mut s = String::from(
        "| case | n (seed) | z_max cm (seed) | Q (seed) | Q_c (Eq. 7) | iterations | converged | L error % |\n|---|---|---|---|---|---|---|---|\n",
    );
    for r in solved {
        let c = &cfg.cases[r.index];
        let seed = |f: &dyn Fn(&drapelab_core::wrinkles::SeedResult) -> String| {
            c.seed.as_ref().map(f).unwrap_or_else(|| "–".into())
        };
        s += &format!(
            "| {} | {} ({}) | {:.2} ({}) | {:.2} ({}) | {:.3} | {} | {} | {:.2} |\n",
            c.case,
            r.result.n,
            seed(&|x| x.n.to_string()),
            100.0 * r.result.zmax_m,
            seed(&|x| x.zmax_cm.map_or("–".into(), |z| format!("{z:.2}"))),
            r.result.q,
            seed(&|x| x.q.map_or("–".into(), |q| format!("{q:.2}"))),
            r.result.q_critical,
            r.result.iterations,
            if r.result.converged { "yes" } else { "no" },
            100.0 * r.result.length_error_rel,
        );
    }
    s
}

/// The input of a wrinkles stage.
pub struct WrinklesInputs {
    /// The wrinkle config TOML.
    pub config: std::path::PathBuf,
}

/// The `run` of the stage kind over this workflow.
pub fn run(ctx: &Job<'_, WrinklesInputs>, p: &WrinklesParams) -> Result<Vec<SolvedCase>> {
    let cfg = load_config(&ctx.inputs.config)?;
    ctx.started(cfg.cases.len());
    let out = |slot: &str| ctx.optional_output(slot).map(Path::to_path_buf);
    let outputs = WrinkleOutputs {
        table: out("table"),
        mesh: out("mesh"),
        recording: out("recording"),
        markdown: out("markdown"),
    };
    let solved = write_wrinkles(&cfg, &outputs, p)?;
    for _ in &cfg.cases {
        ctx.item_done();
    }
    Ok(solved)
}
