//! Proximity of the primitives of one triangle mesh (the sheet against itself): the point–triangle
//! and edge–edge distances with their closest points, a spatial-hash broad phase over boxes that may
//! be swept along a step, and additive continuous collision detection (ACCD: Li, Kaufman, Kim and
//! Jiang, "Codimensional incremental potential contact", 2021, Alg. 1), which finds how far along a
//! step a pair may move before its distance falls to a share of what it was.

use nalgebra::Vector3;

mod bounds;
mod broad_phase;
mod bvh;
mod curvature;

pub use bounds::{BOUND_SHARE, bounded_fraction, brute_force_pairs, pairs_within, vertex_bounds};
pub use broad_phase::{Aabb, candidate_pairs};
use broad_phase::{for_each_cell, hash_entries, owner_bucket, primitive_boxes};
pub use bvh::{BroadPhase, HashGrid, Hierarchy};
pub use curvature::{Mat12, Vec12, edge_edge_mollifier_hessian, pair_distance_hessian};

type V3 = Vector3<f64>;

/// The primitives of a triangle mesh: its triangles and their unique edges (vertex indices into the
/// positions the mesh lives on; vertices that are in no triangle take no part).
#[derive(Debug, Clone, Default)]
pub struct MeshTopology {
    /// Triangles, vertex indices.
    pub triangles: Vec<[u32; 3]>,
    /// Unique edges (a < b).
    pub edges: Vec<[u32; 2]>,
    /// The vertices that belong to at least one triangle, ascending.
    pub vertices: Vec<u32>,
}

impl MeshTopology {
    /// The topology of `triangles`.
    pub fn from_triangles(triangles: Vec<[u32; 3]>) -> Self {
        let mut edges: Vec<[u32; 2]> = triangles
            .iter()
            .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
            .map(|(a, b)| [a.min(b), a.max(b)])
            .collect();
        edges.sort_unstable();
        edges.dedup();
        let mut vertices: Vec<u32> = triangles.iter().flatten().copied().collect();
        vertices.sort_unstable();
        vertices.dedup();
        Self {
            triangles,
            edges,
            vertices,
        }
    }

    /// The topology of `triangles`, shared with every earlier request for the same triangles in
    /// this process (a calibration builds one model per evaluation, each on the same mesh: sorting
    /// its edges each time was 3 % of the main job's calibrate stage).
    pub fn shared(triangles: Vec<[u32; 3]>) -> std::sync::Arc<Self> {
        use std::sync::{Arc, Mutex};
        /// Meshes kept at most; the oldest is dropped beyond.
        const KEPT: usize = 16;
        static SEEN: Mutex<Vec<Arc<MeshTopology>>> = Mutex::new(Vec::new());
        let mut seen = SEEN.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(t) = seen.iter().find(|t| t.triangles == triangles) {
            return t.clone();
        }
        let t = Arc::new(Self::from_triangles(triangles));
        if seen.len() == KEPT {
            seen.remove(0);
        }
        seen.push(t.clone());
        t
    }
}

/// A pair of primitives that share no vertex.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Pair {
    /// A vertex and a triangle (index into [`MeshTopology::triangles`]).
    PointTriangle(u32, u32),
    /// Two edges (indices into [`MeshTopology::edges`], first < second).
    EdgeEdge(u32, u32),
}

impl Pair {
    /// The pair's four vertices: the point then the triangle's three, or the two edges' ends.
    pub fn vertices(self, topo: &MeshTopology) -> [usize; 4] {
        match self {
            Pair::PointTriangle(v, t) => {
                let t = topo.triangles[t as usize];
                [v as usize, t[0] as usize, t[1] as usize, t[2] as usize]
            }
            Pair::EdgeEdge(a, b) => {
                let (a, b) = (topo.edges[a as usize], topo.edges[b as usize]);
                [a[0] as usize, a[1] as usize, b[0] as usize, b[1] as usize]
            }
        }
    }
    /// Whether the pair is point–triangle.
    pub fn is_point_triangle(self) -> bool {
        matches!(self, Pair::PointTriangle(..))
    }
}

