//! The report of seed 002's wrinkles checked against full simulations (issue 36): the seed's
//! table, drapelab's tension-field model and the simulated sheets side by side, the two
//! leave-one-out choices (the lobe threshold, Eq. 7's constant), the sheets as a picture strip
//! and the centre fibres as a plot; the tension-field model's own table after them.

use crate::format::opt;
use anyhow::Result;
use drapelab_app::Job;
use drapelab_app::wrinkles::full::WrinklesFull;
use drapelab_app::wrinkles::params::WrinklesSimulateParams;
use drapelab_app::wrinkles::points::SheetRole;
use drapelab_app::wrinkles::tables::{StartRow, WrinkleFullRow, rows, start_rows};
use drapelab_app::wrinkles::{SolvedCase, report_markdown};
use drapelab_core::wrinkles::WrinkleConfig;
use drapelab_core::wrinkles::full::ReadingKind;
use drapelab_record::write_text;
use plotters::prelude::*;
use std::fmt::Write;

/// The three columns: one row per case.
pub fn comparison_table(rows: &[WrinkleFullRow]) -> String {
    let mut s = String::from(
        "| case | n: seed | n: tension field | n: full simulation (coarse) | z_max cm: seed | tension field | full simulation (coarse) | Q: seed | tension field | full simulation | grids | Newton iterations | wall time s | status |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let _ = writeln!(
            s,
            "| {} | {} | {} | **{}** ({}) | {} | {:.2} | **{:.1}** ({:.1}) | {} | {:.2} | {} | {}, {} | {}, {} | {:.1} | {} |",
            r.case,
            opt(r.n_seed.map(f64::from), 0),
            r.n_tension_field,
            r.n_full_simulation,
            r.n_full_simulation_coarse,
            opt(r.z_max_seed_m.map(|z| 100.0 * z), 2),
            100.0 * r.z_max_tension_field_m,
            100.0 * r.z_max_full_simulation_m,
            100.0 * r.z_max_full_simulation_coarse_m,
            opt(r.q_seed, 2),
            r.q_tension_field,
            opt(r.q_full_simulation, 2),
            r.grid,
            r.grid_coarse,
            r.iterations,
            r.iterations_coarse,
            r.wall_time_s,
            r.status,
        );
    }
    s
}

/// The lobe threshold's leave-one-out: mesh agreement per candidate and the held-out score.
pub fn threshold_section(found: &WrinklesFull) -> String {
    let n = found.cases.len();
    let mut s = String::from(
        "| lobe threshold (fraction of z_max) | cases converged in the mesh |\n|---|---|\n",
    );
    for (k, t) in found.thresholds_rel.iter().enumerate() {
        let hits = found
            .cases
            .iter()
            .filter(|c| c.plate.mesh_converged(*t))
            .count();
        let mark = if k == found.threshold.chosen {
            " (chosen)"
        } else {
            ""
        };
        let _ = writeln!(s, "| {t}{mark} | {hits} of {n} |");
    }
    let _ = write!(
        s,
        "\nHeld out: with the threshold chosen on the other {} cases, the case left out is converged in the \
mesh in **{} of {n}** (chosen per fold: {}).\n",
        n.saturating_sub(1),
        found.threshold.held_out_hits(),
        found
            .threshold
            .held_out
            .iter()
            .map(|h| found.thresholds_rel[h.0].to_string())
            .collect::<Vec<_>>()
            .join(", ")
    );
    s
}

