//! `seed003-report`: seed 003's drape scenes side by side with the seed's numbers, from a
//! `seed003-solve` stage's tables (it solves nothing): every scene at its own grid and at twice its
//! resolution (run times, grid-convergence gap, drape coefficient and folds, penetration); the quarter
//! table against Table 10.2, the rod against Table 10.4 (every contact treatment, and its grid study),
//! the cantilever's load–displacement curve by incremental loading against the single step (§10.3.3)
//! and its free end against the grid (Table 10.1), and the tables of any sweep inputs. Outputs: the
//! Markdown report, an SVG of the drapes seen from above and from the side, the montage of their
//! rendered surfaces, and an SVG of the load–displacement curve.

use crate::report::{Panels, markdown, plot_panels};
use crate::seed003_drawings::{drapes_png, drapes_svg};
use crate::seed003_rod::table_10_4;
use crate::seed003_scenes::{Drape, drapes};
use anyhow::{Result, bail};
use drapelab_app::Job;
use drapelab_app::seed003::tables::{
    CantileverGridRow, LoadStepRow, Loading, Seed003SceneRow, TableEdgeRow,
};
use drapelab_core::scene::ContactMethod;
use drapelab_core::solve::Status;
use drapelab_record::{read_table, write_text};
use polars::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Parameters of a seed003-report stage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Seed003ReportParams {
    /// Title of the report.
    pub title: String,
    /// The seed's wall time of a scene (by scene name) on its Pentium II/266, s.
    #[serde(default)]
    pub seed_times_s: BTreeMap<String, f64>,
}

/// The files a seed 003 report reads: a seed003-solve stage's tables, the seed's, sweeps and pictures.
pub struct Seed003ReportInputs {
    /// A seed003-solve stage's scenes.parquet.
    pub scenes: PathBuf,
    /// A seed003-solve stage's drapes.parquet.
    pub drapes: PathBuf,
    /// A seed003-solve stage's table_edges.parquet (with `table_reference`: Table 10.2).
    pub table_edges: Option<PathBuf>,
    /// Table 10.2's edge points (fvm_table_drape_edges.csv).
    pub table_reference: Option<PathBuf>,
    /// A seed003-solve stage's rod.parquet (with `rod_grid` and `rod_reference`: Table 10.4).
    pub rod: Option<PathBuf>,
    /// A seed003-solve stage's rod_grid.parquet.
    pub rod_grid: Option<PathBuf>,
    /// Table 10.4's corner A (fvm_rod_corner.csv).
    pub rod_reference: Option<PathBuf>,
    /// A seed003-solve stage's load_displacement.parquet (§10.3.3).
    pub load_displacement: Option<PathBuf>,
    /// A seed003-solve stage's cantilever_grid.parquet (with `cantilever_reference`: Table 10.1).
    pub cantilever_grid: Option<PathBuf>,
    /// Table 10.1's free end against the grid (fvm_cantilever_convergence.csv).
    pub cantilever_reference: Option<PathBuf>,
    /// Sweep tables shown as they are.
    pub sweeps: Vec<PathBuf>,
    /// Pictures of textured drape surfaces (surface stages), shown in §10.8's section.
    pub surfaces: Vec<PathBuf>,
}

/// Writes the seed 003 report.
pub fn run(ctx: &Job<'_, Seed003ReportInputs>, p: &Seed003ReportParams) -> Result<()> {
    let files = &ctx.inputs;
    ctx.started(1);
    let scenes = read_table::<Seed003SceneRow>(&files.scenes)?;
    let drapes = drapes(&scenes, &read_table(&files.drapes)?)?;
    let mut md = scenes_section(ctx, p, &scenes);
    if let (Some(t), Some(file)) = (&files.table_edges, &files.table_reference) {
        md += &table_10_2(&read_table(t)?, file)?;
    }
    if let (Some(r), Some(g), Some(file)) = (&files.rod, &files.rod_grid, &files.rod_reference) {
        md += &table_10_4(&read_table(r)?, &read_table(g)?, file)?;
    }
    let mut load_svg = String::new();
    if let Some(f) = &files.load_displacement {
        let (text, svg) = load_displacement(&read_table(f)?)?;
        md += &text;
        load_svg = svg;
    }
    if let (Some(g), Some(file)) = (&files.cantilever_grid, &files.cantilever_reference) {
        md += &table_10_1(&read_table(g)?, file)?;
    }
    for f in &files.sweeps {
        md += &sweep_section(f)?;
    }
    md += &surfaces_section(ctx)?;
    write_outputs(ctx, md, &drapes, &load_svg)?;
    ctx.item_done();
    Ok(())
}

