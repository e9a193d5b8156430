//! Broad phases as swappable objects (ipc-toolkit's `BroadPhase`): the spatial hash
//! ([`HashGrid`], [`super::candidate_pairs`]) and a bounding-volume hierarchy over the triangles'
//! and the edges' boxes ([`Hierarchy`]), giving the same pairs. The hash is the default: the
//! hierarchy, rebuilt per list, was 2–10 % slower on the touching drapes (docs/src/benchmarks.md),
//! both spending their time on the same overlapping boxes and their filter.

use super::broad_phase::primitive_boxes;
use super::{Aabb, MeshTopology, Pair};
use rayon::prelude::*;

/// A broad phase: every pair of a mesh's primitives that share no vertex, whose boxes (the union of
/// their vertices' boxes `vbox` grown by `r`) overlap and that `keep` accepts; sorted, without
/// duplicates, so that any two broad phases give the same list.
pub trait BroadPhase: Send + Sync {
    /// The candidate pairs.
    fn candidate_pairs(
        &self,
        topo: &MeshTopology,
        vbox: &[Aabb],
        r: f64,
        keep: &(dyn Fn(Pair) -> bool + Sync),
    ) -> Vec<Pair>;
}

/// The spatial hash over a uniform grid of cells ([`super::candidate_pairs`]).
#[derive(Debug, Clone, Copy, Default)]
pub struct HashGrid;

impl BroadPhase for HashGrid {
    fn candidate_pairs(
        &self,
        topo: &MeshTopology,
        vbox: &[Aabb],
        r: f64,
        keep: &(dyn Fn(Pair) -> bool + Sync),
    ) -> Vec<Pair> {
        super::candidate_pairs(topo, vbox, r, keep)
    }
}

/// Hierarchies ([`Bvh`]) over the triangles' and the edges' boxes, built per call.
#[derive(Debug, Clone, Copy, Default)]
pub struct Hierarchy;

impl BroadPhase for Hierarchy {
    /// Each vertex's box queried in the triangles' hierarchy and each edge's in the edges'.
    fn candidate_pairs(
        &self,
        topo: &MeshTopology,
        vbox: &[Aabb],
        r: f64,
        keep: &(dyn Fn(Pair) -> bool + Sync),
    ) -> Vec<Pair> {
        let (tboxes, eboxes) = primitive_boxes(topo, vbox, r);
        let (tris, edges) = (Bvh::build(tboxes), Bvh::build(eboxes));
        let point_triangle = topo.vertices.par_iter().flat_map_iter(|&v| {
            let mut out = Vec::new();
            tris.query(&vbox[v as usize].inflate(r), |t| {
                let pair = Pair::PointTriangle(v, t);
                if !topo.triangles[t as usize].contains(&v) && keep(pair) {
                    out.push(pair);
                }
            });
            out
        });
        let edge_edge = (0..topo.edges.len() as u32)
            .into_par_iter()
            .flat_map_iter(|a| {
                let ea = topo.edges[a as usize];
                let mut out = Vec::new();
                edges.query(&edges.boxes[a as usize], |b| {
                    let eb = topo.edges[b as usize];
                    if b > a && !ea.iter().any(|v| eb.contains(v)) {
                        let pair = Pair::EdgeEdge(a, b);
                        if keep(pair) {
                            out.push(pair);
                        }
                    }
                });
                out
            });
        let mut pairs: Vec<Pair> = point_triangle.chain(edge_edge).collect();
        pairs.sort_unstable();
        pairs.dedup();
        pairs
    }
}

/// Boxes a leaf holds at most.
const LEAF: usize = 4;

/// A node: its box and either a run of boxes (`count` > 0: `order[first..first + count]`) or two
/// children (`first + 1` and `right`).
struct Node {
    bounds: Aabb,
    first: u32,
    count: u32,
    right: u32,
}

/// A hierarchy over a list of boxes, split at the median of the longest axis of the centres' box.
pub struct Bvh {
    nodes: Vec<Node>,
    order: Vec<u32>,
    boxes: Vec<Aabb>,
}

