//! `seed003-report`: seed 003's drape scenes side by side with the seed's numbers. Every input scene is
//! solved at its own grid and at twice its resolution (run times, grid-convergence gap, drape
//! coefficient and folds, penetration); the quarter table against Table 10.2, the rod against Table 10.4
//! (both contact treatments), a cantilever scene's load–displacement curve by incremental loading
//! against the single-step solve (§10.3.3), and the tables of any sweep inputs (e.g. the perturbation
//! sweep of a pedestal drape). Outputs: the Markdown report, an SVG of the drapes seen from above and
//! from the side, and an SVG of the load–displacement curve.

use crate::report::{Panels, markdown, plot_panels};
use anyhow::{Context, Result};
use drapelab_app::Job;
use drapelab_core::measure::drape_measures;
use drapelab_core::scene::{ContactMethod, Scene};
use drapelab_core::simulate::{Solution, solve_scene};
use drapelab_core::solve::{NoObserver, solve_static_loads};
use drapelab_record::write_text;
use plotters::prelude::*;
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

/// The scene on a grid twice as fine (2n − 1 lines per side; pinned particles moved with it).
pub fn refined(scene: &Scene) -> Scene {
    scene.regridded(2 * scene.cloth.nx - 1, 2 * scene.cloth.ny - 1)
}

/// A scene solved on its grid and on one twice as fine, with the gap between the two drapes.
pub struct Solved {
    scene: Scene,
    coarse: Solution,
    fine: Solution,
    gap_m: f64,
}

/// Solves a scene on its grid and on [`refined`]'s.
pub fn solve_pair(scene: &Scene) -> Solved {
    let coarse = solve_scene(scene, &mut NoObserver);
    let fine = solve_scene(&refined(scene), &mut NoObserver);
    let gap_m = if coarse.report.is_converged() && fine.report.is_converged() {
        let g = &coarse.grid;
        (0..g.ny)
            .flat_map(|j| (0..g.nx).map(move |i| (i, j)))
            .map(|(i, j)| (coarse.at(i, j) - fine.at_material(g.xs[i], g.ys[j])).norm())
            .fold(0.0, f64::max)
    } else {
        f64::NAN
    };
    Solved {
        scene: scene.clone(),
        coarse,
        fine,
        gap_m,
    }
}

