//! `benchmark-report`: Pareto fronts of time against error per scene, the fitted scaling exponents,
//! Newton's work, seed 000's slack-net population, the skips and the peer ratios: all from the
//! measured tables.

use crate::report::{Panels, markdown, plot_panels};
use anyhow::{Context, Result};
use drapelab_app::Job;
use drapelab_core::benchmark::{fitted_exponent, pareto_front};
use drapelab_core::scene::SolverKind;
use drapelab_core::solve::Status;
use drapelab_record::write_text;
use polars::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt::Write as _;

/// The names the benchmark table writes for a converged solve and the static solver.
pub const CONVERGED: &str = Status::Converged.as_str();
/// The static solver's name in the benchmark table.
pub const STATIC: &str = SolverKind::Static.name();

/// Parameters of a benchmark-report stage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BenchmarkReportParams {
    /// Title of the report.
    pub title: String,
    /// The tolerance whose rows make the scaling fits. Default 1e-6.
    #[serde(default = "default_scaling_tol")]
    pub scaling_tolerance: f64,
}

/// Default of `scaling_tolerance`: 1e-6.
pub fn default_scaling_tol() -> f64 {
    1e-6
}

/// Reads a benchmark table.
pub fn read(path: &std::path::Path) -> Result<DataFrame> {
    Ok(LazyFrame::scan_parquet(
        PlRefPath::from(path.to_string_lossy().as_ref()),
        ScanArgsParquet::default(),
    )?
    .collect()?)
}

/// The tables a benchmark report reads.
pub struct BenchmarkReportInputs {
    /// bench.parquet tables of benchmark stages.
    pub bench: Vec<std::path::PathBuf>,
    /// population.parquet of a benchmark stage.
    pub population: Option<std::path::PathBuf>,
    /// peers.parquet.
    pub peers: Option<std::path::PathBuf>,
    /// skips.parquet.
    pub skips: Option<std::path::PathBuf>,
    /// bench.parquet of a benchmark stage run with self-contact on and off.
    pub self_contact: Option<std::path::PathBuf>,
}

/// Writes the benchmark report and its plots.
pub fn run(ctx: &Job<'_, BenchmarkReportInputs>, p: &BenchmarkReportParams) -> Result<()> {
    ctx.started(1);
    let files = &ctx.inputs;
    let mut bench: Option<DataFrame> = None;
    for f in &files.bench {
        let df = read(f)?;
        bench = Some(match bench {
            None => df,
            Some(b) => b.vstack(&df)?,
        });
    }
    let bench = bench.context("a benchmark report needs bench.parquet inputs")?;
    let c = BenchCols::of(&bench)?;
    let mut md = format!(
        "# {}\n\n{} from the measured tables: every number and \
point below comes from `bench.parquet` and `peers.parquet` of this run.\n\n",
        p.title,
        ctx.made_by()
    );
    let (pareto, svg) = pareto_section(&c)?;
    md += &pareto;
    md += &scaling_section(&c, p.scaling_tolerance);
    md += &endings_section(&c);
    md += &newton_work_section(&bench)?;
    md += &settling_section(&c, &bench)?;
    if let Some(pop) = &files.population {
        md += &population_section(&drapelab_record::read_table(pop)?);
    }
    if let Some(sc) = &files.self_contact {
        md += &self_contact_section(&read(sc)?)?;
    }
    md += "\n## Every point\n\n";
    md += &markdown(&bench);
    if let Some(skips) = &files.skips {
        md += "\n## What skipping saves, measured on and off in the same run\n\n";
        md += &markdown(&read(skips)?);
        md += "\nsaved_fraction = 1 − time with the skip / time without it.\n";
    }
    if let Some(peers) = &files.peers {
        md += "\n## Peers, run beside drapelab in the same stage\n\n";
        md += &markdown(&read(peers)?);
        md += "\nratio = peer time / drapelab time (> 1: drapelab is faster). The scipy script solves the same \
hang4 model by sparse Newton to the same force tolerance; the centre heights show both reach the same \
equilibrium.\n";
    }
    write_text(ctx.output("markdown")?, &md)?;
    write_text(ctx.output("plot")?, &svg)?;
    ctx.item_done();
    Ok(())
}

/// The columns of the benchmark tables the report reads.
pub struct BenchCols {
    rows: usize,
    scene: StringChunked,
    solver: StringChunked,
    status: StringChunked,
    n: UInt64Chunked,
    tol: Float64Chunked,
    wall: Float64Chunked,
    iters: UInt64Chunked,
    err: Float64Chunked,
}