/// Every scene at its grid and at twice its resolution.
pub fn scenes_section<I>(
    ctx: &Job<'_, I>,
    p: &Seed003ReportParams,
    scenes: &[Seed003SceneRow],
) -> String {
    let mut md = format!(
        "# {}\n\n{}. Every scene of `datasets/scenes/` named below is \
solved at its own grid and at twice its resolution (2n − 1 lines per side); times are this machine's, \
the seed's are on a Pentium II/266.\n\n## Scenes\n\n",
        p.title,
        ctx.made_by()
    );
    md += "| scene | grid | contact | status | iterations | time s | time at 2× s | seed's time s | grid gap mm | DC % | folds | penetration m |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for s in scenes {
        let _ = writeln!(
            md,
            "| {} | {}×{} | {} | {} | {} | {:.2} | {:.2} | {} | {} | {} | {} | {} |",
            s.scene,
            s.nx,
            s.ny,
            match s.contact {
                None => "–",
                Some(ContactMethod::Barrier) => "barrier",
                Some(ContactMethod::VerticalGap) => "vertical gap",
            },
            s.status.as_str(),
            s.iterations,
            s.wall_time_s,
            s.fine_wall_time_s,
            p.seed_times_s
                .get(&s.scene)
                .map_or("–".into(), |t| format!("{t:.0}")),
            match s.grid_gap_m {
                Some(g) => format!("{:.2}", g * 1e3),
                None => format!("– (2×: {})", s.fine_status.as_str()),
            },
            s.drape_coefficient_pct
                .map_or("–".into(), |d| format!("{d:.1}")),
            s.folds.map_or("–".into(), |f| f.to_string()),
            s.max_penetration_m
                .map_or("–".into(), |m| format!("{m:.1e}")),
        );
    }
    md += "\nGrid gap: the largest distance between a particle of the drape and the same material point on \
the grid twice as fine. DC: drape coefficient (S − S_s)/(S_f − S_s) of the vertical projection, for scenes \
on a table or pedestal (a quarter model stands for its whole sheet); folds: nodes of the projection's \
outline (not counted for a quarter model). A large grid gap on a pedestal or sphere is the fold \
pattern changing with the grid (the folds' number and place are a bifurcation), not a solver error.\n\n";
    md
}

/// Table 10.2: the quarter table's edge points, drapelab's (`edges`, in the reference's order)
/// beside the seed's (`file`).
pub fn table_10_2(edges: &[TableEdgeRow], file: &Path) -> Result<String> {
    let mut md = String::new();
    md += "## Table 10.2: edge points of the concentric table drape (quarter model)\n\n| point | initial cm | seed 003 cm | drapelab cm | distance cm |\n|---|---|---|---|---|\n";
    let rows = crate::calibration_report::read_csv(file)?;
    if rows.len() != edges.len() {
        bail!(
            "{}: {} points, the table_edges table has {}",
            file.display(),
            rows.len(),
            edges.len()
        );
    }
    for (row, e) in rows.iter().zip(edges) {
        let f = |k: &str| crate::seed003_rod::cm_field(row, k);
        let (x0, y0) = (f("x0_cm"), f("y0_cm"));
        let pt = (e.x_m * 100.0, e.y_m * 100.0, e.drop_m * 100.0);
        let d =
            ((pt.0 - f("x_cm")).powi(2) + (pt.1 - f("y_cm")).powi(2) + (pt.2 - f("z_cm")).powi(2))
                .sqrt();
        let _ = writeln!(
            md,
            "| {} | ({x0}, {y0}, 0) | ({:.2}, {:.2}, {:.2}) | ({:.2}, {:.2}, {:.2}) | {d:.2} |",
            e.point,
            f("x_cm"),
            f("y_cm"),
            f("z_cm"),
            pt.0,
            pt.1,
            pt.2
        );
    }
    md += "\nz is the drop (down positive). drapelab's quarter model: symmetry planes along x = 0 and \
y = 0, the part on the table fixed, the seed's 31 × 31 grid graded towards the table's edge \
(`cloth.refine_x_m`, `refine_y_m`; Fig. 10.3), drapelab's points interpolated at the same material points.\n\n";
    Ok(md)
}

