//! `calibration-report`: the Markdown report of a calibration (seed 000's Tables 4 and 6, Figs 10 and
//! 13) from the tables of the tune, calibrate and validate stages, with polars for the tables and
//! plotters for the figures.

use crate::report::{Panels, markdown, plot_panels};
use anyhow::Result;
use drapelab_app::Job;
use drapelab_core::calibrate::sample_number;
use drapelab_record::write_text;
use polars::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Parameters of a calibration-report stage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CalibrationReportParams {
    /// Title of the report.
    pub title: String,
}

/// Scans a calibration table lazily.
pub fn scan(p: &Path) -> Result<LazyFrame> {
    Ok(LazyFrame::scan_parquet(
        PlRefPath::from(p.to_string_lossy().as_ref()),
        ScanArgsParquet::default(),
    )?)
}

/// Rows of a seed CSV (comment lines skipped) as maps of column → value.
pub fn read_csv(path: &Path) -> Result<Vec<BTreeMap<String, String>>> {
    Ok(drapelab_record::read_csv(path)?)
}

/// The tables a calibration report reads.
pub struct CalibrationReportInputs {
    /// A calibrate stage's results.parquet.
    pub results: PathBuf,
    /// A validate stage's validation.parquet.
    pub validation: PathBuf,
    /// A calibrate stage's evaluations.parquet.
    pub evaluations: PathBuf,
    /// A calibrate stage's comparison.parquet.
    pub comparison: PathBuf,
    /// A tune stage's main_effects.parquet.
    pub main_effects: PathBuf,
    /// Seed 000's 4-corner optima (ica_optimum_4corner.csv).
    pub seed_optimum: PathBuf,
    /// Seed 000's 2-corner errors (ica_validation_2corner.csv).
    pub seed_validation: PathBuf,
}

/// Writes the calibration report and its plots.
pub fn run(ctx: &Job<'_, CalibrationReportInputs>, p: &CalibrationReportParams) -> Result<()> {
    let files = &ctx.inputs;
    ctx.started(1);
    let md = ctx.output("markdown")?;
    let (conv_svg, effects_svg) = (
        ctx.optional_output("convergence_plot"),
        ctx.optional_output("main_effects_plot"),
    );
    let truth4: BTreeMap<u32, BTreeMap<String, String>> = read_csv(&files.seed_optimum)?
        .into_iter()
        .filter_map(|r| Some((r.get("sample")?.parse().ok()?, r)))
        .collect();
    let seed6: BTreeMap<u32, String> = read_csv(&files.seed_validation)?
        .into_iter()
        .filter_map(|r| Some((r.get("sample")?.parse().ok()?, r.get("error_pct")?.clone())))
        .collect();
    let res = scan(&files.results)?.collect()?;
    let t4 = table_4(&res, &truth4)?;
    let t6 = table_6(&scan(&files.validation)?.collect()?, &seed6)?;
    let convergence = fig_13(&files.evaluations)?;
    if let Some(svg) = conv_svg {
        write_text(svg, &convergence)?;
    }
    let effects = fig_10(&scan(&files.main_effects)?.collect()?)?;
    if let Some(svg) = effects_svg {
        write_text(svg, &effects)?;
    }
    // ICA against CMA-ES at the same budget.
    let cmp = scan(&files.comparison)?
        .group_by([col("optimizer")])
        .agg([
            len().alias("runs"),
            col("evaluations").mean().alias("mean_evaluations"),
            col("best_cost_pct").mean().alias("mean_best_pct"),
            col("best_cost_pct").median().alias("median_best_pct"),
        ])
        .sort(["optimizer"], SortMultipleOptions::default())
        .collect()?;
    let rel = |o: Option<&Path>| {
        o.and_then(|o| o.strip_prefix(md.parent().unwrap_or(Path::new(""))).ok())
            .map(|p| p.to_string_lossy().to_string())
            .unwrap_or_default()
    };
    let text = format!(
        "# {}\n\n{}. The photos are synthetic (datasets/knitted/README.md): the\ntruth of each sample is seed 000 Table 4, shown in brackets.\n\n## Calibrated parameters, 4-corner hang (Table 4)\n\n{t4}\nBest of the ICA runs, polished by Nelder–Mead over stiffness and natural length (the curve distance of\nICA alone in brackets). ± 2σ: the interval the photos allow, from the curvature of the cost and its\nresidual (nonlinear least squares); a parameter is identifiable when that interval is within 5 % of its\nvalue. Eq. 5 compares the quartics' coefficients in coordinates centred on the edge.\n\n## Validation on the 2-corner hang (Table 6)\n\n{t6}\n## Convergence (Fig. 13)\n\n![best cost per decade]({})\n\n## Taguchi main effects (Fig. 10)\n\n![main effects]({})\n\n## ICA, CMA-ES at the same budget, and Levenberg–Marquardt\n\nLevenberg–Marquardt (calibration by gradients) runs once per sample over stiffness and natural length for each topology, from the best node of the warm-start lattice ICA's runs share; its evaluations are equilibrium solves, each with the sensitivities its Jacobian comes from.\n\n{}",
        p.title,
        ctx.made_by(),
        rel(conv_svg),
        rel(effects_svg),
        markdown(&cmp)
    ) + &lm_intervals_section(&files.comparison, &res)?
        + &run_time_section(&res, &cmp)?;
    write_text(md, &text)?;
    ctx.item_done();
    Ok(())
}