impl BenchCols {
    fn of(bench: &DataFrame) -> Result<Self> {
        Ok(Self {
            rows: bench.height(),
            scene: bench.column("scene")?.str()?.clone(),
            solver: bench.column("solver")?.str()?.clone(),
            status: bench.column("status")?.str()?.clone(),
            n: bench.column("particles_per_side")?.u64()?.clone(),
            tol: bench.column("tolerance_rel")?.f64()?.clone(),
            wall: bench.column("wall_time_s")?.f64()?.clone(),
            iters: bench.column("iterations")?.u64()?.clone(),
            err: bench.column("error_m")?.f64()?.clone(),
        })
    }
}

/// Run time against error: the Pareto front of each scene, as a Markdown section and an SVG.
pub fn pareto_section(c: &BenchCols) -> Result<(String, String)> {
    let BenchCols {
        scene,
        solver,
        status,
        wall,
        err,
        ..
    } = c;
    let mut panels = Panels::new();
    let mut all: BTreeMap<String, Vec<(f64, f64)>> = BTreeMap::new();
    let mut md = String::new();
    for r in 0..c.rows {
        let (Some(s), Some(sv), Some(t), Some(e)) =
            (scene.get(r), solver.get(r), wall.get(r), err.get(r))
        else {
            continue;
        };
        if status.get(r) != Some(CONVERGED) || e <= 0.0 {
            continue;
        }
        let pt = (t.log10(), e.log10());
        panels
            .entry(s.to_string())
            .or_default()
            .entry(sv.to_string())
            .or_default()
            .push(pt);
        all.entry(s.to_string()).or_default().push((t, e));
    }
    for (s, pts) in &all {
        panels.entry(s.clone()).or_default().insert(
            "Pareto front".into(),
            pareto_front(pts)
                .iter()
                .map(|(t, e)| (t.log10(), e.log10()))
                .collect(),
        );
    }
    for lines in panels.values_mut() {
        for pts in lines.values_mut() {
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        }
    }
    let svg = plot_panels(
        &panels,
        "log10 wall time (s)",
        "log10 error vs reference (m)",
        Some("scene"),
    )?;
    md += "## Run time against error\n\nThe error is the largest particle distance to the reference: the finest static \
solution (at the grid points both share), or for the cantilever the exact heavy elastica. Converged points only.\n\n\
![Pareto fronts](benchmark_pareto.svg)\n\n| scene | Pareto front: (wall time s, error m) |\n|---|---|\n";
    for (s, pts) in &all {
        let front: Vec<String> = pareto_front(pts)
            .iter()
            .map(|(t, e)| format!("({t:.3e}, {e:.2e})"))
            .collect();
        let _ = writeln!(md, "| {s} | {} |", front.join(" "));
    }
    Ok((md, svg))
}

/// Scaling: static wall time against particle count, and explicit time per step, per scene at the
/// tolerance `scaling_tolerance`.
pub fn scaling_section(c: &BenchCols, scaling_tolerance: f64) -> String {
    let BenchCols {
        scene,
        solver,
        status,
        n,
        tol,
        wall,
        iters,
        ..
    } = c;
    let mut md = String::new();
    let _ = write!(
        md,
        "\n## Scaling\n\nConverged runs at tolerance {:.0e}; the exponent p of wall time ∝ (particles)^p by least \
squares on the logarithms.\n\n| scene | solver | sides | fitted exponent of wall time against particle count |\n|---|---|---|---|\n",
        scaling_tolerance
    );
    let mut series: BTreeMap<(String, String), Vec<(f64, f64)>> = BTreeMap::new();
    for r in 0..c.rows {
        let (Some(s), Some(sv), Some(k), Some(t), Some(tl), Some(it)) = (
            scene.get(r),
            solver.get(r),
            n.get(r),
            wall.get(r),
            tol.get(r),
            iters.get(r),
        ) else {
            continue;
        };
        if status.get(r) != Some(CONVERGED) || (tl / scaling_tolerance - 1.0).abs() > 1e-9 {
            continue;
        }
        let particles = (k * k) as f64;
        if sv == STATIC {
            series
                .entry((s.into(), "static (whole solve)".into()))
                .or_default()
                .push((particles, t));
        } else if sv == SolverKind::ExplicitEuler.name() && it > 0 {
            series
                .entry((s.into(), "explicit Euler (one step)".into()))
                .or_default()
                .push((particles, t / it as f64));
        }
    }
    for ((s, sv), pts) in &series {
        let sides: Vec<String> = pts
            .iter()
            .map(|(p, _)| format!("{}", p.sqrt().round()))
            .collect();
        let _ = writeln!(
            md,
            "| {s} | {sv} | {} | {} |",
            sides.join(", "),
            fitted_exponent(pts).map_or("–".into(), |e| format!("{e:.2}"))
        );
    }
    md
}

