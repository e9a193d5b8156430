//! Edge points straight from a simulated drape, as the camera of [`super::render`] sees them: a
//! view along +y, image plane (x, z), orthographic or through a pinhole ([`Projection`]). For a 4-corner hang the lower boundary of the
//! silhouette is, at each grid column, its lowest particle; for a 2-corner hang the four edges are the
//! sheet's boundary rows and columns.

use super::{Projection, View};
use crate::cloth::Grid;
use nalgebra::{Vector2, Vector3};
use serde::{Deserialize, Serialize};

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

/// Every grid particle in the camera's frame, cm: (along the reference line from the left fixed
/// corner, up from it) in the image plane (x, z) of a camera looking along +y, projected by
/// `projection` onto the plane of the fixed corners; and the corners' span, cm.
fn camera_cm(
    grid: &Grid,
    x: &[Vector3<f64>],
    corners: [(usize, usize); 2],
    projection: Projection,
) -> (Vec<(f64, f64)>, f64) {
    let proj = |p: &Vector3<f64>| Vector2::new(p.x, p.z);
    let (a, b) = (
        &x[grid.index(corners[0].0, corners[0].1)],
        &x[grid.index(corners[1].0, corners[1].1)],
    );
    let (c0, c1) = (proj(a), proj(b));
    let plane_y = 0.5 * (a.y + b.y);
    let line = ReferenceLine::new(c0, c1);
    let cm = x[..grid.len()]
        .iter()
        .map(|p| {
            let (a, u) = line.coords(proj(p));
            projection.project((a * 100.0, u * 100.0), p.y - plane_y)
        })
        .collect();
    (cm, (c1 - c0).norm() * 100.0)
}