/// Table 4: calibrated against ground truth (the dataset was made from Table 4).
pub fn table_4(
    res: &DataFrame,
    truth4: &BTreeMap<u32, BTreeMap<String, String>>,
) -> Result<String> {
    let mut t4 = String::from(
        "| sample | stiffness N/m ± 2σ (truth) | natural length mm ± 2σ (truth) | topology (truth) | objective Eq. 5 % (seed) | curve distance % (ICA alone) | spread of runs % | identifiable to 5 %: stiffness, natural length, damping, elongation |\n|---|---|---|---|---|---|---|---|\n",
    );
    let s = res.column("sample")?.str()?.clone();
    let f = |name: &str| -> Result<Float64Chunked> { Ok(res.column(name)?.f64()?.clone()) };
    let b = |name: &str| -> Result<BooleanChunked> { Ok(res.column(name)?.bool()?.clone()) };
    let (k, l0, eq5, cd, spread) = (
        f("stiffness_N_per_m")?,
        f("natural_length_m")?,
        f("objective_pct")?,
        f("curve_distance_pct")?,
        f("spread_curve_distance_pct")?,
    );
    let (dk, dl0, cd_ica) = (
        f("stiffness_uncertainty_N_per_m")?,
        f("natural_length_uncertainty_m")?,
        f("ica_curve_distance_pct")?,
    );
    let pm = |v: Option<f64>, scale: f64, digits: usize| match v {
        Some(v) => format!("{:.*}", digits, v * scale),
        None => "∞".into(),
    };
    let topo = res.column("topology")?.str()?.clone();
    let (ik, il, id, ie) = (
        b("identifiable_stiffness")?,
        b("identifiable_natural_length")?,
        b("identifiable_damping")?,
        b("identifiable_elongation_rate")?,
    );
    let yes = |v: Option<bool>| if v == Some(true) { "yes" } else { "no" };
    for r in 0..res.height() {
        let name = s.get(r).unwrap_or_default();
        let n = sample_number(name).unwrap_or(0);
        let t = truth4.get(&n);
        let tv = |c: &str| t.and_then(|t| t.get(c)).cloned().unwrap_or_default();
        t4 += &format!(
            "| {n} | {:.0} ± {} ({}) | {:.2} ± {} ({}) | {} ({}) | {:.3} ({}) | {:.3} ({:.3}) | {:.3} | {}, {}, {}, {} |\n",
            k.get(r).unwrap_or(f64::NAN),
            pm(dk.get(r), 1.0, 0),
            tv("spring_stiffness_N_per_m"),
            l0.get(r).unwrap_or(f64::NAN) * 1000.0,
            pm(dl0.get(r), 1000.0, 2),
            tv("natural_length_mm"),
            topo.get(r).unwrap_or_default(),
            tv("topology"),
            eq5.get(r).unwrap_or(f64::NAN),
            tv("error_pct"),
            cd.get(r).unwrap_or(f64::NAN),
            cd_ica.get(r).unwrap_or(f64::NAN),
            spread.get(r).unwrap_or(f64::NAN),
            yes(ik.get(r)),
            yes(il.get(r)),
            yes(id.get(r)),
            yes(ie.get(r)),
        );
    }
    Ok(t4)
}

