//! The report's fabric part (issue 50): the twelve sheets read as fabric beside the plates, each
//! table's trend, Eq. 7 refitted to the fabric sheets by leave-one-case-out, the map over bending
//! length × shear rigidity, and the seed's photographed cloth (Fig. 4).

use crate::format::opt;
use drapelab_app::wrinkles::full::WrinklesFull;
use drapelab_app::wrinkles::points::{SheetRole, SheetVerdict, TensionFieldFit};
use drapelab_app::wrinkles::tables::WrinkleFullRow;
use drapelab_core::wrinkles::full::ReadingKind;
use std::fmt::Write;

/// Counts over the rows: (solved and converged in the mesh, tension field within ±1 of the
/// simulation, seed within ±1 of the simulation).
pub fn agreement_counts(rows: &[WrinkleFullRow]) -> (usize, usize, usize) {
    let within = |a: i32, b: i32| (a - b).abs() <= 1;
    (
        rows.iter()
            .filter(|r| r.status == SheetVerdict::Converged)
            .count(),
        rows.iter()
            .filter(|r| within(r.n_tension_field, r.n_full_simulation))
            .count(),
        rows.iter()
            .filter(|r| r.n_seed.is_some_and(|n| within(n, r.n_full_simulation)))
            .count(),
    )
}

/// The rows of one reading and role.
fn select(all: &[WrinkleFullRow], reading: ReadingKind, role: SheetRole) -> Vec<&WrinkleFullRow> {
    all.iter()
        .filter(|r| r.reading == reading && r.role == role)
        .collect()
}

/// The whole fabric section; empty when no sheet was read as fabric.
pub fn fabric_section(found: &WrinklesFull, all: &[WrinkleFullRow]) -> String {
    let (plates, fabrics) = (
        select(all, ReadingKind::Plate, SheetRole::Table),
        select(all, ReadingKind::Fabric, SheetRole::Table),
    );
    if fabrics.is_empty() {
        return String::new();
    }
    let mut s = format!(
        "\n## The sheets read as fabric\n\n{}\n",
        crate::wrinkles_text::FABRIC
    );
    s += &side_by_side(&plates, &fabrics);
    let n = fabrics.len();
    let owned: Vec<WrinkleFullRow> = fabrics.iter().map(|r| (*r).clone()).collect();
    let (converged, tf, seed) = agreement_counts(&owned);
    let n_equal = fabrics.iter().filter(|r| r.status.agrees_on_n()).count();
    let zmax_moves: Vec<f64> = fabrics
        .iter()
        .map(|r| 100.0 * (r.z_max_full_simulation_coarse_m / r.z_max_full_simulation_m - 1.0))
        .collect();
    let _ = write!(
        s,
        "\nOn the two meshes ({} and {}) the fabric sheets agree on n in **{n_equal} of {n}**; z_max also within \
10 % in {converged} of {n} (the coarser mesh's z_max is {:.0} to {:.0} % above the finer one's: a fold's \
radius is of the order of the bending length, below the grid spacing, so z_max still moves where n has \
settled). The tension field with the config's Eq. 7 is within ±1 of the fabric sheets in **{tf} of {n}**, \
the seed's table in **{seed} of {n}**.\n\n{}\n{}",
        fabrics[0].grid_coarse,
        fabrics[0].grid,
        zmax_moves.iter().copied().fold(f64::INFINITY, f64::min),
        zmax_moves.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        trends(&plates, &fabrics),
        found
            .fabric_fit
            .as_ref()
            .map_or(String::new(), |f| fit_section(found, f)),
    );
    s += &map_section(all, found.fabric_fit.as_ref());
    s += &photograph_section(all);
    s
}