/// The edge points (cm) of a drape for `view`; `corners` are the grid indices of the left and right
/// fixed corners as the camera sees them.
pub fn edges_from_particles(
    grid: &Grid,
    x: &[Vector3<f64>],
    view: View,
    corners: [(usize, usize); 2],
    projection: Projection,
) -> Vec<(String, Vec<(f64, f64)>)> {
    let (all, span) = camera_cm(grid, x, corners, projection);
    let cm = |i: usize, j: usize| all[grid.index(i, j)];
    match view {
        View::Hang4 => {
            let pts = (0..grid.nx)
                .map(|i| {
                    (0..grid.ny)
                        .map(|j| cm(i, j))
                        .fold(
                            (0.0, f64::INFINITY),
                            |best, p| if p.1 < best.1 { p } else { best },
                        )
                })
                .collect();
            vec![(
                "bottom".into(),
                super::trim_edge("bottom", resample(pts), span, 0.0),
            )]
        }
        View::Hang2 => {
            let top_j = corners[0].1;
            let bottom_j = if top_j == 0 { grid.ny - 1 } else { 0 };
            let row = |j: usize| (0..grid.nx).map(|i| cm(i, j)).collect::<Vec<_>>();
            // Side edges: x = depth below the line, y = offset along the line from the corner's vertical.
            let side = |i: usize, offset: f64| {
                (0..grid.ny)
                    .map(|j| {
                        let (a, u) = cm(i, j);
                        (-u, a - offset)
                    })
                    .collect::<Vec<_>>()
            };
            let depth = |i: usize| -cm(i, bottom_j).1;
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

/// Which curve stands for a simulated drape's edge.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum EdgeSource {
    /// The silhouette of the drape's triangles as the camera sees it (what a photo shows).
    #[default]
    Silhouette,
    /// The polyline through the particles: the lowest of each column (hang4) or the boundary rows
    /// and columns (hang2).
    Particles,
}

/// The edge points (cm) of a drape for `view`, as `source` says.
pub fn simulated_edges(
    grid: &Grid,
    x: &[Vector3<f64>],
    view: View,
    corners: [(usize, usize); 2],
    source: EdgeSource,
    projection: Projection,
) -> Vec<(String, Vec<(f64, f64)>)> {
    match source {
        EdgeSource::Particles => edges_from_particles(grid, x, view, corners, projection),
        EdgeSource::Silhouette => edges_from_silhouette(grid, x, view, corners, projection),
    }
}

/// A straight piece of the silhouette's boundary in (s, t): t as a function of s between two points.
type Segment = ((f64, f64), (f64, f64));

/// The lower (or upper) envelope t(s) of `segments` at each of `samples` (None where no segment
/// spans s). The silhouette of a triangle mesh is bounded by its triangles' edges, so this envelope
/// over every edge is the silhouette's boundary.
fn envelope(segments: &[Segment], samples: &[f64], lower: bool) -> Vec<Option<f64>> {
    let mut out: Vec<Option<f64>> = vec![None; samples.len()];
    let (s0, ds) = (samples[0], samples[1] - samples[0]);
    for &((sa, ta), (sb, tb)) in segments {
        let (lo, hi) = (sa.min(sb), sa.max(sb));
        let k0 = ((lo - s0) / ds).ceil().max(0.0) as usize;
        let k1 = (((hi - s0) / ds).floor().max(-1.0) + 1.0) as usize;
        let span = &mut out[k0.min(samples.len())..k1.min(samples.len())];
        let at = &samples[k0.min(samples.len())..k1.min(samples.len())];
        // t(s) along the segment: its slope once, not a division per sample.
        let (slope, flat) = match (sb - sa).abs() < 1e-12 {
            true => (0.0, Some(if lower { ta.min(tb) } else { ta.max(tb) })),
            false => ((tb - ta) / (sb - sa), None),
        };
        for (o, &s) in span.iter_mut().zip(at) {
            let t = flat.unwrap_or(ta + slope * (s - sa));
            *o = Some(match *o {
                None => t,
                Some(v) if lower => v.min(t),
                Some(v) => v.max(t),
            });
        }
    }
    out
}

/// `n` + 1 equally spaced samples over [a, b].
fn linspace(a: f64, b: f64, n: usize) -> Vec<f64> {
    (0..=n).map(|k| a + (b - a) * k as f64 / n as f64).collect()
}

/// The edge points (cm) of the silhouette of a drape's triangles, seen by a camera along +y that
/// projects as `projection` says: the lower boundary (hang4), or the top, bottom, left and right boundaries (hang2),
/// sampled 64 times per grid spacing.
pub fn edges_from_silhouette(
    grid: &Grid,
    x: &[Vector3<f64>],
    view: View,
    corners: [(usize, usize); 2],
    projection: Projection,
) -> Vec<(String, Vec<(f64, f64)>)> {
    let (cm, span) = camera_cm(grid, x, corners, projection);
    // Each mesh edge once (an inner edge borders two triangles).
    let mut edges: Vec<(u32, u32)> = crate::cloth::grid_triangles(grid)
        .iter()
        .flat_map(|t| (0..3).map(move |k| (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3]))))
        .collect();
    edges.sort_unstable();
    edges.dedup();
    let along_up: Vec<Segment> = edges
        .iter()
        .map(|&(a, b)| (cm[a as usize], cm[b as usize]))
        .collect();
    let n = 64 * (grid.nx.max(grid.ny) - 1);
    let xs = linspace(0.0, span, n);
    let curve = |lower: bool| -> Vec<(f64, f64)> {
        xs.iter()
            .zip(envelope(&along_up, &xs, lower))
            .filter_map(|(&a, t)| Some((a, t?)))
            .collect()
    };
    match view {
        View::Hang4 => vec![(
            "bottom".into(),
            super::trim_edge("bottom", curve(true), span, 0.0),
        )],
        View::Hang2 => {
            // The bottom edge, and its depths at the two corners' verticals taken as a photo's are:
            // from the quartic through the trimmed edge (a pinhole tilts the side columns, so the
            // silhouette's own end points are the corners, not the bottom).
            let bottom = super::trim_edge("bottom", curve(true), span, 0.0);
            let bottom_fit = super::EdgeFit::from_points("bottom", &bottom, 4);
            let depth_at = |a: f64| bottom_fit.as_ref().map_or(0.0, |f| -f.eval(a));
            // Side edges: x = depth below the line, y = offset along the line from the corner's
            // vertical; the leftmost (rightmost) point of the silhouette at each depth.
            let depth_up: Vec<Segment> = along_up
                .iter()
                .map(|&((a0, u0), (a1, u1))| ((-u0, a0), (-u1, a1)))
                .collect();
            let deepest = cm.iter().map(|p| -p.1).fold(0.0, f64::max);
            let ds = linspace(0.0, deepest, n);
            let side = |lower: bool, offset: f64| -> Vec<(f64, f64)> {
                ds.iter()
                    .zip(envelope(&depth_up, &ds, lower))
                    .filter_map(|(&d, a)| Some((d, a? - offset)))
                    .collect()
            };
            let (d_left, d_right) = (depth_at(0.0), depth_at(span));
            vec![
                (
                    "top".into(),
                    super::trim_edge("top", curve(false), span, 0.0),
                ),
                ("bottom".into(), bottom),
                (
                    "left".into(),
                    super::trim_edge("left", side(true, 0.0), span, d_left),
                ),
                (
                    "right".into(),
                    super::trim_edge("right", side(false, span), span, d_right),
                ),
            ]
        }
    }
}
