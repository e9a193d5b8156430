//! Proximity of the primitives of one triangle mesh (the sheet against itself): the point–triangle
//! and edge–edge distances with their closest points, a spatial-hash broad phase over boxes that may
//! be swept along a step, and additive continuous collision detection (ACCD: Li, Kaufman, Kim and
//! Jiang, "Codimensional incremental potential contact", 2021, Alg. 1), which finds how far along a
//! step a pair may move before its distance falls to a share of what it was.

use nalgebra::Vector3;

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

/// An axis-aligned box.
#[derive(Debug, Clone, Copy)]
pub struct Aabb {
    /// Lower corner.
    pub lo: V3,
    /// Upper corner.
    pub hi: V3,
}

impl Aabb {
    /// The box of a point.
    pub fn point(p: &V3) -> Self {
        Self { lo: *p, hi: *p }
    }
    /// This box grown to hold `o`.
    pub fn union(&self, o: &Aabb) -> Self {
        Self {
            lo: self.lo.inf(&o.lo),
            hi: self.hi.sup(&o.hi),
        }
    }
    /// This box grown by `r` on every side.
    pub fn inflate(&self, r: f64) -> Self {
        let v = V3::repeat(r);
        Self {
            lo: self.lo - v,
            hi: self.hi + v,
        }
    }
    /// Whether the boxes overlap.
    pub fn overlaps(&self, o: &Aabb) -> bool {
        (0..3).all(|k| self.lo[k] <= o.hi[k] && o.lo[k] <= self.hi[k])
    }
    /// Whether `o` lies inside this box.
    pub fn contains(&self, o: &Aabb) -> bool {
        (0..3).all(|k| self.lo[k] <= o.lo[k] && o.hi[k] <= self.hi[k])
    }
}

/// The boxes of the triangles and edges: the union of their vertices' boxes `vbox`, grown by `r`.
fn primitive_boxes(topo: &MeshTopology, vbox: &[Aabb], r: f64) -> (Vec<Aabb>, Vec<Aabb>) {
    let tboxes = topo
        .triangles
        .iter()
        .map(|t| {
            vbox[t[0] as usize]
                .union(&vbox[t[1] as usize])
                .union(&vbox[t[2] as usize])
                .inflate(r)
        })
        .collect();
    let eboxes = topo
        .edges
        .iter()
        .map(|e| vbox[e[0] as usize].union(&vbox[e[1] as usize]).inflate(r))
        .collect();
    (tboxes, eboxes)
}

/// The spatial hash: for every cell each box overlaps (kind 0 a vertex's box, 1 a triangle's, 2 an
/// edge's), an entry (bucket, kind, index), grouped by bucket (the cell's key hashed into a table of
/// about twice as many buckets as entries; counting sort, then each bucket sorted by kind and index);
/// cells as large as the median triangle box, or an eighth of the largest box of any kind (so that no
/// box spans more than 9³ cells). Returns the entries, the cell size and the bucket count.
fn hash_entries(boxes: [(&[Aabb], &[u32]); 3]) -> (Vec<(u64, u8, u32)>, f64, u64) {
    let mut extents: Vec<f64> = boxes[1].0.iter().map(|b| (b.hi - b.lo).max()).collect();
    if extents.is_empty() {
        return (Vec::new(), 1.0, 1);
    }
    let mid = extents.len() / 2;
    let median = *extents.select_nth_unstable_by(mid, f64::total_cmp).1;
    let largest = boxes
        .iter()
        .flat_map(|(list, _)| list.iter())
        .map(|b| (b.hi - b.lo).max())
        .fold(0.0, f64::max);
    let cell = median.max(largest / 8.0).max(1e-9);
    let span = |b: &Aabb| {
        let lo = (b.lo / cell).map(|v| v.floor() as i64);
        let hi = (b.hi / cell).map(|v| v.floor() as i64);
        (lo, hi)
    };
    let count: usize = boxes
        .iter()
        .flat_map(|(list, _)| list.iter())
        .map(|b| {
            let (lo, hi) = span(b);
            ((hi - lo).map(|d| d as usize + 1)).product()
        })
        .sum();
    let buckets = (2 * count).next_power_of_two().max(2) as u64;
    let mut raw: Vec<(u64, u8, u32)> = Vec::with_capacity(count);
    for (kind, (list, ids)) in boxes.iter().enumerate() {
        for (b, &id) in list.iter().zip(ids.iter()) {
            let (lo, hi) = span(b);
            for i in lo.x..=hi.x {
                for j in lo.y..=hi.y {
                    for k in lo.z..=hi.z {
                        raw.push((bucket_of(cell_key(i, j, k), buckets), kind as u8, id));
                    }
                }
            }
        }
    }
    // Counting sort by bucket, then each bucket by (kind, index).
    let mut start = vec![0usize; buckets as usize + 1];
    for e in &raw {
        start[e.0 as usize + 1] += 1;
    }
    for k in 0..buckets as usize {
        start[k + 1] += start[k];
    }
    let mut entries = vec![(0u64, 0u8, 0u32); raw.len()];
    let mut fill = start.clone();
    for e in raw {
        entries[fill[e.0 as usize]] = e;
        fill[e.0 as usize] += 1;
    }
    for k in 0..buckets as usize {
        if start[k + 1] - start[k] > 1 {
            entries[start[k]..start[k + 1]].sort_unstable();
        }
    }
    (entries, cell, buckets)
}

