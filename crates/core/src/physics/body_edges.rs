//! The sheet's edges and faces against a mesh body's sharp features (issue 77): the obstacle
//! barrier keeps every cloth vertex out of the body, but over a sharp body edge (a table's rim
//! given as a mesh) a cloth edge between a vertex on the top and one hanging down cuts the rim,
//! and a body corner can poke through a cloth triangle between its vertices. This term keeps each
//! cloth edge at a distance from each feature edge of the body (one whose faces are not coplanar)
//! and each cloth triangle from each corner of the body (a vertex on a feature edge): the barrier
//! b(d) of the segments' distance (Ericson §5.1.9) or the point–triangle distance, κ from the cloth
//! stencil's weight as the vertices' barrier sets it, in the manner of IPC's edge–edge and
//! point–triangle pairs (Li et al. 2020), without their mollifier (a cloth edge parallel to a body
//! edge keeps a continuous distance, its gradient turning where the closest points switch). Opt
//! in with `contact.body_edges`.
//!
//! Its gradient is exact (∂d/∂xᵢ = wᵢ n, wᵢ the weight of cloth vertex i in the closest point and n
//! the unit direction from the body's point to it: Danskin's theorem); its Hessian's curvature
//! part b′ ∇²d by central differences of that gradient, left out of the projected Hessian (b′ < 0).
//! The step bound is Offset Geometric Contact's: along a step a stencil's points move at most as
//! far as its farthest vertex, so 90 % of its distance to the nearest feature bounds it.

use super::barrier::barrier;
use super::{EnergyTerm, HessianBlocks, HessianMode, ObstacleBarrier, StepBound, Vecs};
use crate::obstacle::{Obstacle, TriangleBody};
use crate::proximity::{Aabb, point_triangle_distance, segment_segment_distance};
use nalgebra::{Matrix3, Vector3};
use std::sync::Arc;

type V3 = Vector3<f64>;

/// A body feature in the scene's frame.
#[derive(Clone, Copy)]
enum Feature {
    /// A feature edge's ends (against a cloth edge).
    Edge(V3, V3),
    /// A corner (against a cloth triangle).
    Corner(V3),
}

/// The cloth stencils (edges, then triangles) against the mesh bodies' features.
pub struct BodyEdgeBarrier {
    bodies: Vec<(Arc<TriangleBody>, V3)>,
    /// Cloth particles of each stencil: an edge's two (the third unused) or a triangle's three.
    stencils: Vec<([usize; 3], usize)>,
    kappa_J: Vec<f64>,
    d_hat_m: f64,
}

/// One cloth stencil near one body feature: the distance, each cloth vertex's weight in the
/// closest point, the unit direction from the body's point to the cloth's.
struct Pair {
    stencil: usize,
    d: f64,
    w: [f64; 3],
    n: V3,
    feature: Feature,
}

/// The distance of `points` (a cloth edge's two or a triangle's three) from `feature`, the
/// weights of the points in the closest point and the unit direction from the feature to it.
fn distance(points: &[V3], feature: Feature) -> Option<(f64, [f64; 3], V3)> {
    let (d, w, closest, from) = match (feature, points) {
        (Feature::Edge(u, v), [a, b]) => {
            let (d, s, t) = segment_segment_distance(a, b, &u, &v);
            (d, [1.0 - s, s, 0.0], a + (b - a) * s, u + (v - u) * t)
        }
        (Feature::Corner(c), [a, b, p]) => {
            let (d, w) = point_triangle_distance(&c, a, b, p);
            (d, w, a * w[0] + b * w[1] + p * w[2], c)
        }
        _ => return None,
    };
    (d > 0.0).then(|| (d, w, (closest - from) / d))
}