/// Load–displacement by incremental loading against the single step (§10.3.3), from the steps'
/// rows: the text and the SVG.
pub fn load_displacement(steps: &[LoadStepRow]) -> Result<(String, String)> {
    let increments: Vec<&LoadStepRow> = steps
        .iter()
        .filter(|r| r.loading == Loading::Increments)
        .collect();
    let (Some(last), Some(single)) = (
        increments.last(),
        steps.iter().find(|r| r.loading == Loading::SingleStep),
    ) else {
        bail!("the load_displacement table needs increments and a single step");
    };
    let mut md = String::new();
    let curve: Vec<(f64, f64)> = std::iter::once((0.0, 0.0))
        .chain(
            increments
                .iter()
                .map(|r| (r.load_factor, r.tip_deflection_m * 100.0)),
        )
        .collect();
    let _ = write!(
        md,
        "## Load–displacement (§10.3.3): {}\n\nIncremental loading in {} steps: {} Newton \
iterations, {:.3} s, tip deflection {:.4} cm; single step: {} iterations, {:.3} s \
({}), tip deflection {:.4} cm. The seed (Pentium II): 8.35 s in 50 steps against 0.39 s in one \
(warp). Curve: ![load–displacement](seed003_load_displacement.svg)\n\n",
        last.scene,
        increments.len(),
        last.iterations,
        last.wall_time_s,
        curve.last().map_or(f64::NAN, |c| c.1),
        single.iterations,
        single.wall_time_s,
        single.status.as_str(),
        single.tip_deflection_m * 100.0,
    );
    let mut panels = Panels::new();
    panels
        .entry("tip".into())
        .or_default()
        .insert(format!("{} increments", increments.len()), curve);
    let load_svg = plot_panels(&panels, "load factor", "tip deflection (cm)", None)?;
    Ok((md, load_svg))
}

/// Table 10.1: the cantilever's free end against the grid, uniform and graded (`grids`), beside
/// the seed's (`file`) and the exact elastica.
pub fn table_10_1(grids: &[CantileverGridRow], file: &Path) -> Result<String> {
    let Some(first) = grids.first() else {
        return Ok(String::new());
    };
    let mut md = String::new();
    let seed_rows = crate::calibration_report::read_csv(file)?;
    let (exact_u, exact_w) = (first.exact_minus_u_m * 100.0, first.exact_w_m * 100.0);
    let _ = write!(
        md,
        "## Table 10.1: free end of the cantilever against the grid\n\n{}: exact elastica (crates/core/src/elastica.rs) \
−u = {:.4} cm, w = {:.4} cm. drapelab's grid of k intervals has k + 1 lines along the strip; non-uniform \
is cosine-graded towards both ends (grading {}), the seed's is finer at the clamp.\n\n| grid | seed 003 −u cm | \
seed 003 w cm | drapelab −u cm | drapelab w cm | drapelab distance to the elastica cm | status |\n|---|---|---|---|---|---|---|\n",
        first.scene, exact_u, exact_w, first.grading
    );
    for g in grids {
        let seed = seed_rows
            .iter()
            .find(|r| r.get("grid").is_some_and(|x| *x == g.grid));
        let get = |k: &str| {
            seed.and_then(|r| r.get(k))
                .cloned()
                .unwrap_or_else(|| "–".into())
        };
        let (u, w) = (g.minus_u_m * 100.0, g.w_m * 100.0);
        let d = ((u - exact_u).powi(2) + (w - exact_w).powi(2)).sqrt();
        let num = |v: f64| {
            if g.status == Status::Converged {
                format!("{v:.4}")
            } else {
                "–".into()
            }
        };
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} | {} | {} |",
            g.grid.replace("x1", "×1"),
            get("horizontal_displacement_minus_u_cm"),
            get("vertical_displacement_w_cm"),
            num(u),
            num(w),
            num(d),
            g.status.as_str()
        );
    }
    md += "\n";
    Ok(md)
}

