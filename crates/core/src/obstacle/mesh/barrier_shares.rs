//! A mesh body's barrier as a sum over its features (faces +1, edges −1, vertices +1 within the
//! band): the nearest distance's barrier where one feature is nearest, smooth in a concave crease.

use super::{TriangleBody, V3};
use crate::proximity::{Aabb, point_triangle_distance};
use nalgebra::Matrix3;

impl TriangleBody {
    /// The shares of a barrier at `p` (outside, within `reach` of the surface): every face, edge and
    /// vertex of the triangles near it that lies nearer than `reach`, seen from its outside (its
    /// closest feature's pseudo-normal faces `p`), as (distance, unit direction from its closest
    /// point to `p`, that direction's derivative ∂n/∂p, weight): faces +1, edges −1, vertices +1.
    /// Summed, κ Σ w b(d) is the barrier of the nearest distance wherever one feature is nearest
    /// (the features whose closest point is any one point of a flat or convex surface count
    /// F − E + V = 1 there, 0 elsewhere: the inclusion–exclusion of Li et al.'s point–triangle
    /// duplicates), and smooth where the nearest distance has a kink: in a concave crease (an
    /// armpit) both faces count. ∂n/∂p is zero inside a face, (I − nnᵀ − eeᵀ)/d along an edge of
    /// direction e, (I − nnᵀ)/d from a point. None where `p` is on or inside the surface, or
    /// farther than `reach` from it.
    pub fn pieces_within(&self, p: &V3, reach: f64) -> Option<Vec<BarrierShare>> {
        let (d, _) = self.signed_distance_within(p, reach)?;
        if d <= 0.0 {
            return None;
        }
        let tris = self.triangles_overlapping_ids(&Aabb::point(p).inflate(reach));
        let mut edges: Vec<(u32, u32)> = Vec::new();
        let mut corners: Vec<u32> = Vec::new();
        let mut out = Vec::new();
        for &t in &tris {
            let tri = self.triangles[t as usize];
            let c = |k: usize| &self.vertices[tri[k] as usize];
            let (dt, w) = point_triangle_distance(p, c(0), c(1), c(2));
            let q: V3 = (0..3).map(|k| c(k) * w[k]).sum();
            let inside_face = w.iter().all(|&x| x != 0.0);
            let dn = match inside_face {
                true => Matrix3::zeros(),
                false => self.feature_derivative(p, &q, tri, &w),
            };
            share(
                &mut out,
                (p, q, dt, reach),
                self.feature_normal(t, &w),
                dn,
                1.0,
            );
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                edges.push((a.min(b), a.max(b)));
                corners.push(tri[k]);
            }
        }
        edges.sort_unstable();
        edges.dedup();
        corners.sort_unstable();
        corners.dedup();
        for (a, b) in edges {
            let (va, vb) = (&self.vertices[a as usize], &self.vertices[b as usize]);
            let e = vb - va;
            let s = ((p - va).dot(&e) / e.norm_squared()).clamp(0.0, 1.0);
            let q = va + e * s;
            let (normal, dn) = match s {
                0.0 => (self.vertex_normals[a as usize], point_derivative(p, &q)),
                1.0 => (self.vertex_normals[b as usize], point_derivative(p, &q)),
                _ => (self.edge_normals[&(a, b)], edge_derivative(p, &q, &e)),
            };
            share(&mut out, (p, q, (p - q).norm(), reach), normal, dn, -1.0);
        }
        for v in corners {
            let q = self.vertices[v as usize];
            let dn = point_derivative(p, &q);
            let normal = self.vertex_normals[v as usize];
            share(&mut out, (p, q, (p - q).norm(), reach), normal, dn, 1.0);
        }
        Some(out)
    }

    /// ∂n/∂p of a triangle's direction where its closest point `q` lies on an edge or a corner
    /// (weights `w`, one or two of them zero).
    fn feature_derivative(&self, p: &V3, q: &V3, tri: [u32; 3], w: &[f64; 3]) -> Matrix3<f64> {
        let on: Vec<usize> = (0..3).filter(|&k| w[k] != 0.0).collect();
        match on.as_slice() {
            [a, b] => {
                let e = self.vertices[tri[*b] as usize] - self.vertices[tri[*a] as usize];
                edge_derivative(p, q, &e)
            }
            _ => point_derivative(p, q),
        }
    }
}

/// One share of a mesh body's barrier at a point: distance (m), unit direction from the feature's
/// closest point, that direction's derivative, weight (±1).
pub type BarrierShare = (f64, V3, Option<Matrix3<f64>>, f64);

/// Adds the share of a feature whose closest point to `p` is `q` at distance `d`, when it lies
/// within `reach` and `p` is on the side its pseudo-normal `normal` faces.
fn share(
    out: &mut Vec<BarrierShare>,
    (p, q, d, reach): (&V3, V3, f64, f64),
    normal: V3,
    dn: Matrix3<f64>,
    weight: f64,
) {
    if d >= reach || d <= 0.0 {
        return;
    }
    let n = (p - q) / d;
    if n.dot(&normal) > 0.0 {
        out.push((d, n, Some(dn), weight));
    }
}

/// ∂n/∂p of the direction n = (p − q)/|p − q| from a fixed point q: (I − nnᵀ)/d.
fn point_derivative(p: &V3, q: &V3) -> Matrix3<f64> {
    let (d, n) = ((p - q).norm(), (p - q).normalize());
    (Matrix3::identity() - n * n.transpose()) / d
}

/// ∂n/∂p of the direction from the closest point q on a line of direction `e`: (I − nnᵀ − êêᵀ)/d.
fn edge_derivative(p: &V3, q: &V3, e: &V3) -> Matrix3<f64> {
    let (d, n, u) = ((p - q).norm(), (p - q).normalize(), e.normalize());
    (Matrix3::identity() - n * n.transpose() - u * u.transpose()) / d
}
