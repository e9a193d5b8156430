//! Seed 003's rod (Table 10.4) in the report: corner A of the polyester sheet under every contact
//! treatment and material, and its grid study, from a `seed003-solve` stage's tables, beside the
//! experiment and the finite elements.

use anyhow::{Context, Result};
use drapelab_app::seed003::tables::{RodCornerRow, RodGridRow, RodMaterial};
use drapelab_core::scene::ContactMethod;
use drapelab_core::solve::Status;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

/// Table 10.4: the rod's corner A, both contact treatments, and its grid study.
pub fn table_10_4(treatments: &[RodCornerRow], grid: &[RodGridRow], file: &Path) -> Result<String> {
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
    // The must-show's verdict on the seed's scene: Table 10.3's material (with or without the
    // twist rigidity it does not give); Deng's material is reported beside it.
    let mut best = (f64::INFINITY, String::new());
    let mut best_deng = (f64::INFINITY, String::new());
    for row in treatments {
        let label = treatment(row);
        let ((ax, ay, az), (bx, by, bz)) = corner_cm(row);
        let d = dist(ax, ay, az);
        let slot = if row.material == RodMaterial::DengFe {
            &mut best_deng
        } else {
            &mut best
        };
        if row.status == Status::Converged && d < slot.0 {
            *slot = (d, label.clone());
        }
        let _ = writeln!(
            md,
            "| drapelab, {label} ({}) | {ax:.2} | {ay:.2} | {az:.2} | {d:.2} (corner B: ({bx:.2}, {by:.2}, {bz:.2})) |",
            row.status.as_str(),
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
    md += &rod_grid_study(grid, exp, fe);
    Ok(md)
}

/// A treatment's label: its contact and material.
fn treatment(r: &RodCornerRow) -> String {
    let m = r.material.label();
    match (r.contact, r.friction_coefficient) {
        (ContactMethod::VerticalGap, _) => format!("vertical gap (sticky), {m}"),
        (ContactMethod::Barrier, mu) if mu > 0.0 => {
            format!("barrier with friction μ = {mu} (lagged), {m}")
        }
        (ContactMethod::Barrier, _) => format!("barrier (frictionless), {m}"),
    }
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

/// Grid convergence of the rod's corner A (Table 10.1 style) for each material, from the grid
/// study's rows.
pub fn rod_grid_study(rows: &[RodGridRow], exp: (f64, f64, f64), fe: (f64, f64, f64)) -> String {
    let mut md = String::new();
    let dist = |x: f64, y: f64, z: f64| between((x, y, z), exp);
    let vertical_gap = |r: &RodGridRow| r.contact == ContactMethod::VerticalGap;
    md += "### Grid convergence of corner A\n\n| material | contact | grid | status | iterations | time s | x cm | y cm | drop cm | distance to the experiment cm | distance to the finite elements cm |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
    for r in rows {
        let (ax, ay, az) = grid_corner_cm(r);
        let to_fe = between((ax, ay, az), fe);
        let _ = writeln!(
            md,
            "| {} | {} | {n}×{n} | {} | {} | {:.2} | {ax:.2} | {ay:.2} | {az:.2} | {:.2} | {to_fe:.2} |",
            r.material.label(),
            if vertical_gap(r) {
                "vertical gap (sticky)".to_string()
            } else {
                format!("barrier, friction μ = {}", r.friction_coefficient)
            },
            r.status.as_str(),
            r.iterations,
            r.wall_time_s,
            dist(ax, ay, az),
            n = r.grid
        );
    }
    let finest = |m: RodMaterial, vg: bool| {
        rows.iter()
            .rev()
            .find(|r| r.material == m && vertical_gap(r) == vg)
            .map(grid_corner_cm)
    };
    let (table, deng) = (RodMaterial::Table103, RodMaterial::DengFe);
    if let (Some(a), Some(d), Some(v)) = (
        finest(table, false),
        finest(deng, false),
        finest(table, true),
    ) {
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
    md
}

/// Distance between two points given as (x, y, z) in cm.
pub fn between(a: (f64, f64, f64), b: (f64, f64, f64)) -> f64 {
    ((a.0 - b.0).powi(2) + (a.1 - b.1).powi(2) + (a.2 - b.2).powi(2)).sqrt()
}

/// A treatment's corner A and turned corner B (x, y, drop), cm.
pub fn corner_cm(r: &RodCornerRow) -> ((f64, f64, f64), (f64, f64, f64)) {
    (
        (
            r.corner_a_x_m * 100.0,
            r.corner_a_y_m * 100.0,
            r.corner_a_drop_m * 100.0,
        ),
        (
            r.corner_b_x_m * 100.0,
            r.corner_b_y_m * 100.0,
            r.corner_b_drop_m * 100.0,
        ),
    )
}

/// A grid study row's corner A (x, y, drop), cm.
pub fn grid_corner_cm(r: &RodGridRow) -> (f64, f64, f64) {
    (
        r.corner_a_x_m * 100.0,
        r.corner_a_y_m * 100.0,
        r.corner_a_drop_m * 100.0,
    )
}
