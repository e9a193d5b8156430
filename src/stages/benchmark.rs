//! Benchmark stages (issue 8): `benchmark` (every input scene × size × tolerance × solver, with its
//! time, work, memory and error, into a Parquet table), `peers` (a scipy sparse-Newton script and a
//! numpy explicit-Euler script from `benches/peers/`, run beside drapelab in the same stage so that the
//! ratios hold on a noisy machine) and `benchmark-report` (Pareto fronts of time against error per
//! scene, the fitted scaling exponents, the peer ratios: all from the measured tables).

use super::StageContext;
use super::report::{Panels, markdown, plot_panels};
use crate::benchmark::{
    BenchLimits, BenchRow, bench_rows, bench_scene, fitted_exponent, pareto_front,
};
use crate::io::{write_parquet, write_text};
use crate::scene::{Scene, SolverKind};
use crate::simulate::solve_scene;
use crate::solve::NoObserver;
use anyhow::{Context, Result, bail};
use arrow::array::{ArrayRef, Float64Array, RecordBatch, StringArray, UInt64Array};
use arrow::datatypes::{DataType, Field, Schema};
use polars::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::sync::Arc;

/// Parameters of a benchmark stage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BenchmarkParams {
    /// Particles per side, per scene name; scenes not named use `default_sizes`.
    #[serde(default)]
    pub sizes: BTreeMap<String, Vec<usize>>,
    /// Particles per side for scenes not in `sizes`. Default [11, 21, 41].
    #[serde(default = "default_sizes")]
    pub default_sizes: Vec<usize>,
    /// Force tolerances (largest residual / lightest particle's weight). Default [1e-4, 1e-6, 1e-8].
    #[serde(default = "default_tols")]
    pub tolerances: Vec<f64>,
    /// Solvers to run: "static", "implicit-euler", "symplectic-euler", "explicit-euler". Default all.
    #[serde(default)]
    pub solvers: Option<Vec<SolverKind>>,
    /// Largest side for the explicit integrators. Default 21.
    #[serde(default = "default_explicit")]
    pub max_explicit_size: usize,
    /// Largest side for implicit Euler. Default 21.
    #[serde(default = "default_explicit")]
    pub max_implicit_size: usize,
    /// Errors against the exact heavy elastica (scenes that are strips clamped at x-min) instead of
    /// the finest static solution. Default false.
    #[serde(default)]
    pub exact_elastica: bool,
    /// Wall-clock budget of one dynamic point in s: past it the point ends as max-iterations.
    /// Default none.
    #[serde(default)]
    pub max_wall_time_s: Option<f64>,
    /// Static solves of seed 000's slack-net population (the first scene on the 14 × 14 net over
    /// Table 3's box, [`crate::benchmark::slack_net_population`]) written to the output named
    /// `population.parquet`. Default 0 (none).
    #[serde(default)]
    pub slack_net_population: usize,
}

fn default_sizes() -> Vec<usize> {
    vec![11, 21, 41]
}
fn default_tols() -> Vec<f64> {
    vec![1e-4, 1e-6, 1e-8]
}
fn default_explicit() -> usize {
    21
}

fn f64s(v: Vec<f64>) -> ArrayRef {
    Arc::new(Float64Array::from(v))
}

