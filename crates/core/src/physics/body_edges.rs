//! The sheet's edges against a mesh body's edges (issue 77): the obstacle barrier keeps every cloth
//! vertex out of the body, but over a sharp body edge (a table's rim given as a mesh) a cloth edge
//! between a vertex on the top and one hanging down cuts the corner. This term keeps each cloth
//! edge at a distance from each feature edge of the body (one whose faces are not coplanar): the
//! barrier b(d) of the segments' distance d (Ericson §5.1.9), κ from the edge's weight as the
//! vertices' barrier sets it, in the manner of IPC's edge–edge pairs (Li et al. 2020), without
//! their mollifier (a cloth edge parallel to a body edge keeps a continuous distance, its
//! gradient turning where the closest points switch). Opt in with `contact.body_edges`.
//!
//! Its gradient is exact (∂d/∂a = (1 − s) n, ∂d/∂b = s n at the closest points, Danskin's theorem);
//! its Hessian's curvature part b′ ∇²d by central differences of that gradient, left out of the
//! projected Hessian (b′ < 0). The step bound is Offset Geometric Contact's: along a step a segment
//! moves at most as far as its farther end, so 90 % of its distance to the nearest body edge
//! bounds it.

use super::barrier::barrier;
use super::{EnergyTerm, HessianBlocks, ObstacleBarrier, Vecs};
use crate::obstacle::{Obstacle, TriangleBody};
use crate::proximity::{Aabb, segment_segment_distance};
use nalgebra::{Matrix3, Vector3};
use std::sync::Arc;

type V3 = Vector3<f64>;

/// The cloth's edges against the mesh bodies' feature edges.
pub struct BodyEdgeBarrier {
    bodies: Vec<(Arc<TriangleBody>, V3)>,
    edges: Vec<[usize; 2]>,
    kappa_J: Vec<f64>,
    fixed: Vec<bool>,
    d_hat_m: f64,
}

/// One cloth edge near one body edge: the edge's index, its distance and the closest point's
/// parameter s along it (0 at its first end), and the unit direction from the body's point to it.
struct Pair {
    edge: usize,
    d: f64,
    s: f64,
    n: V3,
    /// The body edge's ends in the scene's frame.
    body_edge: (V3, V3),
}