/// Distance between the pair's primitives at the given vertex positions, with coefficients `c` such
/// that the vector between the closest points is r = Σ cᵢ xᵢ (d = |r|); with them fixed, the
/// gradient of d is exact (the closest points minimise the distance).
pub fn pair_distance(point_triangle: bool, x: &[V3; 4]) -> (f64, [f64; 4]) {
    if point_triangle {
        let (d, w) = point_triangle_distance(&x[0], &x[1], &x[2], &x[3]);
        (d, [1.0, -w[0], -w[1], -w[2]])
    } else {
        let (d, s, t) = segment_segment_distance(&x[0], &x[1], &x[2], &x[3]);
        (d, [1.0 - s, s, -(1.0 - t), -t])
    }
}

/// The mollifier of a nearly parallel edge–edge pair (IPC, Li et al. 2020, §4.3, on the squared
/// sine of the edges' angle): with s = sin²θ / `sin2`, m = (2 − s)s below s = 1 and 1 above (C¹
/// there); m and ∇m over the pair's four vertices (edge a's two, then b's), or None where m = 1.
/// The distance between two segments has a kink where they turn parallel (it falls as |φ| when one
/// turns by φ about its middle), so a barrier of it alone has a V-shaped minimum there that Newton
/// cannot converge in; m·b(d) is smooth through it.
pub fn edge_edge_mollifier(x: &[V3; 4], sin2: f64) -> Option<(f64, [V3; 4])> {
    let (ea, eb) = (x[1] - x[0], x[3] - x[2]);
    let (a, b) = (ea.norm_squared(), eb.norm_squared());
    let u = ea.cross(&eb);
    let k = sin2 * a * b;
    let c = u.norm_squared();
    if c >= k || k <= 0.0 {
        return None;
    }
    let s = c / k;
    // dm/ds = 2(1 − s); ∂s/∂eₐ = (2 e_b × u − 2c eₐ/|eₐ|²)/k, ∂s/∂e_b = (2 u × eₐ − 2c e_b/|e_b|²)/k.
    let dm = 2.0 * (1.0 - s) / k;
    let ga = (eb.cross(&u) - ea * (c / a)) * (2.0 * dm);
    let gb = (u.cross(&ea) - eb * (c / b)) * (2.0 * dm);
    Some(((2.0 - s) * s, [-ga, ga, -gb, gb]))
}

/// A lower bound on [`pair_distance`] at a few flops: the gap between the boxes of the pair's two
/// primitives (a broad phase's first test, before the exact distance).
pub fn pair_distance_lower_bound(point_triangle: bool, x: &[V3; 4]) -> f64 {
    let split = if point_triangle { 1 } else { 2 };
    let corners = |k: std::ops::Range<usize>| {
        let (lo, hi) = (x[k.start], x[k.start]);
        x[k].iter().fold((lo, hi), |(l, h), p| (l.inf(p), h.sup(p)))
    };
    let ((la, ha), (lb, hb)) = (corners(0..split), corners(split..4));
    (la - hb).sup(&(lb - ha)).sup(&V3::zeros()).norm()
}

/// Distance from `p` to the triangle `abc` and the barycentric weights of the closest point
/// (Ericson, Real-Time Collision Detection, §5.1.5).
pub fn point_triangle_distance(p: &V3, a: &V3, b: &V3, c: &V3) -> (f64, [f64; 3]) {
    let w = closest_weights(p, a, b, c);
    let q = a * w[0] + b * w[1] + c * w[2];
    ((p - q).norm(), w)
}

fn closest_weights(p: &V3, a: &V3, b: &V3, c: &V3) -> [f64; 3] {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(&ap), ac.dot(&ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return [1.0, 0.0, 0.0];
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(&bp), ac.dot(&bp));
    if d3 >= 0.0 && d4 <= d3 {
        return [0.0, 1.0, 0.0];
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return [1.0 - v, v, 0.0];
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(&cp), ac.dot(&cp));
    if d6 >= 0.0 && d5 <= d6 {
        return [0.0, 0.0, 1.0];
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return [1.0 - w, 0.0, w];
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return [0.0, 1.0 - w, w];
    }
    let denom = va + vb + vc;
    if denom.abs() < 1e-300 {
        // A degenerate (collapsed) triangle: the nearest of its edges' points.
        let cands = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        return cands
            .into_iter()
            .min_by(|u, v| {
                let du = (p - (a * u[0] + b * u[1] + c * u[2])).norm();
                let dv = (p - (a * v[0] + b * v[1] + c * v[2])).norm();
                du.total_cmp(&dv)
            })
            .unwrap_or([1.0, 0.0, 0.0]);
    }
    let (v, w) = (vb / denom, vc / denom);
    [1.0 - v - w, v, w]
}