/// Which load constant c of Eq. 7 the simulations support: agreement (±1) per candidate, the
/// leave-one-out choice and its held-out score, and today's constant.
pub fn constant_section(found: &WrinklesFull, cfg: &WrinkleConfig, shear_ratios: &[f64]) -> String {
    let n = found.cases.len();
    let nu = cfg.defaults.poisson_ratio;
    // The config's c where it reads Eq. 7 as the plate, as these candidates do.
    let today = cfg
        .defaults
        .bending_length_m
        .is_none()
        .then_some(cfg.defaults.buckling_constant);
    // The same agreement against the sheets of lower shear stiffness (coarser mesh).
    let soft: Vec<(f64, Vec<Vec<bool>>)> = shear_ratios
        .iter()
        .filter_map(|&r| Some((r, found.agreement_with(&found.shear_counts(r)?))))
        .collect();
    let mut s = format!(
        "| c | c/(1 − ν²) with ν = {nu} | n of the tension field, case by case | within ±1 of the full simulation |{}\n|---|---|---|---|{}\n",
        soft.iter()
            .map(|(r, _)| format!(" within ±1, shear {r} |"))
            .collect::<String>(),
        "---|".repeat(soft.len())
    );
    for (k, c) in found.buckling_constants.iter().enumerate() {
        let is_today = today.is_some_and(|t| (c - t).abs() < 1e-6 * c);
        let mark = match (k == found.constant.chosen, is_today) {
            (true, true) => " (chosen; today's)",
            (true, false) => " (chosen)",
            (false, true) => " (today's)",
            _ => "",
        };
        let ns: Vec<String> = found
            .tension_field_n
            .iter()
            .map(|v| v[k].to_string())
            .collect();
        let _ = writeln!(
            s,
            "| {c:.0}{mark} | {:.0} | {} | {} of {n} |{}",
            c / (1.0 - nu * nu),
            ns.join(" "),
            found.agreement(k),
            soft.iter()
                .map(|(_, ok)| format!(" {} of {n} |", ok.iter().filter(|row| row[k]).count()))
                .collect::<String>()
        );
    }
    let chosen = found.buckling_constants[found.constant.chosen];
    let _ = write!(
        s,
        "\nHeld out: with c chosen on the other {} cases, the tension field is within ±1 of the simulation on \
the case left out in **{} of {n}** (chosen on all cases: c = {chosen:.0}; {}).",
        n.saturating_sub(1),
        found.constant.held_out_hits(),
        today.map_or(
            "the config reads Eq. 7 for a fabric instead: \"Eq. 7 refitted to fabric\" above"
                .into(),
            |t| format!("today's c = {t:.0}")
        ),
    );
    for (r, ok) in &soft {
        let loo = drapelab_core::wrinkles::full::leave_one_out(ok);
        let _ = write!(
            s,
            " Against the sheets of shear stiffness {r} of the isotropic: chosen c = {:.0}, held out **{} of {n}**.",
            found.buckling_constants[loo.chosen],
            loo.held_out_hits()
        );
    }
    s += " Only c/(1 − ν²) enters Eq. 7, so a reading with another ν is the same reading with c scaled by \
(1 − ν²)/(1 − 0.3²): the wrinkle count cannot tell ν from c.\n";
    s
}

/// Whether the count depends on the start: every case from every start on the coarser mesh, the
/// seed's isotropic shear stiffness.
pub fn starts_section(all: &[StartRow]) -> String {
    let starts: Vec<StartRow> = all
        .iter()
        .filter(|r| r.shear_ratio == 1.0)
        .cloned()
        .collect();
    let mut s = String::from(
        "| case | start | grid | n | z_max cm | energy J | Newton iterations | status | self-crossing edges |\n|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in &starts {
        let mark = if r.result_start {
            " (the result's)"
        } else {
            ""
        };
        let _ = writeln!(
            s,
            "| {} | {}{mark} | {} | {} | {:.1} | {:.5} | {} | {} | {} |",
            r.case,
            r.start,
            r.grid,
            r.n,
            100.0 * r.z_max_m,
            r.energy_J,
            r.iterations,
            r.status,
            r.self_crossing_edges
        );
    }
    let mut cases: Vec<&str> = starts.iter().map(|r| r.case.as_str()).collect();
    cases.dedup();
    let (mut same_n, mut lowest) = (0, 0);
    for c in &cases {
        let mine: Vec<&StartRow> = starts.iter().filter(|r| r.case == *c).collect();
        let result_n = mine.iter().find(|r| r.result_start).map(|r| r.n);
        let best = mine
            .iter()
            .filter(|r| r.status == drapelab_core::solve::Status::Converged)
            .min_by(|a, b| a.energy_J.total_cmp(&b.energy_J));
        lowest += usize::from(best.is_some_and(|b| b.result_start));
        same_n += usize::from(best.is_some_and(|b| Some(b.n) == result_n));
    }
    let _ = write!(
        s,
        "\nThe result's start reaches the lowest energy of the starts in **{lowest} of {}** cases; the \
lowest-energy state of the starts has the result's n in **{same_n} of {}** (a start that ends higher in \
energy is a metastable state; its n is in the table).\n",
        cases.len(),
        cases.len()
    );
    s
}

/// What a fabric's low in-plane shear stiffness does: the result's start with each shear
/// stiffness tried, on the coarser mesh.
pub fn shear_section(all: &[StartRow], start: &str) -> String {
    let mut s = String::from(
        "| case | shear stiffness G·t N/m (fraction of isotropic) | n | z_max cm | energy J | Newton iterations | status | self-crossing edges |\n|---|---|---|---|---|---|---|---|\n",
    );
    for r in all.iter().filter(|r| r.start == start) {
        let _ = writeln!(
            s,
            "| {} | {:.3} ({}) | {} | {:.1} | {:.5} | {} | {} | {} |",
            r.case,
            r.shear_stiffness_N_per_m,
            r.shear_ratio,
            r.n,
            100.0 * r.z_max_m,
            r.energy_J,
            r.iterations,
            r.status,
            r.self_crossing_edges
        );
    }
    s
}