impl BodyEdgeBarrier {
    /// The term for the edges of `triangles` with a free end against the mesh bodies among
    /// `obstacles`; none when no body is a mesh or no edge is free.
    pub fn new(
        obstacles: &[Obstacle],
        triangles: &[[u32; 3]],
        masses: &[f64],
        fixed: &[bool],
        (d_hat_m, g_m_per_s2): (f64, f64),
    ) -> Option<Self> {
        let bodies: Vec<(Arc<TriangleBody>, V3)> = obstacles
            .iter()
            .filter_map(|o| match o {
                Obstacle::Mesh {
                    offset_m,
                    body: Some(b),
                    ..
                } => Some((b.clone(), V3::from(*offset_m))),
                _ => None,
            })
            .collect();
        let mut edges: Vec<[usize; 2]> = triangles
            .iter()
            .flat_map(|t| (0..3).map(move |k| (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3]))))
            .map(|(a, b)| [a as usize, b as usize])
            .filter(|[a, b]| !(fixed[*a] && fixed[*b]))
            .collect();
        edges.sort_unstable();
        edges.dedup();
        if bodies.is_empty() || edges.is_empty() {
            return None;
        }
        let kappa_J = edges
            .iter()
            .map(|[a, b]| {
                let w = 0.5 * (masses[*a] + masses[*b]) * g_m_per_s2;
                ObstacleBarrier::kappa_for_weight(w.max(f64::MIN_POSITIVE), d_hat_m)
            })
            .collect();
        Some(Self {
            bodies,
            edges,
            kappa_J,
            fixed: fixed.to_vec(),
            d_hat_m,
        })
    }

    /// The pairs of cloth edge `e` at `x` within `reach` of a body edge.
    fn edge_pairs(&self, e: usize, x: &Vecs, reach: f64, out: &mut Vec<Pair>) {
        let [a, b] = self.edges[e];
        for (body, offset) in &self.bodies {
            let (pa, pb) = (x[a] - offset, x[b] - offset);
            let bounds = Aabb::point(&pa).union(&Aabb::point(&pb)).inflate(reach);
            for (u, v) in body.edges_near(&bounds) {
                let (d, s, t) = segment_segment_distance(&pa, &pb, &u, &v);
                if d >= reach || d <= 0.0 {
                    continue;
                }
                let (p, q) = (pa + (pb - pa) * s, u + (v - u) * t);
                let body_edge = (u + offset, v + offset);
                out.push(Pair {
                    edge: e,
                    d,
                    s,
                    n: (p - q) / d,
                    body_edge,
                });
            }
        }
    }

    /// Every pair within the barrier's band at `x`.
    fn pairs(&self, x: &Vecs) -> Vec<Pair> {
        let mut out = Vec::new();
        for e in 0..self.edges.len() {
            self.edge_pairs(e, x, self.d_hat_m, &mut out);
        }
        out
    }

    /// ∇d of a pair over its cloth edge's two ends.
    fn grad_d(pair: &Pair) -> [V3; 2] {
        [pair.n * (1.0 - pair.s), pair.n * pair.s]
    }

    /// ∇d over the cloth edge's ends (`xa`, `xb`) against the body edge (`u`, `v`).
    fn segment_grad(xa: &V3, xb: &V3, (u, v): (V3, V3)) -> [V3; 2] {
        let (d, s, t) = segment_segment_distance(xa, xb, &u, &v);
        let n = ((xa + (xb - xa) * s) - (u + (v - u) * t)) / d;
        [n * (1.0 - s), n * s]
    }

    /// The curvature ∇²d of pair `p` (6 × 6 as 2 × 2 blocks) by central differences of ∇d.
    fn curvature(&self, p: &Pair, x: &Vecs) -> [[Matrix3<f64>; 2]; 2] {
        let h = 1e-4 * p.d;
        let mut blocks = [[Matrix3::zeros(); 2]; 2];
        let [a, b] = self.edges[p.edge];
        for j in 0..2 {
            for c in 0..3 {
                let mut ends = [[x[a], x[b]]; 2];
                ends[0][j][c] += h;
                ends[1][j][c] -= h;
                let gp = Self::segment_grad(&ends[0][0], &ends[0][1], p.body_edge);
                let gm = Self::segment_grad(&ends[1][0], &ends[1][1], p.body_edge);
                for i in 0..2 {
                    blocks[i][j].set_column(c, &((gp[i] - gm[i]) / (2.0 * h)));
                }
            }
        }
        blocks
    }
}