/// How each solver ended on each scene.
pub fn endings_section(c: &BenchCols) -> String {
    let BenchCols {
        scene,
        solver,
        status,
        ..
    } = c;
    let mut md = String::new();
    let mut ends: BTreeMap<(String, String), BTreeMap<String, usize>> = BTreeMap::new();
    for r in 0..c.rows {
        if let (Some(s), Some(sv), Some(st)) = (scene.get(r), solver.get(r), status.get(r)) {
            *ends
                .entry((s.into(), sv.into()))
                .or_default()
                .entry(st.into())
                .or_default() += 1;
        }
    }
    md += "\n## How each solver ended\n\nPoints per status (max-iterations includes the wall-time budget of a \
dynamic point).\n\n| scene | solver | converged | max-iterations | diverged | invalid |\n|---|---|---|---|---|---|\n";
    for ((s, sv), counts) in &ends {
        let c = |k: &str| counts.get(k).copied().unwrap_or(0);
        let _ = writeln!(
            md,
            "| {s} | {sv} | {} | {} | {} | {} |",
            c(Status::Converged.as_str()),
            c(Status::MaxIterations.as_str()),
            c(Status::Diverged.as_str()),
            c(Status::Invalid.as_str())
        );
    }
    md
}

/// The static solves' work per scene and grid at the tightest tolerance: Newton iterations,
/// factorizations, back-substitutions, wall time, the factorizations' own time and what is left
/// (assembly, line search, energy and gradient evaluations).
pub fn newton_work_section(bench: &DataFrame) -> Result<String> {
    let tols = bench.column("tolerance_rel")?.f64()?.clone();
    let tightest = (0..tols.len())
        .filter_map(|i| tols.get(i))
        .fold(f64::INFINITY, f64::min);
    let mut md = format!(
        "\n## Newton iterations and factorizations per solve\n\nStatic solves at tolerance {tightest:.0e}, \
from the flat sheet (a coarse or sagged start included in the counts). Factorizations count the failed ones \
too (an indefinite exact Hessian, retried projected); back-substitutions are the triangular solves with \
a factor (a Newton step, a chord step, a preconditioner's application); the factorization time is that of \
the numeric Cholesky factorizations and triangular solves alone, the rest is assembly, line search and \
the coarse start's own overhead.\n\n| scene | particles | status | iterations | factorizations | back-substitutions | wall time (ms) | factorization time (ms) | rest (ms) |\n|---|---|---|---|---|---|---|---|---|\n"
    );
    let col = |c: &str| bench.column(c).map(|c| c.as_materialized_series().clone());
    let (scene, solver, status, n, tol, wall, it, fact, ft) = (
        col("scene")?,
        col("solver")?,
        col("status")?,
        col("particles_per_side")?,
        col("tolerance_rel")?,
        col("wall_time_s")?,
        col("iterations")?,
        col("factorizations")?,
        col("factor_time_s")?,
    );
    let back = col("back_substitutions")?;
    for r in 0..bench.height() {
        if solver.str()?.get(r) != Some(STATIC)
            || tol
                .f64()?
                .get(r)
                .is_none_or(|t| (t / tightest - 1.0).abs() > 1e-9)
        {
            continue;
        }
        let (w, f) = (
            wall.f64()?.get(r).unwrap_or(f64::NAN),
            ft.f64()?.get(r).unwrap_or(f64::NAN),
        );
        let k = n.u64()?.get(r).unwrap_or(0);
        let _ = writeln!(
            md,
            "| {} | {k}×{k} | {} | {} | {} | {} | {:.3} | {:.3} | {:.3} |",
            scene.str()?.get(r).unwrap_or(""),
            status.str()?.get(r).unwrap_or(""),
            it.u64()?.get(r).unwrap_or(0),
            fact.u64()?.get(r).unwrap_or(0),
            back.u64()?.get(r).unwrap_or(0),
            w * 1e3,
            f * 1e3,
            (w - f) * 1e3
        );
    }
    Ok(md)
}