/// Each case as a plate and as a fabric, one row.
fn side_by_side(plates: &[&WrinkleFullRow], fabrics: &[&WrinkleFullRow]) -> String {
    let mut s = String::from(
        "| case | n: seed | n: tension field | n: plate | **n: fabric** (coarse) | z_max cm: plate | fabric (coarse) | bending length mm: plate | fabric | shear N/m: plate | fabric | status (fabric) |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for (p, f) in plates.iter().zip(fabrics) {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | **{}** ({}) | {:.1} | {:.1} ({:.1}) | {:.0} | {:.1} | {:.0} | {:.0} | {} |",
            p.case,
            opt(p.n_seed.map(f64::from), 0),
            f.n_tension_field,
            p.n_full_simulation,
            f.n_full_simulation,
            f.n_full_simulation_coarse,
            100.0 * p.z_max_full_simulation_m,
            100.0 * f.z_max_full_simulation_m,
            100.0 * f.z_max_full_simulation_coarse_m,
            1000.0 * p.bending_length_m,
            1000.0 * f.bending_length_m,
            p.shear_rigidity_N_per_m,
            f.shear_rigidity_N_per_m,
            f.status,
        );
    }
    s
}

/// The table a case belongs to: "I" of "I-h90".
fn table_of(case: &str) -> &str {
    case.split('-').next().unwrap_or("")
}

/// "rises (5, 7, 8)": the sign of the change from the first count to the last, and the counts.
fn trend(v: &[i32]) -> String {
    match (v.first(), v.last()) {
        (Some(&a), Some(&b)) => format!(
            "{} ({})",
            match b.cmp(&a) {
                std::cmp::Ordering::Greater => "rises",
                std::cmp::Ordering::Less => "falls",
                std::cmp::Ordering::Equal => "stays",
            },
            v.iter().map(i32::to_string).collect::<Vec<_>>().join(", ")
        ),
        _ => "–".into(),
    }
}

/// Each table's trend (its cases in the config's order, the varied quantity rising): the seed's
/// against the plate's and the fabric's.
fn trends(plates: &[&WrinkleFullRow], fabrics: &[&WrinkleFullRow]) -> String {
    let mut s = String::from(
        "| table | cases | seed's n | plate's n | fabric's n |\n|---|---|---|---|---|\n",
    );
    let mut names: Vec<&str> = plates.iter().map(|r| table_of(&r.case)).collect();
    names.dedup();
    for name in names {
        let mine = |rows: &[&WrinkleFullRow], n: fn(&WrinkleFullRow) -> Option<i32>| {
            let v: Vec<i32> = rows
                .iter()
                .filter(|r| table_of(&r.case) == name)
                .filter_map(|r| n(r))
                .collect();
            trend(&v)
        };
        let cases: Vec<&str> = plates
            .iter()
            .filter(|r| table_of(&r.case) == name)
            .map(|r| r.case.as_str())
            .collect();
        let _ = writeln!(
            s,
            "| {name} | {} | {} | {} | {} |",
            cases.join(", "),
            mine(plates, |r| r.n_seed),
            mine(plates, |r| Some(r.n_full_simulation)),
            mine(fabrics, |r| Some(r.n_full_simulation)),
        );
    }
    s
}

/// "Eq. 7 with the fabric's 12 w c³, c = 7197" or "… the plate's E t³ …".
fn candidate_name((fabric, c): (bool, f64)) -> String {
    if fabric {
        format!("the fabric's bending term 12 w c_b³, c = {c:.0}")
    } else {
        format!("the plate's bending term E t³/(1 − ν²), c = {c:.0}")
    }
}

/// Eq. 7 refitted to the fabric sheets, with its held-out scores.
fn fit_section(found: &WrinklesFull, fit: &TensionFieldFit) -> String {
    let (hits, n) = fit.held_out(SheetRole::Table);
    let (map_hits, m) = fit.held_out(SheetRole::Map);
    let best = |fabric: bool| {
        (0..fit.candidates.len())
            .filter(|&k| fit.candidates[k].0 == fabric)
            .map(|k| (fit.hits(k, SheetRole::Table).0, k))
            .max()
            .map_or(String::new(), |(h, k)| {
                format!("{h} of {n} with {}", candidate_name(fit.candidates[k]))
            })
    };
    let folds: Vec<String> = fit
        .loo
        .held_out
        .iter()
        .zip(&fit.rows)
        .filter(|(_, r)| r.role == SheetRole::Table)
        .map(|(h, _)| {
            let (f, c) = fit.candidates[h.0];
            format!("{}{c:.0}", if f { "fabric " } else { "plate " })
        })
        .collect();
    let mut s = format!(
        "\n**Eq. 7 refitted to fabric.** Candidates: Eq. 7's bending term read as the plate's E t³/(1 − ν²) or \
as the fabric's 12 w c_b³ (its bending length c_b, the simulation's), each with the {} load constants c of \
the stage; a candidate holds on a sheet when its n is within ±1 of the simulated n (finer mesh); chosen by \
leave-one-case-out (a case's map points leave with it). Chosen on all sheets: {}. Held out: **{hits} of {n}** \
cases",
        found.buckling_constants.len(),
        candidate_name(fit.chosen()),
    );
    if m > 0 {
        let _ = write!(s, " and {map_hits} of {m} map points");
    }
    let alone = fit.cases_only();
    let _ = writeln!(
        s,
        " (per fold: {}). On the cases alone (the map left aside), leave-one-case-out chooses {} and holds \
out **{} of {n}**. In-sample, the best of each reading on the {n} cases: {}; {}.",
        folds.join(", "),
        candidate_name(fit.candidates[alone.chosen]),
        alone.held_out_hits(),
        best(false),
        best(true)
    );
    s
}