impl EnergyTerm for BodyEdgeBarrier {
    fn name(&self) -> String {
        "contact/body-edges".into()
    }
    fn energy(&self, x: &Vecs) -> f64 {
        self.pairs(x)
            .iter()
            .map(|p| self.kappa_J[p.edge] * barrier(p.d, self.d_hat_m).0)
            .sum()
    }
    fn add_gradient(&self, x: &Vecs, g: &mut Vecs) {
        for p in self.pairs(x) {
            let db = self.kappa_J[p.edge] * barrier(p.d, self.d_hat_m).1;
            let [ga, gb] = Self::grad_d(&p);
            let [a, b] = self.edges[p.edge];
            g[a] += ga * db;
            g[b] += gb * db;
        }
    }
    fn add_hessian(&self, x: &Vecs, h: &mut HessianBlocks, project: bool) {
        for p in self.pairs(x) {
            let (_, db, d2b) = barrier(p.d, self.d_hat_m);
            let k = self.kappa_J[p.edge];
            let grad = Self::grad_d(&p);
            let curv = (!project).then(|| self.curvature(&p, x));
            let ends = self.edges[p.edge];
            // The lower triangle of the 2 × 2 blocks: a block at (i, j) stands for its transpose too.
            for i in 0..2 {
                for j in 0..=i {
                    if self.fixed[ends[i]] || self.fixed[ends[j]] {
                        continue;
                    }
                    let mut m = grad[i] * grad[j].transpose() * (k * d2b);
                    if let Some(c) = &curv {
                        m += c[i][j] * (k * db);
                    }
                    h.push(ends[i], ends[j], m);
                }
            }
        }
    }
    fn max_step(&self, x: &Vecs, dx: &Vecs) -> f64 {
        let mut alpha = f64::INFINITY;
        let mut near = Vec::new();
        for (e, [a, b]) in self.edges.iter().enumerate() {
            let moved = dx[*a].norm().max(dx[*b].norm());
            if moved == 0.0 {
                continue;
            }
            near.clear();
            self.edge_pairs(e, x, moved / 0.9, &mut near);
            for p in &near {
                alpha = alpha.min(0.9 * p.d / moved);
            }
        }
        alpha
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit cube [0, 0.1]³ as 12 outward triangles.
    fn cube() -> Obstacle {
        let s = 0.1;
        let v: Vec<V3> = (0..8)
            .map(|i| {
                V3::new(
                    s * (i & 1) as f64,
                    s * ((i >> 1) & 1) as f64,
                    s * (i >> 2) as f64,
                )
            })
            .collect();
        let quads = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        let t: Vec<[u32; 3]> = quads
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .collect();
        Obstacle::Mesh {
            mesh: "cube.obj".into(),
            mesh_unit_m: 1.0,
            offset_m: [0.0; 3],
            body: Some(Arc::new(TriangleBody::new(v, t).unwrap())),
        }
    }

    /// Cloth edges across the cube's top rim (x = 0.1, z = 0.1) and over a diagonal of its top face
    /// (flat: no feature): the gradient is the central difference of the energy, the Hessian that
    /// of the gradient; the diagonal pairs with nothing, and the step bound keeps a step toward the
    /// rim short of it.
    #[test]
    fn cloth_edges_over_a_body_rim_have_the_derivatives_of_their_energy() {
        let x: Vec<V3> = vec![
            V3::new(0.099, 0.03, 0.1006),
            V3::new(0.1006, 0.034, 0.0992),
            V3::new(0.05, 0.05, 0.1004),
            V3::new(0.06, 0.06, 0.1004),
            V3::new(0.3, 0.3, 0.3),
        ];
        let tris = [[0u32, 1, 4], [2, 3, 4]];
        let masses = [1e-4; 5];
        let fixed = [false; 5];
        let term = BodyEdgeBarrier::new(&[cube()], &tris, &masses, &fixed, (1e-3, 9.81)).unwrap();
        let pairs = term.pairs(&x);
        assert!(!pairs.is_empty());
        // The edge over the top face's diagonal (0.4 mm above it, inside the band) pairs with
        // nothing: a flat face's inner edge is no feature.
        assert!(
            pairs.iter().all(|p| term.edges[p.edge] != [2, 3]),
            "not the flat diagonal"
        );
        assert!(
            pairs.iter().any(|p| term.edges[p.edge] == [0, 1]),
            "the rim"
        );
        let mut g = vec![V3::zeros(); 5];
        term.add_gradient(&x, &mut g);
        let mut hb = HessianBlocks::default();
        term.add_hessian(&x, &mut hb, false);
        let column = |p: usize, c: usize| {
            let (mut col, mut e) = (vec![V3::zeros(); 5], vec![V3::zeros(); 5]);
            e[p][c] = 1.0;
            hb.mul_add(&e, &mut col);
            col
        };
        let scale = (0..6)
            .flat_map(|k| column(k / 3, k % 3))
            .map(|v| v.norm())
            .fold(0.0, f64::max);
        let h = 1e-8;
        for p in [0, 1] {
            for c in 0..3 {
                let (mut xp, mut xm) = (x.clone(), x.clone());
                xp[p][c] += h;
                xm[p][c] -= h;
                let fd = (term.energy(&xp) - term.energy(&xm)) / (2.0 * h);
                assert!(
                    (fd - g[p][c]).abs() < 1e-5 * g[p].norm(),
                    "{p} {c}: {fd} vs {}",
                    g[p][c]
                );
                let (mut gp, mut gm) = (vec![V3::zeros(); 5], vec![V3::zeros(); 5]);
                term.add_gradient(&xp, &mut gp);
                term.add_gradient(&xm, &mut gm);
                let col = column(p, c);
                for q in [0, 1] {
                    let fdh = (gp[q] - gm[q]) / (2.0 * h);
                    assert!(
                        (fdh - col[q]).norm() < 1e-4 * scale,
                        "H[{q}][{p},{c}]: {fdh} vs {}",
                        col[q]
                    );
                }
            }
        }
        // A step driving the edge into the rim is cut before it gets there.
        let mut dx = vec![V3::zeros(); 5];
        dx[0] = V3::new(-0.01, 0.0, -0.01);
        dx[1] = V3::new(-0.01, 0.0, -0.01);
        let a = term.max_step(&x, &dx);
        assert!(a > 0.0 && a < 1.0, "{a}");
    }
}
