//! Self-contact's candidate set (ipc-toolkit's candidates as data): the broad phase's pairs and the
//! region each vertex may move in while the list stays complete, and a set handed from a solved
//! neighbour to a new model.

use super::SelfContact;
use crate::physics::Vecs;
use crate::proximity::{
    Aabb, MeshTopology, Pair, pair_distance, pair_distance_lower_bound, relative_motion,
};
use nalgebra::Vector3;

/// The broad phase's candidate list: the pairs that could come within the activation distance
/// while every vertex stays in the region the list covers (its box, or a step's sweep), with each
/// pair's gap at the state the list was built at. It says which pairs may be near, never an
/// energy's value: the contact set is measured from it at each state the solve evaluates.
#[derive(Default, Clone)]
pub(super) struct CandidateList {
    /// Per particle, the box its vertex may move in while `pairs` stays complete.
    pub(super) region: Vec<Aabb>,
    pub(super) pairs: Vec<Pair>,
    /// Per pair, its distance beyond the activation distance at `anchor`, m.
    pub(super) gaps: Vec<f64>,
    /// The positions the list was built at.
    pub(super) anchor: Vec<Vector3<f64>>,
    /// Scratch: each vertex's distance from its anchor.
    pub(super) moved: Vec<f64>,
    pub(super) valid: bool,
    /// When set, the list covers this sweep from `anchor` instead of the vertices' regions.
    pub(super) sweep: Option<Sweep>,
    /// Broad phases run on this list since it was made.
    pub(super) broad_phases: usize,
}

impl CandidateList {
    /// Each vertex's distance from the list's anchor, into `moved`.
    pub(super) fn measure_moves(&mut self, x: &Vecs) {
        self.moved.clear();
        let moves = x
            .iter()
            .zip(self.anchor.iter())
            .map(|(p, q)| (p - q).norm());
        self.moved.extend(moves);
    }

    /// A lower bound on what is left of `pair`'s `gap` (its distance beyond the activation
    /// distance at the anchor) after the moves [`CandidateList::measure_moves`] took: vertices
    /// moved by at most δ move a primitive's every point by at most the largest δ (its points are
    /// convex combinations of them), so the distance falls by at most δ_A + δ_B.
    pub(super) fn gap_left(&self, topo: &MeshTopology, pair: Pair, gap: f64) -> f64 {
        gap - farthest(pair, &pair.vertices(topo), &self.moved)
    }
}

/// The largest of `per_vertex` over each primitive of `pair` (vertices `idx`), summed over the two:
/// how far the pair's distance can fall when every vertex v moves by at most `per_vertex[v]`.
pub(super) fn farthest(pair: Pair, idx: &[usize; 4], per_vertex: &[f64]) -> f64 {
    let most = |k: std::ops::Range<usize>| k.map(|i| per_vertex[idx[i]]).fold(0.0, f64::max);
    let split = if pair.is_point_triangle() { 1 } else { 2 };
    most(0..split) + most(split..4)
}

/// The states a candidate list built for a long step covers: anchor + a·d₁ + b·d₂ for (a, b) in
/// the triangle (−0.1, 0), (1, 0), (0, 1) (one or two directions: a step, or a curved step's
/// tangent and chord; a tenth of the first behind the anchor: [`SWEEP_BACK`]), each vertex
/// within `slack` of such a state. A pair's distance there is at least its distance at the anchor
/// less its vertices' motion relative to their mean (additive CCD's bound) and twice the slack, so
/// the list keeps only the pairs that could come within the activation distance on the way: a
/// sheet falling as a whole keeps the pairs its folds bring together, not every pair its swept
/// boxes overlap (sphere_wool: ~500 pairs against 48,000 a long step).
#[derive(Clone)]
pub(super) struct Sweep {
    dirs: Vec<Vec<Vector3<f64>>>,
    slack: f64,
    /// The directions' products over the mesh's vertices, [d₁·d₁, d₁·d₂, d₂·d₂] (what of them
    /// there is): each state's fit reads them instead of summing them again.
    gram: [f64; 3],
}

