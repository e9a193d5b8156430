//! `report`: polars (lazy scans over the stage's Parquet inputs) for a summary table grouped by the
//! sweep's inputs, and a plotters SVG of one output against one input, per series; written as
//! Markdown (the first output, e.g. `reports/main.md`) beside the plot (the `.svg` output).

use anyhow::{Result, bail};
use drapelab_app::Job;
use drapelab_core::error::KeyError;
use drapelab_record::write_text;
use plotters::prelude::*;
use polars::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

/// Parameters of a report stage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReportParams {
    /// Title of the report.
    pub title: String,
    /// Columns to group the summary by. Default ["scene"].
    #[serde(default = "default_group")]
    pub group_by: Vec<String>,
    /// Column on the plot's x axis (a swept key with its unit, e.g. "material.mass_spring.stiffness_N_per_m").
    pub x: String,
    /// Column on the plot's y axis. Default "centre_z_m".
    #[serde(default = "default_y")]
    pub y: String,
    /// Columns whose values make one line each on the plot. Default: `group_by`.
    #[serde(default)]
    pub series: Vec<String>,
    /// A column whose values each get a panel of their own (stacked), e.g. "scene" when the scenes'
    /// values differ in scale. Default: one panel.
    #[serde(default)]
    pub facet: Option<String>,
    /// Free text placed under the title.
    #[serde(default)]
    pub notes: String,
    /// Whether the summary shows the mean wall time per point (`mean_wall_time_ms`). Default
    /// false: the report then holds no number of this machine, and a rerun elsewhere rewrites it
    /// unchanged (a tracked report stays clean in git).
    #[serde(default)]
    pub timings: bool,
}

impl ReportParams {
    /// Every column the parameters name, with its key.
    fn columns(&self) -> Vec<(String, &str)> {
        let mut v: Vec<(String, &str)> = Vec::new();
        for (i, c) in self.group_by.iter().enumerate() {
            v.push((format!("group_by[{i}]"), c));
        }
        for (i, c) in self.series.iter().enumerate() {
            v.push((format!("series[{i}]"), c));
        }
        v.push(("x".into(), &self.x));
        v.push(("y".into(), &self.y));
        if let Some(f) = &self.facet {
            v.push(("facet".into(), f));
        }
        v
    }
}

/// The columns every `sweep.parquet` has (its first and last row types); between them are the
/// swept keys, dotted scene keys.
fn sweep_columns() -> Vec<String> {
    let mut names = Vec::new();
    for fields in [
        drapelab_record::table_fields::<drapelab_app::sweeps::table::SweepPoint>(),
        drapelab_record::table_fields::<drapelab_app::sweeps::table::SweepOutcome>(),
    ] {
        names.extend(fields.into_iter().flatten().map(|f| f.name().clone()));
    }
    names
}

/// Refuses, when the plan loads, a column that is neither a column of `sweep.parquet` nor a swept
/// scene key (a dotted path such as `cloth.nx`): a report summarises sweep tables.
pub fn check(p: &ReportParams) -> Result<(), KeyError> {
    let known = sweep_columns();
    for (key, c) in p.columns() {
        if !c.contains('.') && !known.iter().any(|k| k == c) {
            return Err(KeyError::new(
                key,
                format!(
                    "unknown column `{c}`: name a column of sweep.parquet ({}) or a swept scene key \
                     such as `cloth.nx`",
                    known.join(", ")
                ),
            ));
        }
    }
    Ok(())
}

/// Refuses, before any query runs, a named column that the tables do not have: an input error
/// naming the pipeline, `stages.STAGE.params.KEY`, the column and the tables' columns (exit 2).
pub fn check_schema<I>(ctx: &Job<'_, I>, lf: &mut LazyFrame, p: &ReportParams) -> Result<()> {
    let schema = lf.collect_schema()?;
    for (key, c) in p.columns() {
        if schema.get(c).is_none() {
            let names: Vec<String> = schema.iter_names().map(|n| n.to_string()).collect();
            return Err(ctx
                .param_error(
                    &key,
                    format!(
                        "the tables have no column `{c}` (they have: {})",
                        names.join(", ")
                    ),
                )
                .into());
        }
    }
    Ok(())
}

pub use drapelab_app::{Lines, Panels};

/// Default of `group`: the columns a report groups by.
pub fn default_group() -> Vec<String> {
    vec!["scene".into()]
}
/// Default of `y`: the column a report plots.
pub fn default_y() -> String {
    "centre_z_m".into()
}