/// Loads a seed 003 scene.
pub fn load(path: &Path) -> Result<Scene> {
    Ok(Scene::load(path, &[])?.scene.into_inner())
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

/// Table 10.4: the rod's corner A, both contact treatments, and its grid study.
pub fn table_10_4(r: &Solved, file: &Path) -> Result<String> {
    let mut md = String::new();
    md += "## Table 10.4: corner A of the polyester sheet on the rod\n\n| source | x cm | y cm | drop cm | distance to the experiment cm |\n|---|---|---|---|---|\n";
    let rows = crate::calibration_report::read_csv(file)?;
    let f = |row: &BTreeMap<String, String>, k: &str| {
        row.get(k)
            .and_then(|v| v.parse::<f64>().ok())
            .unwrap_or(f64::NAN)
    };
    let exp = rows
        .iter()
        .find(|r| r.get("source").is_some_and(|s| s.starts_with("experiment")))
        .map(|r| (f(r, "x_cm"), f(r, "y_cm"), f(r, "z_cm")))
        .context("no experiment row in fvm_rod_corner.csv")?;
    let dist = |x: f64, y: f64, z: f64| between((x, y, z), exp);
    for row in &rows {
        let (x, y, z) = (f(row, "x_cm"), f(row, "y_cm"), f(row, "z_cm"));
        let _ = writeln!(
            md,
            "| {} | {x:.2} | {y:.2} | {z:.2} | {:.2} |",
            row.get("source").cloned().unwrap_or_default(),
            dist(x, y, z)
        );
    }
    let fe = rows
        .iter()
        .find(|r| {
            r.get("source")
                .is_some_and(|s| s.starts_with("finite-element"))
        })
        .map(|r| (f(r, "x_cm"), f(r, "y_cm"), f(r, "z_cm")))
        .unwrap_or((f64::NAN, f64::NAN, f64::NAN));
    let fe_distance = between(fe, exp);
    // The contact treatments, and the materials: Table 10.3 as the seed takes it (no twist
    // rigidity), with an isotropic plate's twist √(D_warp D_weft) that the KES data do not give,
    // and Deng's finite-element material (isotropic: the warp rigidity in every direction).
    let materials = rod_materials(&r.scene);
    let variants: Vec<(String, Scene)> = materials
        .iter()
        .flat_map(|(m, base)| {
            let mut vg = base.clone();
            vg.contact.method = ContactMethod::VerticalGap;
            let mut fr = base.clone();
            fr.contact.friction_coefficient = 0.3;
            [
                (format!("vertical gap (sticky), {m}"), vg),
                (format!("barrier with friction μ = 0.3 (lagged), {m}"), fr),
            ]
        })
        .collect();
    let solved_variants: Vec<(&str, Solution)> = variants
        .par_iter()
        .map(|(l, s)| (l.as_str(), solve_scene(s, &mut NoObserver)))
        .collect();
    let ours = std::iter::once(("barrier (frictionless), Table 10.3", &r.coarse))
        .chain(solved_variants.iter().map(|(l, s)| (*l, s)));
    // The must-show's verdict on the seed's scene: Table 10.3's material (with or without the
    // twist rigidity it does not give); Deng's material is reported beside it.
    let mut best = (f64::INFINITY, String::new());
    let mut best_deng = (f64::INFINITY, String::new());
    for (label, sol) in ours {
        let ((ax, ay, az), (bx, by, bz)) = corner_a(sol);
        let d = dist(ax, ay, az);
        let slot = if label.contains("Deng") {
            &mut best_deng
        } else {
            &mut best
        };
        if sol.report.is_converged() && d < slot.0 {
            *slot = (d, label.to_string());
        }
        let _ = writeln!(
            md,
            "| drapelab, {label} ({}) | {ax:.2} | {ay:.2} | {az:.2} | {d:.2} (corner B: ({bx:.2}, {by:.2}, {bz:.2})) |",
            sol.report.status.as_str(),
        );
    }
    let _ = write!(
        md,
        "\nCorner B is shown turned by 180° about the vertical (where it would be if the drape kept the \
scene's symmetry; frictionless contact lets the sheet roll to one side of the rod). With Table 10.3's \
material the closest of drapelab's treatments at the seed's 33 × 33 grid is {} at {:.2} cm from the \
experiment; the finite elements are at {fe_distance:.2} cm: the issue's must-show (closer than the \
finite elements) is {}. With the finite elements' own material the closest is {} at {:.2} cm, but that \
is a coarse grid's stiffness: the grid study below refines it away.\n\n",
        best.1,
        best.0,
        if best.0 < fe_distance {
            "met"
        } else {
            "not met"
        },
        best_deng.1,
        best_deng.0,
    );
    md += &rod_grid_study(&materials, exp, fe)?;
    Ok(md)
}

/// Grid convergence of the rod's corner A (Table 10.1 style) for each material.
pub fn rod_grid_study(
    materials: &[(&'static str, Scene)],
    exp: (f64, f64, f64),
    fe: (f64, f64, f64),
) -> Result<String> {
    let mut md = String::new();
    let dist = |x: f64, y: f64, z: f64| between((x, y, z), exp);
    // Grid convergence of corner A (Table 10.1 style): the friction barrier for each material,
    // the vertical gap for Table 10.3's and Deng's.
    let sides = [17usize, 25, 33, 41, 49];
    let last = materials.len() - 1;
    let cases: Vec<(usize, bool, usize)> = (0..materials.len())
        .flat_map(|m| [(m, false), (m, true)])
        .filter(|&(m, vg)| !vg || m == 0 || m == last)
        .flat_map(|(m, vg)| sides.iter().map(move |&n| (m, vg, n)))
        .collect();
    let study: Vec<(usize, bool, usize, Solution, f64)> = cases
        .par_iter()
        .map(|&(m, vg, n)| {
            let mut base = materials[m].1.clone();
            if vg {
                base.contact.method = ContactMethod::VerticalGap;
            } else {
                base.contact.friction_coefficient = 0.3;
            }
            let tol = base.solver.static_.residual_tol_rel;
            let s = drapelab_core::benchmark::bench_scene(
                &base,
                n,
                drapelab_core::scene::SolverKind::Static,
                tol,
            );
            let t = Instant::now();
            let sol = solve_scene(&s, &mut NoObserver);
            (m, vg, n, sol, t.elapsed().as_secs_f64())
        })
        .collect();
    md += "### Grid convergence of corner A\n\n| material | contact | grid | status | iterations | time s | x cm | y cm | drop cm | distance to the experiment cm | distance to the finite elements cm |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (m, vg, n, sol, t) in &study {
        let ((ax, ay, az), _) = corner_a(sol);
        let to_fe = between((ax, ay, az), fe);
        let _ = writeln!(
            md,
            "| {} | {} | {n}×{n} | {} | {} | {t:.2} | {ax:.2} | {ay:.2} | {az:.2} | {:.2} | {to_fe:.2} |",
            materials[*m].0,
            if *vg {
                "vertical gap (sticky)"
            } else {
                "barrier, friction μ = 0.3"
            },
            sol.report.status.as_str(),
            sol.report.iterations,
            dist(ax, ay, az)
        );
    }
    let finest = |m: usize, vg: bool| {
        study
            .iter()
            .rev()
            .find(|c| c.0 == m && c.1 == vg)
            .map(|c| corner_a(&c.3).0)
    };
    if let (Some(a), Some(d), Some(v)) = (finest(0, false), finest(last, false), finest(0, true)) {
        let _ = write!(
            md,
            "\nOn the finest grid, corner A hangs {:.2} cm from the experiment with Table 10.3's material (the \
sticky vertical gap {:.2} cm from the friction barrier's corner: the two treatments converge to one drape) and {:.2} cm from the finite-element prediction with Deng's material, the finite elements' own: two different discretisations of the same plate agree, and both stand {:.2}–{:.2} cm inside the experiment's corner ({:.2} cm from the rod's axis horizontally; drapelab {:.2} cm). The coarse grids land closer to the experiment because a grid's bending along the cells' diagonals is stiffer than the continuum's, not because they are more right. Nothing in Table 10.3 stiffens the hanging flap that much; KES bending hysteresis (2HB) would, but the seed does not give it.\n\n",
            dist(a.0, a.1, a.2),
            between(a, v),
            between(d, fe),
            dist(d.0, d.1, d.2).min(dist(a.0, a.1, a.2)),
            dist(d.0, d.1, d.2).max(dist(a.0, a.1, a.2)),
            (exp.0 + exp.1) / std::f64::consts::SQRT_2,
            (a.0 + a.1) / std::f64::consts::SQRT_2,
        );
    }
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
    // (label, intervals along the strip, spacing)
    let grids: Vec<(String, usize, drapelab_core::cloth::Spacing)> =
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
            .collect();
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

/// Distance between two points given as (x, y, z) in cm.
pub fn between(a: (f64, f64, f64), b: (f64, f64, f64)) -> f64 {
    ((a.0 - b.0).powi(2) + (a.1 - b.1).powi(2) + (a.2 - b.2).powi(2)).sqrt()
}

/// The rod drape's corner A (x, y, drop in cm) and corner B turned by 180° about the vertical.
pub fn corner_a(sol: &Solution) -> ((f64, f64, f64), (f64, f64, f64)) {
    let n = sol.grid.nx;
    let a = sol.at(n - 1, n - 1) * 100.0;
    let b = sol.at(0, 0) * 100.0;
    ((a.x, a.y, -a.z), (-b.x, -b.y, -b.z))
}

/// Every drape's tile of the montage (a drape on a table or pedestal also from above).
pub fn drapes_png(solved: &[Solved]) -> image::RgbImage {
    let tiles: Vec<crate::montage::Tile<'_>> = solved
        .iter()
        .map(|s| {
            let n = s.coarse.grid.len();
            crate::montage::Tile {
                name: &s.scene.name,
                grid: &s.coarse.grid,
                x: &s.coarse.x[..n],
                present: drapelab_core::build::present_particles(&s.scene),
                from_above: s.scene.obstacles.iter().any(|o| {
                    matches!(
                        o,
                        drapelab_core::obstacle::Obstacle::Box { .. }
                            | drapelab_core::obstacle::Obstacle::Pedestal { .. }
                    )
                }),
            }
        })
        .collect();
    crate::montage::montage(&tiles)
}

/// Each drape seen from above (x, y; darker is lower) and from the side (x, z), two panels per scene.
pub fn drapes_svg(solved: &[Solved]) -> Result<String> {
    let mut out = String::new();
    {
        let k = solved.len().max(1);
        let root = SVGBackend::with_string(&mut out, (900, 420 * k as u32)).into_drawing_area();
        root.fill(&WHITE)?;
        let rows = root.split_evenly((k, 2));
        for (s, pair) in solved.iter().zip(rows.chunks(2)) {
            let x = s.coarse.grid_positions();
            let present = drapelab_core::build::present_particles(&s.scene);
            let pts: Vec<_> = x
                .iter()
                .zip(&present)
                .filter(|(_, p)| **p)
                .map(|(q, _)| *q)
                .collect();
            let (zmin, zmax) = pts.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, q| {
                (a.0.min(q.z), a.1.max(q.z))
            });
            let shade = |z: f64| {
                let t = if zmax > zmin {
                    (z - zmin) / (zmax - zmin)
                } else {
                    1.0
                };
                let v = (40.0 + 200.0 * t) as u8;
                RGBColor(v / 2, v / 2, v)
            };
            let r = pts
                .iter()
                .fold(0.0f64, |a, q| a.max(q.x.abs()).max(q.y.abs()))
                * 1.05;
            for (area, side) in pair.iter().zip([false, true]) {
                let mut chart = ChartBuilder::on(area)
                    .caption(
                        format!(
                            "{} — {}",
                            s.scene.name,
                            if side { "side (x, z)" } else { "above (x, y)" }
                        ),
                        ("sans-serif", 16),
                    )
                    .margin(8)
                    .x_label_area_size(36)
                    .y_label_area_size(56)
                    .build_cartesian_2d(-r..r, if side { (zmin - 0.01)..0.01 } else { -r..r })?;
                chart
                    .configure_mesh()
                    .x_desc("x (m)")
                    .y_desc(if side { "z (m)" } else { "y (m)" })
                    .draw()?;
                chart.draw_series(pts.iter().map(|q| {
                    Circle::new((q.x, if side { q.z } else { q.y }), 2, shade(q.z).filled())
                }))?;
            }
        }
        root.present()?;
    }
    Ok(out)
}

/// The rod's materials: Table 10.3 as the seed takes it (no twist rigidity), with an isotropic
/// plate's twist rigidity √(D_warp D_weft) (which the KES data do not give), and Deng's (1994)
/// finite-element material: isotropic, the warp bending rigidity in every direction (D_weft = D_t =
/// D_warp; Poisson's ratio 0 here, 0.3 there).
pub fn rod_materials(scene: &Scene) -> Vec<(&'static str, Scene)> {
    let with = |f: &dyn Fn(&mut drapelab_core::material::Continuum, f64, f64)| {
        let mut s = scene.clone();
        if let Some(c) = s.material.continuum.as_mut()
            && let Ok(r) = c.rigidities()
        {
            f(c, r.bending_warp_N_m, r.bending_weft_N_m);
        }
        s
    };
    vec![
        ("Table 10.3", scene.clone()),
        (
            "Table 10.3, twist √(D_warp D_weft)",
            with(&|c, dw, df| c.bending_twist_N_m = Some((dw * df).sqrt())),
        ),
        (
            "Deng's FE material (isotropic D_warp)",
            with(&|c, dw, _| {
                c.bending_weft_gf_cm2_per_cm = None;
                c.bending_weft_N_m = Some(dw);
                c.bending_twist_gf_cm2_per_cm = None;
                c.bending_twist_N_m = Some(dw);
            }),
        ),
    ]
}
