//! The pictures of the Cusick report (issue 16): per fabric, the photographed shadows of the
//! predicted specimens beside the simulated ones (outlines r(θ) seen from above, with the pedestal
//! and the flat specimen), and the measured against the simulated height profile z(r).

use anyhow::Result;
use drapelab_app::cusick::tables::{OutlineRow, PredictionRow, ProfileRow};
use plotters::prelude::*;
use std::collections::BTreeMap;

/// Panels: two per row.
pub const COLS: usize = 2;

/// One fabric's panel: caption, axes in mm with their names, `y.2` labels on y, no grid.
pub fn panel<'a, 'b>(
    area: &'a DrawingArea<SVGBackend<'b>, plotters::coord::Shift>,
    caption: &str,
    x: (std::ops::Range<f64>, &str),
    y: (std::ops::Range<f64>, &str, usize),
) -> Result<
    ChartContext<
        'a,
        SVGBackend<'b>,
        Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
    >,
> {
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 16))
        .margin(8)
        .x_label_area_size(32)
        .y_label_area_size(44)
        .build_cartesian_2d(x.0, y.0)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_labels(7)
        .y_labels(y.2)
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&|v| format!("{v:.0}"))
        .x_desc(x.1)
        .y_desc(y.1)
        .draw()?;
    Ok(chart)
}

/// A closed polyline (mm) of one outline's points.
pub fn closed_mm(points: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut v: Vec<(f64, f64)> = points
        .iter()
        .map(|&(t, r)| (1e3 * r * t.cos(), 1e3 * r * t.sin()))
        .collect();
    if let Some(&first) = v.first() {
        v.push(first);
    }
    v
}

/// A circle of `radius_m` as (x, y) points in mm, for outline plots.
pub fn circle_mm(radius_m: f64) -> Vec<(f64, f64)> {
    let pts: Vec<(f64, f64)> = (0..=180)
        .map(|i| (i as f64 / 180.0 * std::f64::consts::TAU, radius_m))
        .collect();
    closed_mm(&pts)
}

/// The outlines of each fabric grouped by source: photos (of specimens other than the
/// calibration's) and simulated seeds, each a list of (θ, r) points.
pub type Outlines = BTreeMap<i32, (Vec<Points>, Vec<Points>)>;

/// The (θ in rad, r in m) points of one outline.
pub type Points = Vec<(f64, f64)>;

/// Per fabric, the outlines of its other specimens' photos and of the model's seeds.
pub fn group_outlines(
    rows: &[PredictionRow],
    photos: &[OutlineRow],
    model: &[OutlineRow],
) -> Outlines {
    let calib: BTreeMap<i32, i32> = rows
        .iter()
        .map(|r| (r.fabric, r.calibration_sample))
        .collect();
    let mut by: BTreeMap<[i32; 4], Points> = BTreeMap::new();
    for o in photos
        .iter()
        .filter(|o| calib.get(&o.fabric).is_some_and(|c| o.sample != Some(*c)))
    {
        let key = [o.fabric, 0, o.sample.unwrap_or(0), o.capture.unwrap_or(0)];
        by.entry(key).or_default().push((o.theta_rad, o.radius_m));
    }
    for o in model {
        let key = [o.fabric, 1, o.seed.unwrap_or(0), 0];
        by.entry(key).or_default().push((o.theta_rad, o.radius_m));
    }
    let mut out: Outlines = BTreeMap::new();
    for ([fabric, kind, _, _], pts) in by {
        let e = out.entry(fabric).or_default();
        if kind == 0 { &mut e.0 } else { &mut e.1 }.push(pts);
    }
    out
}