/// Runs a benchmark stage.
pub fn run(ctx: &StageContext<'_>, p: &BenchmarkParams) -> Result<()> {
    let scenes: Vec<Scene> = ctx
        .inputs
        .iter()
        .filter(|f| f.extension().is_some_and(|e| e == "toml"))
        .map(|f| Ok(Scene::load(f, &[])?.scene))
        .collect::<Result<_>>()?;
    if scenes.is_empty() {
        bail!("a benchmark needs at least one scene file as input");
    }
    ctx.progress
        .stage_started(&ctx.stage.name, scenes.len() as u64);
    let limits = BenchLimits {
        solvers: p
            .solvers
            .clone()
            .unwrap_or_else(|| crate::benchmark::ALL_SOLVERS.to_vec()),
        max_explicit_size: p.max_explicit_size,
        max_implicit_size: p.max_implicit_size,
        exact_elastica: p.exact_elastica,
        max_wall_time_s: p.max_wall_time_s,
    };
    // Serial on purpose: the points are timed, and peak memory is per process.
    let mut rows: Vec<BenchRow> = Vec::new();
    for s in &scenes {
        let sizes = p.sizes.get(&s.name).unwrap_or(&p.default_sizes);
        rows.extend(bench_rows(s, sizes, &p.tolerances, &limits, |_| {}));
        ctx.progress.item_done(&ctx.stage.name);
    }
    let schema = Arc::new(Schema::new(vec![
        Field::new("scene", DataType::Utf8, false),
        Field::new("particles_per_side", DataType::UInt64, false),
        Field::new("solver", DataType::Utf8, false),
        Field::new("tolerance_rel", DataType::Float64, false),
        Field::new("status", DataType::Utf8, false),
        Field::new("wall_time_s", DataType::Float64, false),
        Field::new("iterations", DataType::UInt64, false),
        Field::new("linear_solves", DataType::UInt64, false),
        Field::new("factorizations", DataType::UInt64, false),
        Field::new("factor_time_s", DataType::Float64, false),
        Field::new("error_m", DataType::Float64, true),
        Field::new("peak_rss_bytes", DataType::UInt64, true),
    ]));
    let cols: Vec<ArrayRef> = vec![
        Arc::new(StringArray::from_iter_values(
            rows.iter().map(|r| r.scene.clone()),
        )),
        Arc::new(UInt64Array::from_iter_values(
            rows.iter().map(|r| r.n as u64),
        )),
        Arc::new(StringArray::from_iter_values(
            rows.iter().map(|r| r.solver.name().to_string()),
        )),
        f64s(rows.iter().map(|r| r.tol).collect()),
        Arc::new(StringArray::from_iter_values(
            rows.iter().map(|r| r.status.clone()),
        )),
        f64s(rows.iter().map(|r| r.wall_time_s).collect()),
        Arc::new(UInt64Array::from_iter_values(
            rows.iter().map(|r| r.iterations as u64),
        )),
        Arc::new(UInt64Array::from_iter_values(
            rows.iter().map(|r| r.linear_solves as u64),
        )),
        Arc::new(UInt64Array::from_iter_values(
            rows.iter().map(|r| r.factorizations as u64),
        )),
        f64s(rows.iter().map(|r| r.factor_time_s).collect()),
        Arc::new(Float64Array::from_iter(
            rows.iter()
                .map(|r| r.error_m.is_finite().then_some(r.error_m)),
        )),
        Arc::new(UInt64Array::from_iter(
            rows.iter().map(|r| r.peak_rss_bytes),
        )),
    ];
    write_parquet(&ctx.outputs[0], &RecordBatch::try_new(schema, cols)?, None)?;
    if p.slack_net_population > 0 {
        let out = ctx
            .outputs
            .iter()
            .find(|o| o.file_name().is_some_and(|n| n == "population.parquet"))
            .context("slack_net_population needs an output named population.parquet")?;
        let mut rows =
            crate::benchmark::slack_net_population(&scenes[0], p.slack_net_population, 8);
        rows.extend(
            crate::benchmark::warm_start_population(&scenes[0], p.slack_net_population, 9).0,
        );
        write_population(out, &rows)?;
    }
    Ok(())
}

/// Writes the slack-net population's solves as a Parquet table.
fn write_population(out: &std::path::Path, rows: &[crate::benchmark::PopulationRow]) -> Result<()> {
    let schema = Arc::new(Schema::new(vec![
        Field::new("start", DataType::Utf8, false),
        Field::new("stiffness_N_per_m", DataType::Float64, false),
        Field::new("natural_length_m", DataType::Float64, false),
        Field::new("topology", DataType::Utf8, false),
        Field::new("areal_density_kg_per_m2", DataType::Float64, false),
        Field::new("status", DataType::Utf8, false),
        Field::new("iterations", DataType::UInt64, false),
        Field::new("factorizations", DataType::UInt64, false),
        Field::new("wall_time_s", DataType::Float64, false),
        Field::new("factor_time_s", DataType::Float64, false),
    ]));
    let u64s = |f: &dyn Fn(&crate::benchmark::PopulationRow) -> usize| -> ArrayRef {
        Arc::new(UInt64Array::from_iter_values(
            rows.iter().map(|r| f(r) as u64),
        ))
    };
    let strs = |f: &dyn Fn(&crate::benchmark::PopulationRow) -> String| -> ArrayRef {
        Arc::new(StringArray::from_iter_values(rows.iter().map(f)))
    };
    let cols: Vec<ArrayRef> = vec![
        strs(&|r| r.start.clone()),
        f64s(rows.iter().map(|r| r.stiffness_N_per_m).collect()),
        f64s(rows.iter().map(|r| r.natural_length_m).collect()),
        strs(&|r| r.topology.clone()),
        f64s(rows.iter().map(|r| r.areal_density_kg_per_m2).collect()),
        strs(&|r| r.status.clone()),
        u64s(&|r| r.iterations),
        u64s(&|r| r.factorizations),
        f64s(rows.iter().map(|r| r.wall_time_s).collect()),
        f64s(rows.iter().map(|r| r.factor_time_s).collect()),
    ];
    write_parquet(out, &RecordBatch::try_new(schema, cols)?, None)
}

