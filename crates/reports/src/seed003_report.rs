//! `seed003-report`: seed 003's drape scenes side by side with the seed's numbers. Every input scene is
//! solved at its own grid and at twice its resolution (run times, grid-convergence gap, drape
//! coefficient and folds, penetration); the quarter table against Table 10.2, the rod against Table 10.4
//! (both contact treatments), a cantilever scene's load–displacement curve by incremental loading
//! against the single-step solve (§10.3.3), and the tables of any sweep inputs (e.g. the perturbation
//! sweep of a pedestal drape). Outputs: the Markdown report, an SVG of the drapes seen from above and
//! from the side, and an SVG of the load–displacement curve.

use crate::report::{Panels, markdown, plot_panels};
use crate::seed003_drawings::{drapes_png, drapes_svg};
use crate::seed003_rod::table_10_4;
pub use crate::seed003_scenes::{Solved, load, refined, solve_pair};
use anyhow::Result;
use drapelab_app::Job;
use drapelab_core::measure::drape_measures;
use drapelab_core::scene::{ContactMethod, Scene};
use drapelab_core::simulate::{Solution, solve_scene};
use drapelab_core::solve::{NoObserver, solve_static_loads};
use drapelab_record::write_text;
use polars::prelude::*;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

/// Parameters of a seed003-report stage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Seed003ReportParams {
    /// Title of the report.
    pub title: String,
    /// The seed's wall time of a scene (by scene name) on its Pentium II/266, s.
    #[serde(default)]
    pub seed_times_s: BTreeMap<String, f64>,
    /// Load increments of the load–displacement comparison. Default 50 (the seed's).
    #[serde(default = "default_steps")]
    pub load_steps: usize,
}

/// Default of `load_steps`: 50 load increments (the seed's).
pub fn default_steps() -> usize {
    50
}

/// Writes the seed 003 report.
pub fn run(ctx: &Job<'_>, p: &Seed003ReportParams) -> Result<()> {
    let scenes: Vec<Scene> = ctx
        .input_files("scenes")
        .iter()
        .map(|f| load(f))
        .collect::<Result<_>>()?;
    ctx.started(scenes.len() + 1);
    let solved: Vec<Solved> = scenes
        .par_iter()
        .map(|s| {
            let r = solve_pair(s);
            ctx.item_done();
            r
        })
        .collect();
    // A scene given in a slot, found among the solved ones by its name.
    let named = |slot: &str| -> Result<Option<&Solved>> {
        let Some(f) = ctx.optional_input(slot)? else {
            return Ok(None);
        };
        let name = load(f)?.name;
        Ok(solved.iter().find(|s| s.scene.name == name))
    };
    let mut md = scenes_section(ctx, p, &solved);
    if let (Some(q), Some(file)) = (
        named("quarter_table")?,
        ctx.optional_input("table_reference")?,
    ) {
        md += &table_10_2(q, file)?;
    }
    if let (Some(r), Some(file)) = (named("rod")?, ctx.optional_input("rod_reference")?) {
        md += &table_10_4(r, file)?;
    }
    let cantilever = ctx.optional_input("cantilever")?.map(load).transpose()?;
    let mut load_svg = String::new();
    if let Some(c) = &cantilever {
        let (text, svg) = load_displacement(c, p)?;
        md += &text;
        load_svg = svg;
    }
    if let (Some(c), Some(file)) = (&cantilever, ctx.optional_input("cantilever_reference")?)
        && let Some(exact) = drapelab_core::elastica::HeavyElastica::of_cantilever(c)
    {
        md += &table_10_1(c, &exact, file)?;
    }
    for f in ctx.input_files("sweeps") {
        md += &sweep_section(f)?;
    }
    md += &surfaces_section(ctx)?;
    write_outputs(ctx, md, &solved, &load_svg)?;
    ctx.item_done();
    Ok(())
}