/// A sweep table as it is (corner columns and solver details left out).
pub fn sweep_section(f: &Path) -> Result<String> {
    let mut md = String::new();
    let df = LazyFrame::scan_parquet(
        PlRefPath::from(f.to_string_lossy().as_ref()),
        ScanArgsParquet::default(),
    )?
    .collect()?;
    let keep: Vec<String> = df
        .get_column_names()
        .iter()
        .map(|c| c.to_string())
        .filter(|c| {
            !c.starts_with("corner_")
                && ![
                    "particles",
                    "solver",
                    "linear_solves",
                    "max_residual_N",
                    "point",
                ]
                .contains(&c.as_str())
        })
        .collect();
    let df = df.select(keep)?;
    let _ = write!(
        md,
        "## Sweep `{}`\n\n{}\n",
        f.parent()
            .and_then(|d| d.file_name())
            .map(|n| n.to_string_lossy())
            .unwrap_or_default(),
        markdown(&df)
    );
    Ok(md)
}

/// Seed 003 §10.8's textured surfaces: the pictures of the `surfaces` input, each captioned with its
/// surface.json (beside the picture when the stage wrote one) or its file name.
pub fn surfaces_section(ctx: &Job<'_, Seed003ReportInputs>) -> Result<String> {
    let files = &ctx.inputs.surfaces;
    if files.is_empty() {
        return Ok(String::new());
    }
    let md_dir = ctx.output("markdown")?.parent().map(Path::to_path_buf);
    let mut md = String::from(
        "## Textured surfaces (§10.8)\n\nAs seed 003's Fig. 10.28: each drape interpolated by a bicubic B-spline \
surface through every particle (uniform knots), a disc extended to the rectangle and trimmed along its outline \
(closed cubic B-splines in the parameter plane), the fabric texture laid on the warp and weft with the repeats \
given; the `.glb` beside each run opens in Blender or any glTF viewer (`drapelab surface --help`).\n\n",
    );
    for f in files {
        let name = f
            .file_name()
            .map(|n| n.to_string_lossy().to_string())
            .unwrap_or_default();
        let link = if f.parent().map(Path::to_path_buf) == md_dir {
            name.clone()
        } else {
            f.display().to_string()
        };
        let _ = writeln!(md, "![{name}]({link})\n");
    }
    Ok(md)
}

/// Writes the report, the drapes' SVG and, when asked, the load–displacement SVG and the montage.
pub fn write_outputs<I>(
    ctx: &Job<'_, I>,
    mut md: String,
    drapes: &[Drape],
    load_svg: &str,
) -> Result<()> {
    md += "## The drapes\n\n![drapes seen from above and from the side](seed003_drapes.svg)\n";
    let drapes_svg = drapes_svg(drapes)?;
    let montage = ctx.optional_output("montage");
    if montage.is_some() {
        let order: Vec<String> = drapes.iter().map(|d| format!("`{}`", d.name)).collect();
        let _ = write!(
            md,
            "\nEach drape as its smooth bicubic B-spline surface (seed 003 §10.8; a disc trimmed along its \
outline), lit by a key and a fill light, orthographic, 30° above the horizon and turned 30° about the \
vertical; pedestal and table drapes also from straight above (their vertical projection). Left to right \
and top to bottom: {}.\n\n\
![rendered drapes](seed003_drapes.png)\n",
            order.join(", ")
        );
    }
    if let Some(out) = montage {
        let img = drapes_png(drapes);
        drapelab_record::write_atomic(out, |f| {
            img.write_to(&mut std::io::BufWriter::new(f), image::ImageFormat::Png)?;
            Ok(())
        })?;
    }
    if let Some(out) = ctx.optional_output("load_displacement") {
        write_text(out, load_svg)?;
    }
    write_text(ctx.output("drapes")?, &drapes_svg)?;
    write_text(ctx.output("markdown")?, &md)?;
    Ok(())
}