/// Distance between the segments p0p1 and q0q1 and the parameters (s, t) ∈ [0, 1]² of the closest
/// points p0 + s(p1 − p0), q0 + t(q1 − q0) (Ericson §5.1.9; parallel segments handled).
pub fn segment_segment_distance(p0: &V3, p1: &V3, q0: &V3, q1: &V3) -> (f64, f64, f64) {
    let (d1, d2, r) = (p1 - p0, q1 - q0, p0 - q0);
    let (a, e, f) = (d1.norm_squared(), d2.norm_squared(), d2.dot(&r));
    let eps = 1e-30;
    let (s, t) = if a <= eps && e <= eps {
        (0.0, 0.0)
    } else if a <= eps {
        (0.0, (f / e).clamp(0.0, 1.0))
    } else {
        let c = d1.dot(&r);
        if e <= eps {
            ((-c / a).clamp(0.0, 1.0), 0.0)
        } else {
            let b = d1.dot(&d2);
            let denom = a * e - b * b;
            let mut s = if denom > 1e-14 * a * e {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut t = (b * s + f) / e;
            if t < 0.0 {
                t = 0.0;
                s = (-c / a).clamp(0.0, 1.0);
            } else if t > 1.0 {
                t = 1.0;
                s = ((b - c) / a).clamp(0.0, 1.0);
            }
            (s, t)
        }
    };
    let d = (p0 + d1 * s - (q0 + d2 * t)).norm();
    (d, s, t)
}

/// A pair's vertex moves `dx` relative to their mean, and l, the most they can bring the pair's two
/// primitives together per unit of time (additive CCD's bound: the longest relative move on each
/// side, summed).
pub fn relative_motion(point_triangle: bool, dx: &[V3; 4]) -> ([V3; 4], f64) {
    let mean = (dx[0] + dx[1] + dx[2] + dx[3]) * 0.25;
    let p: [V3; 4] = std::array::from_fn(|k| dx[k] - mean);
    let l = if point_triangle {
        p[0].norm() + p[1].norm().max(p[2].norm()).max(p[3].norm())
    } else {
        p[0].norm().max(p[1].norm()) + p[2].norm().max(p[3].norm())
    };
    (p, l)
}

/// The first time t ∈ (0, `t_max`] at which the pair, its vertices moving from `x` by `t·dx`, comes
/// within `xi` + `share`·(d₀ − `xi`) of itself (d₀ its distance at t = 0), or infinity when it does not
/// before `t_max` (additive CCD). Conservative: every point before the returned time keeps the pair
/// more than `xi` apart, so nothing crosses. Zero when the pair starts within `xi`.
pub fn additive_ccd(
    point_triangle: bool,
    x: &[V3; 4],
    dx: &[V3; 4],
    xi: f64,
    share: f64,
    t_max: f64,
) -> f64 {
    let (p, l) = relative_motion(point_triangle, dx);
    if l <= 0.0 {
        return f64::INFINITY;
    }
    let gap = |y: &[V3; 4]| pair_distance(point_triangle, y).0 - xi;
    let mut y = *x;
    let g0 = gap(&y);
    if g0 <= 0.0 {
        return 0.0;
    }
    let target = share * g0;
    let (mut t, mut tl) = (0.0, (1.0 - share) * g0 / l);
    // The first bound already passes t_max: no impact (what the loop would find after one more
    // distance).
    if tl > t_max {
        return f64::INFINITY;
    }
    for _ in 0..10_000 {
        for k in 0..4 {
            y[k] += p[k] * tl;
        }
        let g = gap(&y);
        if t > 0.0 && g < target {
            return t;
        }
        t += tl;
        if t > t_max {
            return f64::INFINITY;
        }
        tl = 0.9 * g / l;
    }
    t
}

/// Whether two primitives of the mesh that share no vertex come closer than `d` at positions `x`
/// (a broad phase of range `d` alone: far cheaper than the closest distance over every pair).
pub fn comes_within(topo: &MeshTopology, x: &[V3], d: f64) -> bool {
    let boxes: Vec<Aabb> = x.iter().map(Aabb::point).collect();
    let found = std::sync::atomic::AtomicBool::new(false);
    candidate_pairs(topo, &boxes, d, |p| {
        let idx = p.vertices(topo);
        if pair_distance(p.is_point_triangle(), &idx.map(|k| x[k])).0 < d {
            found.store(true, std::sync::atomic::Ordering::Relaxed);
        }
        false
    });
    found.into_inner()
}

/// The (edge, triangle) pairs that share no vertex and where the edge crosses the triangle at
/// positions `x`: the sheet passing through itself (0 for a sheet that does not).
pub fn edge_triangle_crossings(topo: &MeshTopology, x: &[V3]) -> Vec<(u32, u32)> {
    let vbox: Vec<Aabb> = x.iter().map(Aabb::point).collect();
    let (tboxes, eboxes) = primitive_boxes(topo, &vbox, 0.0);
    let (tids, eids): (Vec<u32>, Vec<u32>) = (
        (0..tboxes.len() as u32).collect(),
        (0..eboxes.len() as u32).collect(),
    );
    let (entries, size, buckets) = hash_entries([(&[], &[]), (&tboxes, &tids), (&eboxes, &eids)]);
    let mut out = Vec::new();
    for_each_cell(&entries, |cell| {
        for e in cell.iter().filter(|c| c.1 == 2).map(|c| c.2) {
            let ed = topo.edges[e as usize];
            for t in cell.iter().filter(|c| c.1 == 1).map(|c| c.2) {
                let tr = topo.triangles[t as usize];
                if tr.contains(&ed[0]) || tr.contains(&ed[1]) {
                    continue;
                }
                let [a, b, c] = tr.map(|k| x[k as usize]);
                let (eb, tb) = (&eboxes[e as usize], &tboxes[t as usize]);
                if eb.overlaps(tb)
                    && owner_bucket(eb, tb, size, buckets) == cell[0].0
                    && segment_crosses_triangle(&x[ed[0] as usize], &x[ed[1] as usize], &a, &b, &c)
                {
                    out.push((e, t));
                }
            }
        }
    });
    out.sort_unstable();
    out.dedup();
    out
}

/// Whether segment pq crosses triangle abc (Möller–Trumbore on the segment; touching counts).
pub fn segment_crosses_triangle(p: &V3, q: &V3, a: &V3, b: &V3, c: &V3) -> bool {
    let dir = q - p;
    let (e1, e2) = (b - a, c - a);
    let h = dir.cross(&e2);
    let det = e1.dot(&h);
    if det.abs() < 1e-300 {
        return false;
    }
    let f = 1.0 / det;
    let s = p - a;
    let u = f * s.dot(&h);
    if !(0.0..=1.0).contains(&u) {
        return false;
    }
    let qv = s.cross(&e1);
    let v = f * dir.dot(&qv);
    if v < 0.0 || u + v > 1.0 {
        return false;
    }
    let t = f * e2.dot(&qv);
    (0.0..=1.0).contains(&t)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64, z: f64) -> V3 {
        V3::new(x, y, z)
    }

    #[test]
    fn distances_match_brute_force_sampling() {
        let (a, b, c) = (v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0));
        for p in [
            v(0.2, 0.2, 0.5),
            v(2.0, -1.0, 0.3),
            v(-1.0, -1.0, 0.0),
            v(0.6, 0.6, -0.2),
        ] {
            let (d, w) = point_triangle_distance(&p, &a, &b, &c);
            let mut best = f64::INFINITY;
            for i in 0..=200 {
                for j in 0..=(200 - i) {
                    let (u, s) = (i as f64 / 200.0, j as f64 / 200.0);
                    best = best.min((p - (a * (1.0 - u - s) + b * u + c * s)).norm());
                }
            }
            assert!(d <= best + 1e-12 && best - d < 1e-2, "{p:?}: {d} vs {best}");
            assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        }
        let (d, s, t) = segment_segment_distance(
            &v(0.0, 0.0, 0.0),
            &v(1.0, 0.0, 0.0),
            &v(0.5, -1.0, 0.3),
            &v(0.5, 1.0, 0.3),
        );
        assert!((d - 0.3).abs() < 1e-12 && (s - 0.5).abs() < 1e-12 && (t - 0.5).abs() < 1e-12);
        // Parallel segments.
        let (d, _, _) = segment_segment_distance(
            &v(0.0, 0.0, 0.0),
            &v(1.0, 0.0, 0.0),
            &v(0.5, 0.0, 0.2),
            &v(1.5, 0.0, 0.2),
        );
        assert!((d - 0.2).abs() < 1e-12);
    }

    #[test]
    fn additive_ccd_stops_a_point_short_of_a_triangle_it_would_cross() {
        let x = [
            v(0.2, 0.2, 0.1),
            v(0.0, 0.0, 0.0),
            v(1.0, 0.0, 0.0),
            v(0.0, 1.0, 0.0),
        ];
        let dx = [v(0.0, 0.0, -0.3), V3::zeros(), V3::zeros(), V3::zeros()];
        let t = additive_ccd(true, &x, &dx, 0.0, 0.1, 1.0);
        // It would touch at t = 1/3; it stops before, within the last 10 % of the gap.
        assert!(t < 1.0 / 3.0 && t > 0.29, "{t}");
        // A tangential slide never comes closer.
        let slide = [v(0.3, 0.0, 0.0), V3::zeros(), V3::zeros(), V3::zeros()];
        assert!(additive_ccd(true, &x, &slide, 0.0, 0.1, 1.0).is_infinite());
        // Two edges crossing through each other.
        let e = [
            v(0.0, 0.0, 0.1),
            v(1.0, 0.0, 0.1),
            v(0.5, -1.0, 0.0),
            v(0.5, 1.0, 0.0),
        ];
        let de = [
            v(0.0, 0.0, -0.2),
            v(0.0, 0.0, -0.2),
            V3::zeros(),
            V3::zeros(),
        ];
        let t = additive_ccd(false, &e, &de, 0.0, 0.1, 1.0);
        assert!(t < 0.5 && t > 0.4, "{t}");
    }

    #[test]
    fn the_mollifier_is_its_own_gradients_integral_and_one_beyond_its_angle() {
        let edges = |phi: f64| {
            [
                v(0.0, 0.0, 0.0),
                v(0.01, 0.0, 0.0),
                v(0.002, 0.004, 0.001),
                v(0.002 + 0.012 * phi.cos(), 0.004 + 0.012 * phi.sin(), 0.001),
            ]
        };
        let sin2 = 1e-3;
        for phi in [1e-3, 0.01, 0.02, 0.03] {
            let y = edges(phi);
            let (m, g) = edge_edge_mollifier(&y, sin2).expect("within the angle");
            assert!(m > 0.0 && m < 1.0, "{m}");
            let h = 1e-9;
            for k in 0..4 {
                for c in 0..3 {
                    let (mut yp, mut ym) = (y, y);
                    yp[k][c] += h;
                    ym[k][c] -= h;
                    let at = |z: &[V3; 4]| edge_edge_mollifier(z, sin2).map_or(1.0, |m| m.0);
                    let fd = (at(&yp) - at(&ym)) / (2.0 * h);
                    assert!(
                        (fd - g[k][c]).abs() < 1e-5 * (1.0 + fd.abs()),
                        "{fd} vs {}",
                        g[k][c]
                    );
                }
            }
        }
        // Beyond ~1.8° the pair is left alone; near it m → 1 with a vanishing slope (C¹).
        assert!(edge_edge_mollifier(&edges(0.05), sin2).is_none());
        let slope = |phi: f64| {
            let (m, g) = edge_edge_mollifier(&edges(phi), sin2).expect("inside");
            (m, g.iter().map(|v| v.norm()).fold(0.0, f64::max))
        };
        let ((m, edge), (_, mid)) = (slope(0.0316), slope(0.02));
        assert!(
            1.0 - m < 1e-5 && edge < 1e-2 * mid,
            "m {m}, slope {edge} against {mid}"
        );
        // Parallel: no energy, no force from the mollifier.
        let (m, _) = edge_edge_mollifier(&edges(0.0), sin2).expect("parallel");
        assert!(m.abs() < 1e-20);
    }

    #[test]
    fn the_box_gap_bounds_every_pair_distance_from_below() {
        // A fixed pseudo-random walk over pairs of primitives at all distances and angles.
        let mut s = 0.5f64;
        let mut r = || {
            s = (s * 9301.0 + 49297.0) % 233280.0;
            s / 233280.0 - 0.5
        };
        let (mut tight, mut apart) = (0, 0);
        for _ in 0..2000 {
            let off = v(r(), r(), r()) * 3.0;
            let y: [V3; 4] = std::array::from_fn(|k| {
                let base = if k >= 2 { off } else { V3::zeros() };
                base + v(r(), r(), r())
            });
            for pt in [true, false] {
                let (lb, d) = (pair_distance_lower_bound(pt, &y), pair_distance(pt, &y).0);
                assert!(lb <= d + 1e-15, "{lb} > {d}");
                tight += usize::from(lb > 0.5 * d);
                apart += usize::from(lb > 0.0);
            }
        }
        // Not vacuous: most separated pairs are bounded within a factor of two.
        assert!(apart > 1000 && tight > apart / 2, "{tight} of {apart}");
    }

    /// Two 3 × 3 patches of 1 cm cells `gap` apart, the upper one shifted by `shift` along x:
    /// positions and triangles.
    fn stacked(gap: f64, shift: f64) -> (Vec<V3>, Vec<[u32; 3]>) {
        let mut x = Vec::new();
        for layer in 0..2 {
            for j in 0..3 {
                for i in 0..3 {
                    let shift = layer as f64 * shift;
                    x.push(v(
                        i as f64 * 0.01 + shift,
                        j as f64 * 0.01,
                        layer as f64 * gap,
                    ));
                }
            }
        }
        let mut tris = Vec::new();
        for layer in 0..2u32 {
            let o = layer * 9;
            for j in 0..2u32 {
                for i in 0..2u32 {
                    let p = o + j * 3 + i;
                    tris.push([p, p + 1, p + 4]);
                    tris.push([p, p + 4, p + 3]);
                }
            }
        }
        (x, tris)
    }

    #[test]
    fn a_sheet_comes_within_a_distance_exactly_when_its_closest_pair_does() {
        for gap in [2e-4, 7e-4, 3e-3] {
            // The upper patch shifted by a third of a cell: its vertices over the lower's triangles.
            let (x, tris) = stacked(gap, 0.0033);
            let topo = MeshTopology::from_triangles(tris);
            for d in [1e-4, 5e-4, 1e-3, 5e-3] {
                assert_eq!(comes_within(&topo, &x, d), gap < d, "gap {gap}, d {d}");
            }
        }
        // One sheet on its own: neighbours share vertices, and nothing else comes near.
        let (x, tris) = stacked(0.0, 0.0);
        let topo = MeshTopology::from_triangles(tris[..8].to_vec());
        assert!(!comes_within(&topo, &x[..9], 5e-3));
    }

    #[test]
    fn the_broad_phase_finds_every_close_pair_of_two_stacked_sheets() {
        // Two 3 × 3 patches 1 mm apart: every vertex of one lies over a triangle of the other.
        let (x, tris) = stacked(1e-3, 0.0);
        let topo = MeshTopology::from_triangles(tris);
        let boxes: Vec<Aabb> = x.iter().map(Aabb::point).collect();
        let pairs = candidate_pairs(&topo, &boxes, 1e-3, |_| true);
        let mut brute = 0;
        for &vtx in &topo.vertices {
            for (t, tri) in topo.triangles.iter().enumerate() {
                let idx = [
                    vtx as usize,
                    tri[0] as usize,
                    tri[1] as usize,
                    tri[2] as usize,
                ];
                let y = idx.map(|k| x[k]);
                if !tri.contains(&vtx) && pair_distance(true, &y).0 < 1.5e-3 {
                    brute += 1;
                    assert!(pairs.contains(&Pair::PointTriangle(vtx, t as u32)));
                }
            }
        }
        assert!(brute > 18, "{brute}");
    }
}
