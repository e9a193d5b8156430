//! `wrinkles`: seed 002's tension-field wrinkles for every case of a config (`drapelab wrinkles` and the
//! pipeline stage kind). Outputs: `wrinkles.parquet` (one row per case), the deformed grids as a
//! Parquet table, a `.rrd` (each grid as a rerun mesh) and a `.md` report with the seed's results
//! beside drapelab's.

use anyhow::Result;
use arrow::array::{
    ArrayRef, BooleanArray, Float64Array, RecordBatch, StringArray, UInt32Array, UInt64Array,
};
use arrow::datatypes::{DataType, Field, Schema};
use drapelab_core::wrinkles::{
    WrinkleConfig, WrinkleMesh, WrinkleResult, load_config, solve, wrinkle_mesh,
};
use drapelab_pipeline::{Slot, StageContext, StageKind};
use drapelab_record::{write_parquet, write_text};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::sync::Arc;

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

fn default_nx() -> usize {
    41
}
fn default_ny() -> usize {
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

fn write_table(out: &Path, cfg: &WrinkleConfig, solved: &[SolvedCase]) -> Result<()> {
    let case = |s: &SolvedCase| &cfg.cases[s.index];
    let inp = |s: &SolvedCase| case(s).inputs(&cfg.defaults);
    let f = |g: &dyn Fn(&SolvedCase) -> f64| -> ArrayRef {
        Arc::new(Float64Array::from_iter_values(solved.iter().map(g)))
    };
    let fields = vec![
        Field::new("case", DataType::Utf8, false),
        Field::new("length_m", DataType::Float64, false),
        Field::new("height_m", DataType::Float64, false),
        Field::new("thickness_m", DataType::Float64, false),
        Field::new("youngs_modulus_Pa", DataType::Float64, false),
        Field::new("poisson_ratio", DataType::Float64, false),
        Field::new("weight_N_per_m2", DataType::Float64, false),
        Field::new("support_displacement_m", DataType::Float64, false),
        Field::new("buckling_constant", DataType::Float64, false),
        Field::new("n", DataType::UInt32, false),
        Field::new("q", DataType::Float64, false),
        Field::new("q_critical", DataType::Float64, false),
        Field::new("zmax_cm", DataType::Float64, false),
        Field::new("iterations", DataType::UInt64, false),
        Field::new("converged", DataType::Boolean, false),
        Field::new("tolerance_rel", DataType::Float64, false),
        Field::new("length_error_rel", DataType::Float64, false),
        Field::new("message", DataType::Utf8, false),
    ];
    let cols: Vec<ArrayRef> = vec![
        Arc::new(StringArray::from_iter_values(
            solved.iter().map(|s| case(s).case.clone()),
        )),
        f(&|s| inp(s).length_m),
        f(&|s| inp(s).height_m),
        f(&|s| inp(s).thickness_m),
        f(&|s| inp(s).youngs_modulus_Pa),
        f(&|s| inp(s).poisson_ratio),
        f(&|s| inp(s).weight_N_per_m2),
        f(&|s| inp(s).support_displacement_m),
        f(&|s| inp(s).buckling_constant),
        Arc::new(UInt32Array::from_iter_values(
            solved.iter().map(|s| s.result.n as u32),
        )),
        f(&|s| s.result.q),
        f(&|s| s.result.q_critical),
        f(&|s| 100.0 * s.result.zmax_m),
        Arc::new(UInt64Array::from_iter_values(
            solved.iter().map(|s| s.result.iterations as u64),
        )),
        Arc::new(BooleanArray::from(
            solved
                .iter()
                .map(|s| s.result.converged)
                .collect::<Vec<_>>(),
        )),
        f(&|s| inp(s).tolerance_rel),
        f(&|s| s.result.length_error_rel),
        Arc::new(StringArray::from_iter_values(
            solved.iter().map(|s| s.result.message.clone()),
        )),
    ];
    write_parquet(
        out,
        &RecordBatch::try_new(Arc::new(Schema::new(fields)), cols)?,
        None,
    )
}

fn write_mesh(
    out: &Path,
    cfg: &WrinkleConfig,
    solved: &[SolvedCase],
    p: &WrinklesParams,
) -> Result<()> {
    let (mut case, mut col, mut row) = (Vec::new(), Vec::new(), Vec::new());
    let (mut x, mut y, mut z) = (Vec::new(), Vec::new(), Vec::new());
    for s in solved {
        let c = &cfg.cases[s.index];
        let m = wrinkle_mesh(&c.inputs(&cfg.defaults), &s.result, p.mesh_nx, p.mesh_ny);
        for (k, pt) in m.points.iter().enumerate() {
            case.push(c.case.clone());
            col.push((k % m.nx) as u32);
            row.push((k / m.nx) as u32);
            x.push(pt[0]);
            y.push(pt[1]);
            z.push(pt[2]);
        }
    }
    let fields = vec![
        Field::new("case", DataType::Utf8, false),
        Field::new("column", DataType::UInt32, false),
        Field::new("row", DataType::UInt32, false),
        Field::new("x_m", DataType::Float64, false),
        Field::new("y_down_m", DataType::Float64, false),
        Field::new("z_out_of_plane_m", DataType::Float64, false),
    ];
    let cols: Vec<ArrayRef> = vec![
        Arc::new(StringArray::from(case)),
        Arc::new(UInt32Array::from(col)),
        Arc::new(UInt32Array::from(row)),
        Arc::new(Float64Array::from(x)),
        Arc::new(Float64Array::from(y)),
        Arc::new(Float64Array::from(z)),
    ];
    write_parquet(
        out,
        &RecordBatch::try_new(Arc::new(Schema::new(fields)), cols)?,
        None,
    )
}

/// Each case's deformed grid as a rerun mesh at `cases/NAME/mesh` (z up: (x, z_out, −y_down)).
fn write_rrd(
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

const REPORT_HEAD: &str = "# Tension-field wrinkles (seed 002, Tables I–IV)\n\nMade by the `wrinkles` stage \
(`drapelab wrinkles datasets/wrinkles/seed_tables.toml --out DIR` gives the same). drapelab's values first, \
the seed's in brackets; Q_c is the critical ratio of Eq. 7, Q = (a₀/a_n)^(1/n) the ratio of Eq. 5 after \
rounding n; L error is |L' − L|/L at convergence (tolerance 5 %, the seed's).\n\n";

const REPORT_TAIL: &str = "\n## Where drapelab and the seed differ, and why\n\n\
- The trends agree (n grows with h and w and falls with t and E; Q falls with w and rises with t), the \
numbers only roughly (z_max within a factor of 1.5 where both have wrinkles; n off by up to a factor of 2).\n\
- The seed's equations are garbled in its text and it gives neither Poisson's ratio nor the load constant c \
of Eq. 7: drapelab reads Eq. 7 as plate buckling, σ_c = c E t²/(l²(1 − ν²)), with ν = 0.3 and c = 135 \
chosen so that Table I's middle row has the seed's Q = 1.29 (datasets/wrinkles/seed_tables.toml).\n\
- With that reading Q_c depends on t³ E/(w h): Table III's thickness range (0.09–0.40 mm, a factor of 88 \
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
            seed(&|x| format!("{:.2}", x.zmax_cm)),
            r.result.q,
            seed(&|x| format!("{:.2}", x.q)),
            r.result.q_critical,
            r.result.iterations,
            if r.result.converged { "yes" } else { "no" },
            100.0 * r.result.length_error_rel,
        );
    }
    s
}