/// Scans every input table lazily, as one frame.
pub fn scan_all(inputs: &[std::path::PathBuf]) -> Result<LazyFrame> {
    let lfs = inputs
        .iter()
        .filter(|p| p.extension().is_some_and(|e| e == "parquet"))
        .map(|p| {
            LazyFrame::scan_parquet(
                PlRefPath::from(p.to_string_lossy().as_ref()),
                ScanArgsParquet::default(),
            )
        })
        .collect::<PolarsResult<Vec<_>>>()?;
    if lfs.is_empty() {
        bail!("a report needs at least one Parquet input");
    }
    Ok(concat(lfs, UnionArgs::default())?)
}

/// A DataFrame as a Markdown table.
pub fn markdown(df: &DataFrame) -> String {
    let names: Vec<String> = df
        .get_column_names()
        .iter()
        .map(|s| s.to_string())
        .collect();
    let mut s = format!(
        "| {} |\n|{}|\n",
        names.join(" | "),
        names.iter().map(|_| "---").collect::<Vec<_>>().join("|")
    );
    for r in 0..df.height() {
        let cells: Vec<String> = df
            .columns()
            .iter()
            .map(|c| match c.get(r) {
                Ok(AnyValue::Float64(v)) if v != 0.0 && (v.abs() < 1e-3 || v.abs() >= 1e6) => {
                    format!("{v:.3e}")
                }
                Ok(AnyValue::Float64(v)) => format!("{v:.6}"),
                Ok(AnyValue::String(v)) => v.to_string(),
                Ok(v) => v.to_string(),
                Err(_) => String::new(),
            })
            .collect();
        s += &format!("| {} |\n", cells.join(" | "));
    }
    s
}

/// The tables a report reads.
pub struct ReportInputs {
    /// Sweep tables (a sweep stage's sweep.parquet).
    pub tables: Vec<std::path::PathBuf>,
}

/// Runs the stage.
pub fn run(ctx: &Job<'_, ReportInputs>, p: &ReportParams) -> Result<()> {
    let md = ctx.output("markdown")?;
    let svg = ctx.output("plot")?;
    ctx.started(2);
    let mut lf = scan_all(&ctx.inputs.tables)?;
    check_schema(ctx, &mut lf, p)?;
    let group: Vec<Expr> = p.group_by.iter().map(|c| col(c.as_str())).collect();
    let aggs = summary_columns(p);
    let summary = lf
        .clone()
        .group_by(group.clone())
        .agg(aggs)
        .sort(p.group_by.clone(), SortMultipleOptions::default())
        .collect()?;
    ctx.item_done();
    let series = if p.series.is_empty() {
        p.group_by.clone()
    } else {
        p.series.clone()
    };
    let mut cols: Vec<Expr> = series
        .iter()
        .map(|c| col(c.as_str()).cast(DataType::String))
        .collect();
    if let Some(f) = &p.facet {
        cols.push(col(f.as_str()).cast(DataType::String).alias("__facet"));
    }
    cols.push(col(p.x.as_str()).cast(DataType::Float64).alias("__x"));
    cols.push(col(p.y.as_str()).cast(DataType::Float64).alias("__y"));
    let pts = lf
        .filter(col("status").eq(lit(drapelab_core::solve::Status::Converged.as_str())))
        .select(cols)
        .sort(["__x"], SortMultipleOptions::default())
        .collect()?;
    let panels = panels_of(&pts, &series, p.facet.is_some())?;
    let svg_text = plot_panels(&panels, &p.x, &p.y, p.facet.as_deref())?;
    write_text(svg, &svg_text)?;
    let svg_rel = svg
        .strip_prefix(md.parent().unwrap_or(Path::new("")))
        .unwrap_or(svg)
        .to_string_lossy()
        .to_string();
    let mut text = format!("# {}\n\n", p.title);
    if !p.notes.is_empty() {
        text += &format!("{}\n\n", p.notes.trim());
    }
    text += &format!("{} from:\n\n", ctx.made_by());
    for i in &ctx.inputs.tables {
        text += &format!("- `{}`\n", i.strip_prefix(&ctx.root).unwrap_or(i).display());
    }
    text += &format!(
        "\n## Summary by {}\n\n{}\n",
        p.group_by.join(", "),
        markdown(&summary)
    );
    text += &format!(
        "\n## `{}` against `{}` (converged points)\n\n![{} against {}]({svg_rel})\n",
        p.y, p.x, p.y, p.x
    );
    write_text(md, &text)?;
    ctx.item_done();
    Ok(())
}