/// Self-contact on and off (issue 32): per scene and size, the static solve's iterations, wall time,
/// the share of it spent in self-contact, the pairs in contact at the end and the crossing edges.
pub fn self_contact_section(t: &DataFrame) -> Result<String> {
    let mut md = String::from(
        "\n## Self-contact: what it costs and what it prevents\n\nThe drapes that touch themselves, each \
solved statically with `contact.self = \"auto\"` (on) and `\"off\"`. Self-contact time is the wall time spent in its \
broad phase, continuous collision detection, energy and derivatives; crossing edges are mesh edges of the final \
drape that pass through a triangle of the sheet (segment–triangle tests). The every-point table above gives \
the cost on the other scenes (`self_contact_time_s` of `bench.parquet`).\n\n| scene | particles | self-contact | \
status | iterations | wall time (s) | self-contact time (s) | pairs in contact | crossing edges |\n|---|---|---|---|---|---|---|---|---|\n",
    );
    let col = |c: &str| t.column(c).map(|c| c.as_materialized_series().clone());
    let (scene, status, n, mode, it, wall, sct, pairs, cross) = (
        col("scene")?,
        col("status")?,
        col("particles_per_side")?,
        col("self_contact")?,
        col("iterations")?,
        col("wall_time_s")?,
        col("self_contact_time_s")?,
        col("self_contact_pairs")?,
        col("crossing_edges")?,
    );
    for r in 0..t.height() {
        let k = n.u64()?.get(r).unwrap_or(0);
        let _ = writeln!(
            md,
            "| {} | {k}×{k} | {} | {} | {} | {:.3} | {:.3} | {} | {} |",
            scene.str()?.get(r).unwrap_or(""),
            mode.str()?.get(r).unwrap_or(""),
            status.str()?.get(r).unwrap_or(""),
            it.u64()?.get(r).unwrap_or(0),
            wall.f64()?.get(r).unwrap_or(f64::NAN),
            sct.f64()?.get(r).unwrap_or(f64::NAN),
            pairs.u64()?.get(r).unwrap_or(0),
            cross.u64()?.get(r).unwrap_or(0),
        );
    }
    Ok(md)
}

/// Every dynamic point that settled: its settle time in simulated and wall time, beside the static
/// solve of the same scene, size and tolerance (issue 19's goal: implicit Euler within 10× of it).
pub fn settling_section(c: &BenchCols, bench: &DataFrame) -> Result<String> {
    let mut md = String::from(
        "\n## Dynamic points that settled\n\nEach converged dynamic point from the flat sheet: simulated time and \
wall time to settle, and its wall time over the static solve's at the same scene, size and tolerance (the static \
solve starts from a coarse grid's solution or the sagged sheet; the fall starts flat). The settled drape may be \
another local minimum than the static one (folds on the rod and the pedestal): its error is in the table of every point.\n\n\
| scene | particles | tolerance | solver | steps | simulated time (s) | wall time (s) | static wall time (s) | ratio |\n|---|---|---|---|---|---|---|---|---|\n",
    );
    let sim = bench.column("sim_time_s")?.f64()?.clone();
    let BenchCols {
        scene,
        solver,
        status,
        n,
        tol,
        wall,
        iters,
        ..
    } = c;
    // The static solve's wall time of each (scene, size, tolerance).
    let key = |r: usize| {
        (
            scene.get(r).map(String::from),
            n.get(r),
            tol.get(r).map(f64::to_bits),
        )
    };
    let static_wall: BTreeMap<_, f64> = (0..c.rows)
        .filter(|&r| solver.get(r) == Some(STATIC))
        .filter_map(|r| Some((key(r), wall.get(r)?)))
        .collect();
    for r in 0..c.rows {
        let sv = solver.get(r).unwrap_or("");
        if sv == STATIC || status.get(r) != Some(CONVERGED) {
            continue;
        }
        let st = static_wall.get(&key(r)).copied();
        let w = wall.get(r).unwrap_or(f64::NAN);
        let side = n.get(r).unwrap_or(0);
        let _ = writeln!(
            md,
            "| {} | {side}×{side} | {:.0e} | {sv} | {} | {:.3} | {w:.3} | {} | {} |",
            scene.get(r).unwrap_or(""),
            tol.get(r).unwrap_or(f64::NAN),
            iters.get(r).unwrap_or(0),
            sim.get(r).unwrap_or(f64::NAN),
            st.map_or("–".into(), |s| format!("{s:.3}")),
            st.map_or("–".into(), |s| format!("{:.1}×", w / s)),
        );
    }
    Ok(md)
}

/// The slack-net population's iterations, factorizations and times per solve (min / median / max).
pub fn population_section(rows: &[drapelab_core::benchmark::PopulationRow]) -> String {
    let of = |which: &str| -> Vec<drapelab_core::benchmark::PopulationRow> {
        rows.iter().filter(|r| r.start == which).cloned().collect()
    };
    let (sagged, lattice) = (of("sagged"), of("lattice"));
    format!(
        "\n## Seed 000's slack-net population\n\nhang4 on the 14 × 14 net, static, at {} points of a Latin \
hypercube over Table 3's stiffness and natural length, the three topologies and Table 2's densities (what a \
calibration asks thousands of times), from the sagged start: {}\nThe same net as the calibration solves it: \
{} points over stiffness, natural length and topology at 45 g/m², each from the drape at the nearest node of \
the calibration's warm-start lattice (`calibrate::SharedLattice`): {}",
        sagged.len(),
        drapelab_core::benchmark::population_table(&sagged),
        lattice.len(),
        drapelab_core::benchmark::population_table(&lattice)
    )
}