/// Parameters of a peers stage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PeersParams {
    /// The Python interpreter (of a virtual environment; numpy and scipy are installed into it when
    /// missing). Default ".venv/bin/python".
    #[serde(default = "default_python")]
    pub python: String,
    /// Sides of the hang4 grid for the static comparison. Default [11, 21, 41].
    #[serde(default = "default_sizes")]
    pub static_sizes: Vec<usize>,
    /// Sides for the per-step explicit Euler comparison. Default [21, 41].
    #[serde(default = "default_step_sizes")]
    pub explicit_sizes: Vec<usize>,
    /// Explicit steps timed. Default 2000.
    #[serde(default = "default_steps")]
    pub explicit_steps: usize,
}

fn default_python() -> String {
    ".venv/bin/python".into()
}
fn default_step_sizes() -> Vec<usize> {
    vec![21, 41]
}
fn default_steps() -> usize {
    2000
}

/// Runs a peers stage: inputs are the hang4 scene and the scripts of `benches/peers/`.
pub fn run_peers(ctx: &StageContext<'_>, p: &PeersParams) -> Result<()> {
    let scene = Scene::load(ctx.input_with_extension("toml")?, &[])?.scene;
    let script = |name: &str| -> Result<std::path::PathBuf> {
        Ok(std::fs::canonicalize(ctx.input_named(name)?)?)
    };
    let (newton, explicit) = (script("scipy_newton.py")?, script("numpy_explicit.py")?);
    // The CHOLMOD peer (cvxopt) runs when its script is an input.
    let cholmod = ctx
        .input_named("cholmod_newton.py")
        .ok()
        .map(std::fs::canonicalize)
        .transpose()?;
    let python = std::path::absolute(ctx.plan.root.join(&p.python))?;
    let has = |py: &std::path::Path| {
        std::process::Command::new(py)
            .args(["-c", "import numpy, scipy, cvxopt"])
            .output()
            .is_ok_and(|o| o.status.success())
    };
    if !has(&python) {
        let venv = python
            .parent()
            .and_then(|b| b.parent())
            .context("python is not inside a virtual environment")?;
        if !python.exists() {
            std::process::Command::new("python3")
                .args(["-m", "venv"])
                .arg(venv)
                .status()
                .context("python3 -m venv")?;
        }
        let ok = std::process::Command::new(&python)
            .args(["-m", "pip", "install", "-q", "numpy", "scipy", "cvxopt"])
            .status()
            .context("pip install numpy scipy cvxopt")?;
        if !ok.success() || !has(&python) {
            bail!(
                "{}: cannot install numpy, scipy and cvxopt",
                python.display()
            );
        }
    }
    let run_py = |script: &std::path::Path, args: &[String]| -> Result<serde_json::Value> {
        let o = std::process::Command::new(&python)
            .arg(script)
            .args(args)
            .current_dir(script.parent().unwrap_or(std::path::Path::new(".")))
            .output()?;
        if !o.status.success() {
            bail!(
                "{}: {}",
                script.display(),
                String::from_utf8_lossy(&o.stderr)
                    .lines()
                    .last()
                    .unwrap_or("failed")
            );
        }
        Ok(serde_json::from_slice(&o.stdout)?)
    };
    let total = p.static_sizes.len() + p.explicit_sizes.len();
    ctx.progress.stage_started(&ctx.stage.name, total as u64);
    // (comparison, n, peer time, drapelab time, peer centre z, drapelab centre z)
    let mut rows: Vec<(&str, usize, f64, f64, f64, f64)> = Vec::new();
    for &n in &p.static_sizes {
        let peer = run_py(&newton, &[n.to_string(), "1e-6".into()])?;
        let s = bench_scene(&scene, n, SolverKind::Static, 1e-6);
        let sol = solve_scene(&s, &mut NoObserver);
        rows.push((
            "static: scipy sparse Newton / drapelab",
            n,
            peer["wall_time_s"].as_f64().unwrap_or(f64::NAN),
            sol.report.wall_time_s,
            peer["centre_z_m"].as_f64().unwrap_or(f64::NAN),
            sol.at(n / 2, n / 2).z,
        ));
        if let Some(script) = &cholmod {
            let peer = run_py(script, &[n.to_string(), "1e-6".into()])?;
            rows.push((
                "static: CHOLMOD (cvxopt) Newton / drapelab",
                n,
                peer["wall_time_s"].as_f64().unwrap_or(f64::NAN),
                sol.report.wall_time_s,
                peer["centre_z_m"].as_f64().unwrap_or(f64::NAN),
                sol.at(n / 2, n / 2).z,
            ));
        }
        ctx.progress.item_done(&ctx.stage.name);
    }
    for &n in &p.explicit_sizes {
        let peer = run_py(&explicit, &[n.to_string(), p.explicit_steps.to_string()])?;
        let mut s = bench_scene(&scene, n, SolverKind::ExplicitEuler, 1e-30);
        // A fixed number of steps at half the stability limit: stop by time, not by convergence.
        let built = crate::cloth::build_scene(&s);
        let dt = 0.5
            * crate::solve::stability_limit_dt(
                &built.model,
                &built.x0,
                crate::solve::Integrator::ExplicitEuler,
                built.model.damping_Ns_per_m,
            )
            .unwrap_or(1e-4);
        s.solver.dynamic.auto_dt_fraction = 0.0;
        s.solver.dynamic.dt_s = dt;
        s.solver.dynamic.max_time_s = dt * p.explicit_steps as f64;
        let sol = solve_scene(&s, &mut NoObserver);
        let steps = sol.report.iterations.max(1) as f64;
        rows.push((
            "explicit Euler per step: numpy / drapelab",
            n,
            peer["per_step_s"].as_f64().unwrap_or(f64::NAN),
            sol.report.wall_time_s / steps,
            f64::NAN,
            f64::NAN,
        ));
        ctx.progress.item_done(&ctx.stage.name);
    }
    let schema = Arc::new(Schema::new(vec![
        Field::new("comparison", DataType::Utf8, false),
        Field::new("particles_per_side", DataType::UInt64, false),
        Field::new("peer_time_s", DataType::Float64, false),
        Field::new("drapelab_time_s", DataType::Float64, false),
        Field::new("ratio", DataType::Float64, false),
        Field::new("peer_centre_z_m", DataType::Float64, true),
        Field::new("drapelab_centre_z_m", DataType::Float64, true),
    ]));
    let opt = |v: f64| v.is_finite().then_some(v);
    let cols: Vec<ArrayRef> = vec![
        Arc::new(StringArray::from_iter_values(rows.iter().map(|r| r.0))),
        Arc::new(UInt64Array::from_iter_values(
            rows.iter().map(|r| r.1 as u64),
        )),
        f64s(rows.iter().map(|r| r.2).collect()),
        f64s(rows.iter().map(|r| r.3).collect()),
        f64s(rows.iter().map(|r| r.2 / r.3).collect()),
        Arc::new(Float64Array::from_iter(rows.iter().map(|r| opt(r.4)))),
        Arc::new(Float64Array::from_iter(rows.iter().map(|r| opt(r.5)))),
    ];
    write_parquet(&ctx.outputs[0], &RecordBatch::try_new(schema, cols)?, None)
}

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