impl BodyEdgeBarrier {
    /// The term for the edges and triangles of `triangles` with a free vertex against the mesh
    /// bodies among `obstacles`; none when no body is a mesh or nothing is free.
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
            .flat_map(|t| (0..3).map(move |k| [t[k], t[(k + 1) % 3]]))
            .map(|[a, b]| [a.min(b) as usize, a.max(b) as usize])
            .collect();
        edges.sort_unstable();
        edges.dedup();
        let stencils: Vec<([usize; 3], usize)> = edges
            .iter()
            .map(|[a, b]| ([*a, *b, *b], 2))
            .chain(triangles.iter().map(|t| (t.map(|v| v as usize), 3)))
            .filter(|(s, n)| s[..*n].iter().any(|p| !fixed[*p]))
            .collect();
        if bodies.is_empty() || stencils.is_empty() {
            return None;
        }
        let kappa_J = stencils
            .iter()
            .map(|(s, n)| {
                let w = s[..*n].iter().map(|p| masses[*p]).sum::<f64>() / *n as f64 * g_m_per_s2;
                ObstacleBarrier::kappa_for_weight(w.max(f64::MIN_POSITIVE), d_hat_m)
            })
            .collect();
        Some(Self {
            bodies,
            stencils,
            kappa_J,
            d_hat_m,
        })
    }

    /// The cloth points of stencil `k` at `x`.
    fn points(&self, k: usize, x: &Vecs) -> Vec<V3> {
        let (s, n) = self.stencils[k];
        s[..n].iter().map(|p| x[*p]).collect()
    }

    /// The pairs of stencil `k` at `x` within `reach` of a body feature.
    fn stencil_pairs(&self, k: usize, x: &Vecs, reach: f64, out: &mut Vec<Pair>) {
        let points = self.points(k, x);
        for (body, offset) in &self.bodies {
            let local: Vec<V3> = points.iter().map(|p| p - offset).collect();
            let bounds = local
                .iter()
                .fold(Aabb::point(&local[0]), |b, p| b.union(&Aabb::point(p)))
                .inflate(reach);
            let features: Vec<Feature> = match points.len() {
                2 => body
                    .edges_near(&bounds)
                    .into_iter()
                    .map(|(u, v)| Feature::Edge(u, v))
                    .collect(),
                _ => body
                    .corners_near(&bounds)
                    .into_iter()
                    .map(Feature::Corner)
                    .collect(),
            };
            for f in features {
                let Some((d, w, n)) = distance(&local, f) else {
                    continue;
                };
                if d < reach {
                    let feature = match f {
                        Feature::Edge(u, v) => Feature::Edge(u + offset, v + offset),
                        Feature::Corner(c) => Feature::Corner(c + offset),
                    };
                    out.push(Pair {
                        stencil: k,
                        d,
                        w,
                        n,
                        feature,
                    });
                }
            }
        }
    }

    /// Every pair within the barrier's band at `x`.
    fn pairs(&self, x: &Vecs) -> Vec<Pair> {
        let mut out = Vec::new();
        for k in 0..self.stencils.len() {
            self.stencil_pairs(k, x, self.d_hat_m, &mut out);
        }
        out
    }

    /// ∇d of a pair over its stencil's vertices.
    fn grad_d(pair: &Pair) -> [V3; 3] {
        pair.w.map(|w| pair.n * w)
    }

    /// The curvature ∇²d of pair `p` (3 × 3 blocks) by central differences of ∇d.
    fn curvature(&self, p: &Pair, x: &Vecs) -> [[Matrix3<f64>; 3]; 3] {
        let h = 1e-4 * p.d;
        let mut blocks = [[Matrix3::zeros(); 3]; 3];
        let points = self.points(p.stencil, x);
        let grad = |pts: &[V3]| {
            distance(pts, p.feature).map_or([V3::zeros(); 3], |(_, w, n)| w.map(|w| n * w))
        };
        for j in 0..points.len() {
            for c in 0..3 {
                let (mut hi, mut lo) = (points.clone(), points.clone());
                hi[j][c] += h;
                lo[j][c] -= h;
                let (gp, gm) = (grad(&hi), grad(&lo));
                for i in 0..points.len() {
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
            .map(|p| self.kappa_J[p.stencil] * barrier(p.d, self.d_hat_m).0)
            .sum()
    }
    fn add_gradient(&self, x: &Vecs, g: &mut Vecs) {
        for p in self.pairs(x) {
            let db = self.kappa_J[p.stencil] * barrier(p.d, self.d_hat_m).1;
            let (s, n) = self.stencils[p.stencil];
            for (i, gi) in Self::grad_d(&p).iter().enumerate().take(n) {
                g[s[i]] += gi * db;
            }
        }
    }
    fn add_hessian(&self, x: &Vecs, h: &mut HessianBlocks, mode: HessianMode) {
        let project = mode.is_projected();
        for p in self.pairs(x) {
            let (_, db, d2b) = barrier(p.d, self.d_hat_m);
            let k = self.kappa_J[p.stencil];
            let grad = Self::grad_d(&p);
            let curv = (!project).then(|| self.curvature(&p, x));
            let (ends, n) = self.stencils[p.stencil];
            // The lower triangle of the blocks: a block at (i, j) stands for its transpose too.
            // Fixed vertices' blocks too: their coupling carries a held vertex's motion into the
            // drape (sensitivities in a key that moves it).
            for i in 0..n {
                for j in 0..=i {
                    let mut m = grad[i] * grad[j].transpose() * (k * d2b);
                    if let Some(c) = &curv {
                        m += c[i][j] * (k * db);
                    }
                    h.push(ends[i], ends[j], m);
                }
            }
        }
    }
    fn step_bound(&self) -> Option<&dyn StepBound> {
        Some(self)
    }
}

impl StepBound for BodyEdgeBarrier {
    fn max_step(&self, x: &Vecs, dx: &Vecs) -> f64 {
        let mut alpha = f64::INFINITY;
        let mut near = Vec::new();
        for (k, (s, n)) in self.stencils.iter().enumerate() {
            let moved = s[..*n].iter().map(|p| dx[*p].norm()).fold(0.0, f64::max);
            if moved == 0.0 {
                continue;
            }
            near.clear();
            self.stencil_pairs(k, x, moved / 0.9, &mut near);
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

    /// The term's gradient against central differences of its energy and its Hessian against
    /// central differences of its gradient, over the particles `moving` of `x`.
    fn check_derivatives(term: &BodyEdgeBarrier, x: &[V3], moving: &[usize]) {
        let n = x.len();
        let mut g = vec![V3::zeros(); n];
        term.add_gradient(x, &mut g);
        let mut hb = HessianBlocks::default();
        term.add_hessian(x, &mut hb, crate::physics::HessianMode::NEWTON);
        let column = |p: usize, c: usize| {
            let (mut col, mut e) = (vec![V3::zeros(); n], vec![V3::zeros(); n]);
            e[p][c] = 1.0;
            hb.mul_add(&e, &mut col);
            col
        };
        let scale = moving
            .iter()
            .flat_map(|&p| (0..3).flat_map(move |c| column(p, c)))
            .map(|v| v.norm())
            .fold(0.0, f64::max);
        let gscale = g.iter().map(|v| v.norm()).fold(0.0, f64::max);
        let h = 1e-8;
        for &p in moving {
            for c in 0..3 {
                let (mut xp, mut xm) = (x.to_vec(), x.to_vec());
                xp[p][c] += h;
                xm[p][c] -= h;
                let fd = (term.energy(&xp) - term.energy(&xm)) / (2.0 * h);
                assert!(
                    (fd - g[p][c]).abs() < 1e-5 * gscale,
                    "{p} {c}: {fd} vs {}",
                    g[p][c]
                );
                let (mut gp, mut gm) = (vec![V3::zeros(); n], vec![V3::zeros(); n]);
                term.add_gradient(&xp, &mut gp);
                term.add_gradient(&xm, &mut gm);
                let col = column(p, c);
                for &q in moving {
                    let fdh = (gp[q] - gm[q]) / (2.0 * h);
                    assert!(
                        (fdh - col[q]).norm() < 1e-4 * scale,
                        "H[{q}][{p},{c}]: {fdh} vs {}",
                        col[q]
                    );
                }
            }
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
        // The edge over the top face's diagonal (0.4 mm above it, inside the band) pairs with
        // nothing: a flat face's inner edge is no feature.
        assert!(
            pairs
                .iter()
                .all(|p| term.stencils[p.stencil].0[..2] != [2, 3]),
            "not the flat diagonal"
        );
        assert!(
            pairs
                .iter()
                .any(|p| term.stencils[p.stencil].0[..2] == [0, 1]),
            "the rim"
        );
        check_derivatives(&term, &x, &[0, 1]);
        // A step driving the edge into the rim is cut before it gets there.
        let mut dx = vec![V3::zeros(); 5];
        dx[0] = V3::new(-0.01, 0.0, -0.01);
        dx[1] = V3::new(-0.01, 0.0, -0.01);
        let a = term.max_step(&x, &dx);
        assert!(a > 0.0 && a < 1.0, "{a}");
    }

    /// A cloth triangle spread over the cube's top corner, 0.5 mm above it, its vertices away from
    /// the rim: the corner pairs with the triangle's inside, with the derivatives of its energy.
    #[test]
    fn a_body_corner_under_a_cloth_triangle_pushes_its_three_vertices() {
        let z = 0.1 + 5e-4;
        let x = vec![
            V3::new(0.085, 0.085, z),
            V3::new(0.125, 0.09, z),
            V3::new(0.09, 0.125, z),
        ];
        let term = BodyEdgeBarrier::new(
            &[cube()],
            &[[0, 1, 2]],
            &[1e-4; 3],
            &[false; 3],
            (1e-3, 9.81),
        )
        .unwrap();
        let pairs = term.pairs(&x);
        let corner: Vec<&Pair> = pairs
            .iter()
            .filter(|p| term.stencils[p.stencil].1 == 3)
            .collect();
        assert_eq!(corner.len(), 1, "one corner under the triangle");
        assert!(
            corner[0].w.iter().all(|w| *w > 0.05),
            "inside: {:?}",
            corner[0].w
        );
        assert!((corner[0].d - 5e-4).abs() < 1e-12 && corner[0].n.z > 0.999);
        check_derivatives(&term, &x, &[0, 1, 2]);
    }
}
