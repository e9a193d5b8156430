//! Uniform refinement of a checked pattern: every triangle split into four at its edges'
//! midpoints (rest and placed shapes alike), so that a bundled pattern runs finer without a new
//! file (`cloth.mesh_refine`). A seam's edge gets one new vertex shared by both pieces; a group
//! gains the midpoints of its edges whose ends both lie in it. The midpoint of a planar quad's
//! edge stays in its plane, so a garment placed with no stretch stays so.

use super::Pattern;
use std::collections::{BTreeMap, HashMap};

/// The midpoint index of each edge of a numbering, created on first use.
struct Midpoints {
    index: HashMap<(usize, usize), usize>,
    next: usize,
}

impl Midpoints {
    fn new(first: usize) -> Self {
        Midpoints {
            index: HashMap::new(),
            next: first,
        }
    }

    /// The midpoint of edge (a, b) and whether it was created now.
    fn of(&mut self, a: usize, b: usize) -> (usize, bool) {
        let key = (a.min(b), a.max(b));
        if let Some(&m) = self.index.get(&key) {
            return (m, false);
        }
        self.index.insert(key, self.next);
        self.next += 1;
        (self.next - 1, true)
    }
}

/// The four triangles of `t` (corners a, b, c) with midpoints `m` of (ab, bc, ca), orientation kept.
fn split(t: [usize; 3], m: [usize; 3]) -> [[usize; 3]; 4] {
    let [a, b, c] = t;
    let [ab, bc, ca] = m;
    [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]
}

impl Pattern {
    /// The pattern with every triangle split into four at its edges' midpoints.
    pub fn refined(&self) -> Pattern {
        let mut q = self.clone();
        let mut vertex_mid = Midpoints::new(self.vertex_count());
        let mut rest_mid = Midpoints::new(self.rest_m.len());
        q.triangles.clear();
        q.rest_triangles.clear();
        for (t, r) in self.triangles.iter().zip(&self.rest_triangles) {
            let mut mv = [0; 3];
            let mut mr = [0; 3];
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let (m, new) = vertex_mid.of(a, b);
                if new {
                    let (pa, pb) = (self.start_m[a], self.start_m[b]);
                    q.start_m.push([0, 1, 2].map(|i| 0.5 * (pa[i] + pb[i])));
                }
                let (ra, rb) = (r[k], r[(k + 1) % 3]);
                let (n, new) = rest_mid.of(ra, rb);
                if new {
                    let (pa, pb) = (self.rest_m[ra], self.rest_m[rb]);
                    q.rest_m
                        .push([0.5 * (pa[0] + pb[0]), 0.5 * (pa[1] + pb[1])]);
                    q.vertex_of_rest.push(m);
                }
                (mv[k], mr[k]) = (m, n);
            }
            q.triangles.extend(split(*t, mv));
            q.rest_triangles.extend(split(*r, mr));
        }
        q.groups = refined_groups(&self.groups, &vertex_mid.index);
        q
    }
}

/// Each group with the midpoints of its edges whose ends are both in it, sorted.
fn refined_groups(
    groups: &BTreeMap<String, Vec<usize>>,
    mids: &HashMap<(usize, usize), usize>,
) -> BTreeMap<String, Vec<usize>> {
    groups
        .iter()
        .map(|(name, members)| {
            let inside = |v: &usize| members.binary_search(v).is_ok();
            let mut v = members.clone();
            v.extend(
                mids.iter()
                    .filter(|((a, b), _)| inside(a) && inside(b))
                    .map(|(_, &m)| m),
            );
            v.sort_unstable();
            (name.clone(), v)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::super::parse_obj;

    /// Two triangles of a unit square, sewn to a third piece along one edge (a garment's seam).
    const GARMENT: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 1 0 1\n\
        vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 3 0\nvt 3 1\nvt 2 0\n\
        g a\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\ng b\nf 2/7 5/5 3/6\ng top\nl 3 4\n";

    #[test]
    fn refining_quarters_every_triangle_keeps_the_area_and_shares_the_seam_midpoint() {
        let p = parse_obj(GARMENT, 1.0).unwrap();
        let q = p.refined();
        assert_eq!(q.triangles.len(), 4 * p.triangles.len());
        assert!((q.rest_area_m2() - p.rest_area_m2()).abs() < 1e-12);
        // 5 vertices + 7 edges (the seam 2–3 counted once); 7 rest vertices + 8 rest edges.
        assert_eq!(q.vertex_count(), 12);
        assert_eq!(q.rest_m.len(), 15);
        // Every rest edge keeps its placed length's ratio: halves of the parent's edges.
        for (t, r) in q.triangles.iter().zip(&q.rest_triangles) {
            for k in 0..3 {
                assert_eq!(q.vertex_of_rest[r[k]], t[k]);
            }
        }
        // The group `top` (vertices 3, 4) gains the midpoint of its edge; `b` its edges' three.
        assert_eq!(q.groups["top"].len(), 3);
        assert_eq!(q.groups["b"].len(), 6);
        let mid = *q.groups["top"].iter().find(|&&v| v >= 5).unwrap();
        assert_eq!(q.start_m[mid], [0.5, 1.0, 0.0]);
        // The refined pattern passes the reader's checks: written back as OBJ and read, equal.
        let reread = parse_obj(&as_obj(&q), 1.0).unwrap();
        assert_eq!(reread.vertex_count(), q.vertex_count());
        assert!((reread.rest_area_m2() - q.rest_area_m2()).abs() < 1e-12);
    }

    /// `p` as OBJ text (placed vertices, flat positions as texture coordinates).
    fn as_obj(p: &super::Pattern) -> String {
        let mut s = String::new();
        p.start_m
            .iter()
            .for_each(|v| s += &format!("v {} {} {}\n", v[0], v[1], v[2]));
        p.rest_m
            .iter()
            .for_each(|v| s += &format!("vt {} {}\n", v[0], v[1]));
        for (t, r) in p.triangles.iter().zip(&p.rest_triangles) {
            s += &format!(
                "f {}/{} {}/{} {}/{}\n",
                t[0] + 1,
                r[0] + 1,
                t[1] + 1,
                r[1] + 1,
                t[2] + 1,
                r[2] + 1
            );
        }
        s
    }
}