/// The shadows SVG: per fabric, the photos' outlines (blue) and the simulated ones (red).
pub fn shadows_svg(
    rows: &[PredictionRow],
    photos: &[OutlineRow],
    model: &[OutlineRow],
    pedestal_radius_m: f64,
    specimen_radius_m: f64,
) -> Result<String> {
    let grouped = group_outlines(rows, photos, model);
    let n_rows = rows.len().div_ceil(COLS).max(1);
    let mut out = String::new();
    {
        let root =
            SVGBackend::with_string(&mut out, (800, 400 * n_rows as u32)).into_drawing_area();
        root.fill(&WHITE)?;
        let areas = root.split_evenly((n_rows, COLS));
        let lim = 1e3 * specimen_radius_m * 1.05;
        let photo = RGBColor(40, 90, 200).mix(0.55);
        let sim = RGBColor(210, 40, 30);
        for (r, area) in rows.iter().zip(&areas) {
            let mut chart = panel(
                area,
                &format!("fabric {}: photos (blue), model (red)", r.fabric),
                (-lim..lim, "x (mm)"),
                (-lim..lim, "y (mm)", 7),
            )?;
            for radius in [pedestal_radius_m, specimen_radius_m] {
                chart.draw_series(LineSeries::new(circle_mm(radius), RGBColor(170, 170, 170)))?;
            }
            if let Some((ph, si)) = grouped.get(&r.fabric) {
                for o in ph {
                    chart.draw_series(LineSeries::new(closed_mm(o), photo.stroke_width(1)))?;
                }
                for o in si {
                    chart.draw_series(LineSeries::new(closed_mm(o), sim.stroke_width(2)))?;
                }
            }
        }
        root.present()?;
    }
    Ok(out)
}

/// The profiles SVG: per fabric, the measured mean height z(r) ± SD (blue) and the simulated
/// mean ± SD over the perturbations (red), in mm.
pub fn profiles_svg(rows: &[PredictionRow], profiles: &[ProfileRow]) -> Result<String> {
    let n_rows = rows.len().div_ceil(COLS).max(1);
    let mut out = String::new();
    {
        let root =
            SVGBackend::with_string(&mut out, (800, 300 * n_rows as u32)).into_drawing_area();
        root.fill(&WHITE)?;
        let areas = root.split_evenly((n_rows, COLS));
        let (zmin, zmax) = profiles
            .iter()
            .flat_map(|p| [p.z_measured_m, p.z_predicted_m])
            .flatten()
            .fold((0.0f64, 0.0f64), |a, z| {
                (a.0.min(1e3 * z), a.1.max(1e3 * z))
            });
        let (rmin, rmax) = profiles.iter().fold((f64::INFINITY, 0.0f64), |a, p| {
            (a.0.min(1e3 * p.radius_m), a.1.max(1e3 * p.radius_m))
        });
        let (rmin, rmax) = if rmin < rmax {
            (rmin, rmax)
        } else {
            (90.0, 150.0)
        };
        for (r, area) in rows.iter().zip(&areas) {
            let mut chart = panel(
                area,
                &format!("fabric {}: meshes (blue), model (red)", r.fabric),
                (rmin - 2.0..rmax + 2.0, "rest radius r (mm)"),
                (zmin - 5.0..zmax + 5.0, "mean height z (mm)", 6),
            )?;
            let mine: Vec<&ProfileRow> = profiles.iter().filter(|p| p.fabric == r.fabric).collect();
            let series =
                |z: fn(&ProfileRow) -> Option<f64>, sd: fn(&ProfileRow) -> Option<f64>, k: f64| {
                    mine.iter()
                        .filter_map(|p| {
                            Some((1e3 * p.radius_m, 1e3 * (z(p)? + k * sd(p).unwrap_or(0.0))))
                        })
                        .collect::<Vec<_>>()
                };
            let blue = RGBColor(40, 90, 200);
            let red = RGBColor(210, 40, 30);
            for (z, sd, colour) in [
                (
                    (|p: &ProfileRow| p.z_measured_m) as fn(&ProfileRow) -> Option<f64>,
                    (|p: &ProfileRow| p.z_measured_sd_m) as fn(&ProfileRow) -> Option<f64>,
                    blue,
                ),
                (
                    |p: &ProfileRow| p.z_predicted_m,
                    |p: &ProfileRow| p.z_predicted_sd_m,
                    red,
                ),
            ] {
                chart.draw_series(LineSeries::new(series(z, sd, 0.0), colour.stroke_width(2)))?;
                for k in [-1.0, 1.0] {
                    chart.draw_series(LineSeries::new(series(z, sd, k), colour.mix(0.4)))?;
                }
            }
        }
        root.present()?;
    }
    Ok(out)
}