/// The map: each named case at every bending length × shear rigidity, with the refitted tension
/// field's count and each table's trend at every point.
fn map_section(all: &[WrinkleFullRow], fit: Option<&TensionFieldFit>) -> String {
    let map = select(all, ReadingKind::Fabric, SheetRole::Map);
    if map.is_empty() {
        return String::new();
    }
    let chosen = fit.map(|f| f.loo.chosen);
    let tf: Vec<Option<usize>> = match fit {
        Some(f) => f
            .rows
            .iter()
            .filter(|r| r.role == SheetRole::Map)
            .map(|r| chosen.map(|k| r.n_tension_field[k]))
            .collect(),
        None => vec![None; map.len()],
    };
    let mut s = String::from(
        "\n### The map: bending length × shear rigidity\n\nEach case below solved read as fabric at the \
ends of the real fabrics' ranges (the stage's `map_bending_lengths_m`, `map_shear_N_per_m`), from the \
result's start, on the points' two meshes; the middle of the ranges is the table above. n on the finer \
mesh (coarser in brackets); the tension field with the refitted Eq. 7 beside it.\n\n\
| case | bending length mm | shear N/m | **n** (coarse) | z_max cm (coarse) | n: tension field (refitted) | grids | status |\n\
|---|---|---|---|---|---|---|---|\n",
    );
    for (r, t) in map.iter().zip(&tf) {
        let _ = writeln!(
            s,
            "| {} | {:.1} | {:.0} | **{}** ({}) | {:.1} ({:.1}) | {} | {}, {} | {} |",
            r.case,
            1000.0 * r.bending_length_m,
            r.shear_rigidity_N_per_m,
            r.n_full_simulation,
            r.n_full_simulation_coarse,
            100.0 * r.z_max_full_simulation_m,
            100.0 * r.z_max_full_simulation_coarse_m,
            opt(t.map(|n| n as f64), 0),
            r.grid,
            r.grid_coarse,
            r.status,
        );
    }
    s += &map_trends(&map);
    s
}

/// At each map point, each table's trend over those of its cases the map holds (two or more).
fn map_trends(map: &[&WrinkleFullRow]) -> String {
    // A point's bending length is read back as (B/w)^(1/3), so equal points differ in the last bits.
    let same = |a: (f64, f64), b: (f64, f64)| {
        (a.0 - b.0).abs() <= 1e-9 * a.0.abs() && (a.1 - b.1).abs() <= 1e-9 * a.1.abs()
    };
    let mut points: Vec<(f64, f64)> = Vec::new();
    for r in map {
        let p = (r.bending_length_m, r.shear_rigidity_N_per_m);
        if !points.iter().any(|&q| same(q, p)) {
            points.push(p);
        }
    }
    let mut tables: Vec<&str> = map.iter().map(|r| table_of(&r.case)).collect();
    tables.dedup();
    let mut s = String::new();
    for t in tables {
        let cases: Vec<&str> = {
            let mut c: Vec<&str> = map
                .iter()
                .filter(|r| table_of(&r.case) == t)
                .map(|r| r.case.as_str())
                .collect();
            c.dedup();
            c
        };
        if cases.len() < 2 {
            continue;
        }
        let _ = write!(s, "\nTable {t} ({}) at each map point: ", cases.join(", "));
        let each: Vec<String> = points
            .iter()
            .map(|&(c_b, g)| {
                let v: Vec<i32> = map
                    .iter()
                    .filter(|r| {
                        table_of(&r.case) == t
                            && same((r.bending_length_m, r.shear_rigidity_N_per_m), (c_b, g))
                    })
                    .map(|r| r.n_full_simulation)
                    .collect();
                format!("{:.1} mm, {g:.0} N/m: n {}", 1000.0 * c_b, trend(&v))
            })
            .collect();
        s += &each.join("; ");
        s += ".\n";
    }
    s
}