/// Every scene at its grid and at twice its resolution.
pub fn scenes_section(ctx: &Job<'_>, p: &Seed003ReportParams, solved: &[Solved]) -> String {
    let mut md = format!(
        "# {}\n\n{}. Every scene of `datasets/scenes/` named below is \
solved at its own grid and at twice its resolution (2n − 1 lines per side); times are this machine's, \
the seed's are on a Pentium II/266.\n\n## Scenes\n\n",
        p.title,
        ctx.made_by()
    );
    md += "| scene | grid | contact | status | iterations | time s | time at 2× s | seed's time s | grid gap mm | DC % | folds | penetration m |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for s in solved {
        let m = s
            .coarse
            .report
            .is_converged()
            .then(|| drape_measures(&s.scene, &s.coarse.x));
        let _ = writeln!(
            md,
            "| {} | {}×{} | {} | {} | {} | {:.2} | {:.2} | {} | {} | {} | {} | {} |",
            s.scene.name,
            s.scene.cloth.nx,
            s.scene.cloth.ny,
            if s.scene.obstacles.is_empty() {
                "–"
            } else if s.scene.contact.method == ContactMethod::Barrier {
                "barrier"
            } else {
                "vertical gap"
            },
            s.coarse.report.status.as_str(),
            s.coarse.report.iterations,
            s.coarse.report.wall_time_s,
            s.fine.report.wall_time_s,
            p.seed_times_s
                .get(&s.scene.name)
                .map_or("–".into(), |t| format!("{t:.0}")),
            if s.gap_m.is_finite() {
                format!("{:.2}", s.gap_m * 1e3)
            } else {
                format!("– (2×: {})", s.fine.report.status.as_str())
            },
            m.and_then(|m| m.drape_coefficient_pct)
                .map_or("–".into(), |d| format!("{d:.1}")),
            m.and_then(|m| m.folds)
                .map_or("–".into(), |f| f.to_string()),
            m.map_or("–".into(), |m| format!("{:.1e}", m.max_penetration_m)),
        );
    }
    md += "\nGrid gap: the largest distance between a particle of the drape and the same material point on \
the grid twice as fine. DC: drape coefficient (S − S_s)/(S_f − S_s) of the vertical projection, for scenes \
on a table or pedestal (a quarter model stands for its whole sheet); folds: nodes of the projection's \
outline (not counted for a quarter model). A large grid gap on a pedestal or sphere is the fold \
pattern changing with the grid (the folds' number and place are a bifurcation), not a solver error.\n\n";
    md
}

/// Table 10.2: the quarter table's edge points.
pub fn table_10_2(q: &Solved, file: &Path) -> Result<String> {
    let mut md = String::new();
    md += "## Table 10.2: edge points of the concentric table drape (quarter model)\n\n| point | initial cm | seed 003 cm | drapelab cm | distance cm |\n|---|---|---|---|---|\n";
    for row in crate::calibration_report::read_csv(file)? {
        let f = |k: &str| {
            row.get(k)
                .and_then(|v| v.parse::<f64>().ok())
                .unwrap_or(f64::NAN)
        };
        let (x0, y0) = (f("x0_cm"), f("y0_cm"));
        let pt = q.coarse.at_material(x0 / 100.0, y0 / 100.0) * 100.0;
        let d =
            ((pt.x - f("x_cm")).powi(2) + (pt.y - f("y_cm")).powi(2) + (-pt.z - f("z_cm")).powi(2))
                .sqrt();
        let _ = writeln!(
            md,
            "| {} | ({x0}, {y0}, 0) | ({:.2}, {:.2}, {:.2}) | ({:.2}, {:.2}, {:.2}) | {d:.2} |",
            row.get("point").cloned().unwrap_or_default(),
            f("x_cm"),
            f("y_cm"),
            f("z_cm"),
            pt.x,
            pt.y,
            -pt.z
        );
    }
    md += "\nz is the drop (down positive). drapelab's quarter model: symmetry planes along x = 0 and \
y = 0, the part on the table fixed, the seed's 31 × 31 grid graded towards the table's edge \
(`cloth.refine_x_m`, `refine_y_m`; Fig. 10.3), drapelab's points interpolated at the same material points.\n\n";
    Ok(md)
}

/// Load–displacement by incremental loading against the single step (§10.3.3): the text and the SVG.
pub fn load_displacement(c: &Scene, p: &Seed003ReportParams) -> Result<(String, String)> {
    let mut md = String::new();
    let mut built = drapelab_core::build::build_scene(&c.clone().validated()?);
    let tip = built.grid.index(built.grid.nx - 1, built.grid.ny / 2);
    let opts = &c.solver.static_;
    let mut x = built.x0.clone();
    let t0 = Instant::now();
    let mut curve = vec![(0.0, 0.0)];
    let mut iters = 0;
    for k in 1..=p.load_steps {
        let load = k as f64 / p.load_steps as f64;
        let r = solve_static_loads(&mut built.model, &mut x, opts, &[load], &mut NoObserver);
        iters += r.iterations;
        curve.push((load, (built.x0[tip].z - x[tip].z) * 100.0));
    }
    let t_inc = t0.elapsed().as_secs_f64();
    let mut y = built.x0.clone();
    let t1 = Instant::now();
    let single = solve_static_loads(&mut built.model, &mut y, opts, &[1.0], &mut NoObserver);
    let t_one = t1.elapsed().as_secs_f64();
    let _ = write!(
        md,
        "## Load–displacement (§10.3.3): {}\n\nIncremental loading in {} steps: {iters} Newton \
iterations, {t_inc:.3} s, tip deflection {:.4} cm; single step: {} iterations, {t_one:.3} s \
({}), tip deflection {:.4} cm. The seed (Pentium II): 8.35 s in 50 steps against 0.39 s in one \
(warp). Curve: ![load–displacement](seed003_load_displacement.svg)\n\n",
        c.name,
        p.load_steps,
        curve.last().map_or(f64::NAN, |c| c.1),
        single.iterations,
        single.status.as_str(),
        (built.x0[tip].z - y[tip].z) * 100.0,
    );
    let mut panels = Panels::new();
    panels
        .entry("tip".into())
        .or_default()
        .insert(format!("{} increments", p.load_steps), curve);
    let load_svg = plot_panels(&panels, "load factor", "tip deflection (cm)", None)?;
    Ok((md, load_svg))
}

