//! Edge points straight from a simulated drape, as the camera of [`super::render`] sees them: an
//! orthographic view along +y, image plane (x, z). For a 4-corner hang the lower boundary of the
//! silhouette is, at each grid column, its lowest particle; for a 2-corner hang the four edges are the
//! sheet's boundary rows and columns.

use super::View;
use crate::cloth::Grid;
use nalgebra::{Vector2, Vector3};

/// Reference frame of a photo: the line through the two fixed corners, in the image plane (x, z), m.
#[derive(Debug, Clone, Copy)]
pub struct ReferenceLine {
    /// Left corner.
    pub origin: Vector2<f64>,
    /// Unit vector along the line, towards the right corner.
    pub along: Vector2<f64>,
    /// Unit normal, up.
    pub up: Vector2<f64>,
}

impl ReferenceLine {
    /// The line from `a` to `b` (image-plane points, up = +z).
    pub fn new(a: Vector2<f64>, b: Vector2<f64>) -> Self {
        let along = (b - a).normalize();
        Self {
            origin: a,
            along,
            up: Vector2::new(-along.y, along.x),
        }
    }
    /// (along, up) coordinates of `p`.
    pub fn coords(&self, p: Vector2<f64>) -> (f64, f64) {
        let d = p - self.origin;
        (d.dot(&self.along), d.dot(&self.up))
    }
}

/// The edge points (cm) of a drape for `view`; `corners` are the grid indices of the left and right
/// fixed corners as the camera sees them.
pub fn edges_from_particles(
    grid: &Grid,
    x: &[Vector3<f64>],
    view: View,
    corners: [(usize, usize); 2],
) -> Vec<(String, Vec<(f64, f64)>)> {
    let proj = |p: &Vector3<f64>| Vector2::new(p.x, p.z);
    let c0 = proj(&x[grid.index(corners[0].0, corners[0].1)]);
    let c1 = proj(&x[grid.index(corners[1].0, corners[1].1)]);
    let line = ReferenceLine::new(c0, c1);
    let cm = |p: &Vector3<f64>| {
        let (a, u) = line.coords(proj(p));
        (a * 100.0, u * 100.0)
    };
    match view {
        View::Hang4 => {
            let pts = (0..grid.nx)
                .map(|i| {
                    (0..grid.ny).map(|j| cm(&x[grid.index(i, j)])).fold(
                        (0.0, f64::INFINITY),
                        |best, p| if p.1 < best.1 { p } else { best },
                    )
                })
                .collect();
            let span = (c1 - c0).norm() * 100.0;
            vec![(
                "bottom".into(),
                super::trim_edge("bottom", resample(pts), span, 0.0),
            )]
        }
        View::Hang2 => {
            let top_j = corners[0].1;
            let bottom_j = if top_j == 0 { grid.ny - 1 } else { 0 };
            let row = |j: usize| {
                (0..grid.nx)
                    .map(|i| cm(&x[grid.index(i, j)]))
                    .collect::<Vec<_>>()
            };
            // Side edges: x = depth below the line, y = offset along the line from the corner's vertical.
            let span = (c1 - c0).norm() * 100.0;
            let side = |i: usize, offset: f64| {
                (0..grid.ny)
                    .map(|j| {
                        let (a, u) = cm(&x[grid.index(i, j)]);
                        (-u, a - offset)
                    })
                    .collect::<Vec<_>>()
            };
            let depth = |i: usize| -cm(&x[grid.index(i, bottom_j)]).1;
            let trim = |name: &str, pts: Vec<(f64, f64)>, d: f64| {
                super::trim_edge(name, resample(pts), span, d)
            };
            vec![
                ("top".into(), trim("top", row(top_j), 0.0)),
                ("bottom".into(), trim("bottom", row(bottom_j), 0.0)),
                (
                    "left".into(),
                    trim("left", side(corners[0].0, 0.0), depth(corners[0].0)),
                ),
                (
                    "right".into(),
                    trim("right", side(corners[1].0, span), depth(corners[1].0)),
                ),
            ]
        }
    }
}

/// The polyline through `pts` (sorted by x) sampled at 16 points per interval, so that the fit
/// weighs the curve evenly along x, as a photo's pixel columns do.
fn resample(mut pts: Vec<(f64, f64)>) -> Vec<(f64, f64)> {
    pts.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut out = Vec::with_capacity(pts.len() * 16);
    for w in pts.windows(2) {
        for k in 0..16 {
            let t = k as f64 / 16.0;
            out.push((
                w[0].0 + t * (w[1].0 - w[0].0),
                w[0].1 + t * (w[1].1 - w[0].1),
            ));
        }
    }
    out.extend(pts.last().copied());
    out
}