/// The summary's columns per group: points, converged, the mean wall time (with `timings`), the
/// mean iterations and the y column's range.
fn summary_columns(p: &ReportParams) -> Vec<Expr> {
    let mut aggs = vec![
        len().alias("points"),
        col("status")
            .eq(lit(drapelab_core::solve::Status::Converged.as_str()))
            .sum()
            .alias("converged"),
    ];
    if p.timings {
        aggs.push(
            (col("wall_time_s") * lit(1000.0))
                .mean()
                .alias("mean_wall_time_ms"),
        );
    }
    aggs.extend([
        col("iterations").mean().alias("mean_iterations"),
        col(p.y.as_str()).min().alias(format!("min_{}", p.y)),
        col(p.y.as_str()).max().alias(format!("max_{}", p.y)),
    ]);
    aggs
}

/// The plot's points by panel (facet value) and line (series values), from the columns `__x`,
/// `__y` and `__facet` of `pts`.
fn panels_of(pts: &DataFrame, series: &[String], faceted: bool) -> Result<Panels> {
    let mut panels: Panels = BTreeMap::new();
    let xs = pts.column("__x")?.f64()?.clone();
    let ys = pts.column("__y")?.f64()?.clone();
    let text = |name: &str, r: usize| {
        pts.column(name)
            .ok()
            .and_then(|s| s.str().ok().and_then(|s| s.get(r).map(str::to_string)))
            .unwrap_or_default()
    };
    for r in 0..pts.height() {
        let label = series
            .iter()
            .map(|k| format!("{}={}", k.rsplit('.').next().unwrap_or(k), text(k, r)))
            .collect::<Vec<_>>()
            .join(", ");
        let panel = if faceted {
            text("__facet", r)
        } else {
            String::new()
        };
        if let (Some(x), Some(y)) = (xs.get(r), ys.get(r)) {
            panels
                .entry(panel)
                .or_default()
                .entry(label)
                .or_default()
                .push((x, y));
        }
    }
    Ok(panels)
}

/// Draws one panel per facet value (stacked), each with one line per series, to an SVG string;
/// the axes are labelled with the column names, which carry their units.
pub fn plot_panels(
    panels: &Panels,
    x_label: &str,
    y_label: &str,
    facet: Option<&str>,
) -> Result<String> {
    let mut out = String::new();
    {
        let k = panels.len().max(1);
        let root = SVGBackend::with_string(&mut out, (900, 420 * k as u32)).into_drawing_area();
        root.fill(&WHITE)?;
        let areas = root.split_evenly((k, 1));
        for (area, (name, lines)) in areas.iter().zip(panels) {
            let caption = match facet {
                Some(f) => format!("{f} = {name}"),
                None => format!("{y_label} against {x_label}"),
            };
            draw_lines(area, lines, x_label, y_label, &caption)?;
        }
        root.present()?;
    }
    Ok(out)
}

/// Draws one line per group on a chart.
pub fn draw_lines<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    lines: &Lines,
    x_label: &str,
    y_label: &str,
    caption: &str,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let all: Vec<(f64, f64)> = lines.values().flatten().copied().collect();
    let (mut x0, mut x1, mut y0, mut y1) = all.iter().fold(
        (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ),
        |a, &(x, y)| (a.0.min(x), a.1.max(x), a.2.min(y), a.3.max(y)),
    );
    if all.is_empty() {
        (x0, x1, y0, y1) = (0.0, 1.0, 0.0, 1.0);
    }
    let padx = ((x1 - x0) * 0.05).max(1e-12);
    let pady = ((y1 - y0) * 0.08).max(1e-12);
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(48)
        .y_label_area_size(90)
        .build_cartesian_2d((x0 - padx)..(x1 + padx), (y0 - pady)..(y1 + pady))?;
    chart
        .configure_mesh()
        .x_desc(x_label)
        .y_desc(y_label)
        .draw()?;
    for (k, (label, pts)) in lines.iter().enumerate() {
        let color = Palette99::pick(k).to_rgba();
        chart
            .draw_series(LineSeries::new(pts.iter().copied(), color.stroke_width(2)))?
            .label(label.clone())
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 18, y)], color.stroke_width(2))
            });
        chart.draw_series(
            pts.iter()
                .map(|&(x, y)| Circle::new((x, y), 3, color.filled())),
        )?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerRight)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()?;
    Ok(())
}
