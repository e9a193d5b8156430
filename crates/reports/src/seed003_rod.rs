//! Seed 003's rod (Table 10.4): corner A of the polyester sheet under every contact treatment and
//! material, and its grid study, beside the experiment and the finite elements.

use super::seed003_scenes::Solved;
use anyhow::{Context, Result};
use drapelab_core::scene::{ContactMethod, Scene};
use drapelab_core::simulate::{Solution, solve_scene};
use drapelab_core::solve::NoObserver;
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

/// Table 10.4: the rod's corner A, both contact treatments, and its grid study.
pub fn table_10_4(r: &Solved, file: &Path) -> Result<String> {
    let mut md = String::new();
    md += "## Table 10.4: corner A of the polyester sheet on the rod\n\n| source | x cm | y cm | drop cm | distance to the experiment cm |\n|---|---|---|---|---|\n";
    let rows = crate::calibration_report::read_csv(file)?;
    let f = cm_field;
    let exp = corner_row(&rows, "experiment").context("no experiment row in fvm_rod_corner.csv")?;
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
    let fe = corner_row(&rows, "finite-element").unwrap_or((f64::NAN, f64::NAN, f64::NAN));
    let fe_distance = between(fe, exp);
    // The contact treatments, and the materials: Table 10.3 as the seed takes it (no twist
    // rigidity), with an isotropic plate's twist √(D_warp D_weft) that the KES data do not give,
    // and Deng's finite-element material (isotropic: the warp rigidity in every direction).
    let materials = rod_materials(&r.scene);
    let variants = rod_variants(&materials);
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

/// A CSV row's field `k` as a number (NaN when missing or not a number).
pub(crate) fn cm_field(row: &BTreeMap<String, String>, k: &str) -> f64 {
    row.get(k)
        .and_then(|v| v.parse::<f64>().ok())
        .unwrap_or(f64::NAN)
}

/// The corner (x, y, drop in cm) of the first row of fvm_rod_corner.csv whose source starts with
/// `source`.
pub(crate) fn corner_row(
    rows: &[BTreeMap<String, String>],
    source: &str,
) -> Option<(f64, f64, f64)> {
    rows.iter()
        .find(|r| r.get("source").is_some_and(|s| s.starts_with(source)))
        .map(|r| {
            (
                cm_field(r, "x_cm"),
                cm_field(r, "y_cm"),
                cm_field(r, "z_cm"),
            )
        })
}

/// Each rod material under the sticky vertical gap and under the barrier with lagged friction
/// μ = 0.3, labelled.
pub(crate) fn rod_variants(materials: &[(&'static str, Scene)]) -> Vec<(String, Scene)> {
    materials
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
        .collect()
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
