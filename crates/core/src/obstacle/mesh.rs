//! A rigid body given as a triangle mesh (issue 77's mesh obstacles: a dress form, a mannequin, a
//! table scanned or modelled): its signed distance, sign from the angle-weighted pseudo-normal of the
//! closest feature (Bærentzen and Aanæs, "Signed distance computation using the angle weighted
//! pseudonormal", IEEE TVCG 11(3), 2005), found through a bounding-volume hierarchy built once over
//! the static body, and the height of its upper surface on a vertical line.
//!
//! Triangles face outward when counter-clockwise seen from outside. The sign is right for a closed,
//! consistently oriented mesh; near an open mesh's border it is that of the nearest face's side.

pub use super::mesh_defect::{BodyDefect, closed_surface_defect};
mod barrier_shares;
mod normals;
use normals::{flat_edges, pseudo_normals};

use crate::proximity::{Aabb, point_triangle_distance};
use nalgebra::Vector3;
use std::collections::HashMap;

type V3 = Vector3<f64>;

/// How far outside a face a vertical still meets it (m): as the analytic table's edge slack.
const EDGE_SLACK_M: f64 = 1e-9;

/// Triangles a leaf of the hierarchy holds at most.
const LEAF_SIZE: usize = 4;

/// A node of the hierarchy: its box and either two children or a run of triangles.
#[derive(Debug, Clone, PartialEq)]
struct Node {
    bounds: Aabb,
    /// Inner node: the children's indices; leaf: the run `order[first..first + count]`.
    first: u32,
    count: u32,
    right: u32,
}

/// A static triangle mesh with what its distance queries need, built once.
#[derive(Debug, Clone, PartialEq)]
pub struct TriangleBody {
    vertices: Vec<V3>,
    triangles: Vec<[u32; 3]>,
    face_normals: Vec<V3>,
    /// Angle-weighted pseudo-normal of every vertex.
    vertex_normals: Vec<V3>,
    /// Pseudo-normal of every edge (the sum of its faces' normals), by its sorted ends.
    edge_normals: HashMap<(u32, u32), V3>,
    /// The edges whose two faces are coplanar (a flat face's inner diagonals), by sorted ends.
    flat_edges: std::collections::HashSet<(u32, u32)>,
    /// Per vertex, whether it lies on a feature edge (a corner a sheet can press on).
    corner_flags: Vec<bool>,
    nodes: Vec<Node>,
    /// Triangle indices in the leaves' order.
    order: Vec<u32>,
}