impl Sweep {
    /// The sweep along `dirs` (one or two) over the mesh's `vertices`.
    fn new(dirs: Vec<Vec<Vector3<f64>>>, slack: f64, vertices: &[u32]) -> Self {
        let dot = |a: &[Vector3<f64>], b: &[Vector3<f64>]| {
            let each = vertices.iter().map(|&v| a[v as usize].dot(&b[v as usize]));
            each.sum::<f64>()
        };
        let last = &dirs[dirs.len() - 1];
        let gram = [
            dot(&dirs[0], &dirs[0]),
            dot(&dirs[0], last),
            dot(last, last),
        ];
        Self { dirs, slack, gram }
    }

    /// Whether the state `y` (and the step `dx` from it, if given) lies in the sweep from `anchor`
    /// over the mesh's `vertices`. The set is convex, so a step is covered when both its ends are.
    fn covers(&self, anchor: &Vecs, vertices: &[u32], y: &Vecs, dx: Option<&Vecs>) -> bool {
        let ends = |v: usize| {
            (
                y[v] - anchor[v],
                dx.map_or(y[v], |d| y[v] + d[v]) - anchor[v],
            )
        };
        self.fits(vertices, |v| ends(v).0) && (dx.is_none() || self.fits(vertices, |v| ends(v).1))
    }

    /// Whether the displacements `e(v)` from the anchor are within the slack of a·d₁ + b·d₂ for
    /// the least-squares (a, b) brought into the sweep, or for either direction alone.
    fn fits(&self, vertices: &[u32], e: impl Fn(usize) -> Vector3<f64>) -> bool {
        let d = &self.dirs;
        let dot = |f: &dyn Fn(usize) -> Vector3<f64>, g: &dyn Fn(usize) -> Vector3<f64>| {
            vertices
                .iter()
                .map(|&v| f(v as usize).dot(&g(v as usize)))
                .sum::<f64>()
        };
        let dir = |k: usize| move |v: usize| d[k][v];
        let within = |w: [f64; 2]| {
            vertices.iter().all(|&v| {
                let v = v as usize;
                let z: Vector3<f64> = (0..d.len()).map(|k| d[k][v] * w[k]).sum();
                (e(v) - z).norm() <= self.slack
            })
        };
        let along = |k: usize| {
            let dd = self.gram[2 * k];
            let a = if dd > 0.0 { dot(&e, &dir(k)) / dd } else { 0.0 };
            let mut w = [0.0; 2];
            w[k] = a.clamp(if k == 0 { -SWEEP_BACK } else { 0.0 }, 1.0);
            within(w)
        };
        if d.len() == 2 {
            let [g00, g01, g11] = self.gram;
            let det = g00 * g11 - g01 * g01;
            if det > 1e-12 * g00 * g11 {
                let (r0, r1) = (dot(&e, &dir(0)), dot(&e, &dir(1)));
                let b = ((g00 * r1 - g01 * r0) / det).clamp(0.0, 1.0);
                let a = ((g11 * r0 - g01 * r1) / det).clamp(-SWEEP_BACK * (1.0 - b), 1.0 - b);
                if within([a, b]) {
                    return true;
                }
            }
        }
        (0..d.len()).any(along)
    }
}

/// How far back along its first direction a sweep reaches, as a share of it: the central
/// difference of a curved step's acceleration (the solver's `ACCELERATION_FD`) evaluates the
/// gradient a tenth of the step behind its start.
const SWEEP_BACK: f64 = 0.1;

/// A self-contact term's candidate set as data (ipc-toolkit's candidates): the broad phase's pairs
/// with the region each vertex may move in while the list stays complete. The solve owns it and
/// carries it from state to state ([`super::SelfContact::contact_set`],
/// [`super::SelfContact::max_step_with`] keep it covering the states they are asked about); the
/// term remembers nothing. Handed from a solved neighbour (a calibration lattice's drape,
/// [`crate::solve::WarmData::candidates`]) it starts a new model's solve without a broad phase
/// until a vertex leaves its region. The default is an empty set, which the first query builds.
#[derive(Clone, Default)]
pub struct CandidateSet {
    /// The activation distance ξ + d̂ the list was built for, m.
    pub(super) activation_m: f64,
    /// The number of triangles of the mesh it was built on (the vertices' are checked against
    /// its anchor as it is used).
    pub(super) triangles: usize,
    pub(super) list: CandidateList,
}

