//! Trimming (seed 003 §10.8): the drape's outline in the surface's parameter plane as closed cubic
//! B-spline curves, and which parameters lie inside it.
//!
//! The outline of the kept triangles of a drape's grid (a disc's staircase) is chained into loops;
//! each loop, its one-cell zigzag removed by Taubin smoothing (which does not shrink it), is the
//! control polygon of a uniform periodic cubic B-spline curve through the staircase's middle. Corners on the border of the parameter square are kept
//! sharp (their control point is tripled) where the outline runs along that border, so a region cut
//! by the grid's edge keeps its straight edge and corners; a disc that only touches the border stays
//! round there.

/// A trimming region: closed curves sampled as polygons in the (u, v) parameter plane, inside by the
/// even–odd rule.
#[derive(Debug, Clone, PartialEq)]
pub struct Trim {
    /// Closed polygons (first point not repeated), sampled from the B-spline curves.
    pub loops: Vec<Vec<[f64; 2]>>,
}

/// Samples a curve segment gets per span of its control polygon.
const SAMPLES_PER_SPAN: usize = 8;

/// The uniform cubic B-spline basis at t ∈ [0, 1).
fn basis(t: f64) -> [f64; 4] {
    let s = 1.0 - t;
    [
        s * s * s / 6.0,
        (3.0 * t * t * t - 6.0 * t * t + 4.0) / 6.0,
        (-3.0 * t * t * t + 3.0 * t * t + 3.0 * t + 1.0) / 6.0,
        t * t * t / 6.0,
    ]
}

/// The closed uniform cubic B-spline curve with control polygon `ctrl`, sampled.
fn periodic_curve(ctrl: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let n = ctrl.len();
    let mut out = Vec::with_capacity(n * SAMPLES_PER_SPAN);
    for k in 0..n {
        for s in 0..SAMPLES_PER_SPAN {
            let b = basis(s as f64 / SAMPLES_PER_SPAN as f64);
            let mut p = [0.0; 2];
            for (m, w) in b.iter().enumerate() {
                let c = ctrl[(k + m) % n];
                p[0] += w * c[0];
                p[1] += w * c[1];
            }
            out.push(p);
        }
    }
    out
}

/// Passes of Taubin smoothing of a staircase outline before it becomes a control polygon.
const SMOOTHING_PASSES: usize = 4;

/// Taubin's λ|μ smoothing of a closed polygon (λ = 0.5, μ = −0.53 a pass): removes the staircase's
/// one-cell zigzag without shrinking the outline; `fixed` points (on the parameter square's border)
/// stay.
fn taubin(pts: &mut [[f64; 2]], fixed: &[bool], passes: usize) {
    let n = pts.len();
    for _ in 0..passes {
        for f in [0.5, -0.53] {
            let old = pts.to_vec();
            for k in (0..n).filter(|&k| !fixed[k]) {
                let (a, b) = (old[(k + n - 1) % n], old[(k + 1) % n]);
                for c in 0..2 {
                    pts[k][c] += f * (0.5 * (a[c] + b[c]) - old[k][c]);
                }
            }
        }
    }
}