impl Bvh {
    /// The hierarchy over `boxes`.
    pub fn build(boxes: Vec<Aabb>) -> Self {
        let mut bvh = Self {
            nodes: Vec::with_capacity(2 * boxes.len() / LEAF + 1),
            order: (0..boxes.len() as u32).collect(),
            boxes,
        };
        if !bvh.boxes.is_empty() {
            bvh.split(0, bvh.boxes.len());
        }
        bvh
    }

    /// Builds the node over `order[lo..hi]`; its index.
    fn split(&mut self, lo: usize, hi: usize) -> u32 {
        let me = self.nodes.len() as u32;
        let bounds = self.order[lo..hi]
            .iter()
            .map(|&i| self.boxes[i as usize])
            .reduce(|a, b| a.union(&b))
            .expect("a node holds a box");
        self.nodes.push(Node {
            bounds,
            first: lo as u32,
            count: (hi - lo) as u32,
            right: 0,
        });
        if hi - lo <= LEAF {
            return me;
        }
        let centre = |i: u32| {
            let b = &self.boxes[i as usize];
            (b.lo + b.hi) * 0.5
        };
        let first = centre(self.order[lo]);
        let (cmin, cmax) = self.order[lo..hi]
            .iter()
            .fold((first, first), |(a, b), &i| {
                (a.inf(&centre(i)), b.sup(&centre(i)))
            });
        let axis = (cmax - cmin).imax();
        let mid = (lo + hi) / 2;
        let key = |i: &u32| {
            let b = &self.boxes[*i as usize];
            b.lo[axis] + b.hi[axis]
        };
        self.order[lo..hi].select_nth_unstable_by(mid - lo, |a, b| key(a).total_cmp(&key(b)));
        self.nodes[me as usize].count = 0;
        self.split(lo, mid);
        let right = self.split(mid, hi);
        self.nodes[me as usize].right = right;
        me
    }

    /// Calls `f` with every box index whose box overlaps `q`.
    pub fn query(&self, q: &Aabb, mut f: impl FnMut(u32)) {
        if self.nodes.is_empty() {
            return;
        }
        let mut stack = vec![0u32];
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n as usize];
            if !node.bounds.overlaps(q) {
                continue;
            }
            if node.count > 0 {
                let run = &self.order[node.first as usize..(node.first + node.count) as usize];
                for &i in run {
                    if self.boxes[i as usize].overlaps(q) {
                        f(i);
                    }
                }
            } else {
                stack.push(node.right);
                stack.push(n + 1);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    /// A crumpled 12 × 12 sheet: both broad phases give the same sorted pairs, whatever the boxes'
    /// size and the filter.
    #[test]
    fn the_hierarchy_finds_the_pairs_the_hash_finds() {
        let n = 12usize;
        let mut tris = Vec::new();
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                let p = (j * n + i) as u32;
                tris.extend([
                    [p, p + 1, p + n as u32 + 1],
                    [p, p + n as u32 + 1, p + n as u32],
                ]);
            }
        }
        let topo = MeshTopology::shared(tris);
        let x: Vec<Vector3<f64>> = (0..n * n)
            .map(|k| {
                let (i, j) = ((k % n) as f64, (k / n) as f64);
                Vector3::new(
                    0.3 * (0.7 * i).sin() + 0.01 * i,
                    0.01 * j,
                    0.3 * (0.9 * i + 0.4 * j).cos(),
                )
            })
            .collect();
        for (grow, r) in [(0.0, 0.005), (0.02, 0.01), (0.1, 0.0)] {
            let boxes: Vec<Aabb> = x.iter().map(|p| Aabb::point(p).inflate(grow)).collect();
            for every_other in [false, true] {
                let keep =
                    |p: Pair| !every_other || matches!(p, Pair::PointTriangle(v, _) if v % 2 == 0);
                let hash = HashGrid.candidate_pairs(&topo, &boxes, r, &keep);
                let tree = Hierarchy.candidate_pairs(&topo, &boxes, r, &keep);
                assert!(!hash.is_empty());
                assert_eq!(hash, tree, "grow {grow}, r {r}, filtered {every_other}");
            }
        }
    }
}