fn default_scaling_tol() -> f64 {
    1e-6
}

fn read(path: &std::path::Path) -> Result<DataFrame> {
    Ok(LazyFrame::scan_parquet(
        PlRefPath::from(path.to_string_lossy().as_ref()),
        ScanArgsParquet::default(),
    )?
    .collect()?)
}

/// Runs a benchmark-report stage: inputs `bench.parquet` (and optionally `peers.parquet`); outputs the
/// Markdown report and the SVG of the Pareto fronts.
pub fn run_report(ctx: &StageContext<'_>, p: &BenchmarkReportParams) -> Result<()> {
    ctx.progress.stage_started(&ctx.stage.name, 1);
    let mut bench: Option<DataFrame> = None;
    for f in ctx
        .inputs
        .iter()
        .filter(|f| f.file_name().is_some_and(|n| n == "bench.parquet"))
    {
        let df = read(f)?;
        bench = Some(match bench {
            None => df,
            Some(b) => b.vstack(&df)?,
        });
    }
    let bench = bench.context("a benchmark report needs bench.parquet inputs")?;
    let scene = bench.column("scene")?.str()?.clone();
    let solver = bench.column("solver")?.str()?.clone();
    let status = bench.column("status")?.str()?.clone();
    let n = bench.column("particles_per_side")?.u64()?.clone();
    let tol = bench.column("tolerance_rel")?.f64()?.clone();
    let wall = bench.column("wall_time_s")?.f64()?.clone();
    let iters = bench.column("iterations")?.u64()?.clone();
    let err = bench.column("error_m")?.f64()?.clone();
    let mut panels = Panels::new();
    let mut all: BTreeMap<String, Vec<(f64, f64)>> = BTreeMap::new();
    let mut md = format!(
        "# {}\n\n{} from the measured tables: every number and \
point below comes from `bench.parquet` and `peers.parquet` of this run.\n\n",
        p.title,
        ctx.made_by()
    );
    for r in 0..bench.height() {
        let (Some(s), Some(sv), Some(t), Some(e)) =
            (scene.get(r), solver.get(r), wall.get(r), err.get(r))
        else {
            continue;
        };
        if status.get(r) != Some("converged") || e <= 0.0 {
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
    // Scaling: static wall time against particle count, and explicit time per step, per scene at the
    // tightest tolerance.
    let _ = write!(
        md,
        "\n## Scaling\n\nConverged runs at tolerance {:.0e}; the exponent p of wall time ∝ (particles)^p by least \
squares on the logarithms.\n\n| scene | solver | sides | fitted exponent of wall time against particle count |\n|---|---|---|---|\n",
        p.scaling_tolerance
    );
    let mut series: BTreeMap<(String, String), Vec<(f64, f64)>> = BTreeMap::new();
    for r in 0..bench.height() {
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
        if status.get(r) != Some("converged") || (tl / p.scaling_tolerance - 1.0).abs() > 1e-9 {
            continue;
        }
        let particles = (k * k) as f64;
        if sv == "static" {
            series
                .entry((s.into(), "static (whole solve)".into()))
                .or_default()
                .push((particles, t));
        } else if sv == "explicit-euler" && it > 0 {
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
    // How each solver ended on each scene.
    let mut ends: BTreeMap<(String, String), BTreeMap<String, usize>> = BTreeMap::new();
    for r in 0..bench.height() {
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
            c("converged"),
            c("max-iterations"),
            c("diverged"),
            c("invalid")
        );
    }
    md += &newton_work_section(&bench)?;
    if let Ok(pop) = ctx.input_named("population.parquet") {
        md += &population_section(&read(pop)?)?;
    }
    md += "\n## Every point\n\n";
    md += &markdown(&bench);
    if let Ok(skips) = ctx.input_named("skips.parquet") {
        md += "\n## What skipping saves, measured on and off in the same run\n\n";
        md += &markdown(&read(skips)?);
        md += "\nsaved_fraction = 1 − time with the skip / time without it.\n";
    }
    if let Ok(peers) = ctx.input_named("peers.parquet") {
        md += "\n## Peers, run beside drapelab in the same stage\n\n";
        md += &markdown(&read(peers)?);
        md += "\nratio = peer time / drapelab time (> 1: drapelab is faster). The scipy script solves the same \
hang4 model by sparse Newton to the same force tolerance; the centre heights show both reach the same \
equilibrium.\n";
    }
    for out in &ctx.outputs {
        let text = if out.extension().is_some_and(|e| e == "md") {
            &md
        } else {
            &svg
        };
        write_text(out, text)?;
    }
    ctx.progress.item_done(&ctx.stage.name);
    Ok(())
}

/// The static solves' work per scene and grid at the tightest tolerance: Newton iterations,
/// factorizations, wall time, the factorizations' own time and what is left (assembly, line
/// search, energy and gradient evaluations).
fn newton_work_section(bench: &DataFrame) -> Result<String> {
    let tols = bench.column("tolerance_rel")?.f64()?.clone();
    let tightest = (0..tols.len())
        .filter_map(|i| tols.get(i))
        .fold(f64::INFINITY, f64::min);
    let mut md = format!(
        "\n## Newton iterations and factorizations per solve\n\nStatic solves at tolerance {tightest:.0e}, \
from the flat sheet (a coarse or sagged start included in the counts). Factorizations count the failed ones \
too (an indefinite exact Hessian, retried projected); the factorization time is that of the numeric \
Cholesky factorizations and triangular solves alone, the rest is assembly, line search and the \
coarse start's own overhead.\n\n| scene | particles | status | iterations | factorizations | wall time (ms) | factorization time (ms) | rest (ms) |\n|---|---|---|---|---|---|---|---|\n"
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
    for r in 0..bench.height() {
        if solver.str()?.get(r) != Some("static")
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
            "| {} | {k}×{k} | {} | {} | {} | {:.3} | {:.3} | {:.3} |",
            scene.str()?.get(r).unwrap_or(""),
            status.str()?.get(r).unwrap_or(""),
            it.u64()?.get(r).unwrap_or(0),
            fact.u64()?.get(r).unwrap_or(0),
            w * 1e3,
            f * 1e3,
            (w - f) * 1e3
        );
    }
    Ok(md)
}

/// The slack-net population's iterations, factorizations and times per solve (min / median / max).
fn population_section(pop: &DataFrame) -> Result<String> {
    let f = |c: &str| -> Result<Vec<f64>> {
        let s = pop
            .column(c)?
            .as_materialized_series()
            .cast(&polars::prelude::DataType::Float64)?;
        let ca = s.f64()?;
        Ok((0..ca.len())
            .map(|i| ca.get(i).unwrap_or(f64::NAN))
            .collect())
    };
    let strings = |c: &str| -> Result<Vec<String>> {
        let ca = pop.column(c)?.str()?.clone();
        Ok((0..ca.len())
            .map(|i| ca.get(i).unwrap_or("").to_string())
            .collect())
    };
    let status = strings("status")?;
    let (k, l, d, it, fa, w, ft) = (
        f("stiffness_N_per_m")?,
        f("natural_length_m")?,
        f("areal_density_kg_per_m2")?,
        f("iterations")?,
        f("factorizations")?,
        f("wall_time_s")?,
        f("factor_time_s")?,
    );
    let topology = strings("topology")?;
    let start = strings("start")?;
    let rows: Vec<crate::benchmark::PopulationRow> = (0..pop.height())
        .map(|r| crate::benchmark::PopulationRow {
            start: start[r].clone(),
            stiffness_N_per_m: k[r],
            natural_length_m: l[r],
            topology: topology[r].clone(),
            areal_density_kg_per_m2: d[r],
            status: status[r].clone(),
            iterations: it[r] as usize,
            factorizations: fa[r] as usize,
            wall_time_s: w[r],
            factor_time_s: ft[r],
        })
        .collect();
    let of = |which: &str| -> Vec<crate::benchmark::PopulationRow> {
        rows.iter().filter(|r| r.start == which).cloned().collect()
    };
    let (sagged, lattice) = (of("sagged"), of("lattice"));
    Ok(format!(
        "\n## Seed 000's slack-net population\n\nhang4 on the 14 × 14 net, static, at {} points of a Latin \
hypercube over Table 3's stiffness and natural length, the three topologies and Table 2's densities (what a \
calibration asks thousands of times), from the sagged start: {}\nThe same net as the calibration solves it: \
{} points over stiffness, natural length and topology at 45 g/m², each from the drape at the nearest node of \
the calibration's warm-start lattice (`calibrate::StartLattice`): {}",
        sagged.len(),
        crate::benchmark::population_table(&sagged),
        lattice.len(),
        crate::benchmark::population_table(&lattice)
    ))
}

/// Parameters of a skips stage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct SkipsParams {}

/// Runs a skips stage: each skip the engine makes (a quarter model, recording off, the cost cache, an
/// up-to-date stage, a contact term a scene does not need), and the second thread of a calibration
/// population, measured on and off in the same run, into a Parquet table (`skip`, `scene`,
/// `time_with_skip_s`, `time_without_skip_s`, `saved_fraction`). Inputs: `table_wool.toml`,
/// `table_wool_quarter.toml` and `hang4.toml`.
pub fn run_skips(ctx: &StageContext<'_>, _p: &SkipsParams) -> Result<()> {
    use std::time::Instant;
    let load =
        |name: &str| -> Result<Scene> { Ok(Scene::load(ctx.input_named(name)?, &[])?.scene) };
    ctx.progress.stage_started(&ctx.stage.name, 6);
    let mut rows: Vec<(String, String, f64, f64)> = Vec::new();
    let timed = |f: &mut dyn FnMut()| {
        let t = Instant::now();
        f();
        t.elapsed().as_secs_f64()
    };
    // 1. Symmetry: the quarter model instead of the full one (the same drape, tests/it/contact.rs).
    let (full, quarter) = (load("table_wool.toml")?, load("table_wool_quarter.toml")?);
    let tq = timed(&mut || {
        solve_scene(&quarter, &mut NoObserver);
    });
    let tf = timed(&mut || {
        solve_scene(&full, &mut NoObserver);
    });
    rows.push((
        "symmetry reduction (quarter model)".into(),
        full.name.clone(),
        tq,
        tf,
    ));
    ctx.progress.item_done(&ctx.stage.name);
    // 2. Recording off: simulate with the timeline and the rerun recording off and on.
    let mut hang4 = load("hang4.toml")?;
    hang4.cloth.nx = 21;
    hang4.cloth.ny = 21;
    let tmp = tempfile::tempdir()?;
    let mut with_rec = hang4.clone();
    with_rec.record.timeline = true;
    with_rec.record.rerun = true;
    let mut times = Vec::new();
    for (k, s) in [&hang4, &with_rec].iter().enumerate() {
        let loaded = crate::scene::LoadedScene {
            scene: (*s).clone(),
            path: ctx.input_named("hang4.toml")?.to_path_buf(),
        };
        let out = tmp.path().join(format!("r{k}"));
        let t = Instant::now();
        crate::simulate::simulate_to_dir(&loaded, &out, &mut NoObserver)?;
        times.push(t.elapsed().as_secs_f64());
    }
    rows.push((
        "timeline and rerun recording off".into(),
        hang4.name.clone(),
        times[0],
        times[1],
    ));
    ctx.progress.item_done(&ctx.stage.name);
    // 3. Cached parameter vectors: the same ICA run with the cost cache on and off.
    let mut net = load("hang4.toml")?;
    net.cloth.nx = 11;
    net.cloth.ny = 11;
    let probe = crate::calibrate::Problem::new(net.clone(), vec![], 50.0);
    let measured = probe
        .drape(&[0.4, 0.5, 0.5, 0.3, 0.1])
        .1
        .context("the reference drape did not converge")?;
    // The identifiability analysis sweeps damping and the elongation rate, which a static drape does not
    // see: the cache (keyed on stiffness, natural length and topology) answers those sweeps.
    let best = [0.4, 0.5, 0.5, 0.3, 0.1];
    let mut t_cache = [0.0; 2];
    for (k, caching) in [true, false].into_iter().enumerate() {
        // Sharing the probe's warm-start lattice, so that only the costs are timed.
        let mut problem = probe.fresh();
        problem.measured = measured.clone();
        problem.caching = caching;
        let t = Instant::now();
        crate::calibrate::identifiability(
            &problem,
            &best,
            0.1,
            7,
            crate::calibrate::Noise::FromResidual,
            0.05,
        );
        t_cache[k] = t.elapsed().as_secs_f64();
    }
    rows.push((
        "cached parameter vectors (identifiability analysis)".into(),
        net.name.clone(),
        t_cache[0],
        t_cache[1],
    ));
    ctx.progress.item_done(&ctx.stage.name);
    // 4. Up-to-date stages: a one-stage pipeline run from scratch, then again (nothing to do).
    let proj = tempfile::tempdir()?;
    std::fs::create_dir_all(proj.path().join("pipelines"))?;
    std::fs::create_dir_all(proj.path().join("datasets/scenes"))?;
    std::fs::copy(
        ctx.input_named("hang4.toml")?,
        proj.path().join("datasets/scenes/hang4.toml"),
    )?;
    let file = proj.path().join("pipelines/p.toml");
    std::fs::write(
        &file,
        "name = \"p\"\n[stages.h]\nkind = \"simulate\"\ninputs = [\"datasets/scenes/hang4.toml\"]\n\
         outputs = [\"{run}/h/particles.parquet\", \"{run}/h/run.json\"]\n\
         params.set = { \"cloth.nx\" = 41, \"cloth.ny\" = 41 }\n",
    )?;
    let plan = crate::pipeline::load_plan(&file)?;
    let quiet = Silent;
    let mut t_pipe = [0.0; 2];
    for t in &mut t_pipe {
        let start = Instant::now();
        crate::pipeline::run_pipeline(&plan, &Default::default(), &quiet)?;
        *t = start.elapsed().as_secs_f64();
    }
    rows.push((
        "up-to-date stage skipped".into(),
        "hang4 41×41".into(),
        t_pipe[1],
        t_pipe[0],
    ));
    ctx.progress.item_done(&ctx.stage.name);
    // 5. Terms a scene does not need: hang4 (no obstacle, so no contact term is built) against the
    // same scene with a floor 10 m below that it never reaches (the barrier term is built and
    // evaluated every iteration). 19 a side: both solve from flat (no coarse start).
    let mut bare = load("hang4.toml")?;
    bare.cloth.nx = 19;
    bare.cloth.ny = 19;
    let mut floored = bare.clone();
    floored.obstacles.push(crate::contact::Obstacle::Plane {
        point_m: [0.0, 0.0, -10.0],
        normal: [0.0, 0.0, 1.0],
    });
    let mut t_terms = [0.0; 2];
    for (k, s) in [&bare, &floored].into_iter().enumerate() {
        let mut best = f64::INFINITY;
        for _ in 0..3 {
            best = best.min(timed(&mut || {
                solve_scene(s, &mut NoObserver);
            }));
        }
        t_terms[k] = best;
    }
    rows.push((
        "contact term not built (no obstacle within reach)".into(),
        "hang4 19×19".into(),
        t_terms[0],
        t_terms[1],
    ));
    ctx.progress.item_done(&ctx.stage.name);
    // 6. Threads: one ICA population (16 countries of a calibration, the cache off) costed on a
    // rayon pool of 2 threads against 1.
    let mut rng = <rand::rngs::StdRng as rand::SeedableRng>::seed_from_u64(7);
    let population: Vec<Vec<f64>> = (0..16)
        .map(|_| (0..5).map(|_| rand::Rng::random::<f64>(&mut rng)).collect())
        .collect();
    let mut problem = probe.fresh();
    problem.measured = measured.clone();
    problem.caching = false;
    let mut t_threads = [0.0; 2];
    for (k, threads) in [2usize, 1].into_iter().enumerate() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()?;
        t_threads[k] = timed(&mut || {
            pool.install(|| {
                use rayon::prelude::*;
                let _: Vec<f64> = population.par_iter().map(|u| problem.cost(u)).collect();
            });
        });
    }
    rows.push((
        "second thread (one calibration population of 16, 2 threads against 1)".into(),
        format!("{} 11×11", net.name),
        t_threads[0],
        t_threads[1],
    ));
    ctx.progress.item_done(&ctx.stage.name);
    let schema = Arc::new(Schema::new(vec![
        Field::new("skip", DataType::Utf8, false),
        Field::new("scene", DataType::Utf8, false),
        Field::new("time_with_skip_s", DataType::Float64, false),
        Field::new("time_without_skip_s", DataType::Float64, false),
        Field::new("saved_fraction", DataType::Float64, false),
    ]));
    let cols: Vec<ArrayRef> = vec![
        Arc::new(StringArray::from_iter_values(
            rows.iter().map(|r| r.0.clone()),
        )),
        Arc::new(StringArray::from_iter_values(
            rows.iter().map(|r| r.1.clone()),
        )),
        f64s(rows.iter().map(|r| r.2).collect()),
        f64s(rows.iter().map(|r| r.3).collect()),
        f64s(rows.iter().map(|r| 1.0 - r.2 / r.3).collect()),
    ];
    write_parquet(&ctx.outputs[0], &RecordBatch::try_new(schema, cols)?, None)
}

/// A progress that says nothing (the skips stage runs a pipeline of its own inside).
struct Silent;

impl crate::pipeline::Progress for Silent {
    fn stage_started(&self, _: &str, _: u64) {}
    fn item_done(&self, _: &str) {}
    fn stage_finished(&self, _: &str, _: &str, _: f64) {}
    fn stage_skipped(&self, _: &str, _: &str) {}
}