/// Signed area of a closed polygon (counter-clockwise positive).
fn signed_area(poly: &[[f64; 2]]) -> f64 {
    let n = poly.len();
    (0..n)
        .map(|k| {
            let (a, b) = (poly[k], poly[(k + 1) % n]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum::<f64>()
        / 2.0
}

/// The outline of `triangles` (indices into `points`) as closed loops of point indices, each
/// directed with the region on its left (outer loops counter-clockwise, holes clockwise).
pub fn outline(points: &[[f64; 2]], triangles: &[[u32; 3]]) -> Vec<Vec<u32>> {
    use std::collections::{BTreeMap, BTreeSet};
    let mut directed = BTreeSet::new();
    for t in triangles {
        let poly: Vec<[f64; 2]> = t.iter().map(|&k| points[k as usize]).collect();
        let [a, b, c] = if signed_area(&poly) >= 0.0 {
            *t
        } else {
            [t[0], t[2], t[1]]
        };
        directed.extend([(a, b), (b, c), (c, a)]);
    }
    let mut next: BTreeMap<u32, Vec<u32>> = BTreeMap::new();
    for &(a, b) in &directed {
        if !directed.contains(&(b, a)) {
            next.entry(a).or_default().push(b);
        }
    }
    let mut loops = Vec::new();
    while let Some((&start, _)) = next.iter().find(|(_, v)| !v.is_empty()) {
        let mut lp = vec![start];
        let mut at = start;
        while let Some(b) = next.get_mut(&at).and_then(|v| v.pop()) {
            if b == start {
                break;
            }
            lp.push(b);
            at = b;
        }
        if lp.len() >= 3 {
            loops.push(lp);
        }
    }
    loops
}

impl Trim {
    /// The trimming curves of the region covered by `triangles` (indices into `points`, the nodes'
    /// parameters in [0, 1]²).
    pub fn from_triangles(points: &[[f64; 2]], triangles: &[[u32; 3]]) -> Self {
        // A point where the outline leaves (or joins) a run along the square's border: both on the
        // same border line.
        let edge = |c: f64| c <= 1e-12 || c >= 1.0 - 1e-12;
        let along_border = |p: [f64; 2], q: [f64; 2]| {
            (0..2).any(|k| edge(p[k]) && edge(q[k]) && (p[k] - q[k]).abs() < 1e-12)
        };
        let loops = outline(points, triangles)
            .into_iter()
            .map(|lp| {
                let n = lp.len();
                let mut pts: Vec<[f64; 2]> = lp.iter().map(|&k| points[k as usize]).collect();
                let corner: Vec<bool> = (0..n)
                    .map(|k| {
                        let (a, p, b) = (pts[(k + n - 1) % n], pts[k], pts[(k + 1) % n]);
                        let turn = (p[0] - a[0]) * (b[1] - p[1]) - (p[1] - a[1]) * (b[0] - p[0]);
                        (along_border(a, p) || along_border(p, b)) && turn.abs() > 1e-15
                    })
                    .collect();
                let fixed: Vec<bool> = pts.iter().map(|p| edge(p[0]) || edge(p[1])).collect();
                taubin(&mut pts, &fixed, SMOOTHING_PASSES);
                let mut ctrl = Vec::with_capacity(n + 8);
                for (p, c) in pts.iter().zip(&corner) {
                    ctrl.extend(std::iter::repeat_n(*p, if *c { 3 } else { 1 }));
                }
                periodic_curve(&ctrl)
            })
            .collect();
        Self { loops }
    }

    /// The u where the trimming curves cross the line of parameter v, sorted.
    pub fn crossings(&self, v: f64) -> Vec<f64> {
        let mut us = Vec::new();
        for lp in &self.loops {
            let n = lp.len();
            for k in 0..n {
                let (a, b) = (lp[k], lp[(k + 1) % n]);
                if (a[1] <= v) != (b[1] <= v) {
                    us.push(a[0] + (v - a[1]) / (b[1] - a[1]) * (b[0] - a[0]));
                }
            }
        }
        us.sort_by(f64::total_cmp);
        us
    }

    /// Whether (u, v) lies inside (even–odd rule).
    pub fn contains(&self, u: f64, v: f64) -> bool {
        self.crossings(v).iter().filter(|c| **c < u).count() % 2 == 1
    }

    /// The area enclosed in the parameter plane (holes subtracted).
    pub fn area(&self) -> f64 {
        self.loops.iter().map(|l| signed_area(l)).sum::<f64>().abs()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_square_region_keeps_its_border_corners_and_area() {
        // The whole parameter square as two triangles: its outline is the square, corners sharp.
        let pts = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let t = Trim::from_triangles(&pts, &[[0, 1, 2], [0, 2, 3]]);
        assert_eq!(t.loops.len(), 1);
        assert!((t.area() - 1.0).abs() < 1e-12, "{}", t.area());
        assert!(t.contains(0.5, 0.5) && !t.contains(1.5, 0.5));
    }
}