/// The centre fibres (out of plane against depth, cm), one panel per case: finer mesh dark,
/// coarser light.
pub fn fibres_svg(found: &WrinklesFull) -> Result<String> {
    let cols = 4usize;
    let rows_n = found.cases.len().div_ceil(cols).max(1);
    let mut out = String::new();
    {
        let root =
            SVGBackend::with_string(&mut out, (1000, 330 * rows_n as u32)).into_drawing_area();
        root.fill(&WHITE)?;
        let areas = root.split_evenly((rows_n, cols));
        let t = found.threshold_rel();
        for (c, area) in found.cases.iter().zip(&areas) {
            let (ff, fc) = (c.plate.fine.fibre(), c.plate.coarse.fibre());
            let depth = ff.iter().chain(&fc).fold(0.0f64, |m, p| m.max(p.0)) * 100.0;
            let ymax = ff
                .iter()
                .chain(&fc)
                .fold(1.0f64, |m, p| m.max(100.0 * p.1.abs()));
            let mut chart = crate::cusick_plots::panel(
                area,
                &format!("{}: n = {}", c.case, c.plate.fine.wrinkles(t).n),
                (-ymax * 1.1..ymax * 1.1, "out of plane (cm)"),
                (-depth - 2.0..2.0, "height below supports (cm)", 6),
            )?;
            for (fibre, colour) in [(&fc, RGBColor(150, 170, 220)), (&ff, RGBColor(20, 50, 160))] {
                chart.draw_series(LineSeries::new(
                    fibre.iter().map(|&(d, y)| (100.0 * y, -100.0 * d)),
                    colour.stroke_width(2),
                ))?;
            }
            let lines = c.plate.fine.wrinkles(t).line_depths_m;
            chart.draw_series(
                lines
                    .iter()
                    .map(|d| Circle::new((0.0, -100.0 * d), 3, RGBColor(200, 40, 30).filled())),
            )?;
        }
        root.present()?;
    }
    Ok(out)
}

/// The simulated sheets (finer mesh), four to a row: each case read as a plate, then beside it
/// read as a fabric where it was; then the photographed cloth (Fig. 4) read as fabric.
pub fn sheets_png(found: &WrinklesFull) -> image::RgbImage {
    let photographs = found
        .points
        .iter()
        .filter(|q| q.spec.role == SheetRole::Photograph)
        .map(|q| (format!("{} fabric", q.spec.case), &q.pair.fine));
    let sheets: Vec<(String, &drapelab_app::wrinkles::full::SheetSolve)> = found
        .cases
        .iter()
        .flat_map(|c| {
            std::iter::once((format!("{} plate", c.case), &c.plate.fine)).chain(
                c.fabric
                    .as_ref()
                    .map(|f| (format!("{} fabric", c.case), &f.fine)),
            )
        })
        .chain(photographs)
        .collect();
    let tiles: Vec<crate::montage::Tile<'_>> = sheets
        .iter()
        .map(|(name, s)| crate::montage::Tile {
            name,
            grid: &s.grid,
            x: &s.x[..s.grid.len()],
            present: vec![true; s.grid.len()],
            from_above: false,
        })
        .collect();
    crate::montage::montage(&tiles)
}

/// The tension-field model's own table (the `wrinkles` stage's report body).
fn tension_field_table(found: &WrinklesFull, cfg: &WrinkleConfig) -> String {
    let solved: Vec<SolvedCase> = found
        .cases
        .iter()
        .filter_map(|c| {
            let index = cfg.cases.iter().position(|k| k.case == c.case)?;
            Some(SolvedCase {
                index,
                result: c.tension_field.clone(),
            })
        })
        .collect();
    report_markdown(cfg, &solved)
}

/// Writes the report (`markdown`), the picture strip (`sheets`) and the fibres' plot (`fibres_plot`)
/// the job asks for.
pub fn write_report(
    ctx: &Job<'_>,
    cfg: &WrinkleConfig,
    found: &WrinklesFull,
    p: &WrinklesSimulateParams,
) -> Result<()> {
    if let Some(out) = ctx.optional_output("sheets") {
        let img = sheets_png(found);
        drapelab_record::write_atomic(out, |f| {
            img.write_to(&mut std::io::BufWriter::new(f), image::ImageFormat::Png)?;
            Ok(())
        })?;
    }
    if let Some(out) = ctx.optional_output("fibres_plot") {
        write_text(out, &fibres_svg(found)?)?;
    }
    if let Some(out) = ctx.optional_output("markdown") {
        write_text(out, &markdown(ctx, cfg, found, p))?;
    }
    Ok(())
}