fn cell_key(i: i64, j: i64, k: i64) -> u64 {
    ((i as u64 & 0x1F_FFFF) << 42) | ((j as u64 & 0x1F_FFFF) << 21) | (k as u64 & 0x1F_FFFF)
}

/// The bucket of a cell key (Fibonacci hashing into `buckets`, a power of two).
fn bucket_of(key: u64, buckets: u64) -> u64 {
    (key.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 32) & (buckets - 1)
}

/// The one bucket that handles a pair of overlapping boxes: that of the cell of the lower corner of
/// their overlap, which both boxes were inserted into (so each pair is met once, barring two of their
/// shared cells falling into one bucket, which the caller's dedup removes).
fn owner_bucket(a: &Aabb, b: &Aabb, cell: f64, buckets: u64) -> u64 {
    let c = (a.lo.sup(&b.lo) / cell).map(|v| v.floor() as i64);
    bucket_of(cell_key(c.x, c.y, c.z), buckets)
}

/// Calls `f` with the entries of each bucket of the hash.
fn for_each_cell(entries: &[(u64, u8, u32)], mut f: impl FnMut(&[(u64, u8, u32)])) {
    let mut start = 0;
    while start < entries.len() {
        let key = entries[start].0;
        let end = start + entries[start..].partition_point(|e| e.0 == key);
        f(&entries[start..end]);
        start = end;
    }
}

/// Every pair of primitives that share no vertex, whose boxes, each the union of its vertices'
/// boxes `vbox` grown by `r`, overlap, and that `keep` accepts: the broad phase, a spatial hash.
/// Sorted, without duplicates (deterministic).
pub fn candidate_pairs(
    topo: &MeshTopology,
    vbox: &[Aabb],
    r: f64,
    keep: impl Fn(Pair) -> bool,
) -> Vec<Pair> {
    let (tboxes, eboxes) = primitive_boxes(topo, vbox, r);
    let vboxes: Vec<Aabb> = topo
        .vertices
        .iter()
        .map(|&v| vbox[v as usize].inflate(r))
        .collect();
    let (tids, eids): (Vec<u32>, Vec<u32>) = (
        (0..tboxes.len() as u32).collect(),
        (0..eboxes.len() as u32).collect(),
    );
    let (entries, size, buckets) = hash_entries([
        (&vboxes, &topo.vertices),
        (&tboxes, &tids),
        (&eboxes, &eids),
    ]);
    let mut pairs = Vec::new();
    for_each_cell(&entries, |cell| {
        let found = CellPairs {
            topo,
            vbox,
            boxes: (&tboxes, &eboxes),
            r,
            size,
            buckets,
        };
        found.collect(cell, &keep, &mut pairs)
    });
    pairs.sort_unstable();
    pairs.dedup();
    pairs
}

/// What [`CellPairs::collect`] needs of the hash.
struct CellPairs<'a> {
    topo: &'a MeshTopology,
    vbox: &'a [Aabb],
    boxes: (&'a [Aabb], &'a [Aabb]),
    r: f64,
    size: f64,
    buckets: u64,
}

impl CellPairs<'_> {
    /// The pairs of one hash cell (its entries sorted by kind) that this cell owns and `keep`
    /// accepts.
    fn collect(&self, cell: &[(u64, u8, u32)], keep: &impl Fn(Pair) -> bool, out: &mut Vec<Pair>) {
        let (topo, (tboxes, eboxes)) = (self.topo, self.boxes);
        let key = cell[0].0;
        // The entries are sorted by kind within the cell: vertices, triangles, edges.
        let (a, b) = (
            cell.partition_point(|e| e.1 < 1),
            cell.partition_point(|e| e.1 < 2),
        );
        let (verts, tris, edges) = (&cell[..a], &cell[a..b], &cell[b..]);
        for &(_, _, v) in verts {
            let vb = self.vbox[v as usize].inflate(self.r);
            for &(_, _, t) in tris {
                let tb = &tboxes[t as usize];
                let pair = Pair::PointTriangle(v, t);
                if !topo.triangles[t as usize].contains(&v)
                    && vb.overlaps(tb)
                    && owner_bucket(&vb, tb, self.size, self.buckets) == key
                    && keep(pair)
                {
                    out.push(pair);
                }
            }
        }
        for (k, &(_, _, a)) in edges.iter().enumerate() {
            let ea = topo.edges[a as usize];
            let ab = &eboxes[a as usize];
            for &(_, _, b) in &edges[k + 1..] {
                let eb = topo.edges[b as usize];
                let bb = &eboxes[b as usize];
                if ea.iter().any(|v| eb.contains(v))
                    || !ab.overlaps(bb)
                    || owner_bucket(ab, bb, self.size, self.buckets) != key
                {
                    continue;
                }
                let pair = Pair::EdgeEdge(a.min(b), a.max(b));
                if keep(pair) {
                    out.push(pair);
                }
            }
        }
    }
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
    fn the_broad_phase_finds_every_close_pair_of_two_stacked_sheets() {
        // Two 3 × 3 patches 1 mm apart: every vertex of one lies over a triangle of the other.
        let mut x = Vec::new();
        for layer in 0..2 {
            for j in 0..3 {
                for i in 0..3 {
                    x.push(v(i as f64 * 0.01, j as f64 * 0.01, layer as f64 * 1e-3));
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