impl TriangleBody {
    /// The body of `triangles` over `vertices` (m), checked: every coordinate finite, every index
    /// present, every triangle with an area above 10⁻¹² of the mesh's box's squared size, and the
    /// triangles a closed, consistently outward-oriented surface ([`closed_surface_defect`]): the
    /// pseudo-normal sign of inside and outside means nothing otherwise.
    pub fn new(vertices: Vec<V3>, triangles: Vec<[u32; 3]>) -> Result<Self, BodyDefect> {
        if triangles.is_empty() {
            return Err(BodyDefect::NoTriangles);
        }
        if let Some(v) = vertices
            .iter()
            .position(|p| !p.iter().all(|c| c.is_finite()))
        {
            return Err(BodyDefect::NotFinite(v));
        }
        if let Some(t) = triangles
            .iter()
            .position(|t| t.iter().any(|&v| v as usize >= vertices.len()))
        {
            return Err(BodyDefect::MissingVertex(t));
        }
        let bounds = vertices
            .iter()
            .fold(Aabb::point(&vertices[0]), |b, p| b.union(&Aabb::point(p)));
        let size2 = (bounds.hi - bounds.lo).norm_squared();
        let corner = |t: &[u32; 3], k: usize| vertices[t[k] as usize];
        let mut face_normals = Vec::with_capacity(triangles.len());
        for (i, t) in triangles.iter().enumerate() {
            let n = (corner(t, 1) - corner(t, 0)).cross(&(corner(t, 2) - corner(t, 0)));
            if 0.5 * n.norm() <= 1e-12 * size2 {
                return Err(BodyDefect::Degenerate(i));
            }
            face_normals.push(n.normalize());
        }
        if let Some(d) = closed_surface_defect(&vertices, &triangles) {
            return Err(d);
        }
        let (vertex_normals, edge_normals) = pseudo_normals(&vertices, &triangles, &face_normals);
        let flat_edges = flat_edges(&triangles, &face_normals);
        let mut corner_flags = vec![false; vertices.len()];
        for t in &triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                if !flat_edges.contains(&(a.min(b), a.max(b))) {
                    corner_flags[a as usize] = true;
                    corner_flags[b as usize] = true;
                }
            }
        }
        let mut body = Self {
            vertices,
            triangles,
            face_normals,
            vertex_normals,
            edge_normals,
            flat_edges,
            corner_flags,
            nodes: Vec::new(),
            order: Vec::new(),
        };
        body.build_hierarchy();
        match body.self_intersection() {
            Some(d) => Err(d),
            None => Ok(body),
        }
    }

    /// The first edge that passes through a face sharing no vertex with it, if any (found through
    /// the hierarchy: each edge against the faces whose boxes its box overlaps).
    fn self_intersection(&self) -> Option<BodyDefect> {
        let mut edges: Vec<(u32, u32)> = self
            .triangles
            .iter()
            .flat_map(|t| (0..3).map(move |k| (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3]))))
            .collect();
        edges.sort_unstable();
        edges.dedup();
        edges.into_iter().find_map(|(a, b)| {
            let (p, q) = (self.vertices[a as usize], self.vertices[b as usize]);
            let bounds = Aabb::point(&p).union(&Aabb::point(&q));
            self.triangles_overlapping_ids(&bounds)
                .into_iter()
                .find(|&t| {
                    let tri = self.triangles[t as usize];
                    !tri.contains(&a) && !tri.contains(&b) && {
                        let [u, v, w] = tri.map(|k| self.vertices[k as usize]);
                        crate::proximity::segment_crosses_triangle(&p, &q, &u, &v, &w)
                    }
                })
                .map(|t| BodyDefect::SelfIntersecting(a, b, t as usize))
        })
    }

    /// The vertices, m (the file's frame, before a scene's offset).
    pub fn vertices(&self) -> &[V3] {
        &self.vertices
    }

    /// The triangles, vertex indices, facing outward.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// The number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// The mesh's bounding box, m.
    pub fn bounds(&self) -> Aabb {
        self.nodes[0].bounds
    }

    fn triangle_box(&self, t: u32) -> Aabb {
        let tri = self.triangles[t as usize];
        let p = |k: usize| Aabb::point(&self.vertices[tri[k] as usize]);
        p(0).union(&p(1)).union(&p(2))
    }

    /// Builds the hierarchy: boxes split at the median centroid along their longest side.
    fn build_hierarchy(&mut self) {
        self.order = (0..self.triangles.len() as u32).collect();
        self.nodes.clear();
        let n = self.order.len();
        self.build_node(0, n);
    }

    fn build_node(&mut self, first: usize, count: usize) -> u32 {
        let run = &self.order[first..first + count];
        let bounds = run
            .iter()
            .map(|&t| self.triangle_box(t))
            .reduce(|a, b| a.union(&b))
            .expect("a node holds a triangle");
        let at = self.nodes.len() as u32;
        self.nodes.push(Node {
            bounds,
            first: first as u32,
            count: count as u32,
            right: 0,
        });
        if count <= LEAF_SIZE {
            return at;
        }
        let axis = (bounds.hi - bounds.lo).imax();
        let centre = |t: u32| {
            let tri = self.triangles[t as usize];
            tri.iter()
                .map(|&v| self.vertices[v as usize][axis])
                .sum::<f64>()
        };
        let half = count / 2;
        let mut run = self.order[first..first + count].to_vec();
        run.select_nth_unstable_by(half, |a, b| centre(*a).total_cmp(&centre(*b)));
        self.order[first..first + count].copy_from_slice(&run);
        self.build_node(first, half);
        let right = self.build_node(first + half, count - half);
        let node = &mut self.nodes[at as usize];
        node.count = 0;
        node.right = right;
        at
    }

    /// The closest point of the surface to `p` nearer than `reach`: (distance, triangle,
    /// barycentric weights); none where no triangle lies within `reach` (boxes farther are pruned
    /// at once, so a short reach answers far points from the root).
    fn closest_within(&self, p: &V3, reach: f64) -> Option<(f64, u32, [f64; 3])> {
        let mut best = (reach, u32::MAX, [1.0, 0.0, 0.0]);
        // A median split halves every run: the depth stays below 64 for any mesh that fits in memory.
        let mut stack = [0u32; 64];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let i = stack[top];
            let node = &self.nodes[i as usize];
            if box_distance(&node.bounds, p) >= best.0 {
                continue;
            }
            if node.count == 0 {
                // Visit the nearer child first: it tightens the bound for the other.
                let (l, r) = (i + 1, node.right);
                let (dl, dr) = (
                    box_distance(&self.nodes[l as usize].bounds, p),
                    box_distance(&self.nodes[r as usize].bounds, p),
                );
                let (near, far) = if dl <= dr { (l, r) } else { (r, l) };
                stack[top] = far;
                stack[top + 1] = near;
                top += 2;
                continue;
            }
            for &t in &self.order[node.first as usize..(node.first + node.count) as usize] {
                let tri = self.triangles[t as usize];
                let c = |k: usize| &self.vertices[tri[k] as usize];
                let (d, w) = point_triangle_distance(p, c(0), c(1), c(2));
                if d < best.0 {
                    best = (d, t, w);
                }
            }
        }
        (best.1 != u32::MAX).then_some(best)
    }

    /// Whether the segment pq crosses a face of the body (touching counts): an edge of the sheet
    /// through a thin wall whose ends both lie outside.
    pub fn segment_crosses(&self, p: &V3, q: &V3) -> bool {
        let bounds = Aabb::point(p).union(&Aabb::point(q));
        self.triangles_overlapping(&bounds).iter().any(|t| {
            let [a, b, c] = t.map(|k| self.vertices[k as usize]);
            crate::proximity::segment_crosses_triangle(p, q, &a, &b, &c)
        })
    }

    /// The triangles whose boxes overlap `bounds`, found through the hierarchy.
    fn triangles_overlapping(&self, bounds: &Aabb) -> Vec<[u32; 3]> {
        self.triangles_overlapping_ids(bounds)
            .into_iter()
            .map(|t| self.triangles[t as usize])
            .collect()
    }

    /// The indices of the triangles whose boxes overlap `bounds`, found through the hierarchy.
    fn triangles_overlapping_ids(&self, bounds: &Aabb) -> Vec<u32> {
        let mut found = Vec::new();
        let mut stack = vec![0u32];
        while let Some(i) = stack.pop() {
            let node = &self.nodes[i as usize];
            if !node.bounds.overlaps(bounds) {
                continue;
            }
            if node.count == 0 {
                stack.extend([i + 1, node.right]);
                continue;
            }
            let run = &self.order[node.first as usize..(node.first + node.count) as usize];
            found.extend(
                run.iter()
                    .filter(|&&t| self.triangle_box(t).overlaps(bounds)),
            );
        }
        found
    }

    /// The feature edges (their end points, each once) of the triangles whose boxes overlap
    /// `bounds`: those whose two faces are not coplanar (a flat face's inner diagonal is no edge a
    /// sheet can hang on). The candidates of a segment's closest body edge within that box.
    pub fn edges_near(&self, bounds: &Aabb) -> Vec<(V3, V3)> {
        let mut keys: Vec<(u32, u32)> = self
            .triangles_overlapping(bounds)
            .iter()
            .flat_map(|tri| (0..3).map(move |k| (tri[k], tri[(k + 1) % 3])))
            .map(|(a, b)| (a.min(b), a.max(b)))
            .filter(|k| !self.flat_edges.contains(k))
            .collect();
        keys.sort_unstable();
        keys.dedup();
        keys.iter()
            .map(|&(a, b)| (self.vertices[a as usize], self.vertices[b as usize]))
            .collect()
    }

    /// The corners (vertices on a feature edge: not inside a flat region) of the triangles whose
    /// boxes overlap `bounds` and within them, each once.
    pub fn corners_near(&self, bounds: &Aabb) -> Vec<V3> {
        let mut found: Vec<u32> = self
            .triangles_overlapping(bounds)
            .iter()
            .flatten()
            .copied()
            .filter(|&v| {
                bounds.overlaps(&Aabb::point(&self.vertices[v as usize])) && self.is_corner(v)
            })
            .collect();
        found.sort_unstable();
        found.dedup();
        found.iter().map(|&v| self.vertices[v as usize]).collect()
    }

    /// Whether vertex `v` lies on a feature edge (an edge whose faces are not coplanar).
    fn is_corner(&self, v: u32) -> bool {
        self.corner_flags.get(v as usize).copied().unwrap_or(false)
    }

    /// The pseudo-normal of the feature of triangle `t` that the weights `w` name: the face's own
    /// normal inside it, an edge's where one weight is zero, a vertex's where two are.
    fn feature_normal(&self, t: u32, w: &[f64; 3]) -> V3 {
        let tri = self.triangles[t as usize];
        let on: Vec<usize> = (0..3).filter(|&k| w[k] != 0.0).collect();
        match on.as_slice() {
            [k] => self.vertex_normals[tri[*k] as usize],
            [a, b] => {
                let (u, v) = (tri[*a], tri[*b]);
                self.edge_normals[&(u.min(v), u.max(v))]
            }
            _ => self.face_normals[t as usize],
        }
    }

    /// Signed distance from `p` to the surface (m, positive outside) and the outward unit normal of
    /// the distance there: along p − c from the closest point c, its sign from the closest
    /// feature's pseudo-normal; the pseudo-normal itself on the surface.
    pub fn signed_distance(&self, p: &V3) -> (f64, V3) {
        self.signed_distance_within(p, f64::INFINITY)
            .expect("a body has triangles")
    }

    /// [`TriangleBody::signed_distance`] where the surface lies nearer than `reach` (m); none where
    /// it does not (then the point is farther than `reach` outside, or deeper than `reach` inside:
    /// a barrier of band `reach` needs no more).
    pub fn signed_distance_within(&self, p: &V3, reach: f64) -> Option<(f64, V3)> {
        let (d, t, w) = self.closest_within(p, reach)?;
        let tri = self.triangles[t as usize];
        let c: V3 = (0..3).map(|k| self.vertices[tri[k] as usize] * w[k]).sum();
        let pn = self.feature_normal(t, &w);
        let r = p - c;
        let sign = if r.dot(&pn) < 0.0 { -1.0 } else { 1.0 };
        Some(match r.try_normalize(1e-300) {
            Some(u) if d > 1e-12 * self.bounds_size() => (sign * d, u * sign),
            _ => (sign * d, pn),
        })
    }

    fn bounds_size(&self) -> f64 {
        let b = self.bounds();
        (b.hi - b.lo).norm()
    }

    /// The height of the highest point of the surface on the vertical through (x, y), if the
    /// vertical meets it.
    pub fn top_at(&self, x: f64, y: f64) -> Option<f64> {
        self.highest_hit(x, y).map(|h| h.0)
    }

    /// [`Self::top_at`] where the surface there is horizontal (its face's normal within 10⁻⁴ rad
    /// of up: a table's top, a form's flat shoulder), for the supports rule.
    pub fn flat_top_at(&self, x: f64, y: f64) -> Option<f64> {
        let (z, t) = self.highest_hit(x, y)?;
        (self.face_normals[t as usize].z >= 1.0 - 5e-9).then_some(z)
    }

    /// The height and triangle of the highest point of the surface on the vertical through (x, y).
    fn highest_hit(&self, x: f64, y: f64) -> Option<(f64, u32)> {
        let mut top: Option<(f64, u32)> = None;
        let mut stack = vec![0u32];
        while let Some(i) = stack.pop() {
            let node = &self.nodes[i as usize];
            let b = &node.bounds;
            let e = EDGE_SLACK_M;
            if x < b.lo.x - e
                || x > b.hi.x + e
                || y < b.lo.y - e
                || y > b.hi.y + e
                || top.is_some_and(|(z, _)| b.hi.z <= z)
            {
                continue;
            }
            if node.count == 0 {
                stack.push(i + 1);
                stack.push(node.right);
                continue;
            }
            for &t in &self.order[node.first as usize..(node.first + node.count) as usize] {
                if let Some(z) = self.vertical_hit(t, x, y)
                    && top.is_none_or(|(h, _)| z > h)
                {
                    top = Some((z, t));
                }
            }
        }
        top
    }

    /// Where the vertical through (x, y) meets triangle `t` (its height), if it does.
    fn vertical_hit(&self, t: u32, x: f64, y: f64) -> Option<f64> {
        let tri = self.triangles[t as usize];
        let [a, b, c] = tri.map(|v| self.vertices[v as usize]);
        let det = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
        if det.abs() < 1e-300 {
            return None;
        }
        let u = ((x - a.x) * (c.y - a.y) - (c.x - a.x) * (y - a.y)) / det;
        let v = ((b.x - a.x) * (y - a.y) - (x - a.x) * (b.y - a.y)) / det;
        // A point on an edge counts (grid lines laid on a table's edge by construction): a slack
        // of 1 nm, as the analytic table's.
        let tol = EDGE_SLACK_M / det.abs().sqrt();
        let inside = u >= -tol && v >= -tol && u + v <= 1.0 + tol;
        inside.then(|| a.z + u * (b.z - a.z) + v * (c.z - a.z))
    }
}