impl CandidateSet {
    /// Broad phases this set has run since it was made (a seeded set counts from zero).
    pub fn broad_phases(&self) -> usize {
        self.list.broad_phases
    }
}

impl SelfContact {
    /// `set`'s list, emptied first where it was built for another mesh or activation distance (a
    /// change of coefficients moved ξ + d̂, or the set came from another model): the pairs it
    /// keeps would then not be those in range.
    pub(super) fn fitted<'a>(&self, set: &'a mut CandidateSet) -> &'a mut CandidateList {
        let (act, triangles) = (self.activation_m(), self.topo.triangles.len());
        if set.activation_m != act || set.triangles != triangles {
            *set = CandidateSet {
                activation_m: act,
                triangles,
                list: CandidateList::default(),
            };
        }
        &mut set.list
    }

    /// Makes the candidate list cover `x` (and the step `dx` from it, if given): rebuilt when a
    /// vertex would leave its box or the state its sweep. A step longer than the margin gets a
    /// list for its sweep ([`Sweep`]; with the last one's direction where that was swept from the
    /// same state: a curved step's chord after its tangent); else each vertex's box.
    pub(super) fn ensure(&self, c: &mut CandidateList, x: &Vecs, dx: Option<&Vecs>) {
        let reach = |v: usize| {
            let b = Aabb::point(&x[v]);
            dx.map_or(b, |d| b.union(&Aabb::point(&(x[v] + d[v]))))
        };
        let vertices = &self.topo.vertices;
        let inside = c.valid
            && match &c.sweep {
                Some(s) => c.anchor.len() == x.len() && s.covers(&c.anchor, vertices, x, dx),
                None => {
                    c.region.len() == x.len()
                        && vertices
                            .iter()
                            .all(|&v| c.region[v as usize].contains(&reach(v as usize)))
                }
            };
        if inside {
            return;
        }
        let longest = |d: &Vecs| {
            vertices
                .iter()
                .map(|&v| d[v as usize].norm())
                .fold(0.0, f64::max)
        };
        match dx.filter(|d| longest(d) > self.margin_m) {
            Some(d) => {
                let mut dirs = vec![d.to_vec()];
                if let Some(s) = c
                    .sweep
                    .as_ref()
                    .filter(|_| c.valid && c.anchor.as_slice() == x)
                {
                    dirs.insert(0, s.dirs[s.dirs.len() - 1].clone());
                }
                self.sweep_phase(c, x, dirs);
            }
            None => self.broad_phase(c, x, reach),
        }
    }

    /// The broad phase for the sweep from `x` along `dirs` ([`Sweep`]): each vertex's box holds
    /// its sweep less each direction's median over the mesh (distances do not change when the
    /// sheet moves as a whole), grown by the slack.
    fn sweep_phase(&self, c: &mut CandidateList, x: &Vecs, dirs: Vec<Vec<Vector3<f64>>>) {
        let vertices = &self.topo.vertices;
        let median = |d: &Vecs| {
            Vector3::from_fn(|k, _| {
                let mut v: Vec<f64> = vertices.iter().map(|&i| d[i as usize][k]).collect();
                let m = v.len() / 2;
                *v.select_nth_unstable_by(m, f64::total_cmp).1
            })
        };
        let shifts: Vec<Vector3<f64>> = dirs.iter().map(|d| median(d)).collect();
        let slack = self.margin_m;
        let boxes: Vec<Aabb> = (0..x.len())
            .map(|v| {
                let ends = dirs
                    .iter()
                    .zip(&shifts)
                    .map(|(d, u)| Aabb::point(&(x[v] + d[v] - u)));
                let back = Aabb::point(&(x[v] - (dirs[0][v] - shifts[0]) * SWEEP_BACK));
                ends.fold(back, |b, e| b.union(&e)).inflate(slack)
            })
            .collect();
        let act = self.activation_m();
        let topo = &self.topo;
        c.pairs = self
            .broad_phase
            .candidate_pairs(topo, &boxes, 0.5 * act, &|pair| {
                let (idx, pt) = (pair.vertices(topo), pair.is_point_triangle());
                if !self.can_collide(pair) {
                    return false;
                }
                let reach = dirs
                    .iter()
                    .map(|d| relative_motion(pt, &idx.map(|k| d[k])).1)
                    .fold(0.0, f64::max);
                let at = idx.map(|k| x[k]);
                pair_distance_lower_bound(pt, &at) - reach - 2.0 * slack < act
                    && pair_distance(pt, &at).0 - reach - 2.0 * slack < act
            });
        self.anchor_list(c, x);
        c.region.clear();
        c.sweep = Some(Sweep::new(dirs, slack, vertices));
    }

    /// The list's gaps at `x`, its anchor.
    fn anchor_list(&self, c: &mut CandidateList, x: &Vecs) {
        let (topo, act) = (&self.topo, self.activation_m());
        c.gaps = c
            .pairs
            .iter()
            .map(|pair| {
                let idx = pair.vertices(topo);
                pair_distance(pair.is_point_triangle(), &idx.map(|k| x[k])).0 - act
            })
            .collect();
        c.anchor = x.to_vec();
        c.valid = true;
        c.broad_phases += 1;
        self.work
            .broad_phases
            .fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    }

    /// The broad phase at `x`: each vertex's box is `reach(v)` grown by the margin, and the list keeps
    /// the pairs that could come within the activation distance anywhere inside their boxes.
    pub(super) fn broad_phase(
        &self,
        c: &mut CandidateList,
        x: &Vecs,
        reach: impl Fn(usize) -> Aabb,
    ) {
        c.region = vec![Aabb::point(&Vector3::zeros()); x.len()];
        for &v in &self.topo.vertices {
            c.region[v as usize] = reach(v as usize).inflate(self.margin_m);
        }
        // Boxes overlap far more often than primitives come near (a triangle's box holds its
        // neighbours' vertices): keep a pair only when, each vertex anywhere in its box, it could come
        // within the activation distance: d(x) − ρ_A − ρ_B < ξ + d̂, ρ the farthest a primitive's
        // vertices can move from x inside their boxes.
        let rho: Vec<f64> = (0..x.len())
            .map(|v| {
                let b = &c.region[v];
                (b.hi - x[v]).sup(&(x[v] - b.lo)).norm()
            })
            .collect();
        let act = self.activation_m();
        let topo = &self.topo;
        c.pairs = self
            .broad_phase
            .candidate_pairs(topo, &c.region, 0.5 * act, &|pair| {
                let (idx, pt) = (pair.vertices(topo), pair.is_point_triangle());
                if !self.can_collide(pair) {
                    return false;
                }
                let (at, reach) = (idx.map(|k| x[k]), farthest(pair, &idx, &rho));
                pair_distance_lower_bound(pt, &at) - reach < act
                    && pair_distance(pt, &at).0 - reach < act
            });
        self.anchor_list(c, x);
        c.sweep = None;
    }

    /// The candidate set at `x` that stays valid while each vertex v moves less than `spread[v]`
    /// (m) from it (and the margin beyond): a start anywhere in that reach begins without a broad
    /// phase. A calibration lattice node gives it for the reach of its tangent predictions.
    pub fn candidates_covering(&self, x: &Vecs, spread: &[f64]) -> CandidateSet {
        let mut c = CandidateList::default();
        self.broad_phase(&mut c, x, |v| {
            Aabb::point(&x[v]).inflate(spread.get(v).copied().unwrap_or(0.0))
        });
        CandidateSet {
            activation_m: self.activation_m(),
            triangles: self.topo.triangles.len(),
            list: CandidateList {
                broad_phases: 0,
                ..c
            },
        }
    }
}