/// The seed's photographed cloth (Fig. 4) read as fabric at each support displacement.
fn photograph_section(all: &[WrinkleFullRow]) -> String {
    let rows = select(all, ReadingKind::Fabric, SheetRole::Photograph);
    if rows.is_empty() {
        return String::new();
    }
    let mut s = String::from(
        "\n### The photographed cloth (Fig. 4)\n\nThe seed draws n = 4 over a photograph of a real cloth \
(140 × 140 cm, t = 0.4 mm, E = 40 MPa; its support displacement is not given): simulated here read as the \
fabric above, at Table I's weight and support displacements around Table I's 10 cm, on the points' two \
meshes.\n\n| sheet | n: photograph | **n: fabric** (coarse) | z_max cm (coarse) | n: tension field | grids | status |\n\
|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let _ = writeln!(
            s,
            "| {} | {} | **{}** ({}) | {:.1} ({:.1}) | {} | {}, {} | {} |",
            r.case,
            opt(r.n_seed.map(f64::from), 0),
            r.n_full_simulation,
            r.n_full_simulation_coarse,
            100.0 * r.z_max_full_simulation_m,
            100.0 * r.z_max_full_simulation_coarse_m,
            r.n_tension_field,
            r.grid,
            r.grid_coarse,
            r.status,
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A map row of `case` at bending length `c_b` (m), shear `g` (N/m), with count `n`.
    fn row(case: &str, c_b: f64, g: f64, n: i32) -> WrinkleFullRow {
        WrinkleFullRow {
            case: case.into(),
            n_seed: None,
            n_tension_field: 0,
            n_full_simulation: n,
            n_full_simulation_coarse: n,
            z_max_full_simulation_m: 0.1,
            wall_time_s: 1.0,
            status: SheetVerdict::Converged,
            reading: ReadingKind::Fabric,
            bending_length_m: c_b,
            shear_rigidity_N_per_m: g,
            role: SheetRole::Map,
            z_max_full_simulation_coarse_m: 0.1,
            z_max_seed_m: None,
            z_max_tension_field_m: 0.0,
            q_seed: None,
            q_tension_field: 1.0,
            q_full_simulation: None,
            line_depths_full_simulation_m: Vec::new(),
            threshold_rel: 0.0,
            grid: "9x9".into(),
            grid_coarse: "5x5".into(),
            iterations: 1,
            iterations_coarse: 1,
            wall_time_fine_s: 1.0,
            energy_J: 0.0,
            self_crossing_edges: 0,
            status_fine: drapelab_core::solve::Status::Converged,
            status_coarse: drapelab_core::solve::Status::Converged,
        }
    }

    /// A bending length read back as (B/w)^(1/3) differs between cases in its last bits: the trend
    /// line still holds one entry per map point, with every case's count.
    #[test]
    fn map_points_that_differ_in_the_last_bits_are_one_point_of_the_trend() {
        let c = 0.007;
        let rows = [
            row("I-h90", c, 17.0, 1),
            row("I-h140", c * (1.0 + 1e-15), 17.0, 3),
            row("I-h235", c * (1.0 - 1e-15), 17.0, 3),
        ];
        let refs: Vec<&WrinkleFullRow> = rows.iter().collect();
        let s = map_trends(&refs);
        assert_eq!(s.matches("mm,").count(), 1, "{s}");
        assert!(s.contains("n rises (1, 3, 3)"), "{s}");
        assert!(!s.contains('–'), "{s}");
    }
}