/// Table 6: validation on the 2-corner hang.
pub fn table_6(val: &DataFrame, seed6: &BTreeMap<u32, String>) -> Result<String> {
    let mut t6 = String::from(
        "| sample | objective Eq. 5 % | seed 000 Table 6 % | curve distance % |\n|---|---|---|---|\n",
    );
    let (vs, ve, vc) = (
        val.column("sample")?.str()?.clone(),
        val.column("objective_pct")?.f64()?.clone(),
        val.column("curve_distance_pct")?.f64()?.clone(),
    );
    for r in 0..val.height() {
        let n = sample_number(vs.get(r).unwrap_or_default()).unwrap_or(0);
        t6 += &format!(
            "| {n} | {:.2} | {} | {:.3} |\n",
            ve.get(r).unwrap_or(f64::NAN),
            seed6.get(&n).cloned().unwrap_or_default(),
            vc.get(r).unwrap_or(f64::NAN)
        );
    }
    Ok(t6)
}

/// Fig. 13: best cost per decade of each sample's first run (a lazy group-by over every evaluation),
/// as SVG.
pub fn fig_13(evaluations: &Path) -> Result<String> {
    let conv = scan(evaluations)?
        .filter(col("run").eq(lit(0u32)))
        .group_by([col("sample"), col("decade")])
        .agg([
            col("cost_pct").min().alias("best"),
            col("cost_pct").mean().alias("mean"),
        ])
        .sort(["sample", "decade"], SortMultipleOptions::default())
        .collect()?;
    let mut panels: Panels = BTreeMap::new();
    let (cs, cdk, cb) = (
        conv.column("sample")?.str()?.clone(),
        conv.column("decade")?.u32()?.clone(),
        conv.column("best")?.f64()?.clone(),
    );
    let mut running: BTreeMap<String, f64> = BTreeMap::new();
    for r in 0..conv.height() {
        let name = format!(
            "sample {}",
            sample_number(cs.get(r).unwrap_or_default()).unwrap_or(0)
        );
        let best = running.entry(name.clone()).or_insert(f64::INFINITY);
        *best = best.min(cb.get(r).unwrap_or(f64::INFINITY));
        panels
            .entry("best cost".into())
            .or_default()
            .entry(name)
            .or_default()
            .push((cdk.get(r).unwrap_or(0) as f64, *best));
    }
    plot_panels(
        &panels,
        "decade",
        "best curve distance so far (% of side)",
        None,
    )
}

/// Fig. 10: the main effects of the tuning, as SVG.
pub fn fig_10(me: &DataFrame) -> Result<String> {
    let mut fx: Panels = BTreeMap::new();
    let (mf, ml, mv) = (
        me.column("factor")?.str()?.clone(),
        me.column("level")?.u32()?.clone(),
        me.column("mean_sn_db")?.f64()?.clone(),
    );
    for r in 0..me.height() {
        fx.entry("main effects".into())
            .or_default()
            .entry(mf.get(r).unwrap_or_default().to_string())
            .or_default()
            .push((ml.get(r).unwrap_or(0) as f64, mv.get(r).unwrap_or(f64::NAN)));
    }
    plot_panels(
        &fx,
        "factor level (1..3)",
        "mean S/N (dB, smaller-the-better)",
        None,
    )
}

