//! The broad phase of the sheet's self-proximity: boxes around vertices (swept along a step when
//! asked), triangles and edges, hashed into a uniform grid of cells, and the candidate pairs of
//! primitives that share a cell and no vertex (ipc-toolkit's hash grid).

use super::{MeshTopology, Pair, V3};
use rayon::prelude::*;

/// An axis-aligned box.
#[derive(Debug, Clone, Copy, PartialEq)]
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
pub(super) fn primitive_boxes(
    topo: &MeshTopology,
    vbox: &[Aabb],
    r: f64,
) -> (Vec<Aabb>, Vec<Aabb>) {
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
pub(super) fn hash_entries(boxes: [(&[Aabb], &[u32]); 3]) -> (Vec<(u64, u8, u32)>, f64, u64) {
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
pub(super) fn owner_bucket(a: &Aabb, b: &Aabb, cell: f64, buckets: u64) -> u64 {
    let c = (a.lo.sup(&b.lo) / cell).map(|v| v.floor() as i64);
    bucket_of(cell_key(c.x, c.y, c.z), buckets)
}

/// Calls `f` with the entries of each bucket of the hash.
pub(super) fn for_each_cell(entries: &[(u64, u8, u32)], mut f: impl FnMut(&[(u64, u8, u32)])) {
    let mut start = 0;
    while start < entries.len() {
        let key = entries[start].0;
        let end = start + entries[start..].partition_point(|e| e.0 == key);
        f(&entries[start..end]);
        start = end;
    }
}

/// The entries cut into about `parts` runs of whole buckets (for workers to take one each).
fn bucket_runs(entries: &[(u64, u8, u32)], parts: usize) -> Vec<&[(u64, u8, u32)]> {
    let step = entries.len().div_ceil(parts.max(1)).max(1);
    let mut runs = Vec::with_capacity(parts);
    let mut start = 0;
    while start < entries.len() {
        let mut end = (start + step).min(entries.len());
        if end < entries.len() {
            let key = entries[end - 1].0;
            end += entries[end..].partition_point(|e| e.0 == key);
        }
        runs.push(&entries[start..end]);
        start = end;
    }
    runs
}

/// Every pair of primitives that share no vertex, whose boxes, each the union of its vertices'
/// boxes `vbox` grown by `r`, overlap, and that `keep` accepts: the broad phase, a spatial hash.
/// Sorted, without duplicates (deterministic).
pub fn candidate_pairs(
    topo: &MeshTopology,
    vbox: &[Aabb],
    r: f64,
    keep: impl Fn(Pair) -> bool + Sync,
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
    let found = CellPairs {
        topo,
        vbox,
        boxes: (&tboxes, &eboxes),
        r,
        size,
        buckets,
    };
    // Buckets are independent: runs of them go to rayon's workers (the order is restored below).
    let runs = bucket_runs(&entries, 8 * rayon::current_num_threads());
    let mut pairs: Vec<Pair> = runs
        .into_par_iter()
        .flat_map_iter(|run| {
            let mut out = Vec::new();
            for_each_cell(run, |cell| found.collect(cell, &keep, &mut out));
            out
        })
        .collect();
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_of_buckets_cover_the_entries_and_never_split_a_bucket() {
        let entries: Vec<(u64, u8, u32)> = (0..1000u32).map(|k| ((k / 7) as u64, 0, k)).collect();
        for parts in [1, 3, 16, 5000] {
            let runs = bucket_runs(&entries, parts);
            assert_eq!(runs.iter().map(|r| r.len()).sum::<usize>(), entries.len());
            for w in runs.windows(2) {
                assert_ne!(
                    w[0].last().unwrap().0,
                    w[1][0].0,
                    "bucket split ({parts} parts)"
                );
            }
            assert!(
                runs.len() <= parts.min(143),
                "{} runs for {parts}",
                runs.len()
            );
        }
    }
}
