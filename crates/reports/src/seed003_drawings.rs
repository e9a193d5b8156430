//! Seed 003's drapes drawn: each from above and from the side (SVG), and the montage of their
//! rendered surfaces (PNG).

use super::seed003_scenes::Drape;
use anyhow::Result;
use plotters::prelude::*;

/// Every drape's tile of the montage (a drape on a table or pedestal also from above).
pub fn drapes_png(drapes: &[Drape]) -> image::RgbImage {
    let tiles: Vec<crate::montage::Tile<'_>> = drapes
        .iter()
        .map(|d| crate::montage::Tile {
            name: &d.name,
            grid: &d.grid,
            x: &d.x,
            present: d.present.clone(),
            from_above: d.from_above,
        })
        .collect();
    crate::montage::montage(&tiles)
}

/// Each drape seen from above (x, y; darker is lower) and from the side (x, z), two panels per scene.
pub fn drapes_svg(drapes: &[Drape]) -> Result<String> {
    let mut out = String::new();
    {
        let k = drapes.len().max(1);
        let root = SVGBackend::with_string(&mut out, (900, 420 * k as u32)).into_drawing_area();
        root.fill(&WHITE)?;
        let rows = root.split_evenly((k, 2));
        for (s, pair) in drapes.iter().zip(rows.chunks(2)) {
            let pts: Vec<_> =
                s.x.iter()
                    .zip(&s.present)
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
                            s.name,
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