/// The whole report.
pub fn markdown(
    ctx: &Job<'_>,
    cfg: &WrinkleConfig,
    found: &WrinklesFull,
    p: &WrinklesSimulateParams,
) -> String {
    // Both tables once: each row counts its sheet's self-crossings.
    let all = rows(found, p);
    let reading = |kind: ReadingKind| -> Vec<WrinkleFullRow> {
        all.iter()
            .filter(|x| x.reading == kind && x.role == SheetRole::Table)
            .cloned()
            .collect()
    };
    let r = reading(ReadingKind::Plate);
    let starts = start_rows(found, p.start);
    let n = r.len();
    let (converged, tf, seed) = crate::wrinkles_fabric::agreement_counts(&r);
    let name = |slot: &str| {
        ctx.optional_output(slot)
            .and_then(|p| p.file_name())
            .map(|f| f.to_string_lossy().into_owned())
    };
    let mut s = format!(
        "# Seed 002's wrinkles: the seed, the tension-field model and a full simulation\n\n{}. \
The recording of the simulated sheets (both meshes) is the stage's `.rrd` (`rerun FILE`).\n\n",
        ctx.made_by()
    );
    s += crate::wrinkles_text::SETUP;
    let _ = write!(
        s,
        "\n## Three columns side by side\n\n**{converged} of {n}** cases converged in the mesh (both solves \
at equilibrium, n equal on both meshes, z_max within 10 %). The tension-field model is within ±1 wrinkle of \
the full simulation in **{tf} of {n}** cases, the seed's own table in **{seed} of {n}**. Bold: the finer \
mesh, the result; in brackets the coarser one. Self-crossing edges (the sheet passing through itself): \
{} on the finer sheets, {} over every coarser solve below.\n\n{}",
        r.iter().map(|x| x.self_crossing_edges).sum::<u32>(),
        starts.iter().map(|x| x.self_crossing_edges).sum::<u32>(),
        comparison_table(&r)
    );
    if let Some(png) = name("sheets") {
        let _ = write!(
            s,
            "\n![the simulated sheets, finer mesh]({png})\n\nThe simulated sheets on the finer mesh, 30° \
above the horizon and turned 30°, in the order of the table: each case read as a plate, then as a fabric; \
then the photographed cloth (Fig. 4) read as fabric.\n"
        );
    }
    if let Some(svg) = name("fibres_plot") {
        let _ = write!(
            s,
            "\n![centre fibres]({svg})\n\nThe centre fibre of each sheet: out-of-plane displacement against \
height below the supports, finer mesh dark, coarser light; red dots: the wrinkle lines counted.\n"
        );
    }
    s += &crate::wrinkles_fabric::fabric_section(found, &all);
    s += &method_sections(found, cfg, p, &starts);
    s += &crate::wrinkles_text::findings(found, &r, &starts, &cfg.defaults);
    let _ = write!(
        s,
        "\n## The tension-field model (Eqs. 5–10) case by case\n\ndrapelab's values first, the seed's in \
brackets; Q_c is the critical ratio of Eq. 7; L error is |L' − L|/L at convergence.\n\n{}",
        tension_field_table(found, cfg)
    );
    s
}

/// How the count was made robust: the starts, the shear stiffnesses, the lobe threshold and Eq. 7's
/// constant against the plate sheets.
fn method_sections(
    found: &WrinklesFull,
    cfg: &WrinkleConfig,
    p: &WrinklesSimulateParams,
    starts: &[StartRow],
) -> String {
    let mut s = String::new();
    let _ = write!(
        s,
        "\n## Does the count depend on the start?\n\nThe result's start is \"{}\"; the coarser mesh is also \
solved from {}. \"compressed\": every row squeezed to the span l (a membrane strain of l/L − 1 that the sheet \
must buckle away); \"folded-K\": K folds put in by hand across the sheet.\n\n{}",
        p.start,
        p.other_starts
            .iter()
            .map(|s| format!("\"{s}\""))
            .collect::<Vec<_>>()
            .join(" and "),
        starts_section(starts)
    );
    if !p.shear_ratios.is_empty() {
        let _ = write!(
            s,
            "\n## What a fabric's low shear stiffness does\n\n{}\n{}",
            crate::wrinkles_text::SHEAR,
            shear_section(starts, &p.start.to_string())
        );
    }
    let _ = write!(
        s,
        "\n## How n is counted: the lobe threshold, chosen by leave-one-out\n\n{}\n{}",
        crate::wrinkles_text::COUNTING,
        threshold_section(found)
    );
    let _ = write!(
        s,
        "\n## Which reading of Eq. 7 the simulations support\n\n{}\n{}",
        crate::wrinkles_text::EQ7,
        constant_section(found, cfg, &p.shear_ratios)
    );
    s
}