/// Table 10.1: the cantilever's free end against the grid, uniform and graded, beside the seed's and
/// the exact elastica.
pub fn table_10_1(
    c: &Scene,
    exact: &drapelab_core::elastica::HeavyElastica,
    file: &Path,
) -> Result<String> {
    let mut md = String::new();
    let seed_rows = crate::calibration_report::read_csv(file)?;
    let l = c.cloth.size_x_m;
    let (xe, ze) = exact.tip();
    let tip_cm = |sol: &Solution| {
        let q = sol.at(sol.grid.nx - 1, sol.grid.ny / 2) - sol.at(0, sol.grid.ny / 2);
        ((l - q.x) * 100.0, -q.z * 100.0)
    };
    let grids = cantilever_grids();
    let solved: Vec<(String, Solution)> = grids
        .par_iter()
        .map(|(label, k, spacing)| {
            let mut s = c.regridded(k + 1, c.cloth.ny);
            s.cloth.spacing = *spacing;
            // Fine strips take more Newton iterations from flat than the scene allows at its grid.
            s.solver.static_.max_iterations = s.solver.static_.max_iterations.max(5000);
            (label.clone(), solve_scene(&s, &mut NoObserver))
        })
        .collect();
    let _ = write!(
        md,
        "## Table 10.1: free end of the cantilever against the grid\n\n{}: exact elastica (crates/core/src/elastica.rs) \
−u = {:.4} cm, w = {:.4} cm. drapelab's grid of k intervals has k + 1 lines along the strip; non-uniform \
is cosine-graded towards both ends (grading {}), the seed's is finer at the clamp.\n\n| grid | seed 003 −u cm | \
seed 003 w cm | drapelab −u cm | drapelab w cm | drapelab distance to the elastica cm | status |\n|---|---|---|---|---|---|---|\n",
        c.name,
        (l - xe) * 100.0,
        -ze * 100.0,
        c.cloth.grading
    );
    for (label, sol) in &solved {
        let seed = seed_rows
            .iter()
            .find(|r| r.get("grid").is_some_and(|g| g == label));
        let get = |k: &str| {
            seed.and_then(|r| r.get(k))
                .cloned()
                .unwrap_or_else(|| "–".into())
        };
        let (u, w) = tip_cm(sol);
        let d = ((u - (l - xe) * 100.0).powi(2) + (w + ze * 100.0).powi(2)).sqrt();
        let num = |v: f64| {
            if sol.report.is_converged() {
                format!("{v:.4}")
            } else {
                "–".into()
            }
        };
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} | {} | {} |",
            label.replace("x1", "×1"),
            get("horizontal_displacement_minus_u_cm"),
            get("vertical_displacement_w_cm"),
            num(u),
            num(w),
            num(d),
            sol.report.status.as_str()
        );
    }
    md += "\n";
    Ok(md)
}

/// Table 10.1's grids: (label, intervals along the strip, spacing), uniform 5–320 and graded 56, 112.
fn cantilever_grids() -> Vec<(String, usize, drapelab_core::cloth::Spacing)> {
    [5usize, 10, 20, 40, 80, 160, 320]
        .iter()
        .map(|&k| {
            (
                format!("uniform {k}x1"),
                k,
                drapelab_core::cloth::Spacing::Uniform,
            )
        })
        .chain([56usize, 112].iter().map(|&k| {
            (
                format!("non-uniform {k}x1"),
                k,
                drapelab_core::cloth::Spacing::Graded,
            )
        }))
        .collect()
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
pub fn surfaces_section(ctx: &Job<'_>) -> Result<String> {
    let files = ctx.input_files("surfaces");
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
pub fn write_outputs(
    ctx: &Job<'_>,
    mut md: String,
    solved: &[Solved],
    load_svg: &str,
) -> Result<()> {
    md += "## The drapes\n\n![drapes seen from above and from the side](seed003_drapes.svg)\n";
    let drapes_svg = drapes_svg(solved)?;
    let montage = ctx.optional_output("montage");
    if montage.is_some() {
        let order: Vec<String> = solved
            .iter()
            .map(|s| format!("`{}`", s.scene.name))
            .collect();
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
        let img = drapes_png(solved);
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