/// The `wrinkles` stage kind.
pub struct Wrinkles;

impl StageKind for Wrinkles {
    type Params = WrinklesParams;
    const KIND: &'static str = "wrinkles";
    const SUMMARY: &'static str = "Seed 002's tension-field wrinkles of every case of a config";
    const INPUTS: &'static [Slot] = &[Slot::one("config", "the wrinkle config TOML")];
    const OUTPUTS: &'static [Slot] = &[
        Slot::optional("table", "wrinkles.parquet: one row per case"),
        Slot::optional("mesh", "the deformed grids, Parquet"),
        Slot::optional("recording", "each grid as a rerun mesh, .rrd"),
        Slot::optional("markdown", "the report, .md"),
    ];
    fn run(ctx: &StageContext<'_>, p: &WrinklesParams) -> Result<()> {
        let cfg = load_config(ctx.input("config")?)?;
        ctx.progress
            .stage_started(&ctx.stage.name, cfg.cases.len() as u64);
        let out = |slot: &str| ctx.optional_output(slot).map(Path::to_path_buf);
        let outputs = WrinkleOutputs {
            table: out("table"),
            mesh: out("mesh"),
            recording: out("recording"),
            markdown: out("markdown"),
        };
        write_wrinkles(&cfg, &outputs, p)?;
        for _ in &cfg.cases {
            ctx.progress.item_done(&ctx.stage.name);
        }
        Ok(())
    }
}