/// The distance from `p` to the box (0 inside).
fn box_distance(b: &Aabb, p: &V3) -> f64 {
    (b.lo - p).sup(&(p - b.hi)).sup(&V3::zeros()).norm()
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A sphere of radius `r` centred at the origin: an icosahedron subdivided `levels` times, its
    /// vertices on the sphere, triangles counter-clockwise seen from outside.
    pub(crate) fn icosphere(r: f64, levels: usize) -> (Vec<V3>, Vec<[u32; 3]>) {
        let g = (1.0 + 5f64.sqrt()) / 2.0;
        let mut v: Vec<V3> = [
            [-1.0, g, 0.0],
            [1.0, g, 0.0],
            [-1.0, -g, 0.0],
            [1.0, -g, 0.0],
            [0.0, -1.0, g],
            [0.0, 1.0, g],
            [0.0, -1.0, -g],
            [0.0, 1.0, -g],
            [g, 0.0, -1.0],
            [g, 0.0, 1.0],
            [-g, 0.0, -1.0],
            [-g, 0.0, 1.0],
        ]
        .iter()
        .map(|p| V3::new(p[0], p[1], p[2]).normalize())
        .collect();
        let mut t: Vec<[u32; 3]> = vec![
            [0, 11, 5],
            [0, 5, 1],
            [0, 1, 7],
            [0, 7, 10],
            [0, 10, 11],
            [1, 5, 9],
            [5, 11, 4],
            [11, 10, 2],
            [10, 7, 6],
            [7, 1, 8],
            [3, 9, 4],
            [3, 4, 2],
            [3, 2, 6],
            [3, 6, 8],
            [3, 8, 9],
            [4, 9, 5],
            [2, 4, 11],
            [6, 2, 10],
            [8, 6, 7],
            [9, 8, 1],
        ];
        for _ in 0..levels {
            let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
            let mut split = |a: u32, b: u32, v: &mut Vec<V3>| {
                *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                    v.push(((v[a as usize] + v[b as usize]) * 0.5).normalize());
                    (v.len() - 1) as u32
                })
            };
            let mut next = Vec::new();
            for [a, b, c] in t {
                let (ab, bc, ca) = (
                    split(a, b, &mut v),
                    split(b, c, &mut v),
                    split(c, a, &mut v),
                );
                next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
            }
            t = next;
        }
        (v.into_iter().map(|p| p * r).collect(), t)
    }

    #[test]
    fn a_meshed_sphere_has_the_spheres_signed_distance_within_its_sagitta() {
        let r = 0.1;
        let mut previous = f64::INFINITY;
        for levels in [2, 3, 4] {
            let (v, t) = icosphere(r, levels);
            let body = TriangleBody::new(v.clone(), t.clone()).expect("a valid mesh");
            // A face's corners lie on the sphere, so it lies inside it by at most the depth of a
            // cap over its circumcircle (radius at most the longest edge / √3).
            let vs = &v;
            let edge = t
                .iter()
                .flat_map(|f| {
                    (0..3).map(move |k| (vs[f[k] as usize] - vs[f[(k + 1) % 3] as usize]).norm())
                })
                .fold(0.0, f64::max);
            let sagitta = r - (r * r - edge * edge / 3.0).sqrt();
            let mut worst: f64 = 0.0;
            for k in 0..400 {
                let (a, b) = (
                    k as f64 * 2.399963,
                    (1.0 - 2.0 * (k as f64 + 0.5) / 400.0).acos(),
                );
                let dir = V3::new(b.sin() * a.cos(), b.sin() * a.sin(), b.cos());
                for s in [0.5, 0.95, 1.02, 1.3] {
                    let p = dir * (r * s);
                    let (d, n) = body.signed_distance(&p);
                    let exact = r * s - r;
                    // Inside or out, the faces' points are nearer the centre than the sphere's.
                    assert!(
                        d >= exact - 1e-12 && d <= exact + sagitta + 1e-12,
                        "{levels}: {d} vs {exact}"
                    );
                    assert!(n.dot(&dir) > 0.9, "{levels}: normal {n} at {dir}");
                    worst = worst.max((d - exact).abs());
                }
            }
            assert!(
                worst < previous,
                "{levels}: the gap shrinks as the mesh is refined"
            );
            previous = worst;
        }
    }

    #[test]
    fn the_hierarchy_finds_the_brute_force_closest_triangle() {
        let (v, t) = icosphere(0.2, 3);
        let body = TriangleBody::new(v.clone(), t.clone()).expect("a valid mesh");
        for k in 0..200 {
            let f = k as f64;
            let p = V3::new((f * 0.37).sin(), (f * 0.71).cos(), (f * 1.3).sin()) * 0.4;
            let brute = t
                .iter()
                .map(|tri| {
                    point_triangle_distance(
                        &p,
                        &v[tri[0] as usize],
                        &v[tri[1] as usize],
                        &v[tri[2] as usize],
                    )
                    .0
                })
                .fold(f64::INFINITY, f64::min);
            assert_eq!(body.signed_distance(&p).0.abs(), brute, "{p}");
        }
    }

    /// The query with a reach answers exactly as the full one where the surface lies within the
    /// reach (inside or outside) and none where it does not.
    #[test]
    fn a_query_within_a_reach_is_the_full_query_or_none_beyond_it() {
        let (v, t) = icosphere(0.1, 3);
        let body = TriangleBody::new(v, t).expect("a valid mesh");
        let (mut near, mut far) = (0, 0);
        for k in 0..400 {
            let s = k as f64;
            let p = V3::new((s * 0.71).sin(), (s * 1.37).cos(), (s * 0.29).sin()) * 0.13;
            let full = body.signed_distance(&p);
            match body.signed_distance_within(&p, 0.01) {
                Some(within) => {
                    assert_eq!(within, full, "{p}");
                    near += 1;
                }
                None => {
                    assert!(full.0.abs() >= 0.01, "{p}: {}", full.0);
                    far += 1;
                }
            }
        }
        assert!(near > 20 && far > 20, "{near} near, {far} far");
    }

    #[test]
    fn the_top_of_a_meshed_sphere_lies_on_its_surface() {
        let (v, t) = icosphere(0.1, 4);
        let body = TriangleBody::new(v, t).expect("a valid mesh");
        for (x, y) in [(0.0, 0.0), (0.03, -0.05), (0.07, 0.02)] {
            let z = body.top_at(x, y).expect("over the sphere");
            let exact = (0.01f64 - x * x - y * y).sqrt();
            assert!(z <= exact && z > exact - 2e-3, "{z} vs {exact}");
            assert!(body.signed_distance(&V3::new(x, y, z)).0.abs() < 1e-12);
        }
        assert_eq!(body.top_at(0.2, 0.0), None);
    }

    #[test]
    fn bad_meshes_are_refused_with_their_defect() {
        let (v, t) = icosphere(0.1, 0);
        assert_eq!(
            TriangleBody::new(v.clone(), vec![]).err(),
            Some(BodyDefect::NoTriangles)
        );
        let mut nan = v.clone();
        nan[3].y = f64::NAN;
        assert_eq!(
            TriangleBody::new(nan, t.clone()).err(),
            Some(BodyDefect::NotFinite(3))
        );
        let mut missing = t.clone();
        missing[5][1] = 99;
        assert_eq!(
            TriangleBody::new(v.clone(), missing).err(),
            Some(BodyDefect::MissingVertex(5))
        );
        let mut flat = t.clone();
        flat[7] = [1, 1, 2];
        assert_eq!(
            TriangleBody::new(v, flat).err(),
            Some(BodyDefect::Degenerate(7))
        );
    }
}
