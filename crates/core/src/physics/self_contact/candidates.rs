//! Self-contact's candidate set (ipc-toolkit's collision set as data): the broad phase's pairs, the
//! region each vertex may move in while the list stays complete, the active pairs measured once per
//! state, and a set handed from a solved neighbour to a new model.

use super::SelfContact;
use crate::physics::Vecs;
use crate::proximity::{Aabb, MeshTopology, Pair, candidate_pairs, pair_distance};
use nalgebra::Vector3;

#[derive(Default, Clone)]
pub(super) struct Cache {
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
    pub(super) broad_phases: usize,
    pub(super) time_s: f64,
    /// The active pairs (vertices, distance, coefficients) at `active_at` for the activation
    /// distance `active_m`: energy, gradient and Hessian at one state measure them once.
    pub(super) active: Vec<([usize; 4], f64, [f64; 4], bool)>,
    pub(super) active_at: Vec<Vector3<f64>>,
    pub(super) active_m: f64,
}

impl Cache {
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
    /// distance at the anchor) after the moves [`Cache::measure_moves`] took: vertices moved by at
    /// most δ move a primitive's every point by at most the largest δ (its points are convex
    /// combinations of them), so the distance falls by at most δ_A + δ_B.
    pub(super) fn gap_left(&self, topo: &MeshTopology, pair: Pair, gap: f64) -> f64 {
        let idx = pair.vertices(topo);
        let reach = |k: std::ops::Range<usize>| k.map(|i| self.moved[idx[i]]).fold(0.0, f64::max);
        let split = if pair.is_point_triangle() { 1 } else { 2 };
        gap - reach(0..split) - reach(split..4)
    }
}

/// A self-contact term's candidate set as data (ipc-toolkit's collision set): the broad phase's
/// pairs with the region each vertex may move in while the list stays complete. Taken from a
/// solved neighbour (a calibration lattice's drape), it seeds a new model's term so that a solve
/// starting nearby runs no broad phase until a vertex leaves its region; the pairs a seeded term
/// measures are those a fresh broad phase would keep within range, in the same order.
#[derive(Clone)]
pub struct CandidateSet {
    /// The activation distance ξ + d̂ the list was built for, m.
    pub(super) activation_m: f64,
    /// Vertices and triangles of the mesh it was built on.
    pub(super) size: (usize, usize),
    pub(super) cache: Cache,
}

impl SelfContact {
    /// The candidate set at hand, when a broad phase has run.
    pub fn candidates(&self) -> Option<CandidateSet> {
        let c = self.cache.lock().unwrap_or_else(|e| e.into_inner());
        c.valid.then(|| CandidateSet {
            activation_m: self.activation_m(),
            size: (c.region.len(), self.topo.triangles.len()),
            cache: Cache {
                moved: Vec::new(),
                broad_phases: 0,
                time_s: 0.0,
                ..c.clone()
            },
        })
    }

    /// Takes `set` as this term's candidate set where it was built for the same mesh and
    /// activation distance (true); else leaves the term as it is (false).
    pub fn seed(&self, set: &CandidateSet) -> bool {
        let mut c = self.cache.lock().unwrap_or_else(|e| e.into_inner());
        let fits = set.activation_m == self.activation_m()
            && set.size.1 == self.topo.triangles.len()
            && self
                .topo
                .vertices
                .iter()
                .all(|&v| (v as usize) < set.size.0);
        if fits {
            let (phases, time) = (c.broad_phases, c.time_s);
            *c = Cache {
                broad_phases: phases,
                time_s: time,
                ..set.cache.clone()
            };
        }
        fits
    }

    /// Makes the candidate list cover `x` (and the step `dx` from it, if given): rebuilt when a
    /// vertex would leave its box.
    pub(super) fn ensure(&self, c: &mut Cache, x: &Vecs, dx: Option<&Vecs>) {
        let reach = |v: usize| {
            let b = Aabb::point(&x[v]);
            dx.map_or(b, |d| b.union(&Aabb::point(&(x[v] + d[v]))))
        };
        let inside = c.valid
            && c.region.len() == x.len()
            && self
                .topo
                .vertices
                .iter()
                .all(|&v| c.region[v as usize].contains(&reach(v as usize)));
        if inside {
            return;
        }
        self.broad_phase(c, x, reach);
    }

    /// The broad phase at `x`: each vertex's box is `reach(v)` grown by the margin, and the list keeps
    /// the pairs that could come within the activation distance anywhere inside their boxes.
    pub(super) fn broad_phase(&self, c: &mut Cache, x: &Vecs, reach: impl Fn(usize) -> Aabb) {
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
        c.pairs = candidate_pairs(topo, &c.region, 0.5 * act, |pair| {
            let idx = pair.vertices(topo);
            let reach = |k: std::ops::Range<usize>| k.map(|i| rho[idx[i]]).fold(0.0, f64::max);
            let (a, b) = if pair.is_point_triangle() {
                (reach(0..1), reach(1..4))
            } else {
                (reach(0..2), reach(2..4))
            };
            pair_distance(pair.is_point_triangle(), &idx.map(|k| x[k])).0 - a - b < act
        });
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
    }

    /// The candidate set at `x` that stays valid while each vertex v moves less than `spread[v]`
    /// (m) from it (and the margin beyond): a start anywhere in that reach begins without a broad
    /// phase. A calibration lattice node gives it for the reach of its tangent predictions.
    pub fn candidates_covering(&self, x: &Vecs, spread: &[f64]) -> CandidateSet {
        let mut c = Cache::default();
        self.broad_phase(&mut c, x, |v| {
            Aabb::point(&x[v]).inflate(spread.get(v).copied().unwrap_or(0.0))
        });
        CandidateSet {
            activation_m: self.activation_m(),
            size: (c.region.len(), self.topo.triangles.len()),
            cache: Cache {
                broad_phases: 0,
                ..c
            },
        }
    }
}