/// The number of hang simulations of the calibration (cache misses: ICA, polish, identifiability
/// and the CMA-ES baseline's evaluations). Stage wall times are not read here (other stages'
/// manifests are not this stage's inputs): `drapelab status` lists them.
/// Levenberg–Marquardt's estimates with their 2σ intervals from JᵀJ beside the polished ICA
/// optimum's curvature-based ones, per sample (empty when no Levenberg–Marquardt row exists).
pub fn lm_intervals_section(comparison: &Path, res: &DataFrame) -> Result<String> {
    let lm = scan(comparison)?
        .filter(col("optimizer").eq(lit("levenberg-marquardt")))
        .select([
            col("sample"),
            col("stiffness_N_per_m").alias("lm_k"),
            col("stiffness_2sigma_N_per_m").alias("lm_k2"),
            col("natural_length_m").alias("lm_l"),
            col("natural_length_2sigma_m").alias("lm_l2"),
        ]);
    let table = res
        .clone()
        .lazy()
        .select([
            col("sample"),
            col("stiffness_N_per_m").alias("ica_k"),
            col("stiffness_uncertainty_N_per_m").alias("ica_k2"),
            col("natural_length_m").alias("ica_l"),
            col("natural_length_uncertainty_m").alias("ica_l2"),
        ])
        .join(
            lm,
            [col("sample")],
            [col("sample")],
            JoinArgs::new(JoinType::Inner),
        )
        .sort(["sample"], SortMultipleOptions::default())
        .collect()?;
    if table.height() == 0 {
        return Ok(String::new());
    }
    let f = |c: &str, i: usize| -> Result<Option<f64>> { Ok(table.column(c)?.f64()?.get(i)) };
    let pm = |v: Option<f64>, h: Option<f64>, scale: f64, digits: usize| match (v, h) {
        (Some(v), Some(h)) => format!("{:.digits$} ± {:.digits$}", v * scale, h * scale),
        (Some(v), None) => format!("{:.digits$} ± ∞", v * scale),
        _ => "—".to_string(),
    };
    let mut md = String::from(
        "\n## Intervals: Levenberg–Marquardt's JᵀJ beside the curvature\n\nStiffness (N/m) and natural \
length (mm) ± 2σ. Levenberg–Marquardt's from σ̂²(JᵀJ)⁻¹ at its optimum, its residuals (samples along the \
edges) taken as independent, which makes them narrower; the ICA optimum's from the cost's curvature with \
5 degrees of freedom per edge (Table 4). ∞: the cost is flat along that parameter.\n\n| sample | \
stiffness, LM | stiffness, ICA | natural length, LM | natural length, ICA |\n|---|---|---|---|---|\n",
    );
    let samples = table.column("sample")?.str()?.clone();
    for i in 0..table.height() {
        md += &format!(
            "| {} | {} | {} | {} | {} |\n",
            samples.get(i).unwrap_or(""),
            pm(f("lm_k", i)?, f("lm_k2", i)?, 1.0, 0),
            pm(f("ica_k", i)?, f("ica_k2", i)?, 1.0, 0),
            pm(f("lm_l", i)?, f("lm_l2", i)?, 1e3, 2),
            pm(f("ica_l", i)?, f("ica_l2", i)?, 1e3, 2),
        );
    }
    Ok(md)
}

/// The run-time section: each calibration's time beside its comparison's.
pub fn run_time_section(res: &DataFrame, cmp: &DataFrame) -> Result<String> {
    let sims_col = res.column("simulations")?.cast(&DataType::UInt64)?;
    let sims_ca = sims_col.u64()?;
    let sims: u64 = (0..sims_ca.len()).filter_map(|i| sims_ca.get(i)).sum();
    let cmaes: f64 = cmp
        .clone()
        .lazy()
        .filter(col("optimizer").eq(lit("cma-es")))
        .select([(col("mean_evaluations") * col("runs").cast(DataType::Float64)).sum()])
        .collect()?
        .column("mean_evaluations")?
        .f64()?
        .get(0)
        .unwrap_or(0.0);
    Ok(format!(
        "\n## Run time\n\nThe wall time of each stage's last run: `drapelab status PIPELINE` (from the \
stages' manifests).\n\nSimulations of the 4-corner hang in the calibration: {sims} (ICA, polish and identifiability, distinct \
parameter vectors) and {cmaes:.0} for the CMA-ES baseline.\n"
    ))
}
