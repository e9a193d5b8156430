//! Self-contact of the sheet (incremental potential contact, codimensional form): every vertex and
//! triangle, and every two edges, that share no vertex repel by E = κ b(d − ξ) with the barrier b of
//! [`super::ObstacleBarrier`] over the band d̂, where d is their distance and ξ the fabric's
//! thickness: the mid-surfaces of two layers stay more than ξ apart and the force starts at ξ + d̂.
//! Two edges within ~1.8° of parallel repel by κ m b(d − ξ), m IPC's mollifier of their angle
//! ([`edge_edge_mollifier`]): their distance has a kink where they turn parallel, a valley Newton
//! crawls in where folded layers lie on each other with their edges aligned.
//! The energy is infinite at d ≤ ξ, and [`super::StepBound::max_step`] bounds every step by additive
//! continuous collision detection so that no pair comes closer than ξ + 10 % of its gap along it: a
//! line search that keeps the energy finite can never carry the sheet through itself.
//!
//! The broad phase (a swappable [`BroadPhase`], the spatial hash by default) builds a
//! [`CandidateSet`], which the solve owns and hands to every query; it is rebuilt only when the
//! sheet leaves the region the set covers: each vertex's box, swept along the step and grown by a
//! margin of a quarter of the shortest edge. On a smooth sheet no pair of non-adjacent primitives
//! is within reach, the list is empty, and the term costs a comparison of positions with boxes.
//! The term itself keeps no state of a solve: its energy and derivatives at x, asked without a
//! set, build one for x.

mod candidates;
mod contact_set;
mod pair;
mod potential;

use super::barrier::{barrier, barrier_band_derivatives};
use super::{EnergyTerm, HessianBlocks, HessianMode, StepBound, Vecs};
use crate::proximity::{
    Aabb, BroadPhase, HashGrid, MeshTopology, Pair, additive_ccd, pair_distance, relative_motion,
};
pub use candidates::CandidateSet;
pub use contact_set::{ContactPair, ContactSet, PairKind};
use nalgebra::Vector3;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::time::Instant;

/// What self-contact looks like at a state (for run reports).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SelfContactState {
    /// The smallest distance between two primitives that share no vertex, m (infinite when no two
    /// are within the longest edge of each other).
    pub min_distance_m: f64,
    /// The barrier's stiffness κ now, J.
    pub kappa_J: f64,
    /// κ over its value as built (1 unless stiffened where layers pressed).
    pub kappa_growth: f64,
    /// Pairs within the activation distance ξ + d̂.
    pub active_pairs: usize,
    /// Broad phases the term has run so far, over every candidate set.
    pub broad_phases: usize,
    /// Wall time spent so far in the term's contact-set and step-bound queries (broad and narrow
    /// phase, CCD), s.
    pub time_s: f64,
}

/// Self-contact between the primitives of a triangulated sheet.
pub struct SelfContact {
    topo: std::sync::Arc<MeshTopology>,
    /// Thickness ξ, m: the closest two layers' mid-surfaces may come.
    pub thickness_m: f64,
    /// Barrier band d̂ beyond the thickness, m: the force starts at ξ + d̂.
    pub band_m: f64,
    /// Barrier stiffness κ, J.
    pub kappa_J: f64,
    /// The largest κ [`SelfContact::stiffen_barrier`] raises it to, J.
    kappa_limit_J: f64,
    margin_m: f64,
    /// The longest vertex move checked with one broad phase, m: four of the longest rest edge.
    piece_m: f64,
    /// The broad phase that builds the candidate list ([`HashGrid`] unless set by
    /// [`SelfContact::with_broad_phase`]).
    broad_phase: Box<dyn BroadPhase>,
    /// What the term's queries cost so far (counters for the run report, no state of a solve).
    work: Work,
    /// Each vertex's twin class (vertices of one class are to become one particle: a seam's two
    /// sides while it is sewn); a pair joined through a class, like a pair sharing a vertex, is
    /// not a contact (ipc-toolkit's `can_collide`). Empty: every vertex its own class.
    twins: Vec<u32>,
}

/// The work counters of a self-contact term.
#[derive(Default)]
struct Work {
    broad_phases: AtomicUsize,
    nanos: AtomicU64,
}

impl Work {
    /// Adds the time since `start`.
    fn add_time(&self, start: Instant) {
        let ns = start.elapsed().as_nanos().min(u64::MAX as u128) as u64;
        self.nanos.fetch_add(ns, Ordering::Relaxed);
    }
}

impl SelfContact {
    /// Self-contact of the sheet `triangles` (vertex indices into the positions) at rest positions
    /// `x0`, thickness `thickness_m` and band `band_m`, κ such that the barrier's force equals
    /// `weight_N` (a particle's weight) a tenth of the band into it.
    pub fn new(
        triangles: Vec<[u32; 3]>,
        x0: &Vecs,
        thickness_m: f64,
        band_m: f64,
        weight_N: f64,
    ) -> Self {
        let topo = MeshTopology::shared(triangles);
        let shortest = topo
            .edges
            .iter()
            .map(|e| (x0[e[0] as usize] - x0[e[1] as usize]).norm())
            .fold(f64::INFINITY, f64::min);
        let longest = topo
            .edges
            .iter()
            .map(|e| (x0[e[0] as usize] - x0[e[1] as usize]).norm())
            .fold(0.0, f64::max);
        let margin_m = if shortest.is_finite() {
            (0.1 * shortest).max(0.25 * (thickness_m + band_m))
        } else {
            thickness_m + band_m
        };
        let kappa_J = super::ObstacleBarrier::kappa_for_weight(weight_N, band_m);
        Self {
            topo,
            thickness_m,
            band_m,
            kappa_J,
            kappa_limit_J: KAPPA_GROWTH_LIMIT * kappa_J,
            margin_m,
            piece_m: (4.0 * longest).max(margin_m),
            broad_phase: Box::new(HashGrid),
            work: Work::default(),
            twins: Vec::new(),
        }
    }

    /// The term with `twins[v]` the class of vertex v: the two sides of a seam being sewn (one
    /// class a welded vertex) do not repel where they are to meet.
    pub fn with_twins(mut self, twins: Vec<u32>) -> Self {
        self.twins = twins;
        self
    }

    /// Whether `pair` may be a contact: no vertex of one primitive is a twin of one of the other's.
    pub(super) fn can_collide(&self, pair: Pair) -> bool {
        if self.twins.is_empty() {
            return true;
        }
        let c = pair.vertices(&self.topo).map(|v| self.twins[v]);
        let (a, b) = if pair.is_point_triangle() {
            (&c[..1], &c[1..])
        } else {
            (&c[..2], &c[2..])
        };
        !a.iter().any(|v| b.contains(v))
    }

    /// The term with `broad_phase` building its candidate lists (the same pairs, another cost).
    pub fn with_broad_phase(mut self, broad_phase: Box<dyn BroadPhase>) -> Self {
        self.broad_phase = broad_phase;
        self
    }

    /// Raises κ where a pair has been pressed to within a small fraction of its band
    /// (incremental potential contact's adaptive κ, Li et al. 2020): at a gap where κ b′ balances
    /// a force F the barrier's curvature is about F²/(κ d̂²), so stacked layers that press a pair
    /// nanometres from its limit leave Newton a nearly singular system until κ grows. Doubles κ
    /// when the closest pair of `set` (the contact set at the solve's state) has a gap beyond the
    /// thickness under [`STIFFEN_GAP`] of the band, up to [`KAPPA_GROWTH_LIMIT`] times its start;
    /// true when it did. Called between the steps of a dynamic solve and after closing steps of a
    /// static one ([`crate::solve::StaticOptions::kappa_adapt_gap_rel`]). The set stays valid: κ
    /// scales the barrier, not its activation distance.
    pub fn stiffen_barrier(&mut self, set: &ContactSet) -> bool {
        if self.kappa_J * 2.0 > self.kappa_limit_J {
            return false;
        }
        let closest = self.closest_gap_rel(set).unwrap_or(f64::INFINITY);
        let pressed = closest < STIFFEN_GAP;
        if pressed {
            self.kappa_J *= 2.0;
        }
        pressed
    }
    /// Sets κ to `growth` times κ as built (clamped to 1 ..= [`KAPPA_GROWTH_LIMIT`]): a restart
    /// taking up the κ its run's solve adapted ([`crate::physics::Adapted`]).
    pub fn set_kappa_growth(&mut self, growth: f64) {
        let g = if growth.is_finite() {
            growth.clamp(1.0, KAPPA_GROWTH_LIMIT)
        } else {
            1.0
        };
        self.kappa_J = self.kappa_built_J() * g;
    }
    /// The smallest gap of a pair of `set` beyond the thickness, as a fraction of the band (0 at
    /// the thickness, 1 at the edge of the band), or None with no pair in range: what a static
    /// solve watches to adapt κ.
    pub fn closest_gap_rel(&self, set: &ContactSet) -> Option<f64> {
        let closest = set.min_distance_m() - self.thickness_m;
        closest.is_finite().then_some(closest / self.band_m)
    }

    /// The activation distance ξ + d̂, m.
    pub fn activation_m(&self) -> f64 {
        self.thickness_m + self.band_m
    }

    /// The mesh's primitives.
    pub fn topology(&self) -> &MeshTopology {
        &self.topo
    }

    /// The contact set at `x`: every pair of primitives sharing no vertex within the activation
    /// distance ξ + d̂, from the narrow phase over `candidates` (the solve's candidate set, made to
    /// cover `x` first: a broad phase where `x` left its region), with the blocks of the pairs
    /// near range as the Hessian's hints. The solve builds one per state and hands it to
    /// [`SelfContact::energy_of`] and the rest.
    pub fn contact_set(&self, x: &Vecs, candidates: &mut CandidateSet) -> ContactSet {
        let start = Instant::now();
        let c = self.fitted(candidates);
        self.ensure(c, x, None);
        c.measure_moves(x);
        let act = self.activation_m();
        let mut set = ContactSet::default();
        for (&pair, &gap) in c.pairs.iter().zip(c.gaps.iter()) {
            // A pair whose gap still exceeds its vertices' moves is out of range, unmeasured.
            let left = c.gap_left(&self.topo, pair, gap);
            if left >= self.margin_m {
                continue;
            }
            let idx = pair.vertices(&self.topo);
            let split = if pair.is_point_triangle() { 1 } else { 2 };
            for &a in &idx[..split] {
                for &b in &idx[split..] {
                    set.hints.push((a.max(b) as u32, a.min(b) as u32));
                }
            }
            if left >= 0.0 {
                continue;
            }
            let pt = pair.is_point_triangle();
            let (d, coef) = pair_distance(pt, &idx.map(|k| x[k]));
            if d < act {
                let kind = match pt {
                    true => PairKind::PointTriangle,
                    false => PairKind::EdgeEdge,
                };
                set.pairs.push(ContactPair {
                    kind,
                    vertices: idx,
                    distance_m: d,
                    coefficients: coef,
                });
            }
        }
        self.work.add_time(start);
        set
    }

    /// [`SelfContact::contact_set`] with a candidate set of its own, built for `x`.
    pub fn contact_set_here(&self, x: &Vecs) -> ContactSet {
        self.contact_set(x, &mut CandidateSet::default())
    }

    /// The first impact time in (0, 1] of the candidate pairs moving from `x` by `seg`
    /// ([`additive_ccd`], keeping a tenth of each pair's gap), infinity when none. A pair is passed
    /// over when additive CCD would return at its first bound: its distance is at least its gap at
    /// the list's anchor less its vertices' moves since, so (1 − 0.1)(d − ξ)/l > 1 holds without
    /// measuring d. The same result, without the distance computations that were a quarter of a
    /// settling implicit run's time (issue 47).
    fn piece_impact(&self, c: &mut candidates::CandidateList, x: &Vecs, seg: &Vecs) -> f64 {
        const SHARE: f64 = 0.1;
        c.measure_moves(x);
        let act = self.activation_m();
        let reach: Vec<f64> = seg.iter().map(|d| d.norm()).collect();
        let mut toi = f64::INFINITY;
        for (&pair, &gap) in c.pairs.iter().zip(c.gaps.iter()) {
            let idx = pair.vertices(&self.topo);
            let lower = c.gap_left(&self.topo, pair, gap) + act - self.thickness_m;
            if lower > 0.0 {
                // The gap shrinks by at most its vertices' whole moves: when that leaves more
                // than the share, additive CCD never stops (cheaper than the relative motion).
                if (1.0 - SHARE) * lower > candidates::farthest(pair, &idx, &reach) {
                    continue;
                }
                let (_, l) = relative_motion(pair.is_point_triangle(), &idx.map(|k| seg[k]));
                if (1.0 - SHARE) * lower > l {
                    continue;
                }
            }
            let t = additive_ccd(
                pair.is_point_triangle(),
                &idx.map(|k| x[k]),
                &idx.map(|k| seg[k]),
                self.thickness_m,
                SHARE,
                1.0,
            );
            toi = toi.min(t);
        }
        toi
    }

    /// κ as built, J (before any growth where layers pressed).
    fn kappa_built_J(&self) -> f64 {
        self.kappa_limit_J / KAPPA_GROWTH_LIMIT
    }

    /// κ over κ as built (1 unless a solve stiffened the barrier).
    pub fn kappa_growth(&self) -> f64 {
        self.kappa_J / self.kappa_built_J()
    }

    /// The state of self-contact at `x`: smallest distance between primitives sharing no vertex
    /// (searched within the longest edge), active pairs, and the work done so far.
    pub fn state(&self, x: &Vecs) -> SelfContactState {
        let longest = self
            .topo
            .edges
            .iter()
            .map(|e| (x[e[0] as usize] - x[e[1] as usize]).norm())
            .fold(0.0, f64::max);
        let boxes: Vec<Aabb> = x.iter().map(Aabb::point).collect();
        // Distances are non-negative, so their bits order as they do (an atomic minimum).
        let least = std::sync::atomic::AtomicU64::new(f64::INFINITY.to_bits());
        let topo = &self.topo;
        self.broad_phase
            .candidate_pairs(topo, &boxes, 0.5 * longest, &|p| {
                if !self.can_collide(p) {
                    return false;
                }
                let idx = p.vertices(&self.topo);
                let d = pair_distance(p.is_point_triangle(), &idx.map(|k| x[k])).0;
                least.fetch_min(d.to_bits(), std::sync::atomic::Ordering::Relaxed);
                false
            });
        let min_distance_m = f64::from_bits(least.into_inner());
        let active_pairs = self.contact_set_here(x).len();
        SelfContactState {
            min_distance_m,
            kappa_J: self.kappa_J,
            kappa_growth: self.kappa_growth(),
            active_pairs,
            broad_phases: self.work.broad_phases.load(Ordering::Relaxed),
            time_s: self.work.nanos.load(Ordering::Relaxed) as f64 * 1e-9,
        }
    }
}

/// A pair pressed to within this fraction of the band beyond the thickness doubles κ: κ is built
/// to balance one particle's weight there, so a pair pressed closer carries more than one's.
const STIFFEN_GAP: f64 = 0.1;

/// κ grows at most this factor above its start.
const KAPPA_GROWTH_LIMIT: f64 = 1024.0;

impl EnergyTerm for SelfContact {
    fn name(&self) -> String {
        "contact/self".into()
    }
    /// [`SelfContact::energy_of`] the contact set built at `x`.
    fn energy(&self, x: &Vecs) -> f64 {
        self.energy_of(&self.contact_set_here(x), x)
    }
    /// [`SelfContact::add_gradient_of`] the contact set built at `x`.
    fn add_gradient(&self, x: &Vecs, g: &mut Vecs) {
        self.add_gradient_of(&self.contact_set_here(x), x, g);
    }
    /// [`SelfContact::add_hessian_with_hints`] of the contact set built at `x`.
    fn add_hessian(&self, x: &Vecs, h: &mut HessianBlocks, mode: HessianMode) {
        self.add_hessian_with_hints(&self.contact_set_here(x), x, h, mode);
    }
    fn step_bound(&self) -> Option<&dyn StepBound> {
        Some(self)
    }
    /// ξ (m), d̂ (m), κ₀ (J): the fabric's thickness, the barrier's band and its stiffness as built
    /// (κ = κ₀ times the growth a solve gave it where layers pressed, held as κ₀ moves: a scene
    /// rebuilt at a neighbouring parameter has κ₀ of its own and growth 1).
    fn coefficients(&self) -> Vec<f64> {
        vec![self.thickness_m, self.band_m, self.kappa_built_J()]
    }
    fn set_coefficients(&mut self, c: &[f64]) {
        let growth = self.kappa_growth();
        (self.thickness_m, self.band_m) = (c[0], c[1]);
        self.kappa_J = c[2] * growth;
        self.kappa_limit_J = KAPPA_GROWTH_LIMIT * c[2];
    }
    /// Analytic in all three: κ ∂b′/∂c ∇d per pair, with ∂b′/∂ξ = −b″ and ∂b′/∂d̂ from
    /// [`barrier_band_derivatives`].
    fn add_coefficient_gradient(&self, x: &Vecs, dc: &[f64], g: &mut Vecs) -> bool {
        let [dxi, dband, dkappa] = match dc {
            [a, b, c] => [*a, *b, *c * self.kappa_growth()],
            _ => return false,
        };
        let along = |gap| {
            let (b, db, d2b) = barrier(gap, self.band_m);
            let (db_dband, ddb) = barrier_band_derivatives(gap, self.band_m);
            let slope = dkappa * db + self.kappa_J * (ddb * dband - d2b * dxi);
            let value = dkappa * b + self.kappa_J * (db_dband * dband - db * dxi);
            (slope, value)
        };
        self.add_pair_forces(&self.contact_set_here(x), (x, g), along);
        true
    }
    fn coefficient_energy(&self, x: &Vecs, dc: &[f64]) -> Option<f64> {
        let [dxi, dband, dkappa] = match dc {
            [a, b, c] => [*a, *b, *c * self.kappa_growth()],
            _ => return None,
        };
        let value = |gap| {
            let (b, db, _) = barrier(gap, self.band_m);
            let db_dband = barrier_band_derivatives(gap, self.band_m).0;
            dkappa * b + self.kappa_J * (db_dband * dband - db * dxi)
        };
        Some(self.sum_pairs(&self.contact_set_here(x), x, value))
    }
}

impl StepBound for SelfContact {
    /// [`SelfContact::max_step_with`] a candidate set of its own.
    fn max_step(&self, x: &Vecs, dx: &Vecs) -> f64 {
        self.max_step_with(x, dx, &mut CandidateSet::default())
    }
}

impl SelfContact {
    /// The collision-free step size: additive CCD over every pair of `candidates` (the solve's
    /// set, made to cover the step). A long step (far from equilibrium Newton may propose a
    /// vertex move of a metre) is checked in pieces of at most `piece_m` per vertex, each with its
    /// own broad phase, so that no swept box spans the sheet; the first piece with an impact gives
    /// the bound.
    pub fn max_step_with(&self, x: &Vecs, dx: &Vecs, candidates: &mut CandidateSet) -> f64 {
        let start = Instant::now();
        let c = self.fitted(candidates);
        let longest = self
            .topo
            .vertices
            .iter()
            .map(|&v| dx[v as usize].norm())
            .fold(0.0, f64::max);
        let pieces = (longest / self.piece_m).ceil().clamp(1.0, 10_000.0) as usize;
        let share = 1.0 / pieces as f64;
        let seg: Vec<Vector3<f64>> = dx.iter().map(|d| d * share).collect();
        let mut xk = x.to_vec();
        let mut bound = f64::INFINITY;
        for k in 0..pieces {
            if k > 0 {
                for (p, d) in xk.iter_mut().zip(&seg) {
                    *p += d;
                }
            }
            self.ensure(c, &xk, Some(&seg));
            let toi = self.piece_impact(c, &xk, &seg);
            if toi.is_finite() {
                bound = (k as f64 + toi) * share;
                break;
            }
        }
        self.work.add_time(start);
        bound
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::PairCurvature;
    use crate::physics::tests::check_gradient;
    use crate::proximity::Pair;

    /// Two 3 × 3 patches, the upper one `gap` above the lower.
    fn stacked(gap: f64) -> (Vec<Vector3<f64>>, Vec<[u32; 3]>) {
        let mut x = Vec::new();
        for layer in 0..2 {
            for j in 0..3 {
                for i in 0..3 {
                    let wob = 1e-4 * ((i * 7 + j * 3 + layer) as f64).sin();
                    x.push(Vector3::new(
                        i as f64 * 0.01 + wob,
                        j as f64 * 0.01,
                        layer as f64 * gap + wob,
                    ));
                }
            }
        }
        // Two triangles per cell of each 3 × 3 layer.
        let mut tris = Vec::new();
        for layer in 0..2u32 {
            for j in 0..2u32 {
                for i in 0..2u32 {
                    let p = layer * 9 + j * 3 + i;
                    tris.push([p, p + 1, p + 4]);
                    tris.push([p, p + 4, p + 3]);
                }
            }
        }
        (x, tris)
    }

    /// Two flat 3 × 3 layers `gap` apart.
    fn pressed(gap: f64) -> (Vec<Vector3<f64>>, Vec<[u32; 3]>) {
        let (mut x, tris) = stacked(gap);
        x.iter_mut()
            .enumerate()
            .for_each(|(k, p)| p.z = if k < 9 { 0.0 } else { gap });
        (x, tris)
    }

    /// How far `term`'s Newton Hessian (or its projected one) at `x` misses the change of its
    /// gradient along a sliding, closing move of the upper layer (central differences): the
    /// relative norm of the difference.
    fn hessian_miss(term: &SelfContact, x: &[Vector3<f64>], mode: HessianMode) -> f64 {
        let v: Vec<Vector3<f64>> = (0..x.len())
            .map(|k| match k >= 9 {
                true => Vector3::new(1.0, 0.3 * (k as f64).sin(), -0.2),
                false => Vector3::zeros(),
            })
            .collect();
        let grad = |s: f64| {
            let y: Vec<Vector3<f64>> = x.iter().zip(&v).map(|(p, d)| p + d * s).collect();
            let mut g = vec![Vector3::zeros(); y.len()];
            term.add_gradient(&y, &mut g);
            g
        };
        let eps = 1e-9;
        let (gp, gm) = (grad(eps), grad(-eps));
        let fd: Vec<Vector3<f64>> = gp
            .iter()
            .zip(&gm)
            .map(|(a, b)| (a - b) / (2.0 * eps))
            .collect();
        let mut h = HessianBlocks::default();
        term.add_hessian(x, &mut h, mode);
        let mut hv = vec![Vector3::zeros(); x.len()];
        h.mul_add(&v, &mut hv);
        let num: f64 = hv
            .iter()
            .zip(&fd)
            .map(|(a, b)| (a - b).norm_squared())
            .sum();
        let den: f64 = fd.iter().map(|b| b.norm_squared()).sum();
        (num / den).sqrt()
    }

    /// A pair pressed within 10 % of the band beyond the thickness doubles κ (incremental potential
    /// contact's adaptive κ), one held at 20 % does not, and κ stops growing at its limit.
    #[test]
    fn a_pressed_pair_stiffens_the_barrier_up_to_its_limit() {
        // Two flat layers `gap` apart (the lower at z = 0).
        let flat = |gap: f64| {
            let (mut x, tris) = stacked(gap);
            x.iter_mut()
                .enumerate()
                .for_each(|(k, p)| p.z = if k < 9 { 0.0 } else { gap });
            (x, tris)
        };
        let (xi, band) = (5e-4, 1e-3);
        let (pressed, tris) = flat(xi + 0.05 * band);
        let (held, _) = flat(xi + 0.2 * band);
        let mut term = SelfContact::new(tris, &held, xi, band, 1e-3);
        let k0 = term.kappa_J;
        let (held, pressed) = (
            term.contact_set_here(&held),
            term.contact_set_here(&pressed),
        );
        assert!(!term.stiffen_barrier(&held));
        assert_eq!(term.kappa_J, k0);
        assert!(term.stiffen_barrier(&pressed));
        assert_eq!(term.kappa_J, 2.0 * k0);
        while term.stiffen_barrier(&pressed) {}
        assert!(term.kappa_J <= KAPPA_GROWTH_LIMIT * k0);
        assert!(2.0 * term.kappa_J > KAPPA_GROWTH_LIMIT * k0);
    }

    /// Layers pressed to 5 % of the band: in a time step Newton's Hessian (unprojected) is the exact one for the
    /// pinned pairs and predicts the gradient's change along a sliding, closing move nearly as
    /// finite differences do; projected, the distance's curvature is left out and it misses.
    #[test]
    fn a_pinned_pair_gets_its_exact_curvature_unless_projected() {
        let (xi, band) = (5e-4, 1e-3);
        let (x, tris) = pressed(xi + 0.05 * band);
        let term = SelfContact::new(tris, &x, xi, band, 1e-3);
        // An equilibrium solve's Newton Hessian: the normal-only curvature, as projected.
        let (equilibrium, projected) = (
            hessian_miss(&term, &x, HessianMode::NEWTON),
            hessian_miss(&term, &x, HessianMode::Projected),
        );
        assert!((equilibrium - projected).abs() <= 1e-12 * projected);
        let time_step = HessianMode::Newton(PairCurvature::Pinned);
        let (exact, projected) = (
            hessian_miss(&term, &x, time_step),
            hessian_miss(&term, &x, HessianMode::Projected),
        );
        // What remains (0.4 %) is no error of the blocks (analytic, each its pair's central
        // difference to 1e-6): the layers' grids are aligned, so closest points sit on region
        // borders, where the distance's curvature jumps.
        assert!(exact < 0.01, "exact {exact:e}, projected {projected:e}");
        assert!(
            projected > 10.0 * exact,
            "exact {exact:e}, projected {projected:e}"
        );
    }

    #[test]
    fn a_long_equilibrium_solve_gives_every_active_pair_its_exact_curvature() {
        // Layers half the band beyond the thickness: in range, not pinned, so a time step's
        // Hessian keeps their normal-only curvature; a solve that has run long does not.
        let (xi, band) = (5e-4, 1e-3);
        let (x, tris) = pressed(xi + 0.5 * band);
        let term = SelfContact::new(tris, &x, xi, band, 1e-3);
        assert!(term.energy(&x) > 0.0);
        let usual = hessian_miss(&term, &x, HessianMode::NEWTON);
        let time_step = HessianMode::Newton(PairCurvature::Pinned);
        assert_eq!(hessian_miss(&term, &x, time_step), usual);
        let all = hessian_miss(&term, &x, HessianMode::Newton(PairCurvature::All));
        assert!(
            all < 0.01 && usual > 10.0 * all,
            "all {all:e}, usual {usual:e}"
        );
        let projected = hessian_miss(&term, &x, HessianMode::Projected);
        assert_eq!(projected, usual, "projected as before");
        // The exact Hessian of derivatives: every pair's whole curvature, as a long solve's.
        let exact = hessian_miss(&term, &x, HessianMode::Exact);
        assert!(
            (exact - all).abs() <= 1e-12 * all,
            "exact {exact:e}, all {all:e}"
        );
    }

    /// The energy and gradient of `term` at `y` on the contact set measured over `set`.
    fn measured(
        term: &SelfContact,
        y: &[Vector3<f64>],
        set: &mut CandidateSet,
    ) -> (f64, Vec<Vector3<f64>>) {
        let at = term.contact_set(y, set);
        let mut g = vec![Vector3::zeros(); y.len()];
        term.add_gradient_of(&at, y, &mut g);
        (term.energy_of(&at, y), g)
    }

    /// The active pairs measured over a candidate set carried from state to state are those a
    /// fresh term measures: after other states in between, or once the term's activation distance
    /// moved (the set is then rebuilt for it).
    #[test]
    fn active_pairs_measured_at_a_state_are_those_a_fresh_term_measures() {
        let (x, tris) = stacked(1.2e-3);
        let (y, _) = stacked(8e-4);
        let fresh = |c: [f64; 3], z: &[Vector3<f64>]| {
            let mut t = SelfContact::new(tris.clone(), &x, 5e-4, 1e-3, 1e-3);
            t.set_coefficients(&c);
            let mut g = vec![Vector3::zeros(); z.len()];
            t.add_gradient(z, &mut g);
            (t.energy(z), g)
        };
        let mut term = SelfContact::new(tris.clone(), &x, 5e-4, 1e-3, 1e-3);
        let c0 = [term.thickness_m, term.band_m, term.kappa_J];
        let mut set = CandidateSet::default();
        for z in [&x, &y, &x, &x, &y] {
            assert_eq!(measured(&term, z, &mut set), fresh(c0, z));
        }
        assert_eq!(
            set.broad_phases(),
            1,
            "the moves stayed in the list's region"
        );
        // A band twice as wide: more pairs active at x, the set rebuilt for the new distance.
        let c1 = [c0[0], 2.0 * c0[1], c0[2]];
        term.set_coefficients(&c1);
        assert_eq!(measured(&term, &x, &mut set), fresh(c1, &x));
        assert_eq!(set.activation_m, term.activation_m());
        assert!(measured(&term, &x, &mut set).0 > fresh(c0, &x).0);
    }

    #[test]
    fn gradient_matches_finite_differences_and_energy_grows_as_layers_close() {
        let (x, tris) = stacked(1.2e-3);
        let term = SelfContact::new(tris.clone(), &x, 5e-4, 1e-3, 1e-3);
        assert!(term.energy(&x) > 0.0);
        check_gradient(&term, &x);
        let (near, _) = stacked(8e-4);
        assert!(term.energy(&near) > term.energy(&x));
        let (touching, _) = stacked(4e-4);
        assert!(term.energy(&touching).is_infinite());
        let (far, _) = stacked(5e-3);
        assert_eq!(term.energy(&far), 0.0);
    }

    /// Twins (a seam's sides being sewn) do not repel where they are joined: the upper layer's
    /// middle vertex made a twin of the lower's leaves out exactly the pairs joined through it,
    /// and the step bound lets the twins meet while the rest of the layers still cannot.
    #[test]
    fn pairs_joined_through_twins_are_no_contacts() {
        let (x, tris) = stacked(1.2e-3);
        let plain = SelfContact::new(tris.clone(), &x, 5e-4, 1e-3, 1e-3);
        let mut twins: Vec<u32> = (0..18).collect();
        twins[13] = 4;
        let twinned = SelfContact::new(tris, &x, 5e-4, 1e-3, 1e-3).with_twins(twins);
        let (all, kept) = (plain.contact_set_here(&x), twinned.contact_set_here(&x));
        let joined = |p: &ContactPair| {
            let v = p.vertices;
            let (a, b) = if p.is_point_triangle() {
                (&v[..1], &v[1..])
            } else {
                (&v[..2], &v[2..])
            };
            (a.contains(&4) && b.contains(&13)) || (a.contains(&13) && b.contains(&4))
        };
        let expected = all.pairs.iter().filter(|p| !joined(p)).count();
        assert!(expected < all.len() && kept.len() == expected);
        // Moving the upper middle vertex onto the lower one: no step bound from the twins'
        // own pairs, but the upper layer as a whole cannot pass the lower.
        let mut dx = vec![Vector3::zeros(); x.len()];
        dx[13] = x[4] - x[13];
        assert!(twinned.max_step(&x, &dx) >= 1.0);
        assert!(plain.max_step(&x, &dx) < 1.0);
        let down: Vec<Vector3<f64>> = (0..18)
            .map(|v| Vector3::new(0.0, 0.0, if v >= 9 { -2.4e-3 } else { 0.0 }))
            .collect();
        assert!(twinned.max_step(&x, &down) < 1.0);
    }

    /// The pairs left unmeasured because their vertices have not moved far enough to reach the
    /// activation distance are exactly those out of range: moved within the region its list
    /// covers, a term keeps the energy and gradient of a term whose list is built afresh.
    /// The upper layer of [`stacked`] brought down 0.6–0.9 mm, tilted (within the 1 mm margin:
    /// no new broad phase), into the 1.5 mm activation distance at one side.
    fn lowered(x: &[Vector3<f64>]) -> Vec<Vector3<f64>> {
        x.iter()
            .enumerate()
            .map(|(p, v)| match p >= 9 {
                true => v + Vector3::new(0.0, 0.0, -6e-4 - 1.5e-2 * v.x),
                false => *v,
            })
            .collect()
    }

    /// [`lowered`], its upper layer `extra` (m) further down.
    fn sunk(x: &[Vector3<f64>], extra: f64) -> Vec<Vector3<f64>> {
        let y = lowered(x).into_iter().enumerate();
        y.map(|(p, v)| v - Vector3::z() * if p >= 9 { extra } else { 0.0 })
            .collect()
    }

    #[test]
    fn pruned_pairs_are_the_ones_out_of_range() {
        let (x, tris) = stacked(2.2e-3);
        let kept = SelfContact::new(tris.clone(), &x, 5e-4, 1e-3, 1e-3);
        let mut set = CandidateSet::default();
        assert_eq!(measured(&kept, &x, &mut set).0, 0.0);
        let y = lowered(&x);
        let fresh = SelfContact::new(tris, &y, 5e-4, 1e-3, 1e-3);
        assert_measures_alike((&kept, &mut set), &fresh, &y);
        assert_eq!(set.broad_phases(), 1);
    }

    /// `a` over the candidate set `set` (built at another state) measures at `y` (in range) the
    /// energy and gradient of `fresh` at `y` (its own set built there), bit for bit.
    fn assert_measures_alike(
        (a, set): (&SelfContact, &mut CandidateSet),
        fresh: &SelfContact,
        y: &[Vector3<f64>],
    ) {
        assert!(fresh.energy(y) > 0.0);
        let mut g_fresh = vec![Vector3::zeros(); y.len()];
        fresh.add_gradient(y, &mut g_fresh);
        assert_eq!(measured(a, y, set), (fresh.energy(y), g_fresh));
    }

    #[test]
    fn a_seeded_term_measures_what_a_fresh_one_does_without_a_broad_phase() {
        let (x, tris) = stacked(2.2e-3);
        let solved = SelfContact::new(tris.clone(), &x, 5e-4, 1e-3, 1e-3);
        let mut set = CandidateSet::default();
        assert_eq!(measured(&solved, &x, &mut set).0, 0.0);
        assert_eq!(set.broad_phases(), 1);
        // A new model's term (another weight, so another κ) over the solved one's set, at a state
        // moved within the set's margin into range.
        let y = lowered(&x);
        let seeded = SelfContact::new(tris.clone(), &x, 5e-4, 1e-3, 2e-3);
        let fresh = SelfContact::new(tris.clone(), &y, 5e-4, 1e-3, 2e-3);
        let mut handed = set.clone();
        assert_measures_alike((&seeded, &mut handed), &fresh, &y);
        assert_eq!(handed.broad_phases(), 1, "the handed set covered the move");
        // A set built for another activation distance is rebuilt for the term's.
        let thicker = SelfContact::new(tris, &x, 6e-4, 1e-3, 1e-3);
        let mut other = set.clone();
        thicker.contact_set(&x, &mut other);
        assert_eq!(other.activation_m, thicker.activation_m());
        assert_eq!(other.broad_phases(), 1, "counted from its rebuild");
    }

    #[test]
    fn a_set_covering_a_spread_serves_a_move_beyond_the_margin_without_a_broad_phase() {
        // The upper layer 5 mm up, far out of range, then brought down 4.4–4.7 mm into range: a
        // move beyond the 1 mm margin, which a set covering the node alone would not serve.
        let (x, tris) = stacked(6e-3);
        let node = SelfContact::new(tris.clone(), &x, 5e-4, 1e-3, 1e-3);
        let y = sunk(&x, 3.8e-3);
        let spread: Vec<f64> = (0..18).map(|p| if p >= 9 { 5e-3 } else { 0.0 }).collect();
        let mut set = node.candidates_covering(&x, &spread);
        let seeded = SelfContact::new(tris.clone(), &x, 5e-4, 1e-3, 1e-3);
        let fresh = SelfContact::new(tris.clone(), &y, 5e-4, 1e-3, 1e-3);
        assert_measures_alike((&seeded, &mut set), &fresh, &y);
        assert_eq!(set.broad_phases(), 0);
        // Without the spread the same move needs a broad phase of its own.
        let mut narrow = node.candidates_covering(&x, &[0.0; 18]);
        assert_measures_alike((&seeded, &mut narrow), &fresh, &y);
        assert_eq!(narrow.broad_phases(), 1);
    }

    #[test]
    fn a_long_steps_list_holds_the_pairs_it_brings_together_and_serves_its_line_search() {
        // Both layers fall 3 cm (thirty margins), the upper one 5.1–5.4 mm further, into range.
        let (x, tris) = stacked(6e-3);
        let term = SelfContact::new(tris.clone(), &x, 5e-4, 1e-3, 1e-3);
        let dx: Vec<Vector3<f64>> = sunk(&x, 4.5e-3)
            .iter()
            .zip(&x)
            .map(|(l, v)| l - v - Vector3::z() * 3e-2)
            .collect();
        let mut set = CandidateSet::default();
        let bound = term.max_step_with(&x, &dx, &mut set);
        // Its bound is additive CCD's over every pair of the mesh (the list misses no pair that
        // stops the step).
        let topo = term.topology();
        let all = (0..18u32)
            .flat_map(|v| (0..8u32).map(move |t| Pair::PointTriangle(v, t)))
            .chain(
                (0..topo.edges.len() as u32)
                    .flat_map(|a| (0..a).map(move |b| Pair::EdgeEdge(b, a))),
            )
            .filter(|pair| {
                let idx = pair.vertices(topo);
                let split = if pair.is_point_triangle() { 1 } else { 2 };
                !idx[..split].iter().any(|v| idx[split..].contains(v))
            });
        let want = all
            .map(|pair| {
                let idx = pair.vertices(topo);
                let (y, d) = (idx.map(|k| x[k]), idx.map(|k| dx[k]));
                additive_ccd(pair.is_point_triangle(), &y, &d, 5e-4, 0.1, 1.0)
            })
            .fold(f64::INFINITY, f64::min);
        assert!(bound < 1.0 && bound > 0.5, "{bound}");
        assert_eq!(bound, want);
        {
            // Only pairs across the layers: within a layer nothing moves relative to anything.
            let c = &set.list;
            assert!(c.sweep.is_some() && !c.pairs.is_empty());
            let across = |p: &Pair| {
                let idx = p.vertices(topo);
                idx.iter().any(|&v| v < 9) && idx.iter().any(|&v| v >= 9)
            };
            assert!(c.pairs.iter().all(across), "{}", c.pairs.len());
        }
        // The line search's states (and a tenth of the step behind) measure what fresh terms do,
        // with no broad phase beyond the step's.
        let at =
            |a: f64| -> Vec<Vector3<f64>> { x.iter().zip(&dx).map(|(v, d)| v + d * a).collect() };
        for a in [-0.1, 0.5, 0.9 * bound] {
            let y = at(a);
            let fresh = SelfContact::new(tris.clone(), &y, 5e-4, 1e-3, 1e-3);
            assert_eq!(measured(&term, &y, &mut set).0, fresh.energy(&y));
        }
        assert_measures_alike(
            (&term, &mut set),
            &SelfContact::new(tris, &at(bound), 5e-4, 1e-3, 1e-3),
            &at(bound),
        );
        assert_eq!(set.broad_phases(), 1);
    }

    /// Two flat 3 × 3 layers `gap` apart, the upper one shifted by `shift` along x and turned by
    /// `phi` about the vertical through the middle of its edge (10, 13): its y-edges pass their
    /// twins below at that offset.
    fn turned(gap: f64, phi: f64, shift: f64) -> (Vec<Vector3<f64>>, Vec<[u32; 3]>) {
        let (mut x, tris) = pressed(gap);
        for (k, p) in x.iter_mut().enumerate() {
            let (i, j) = ((k % 9 % 3) as f64, (k % 9 / 3) as f64);
            *p = Vector3::new(i * 0.01, j * 0.01, p.z);
        }
        let c = turn_centre(shift);
        for p in x.iter_mut().skip(9) {
            let r = *p + Vector3::new(shift, 0.0, 0.0) - c;
            let (s, co) = phi.sin_cos();
            *p = c + Vector3::new(r.x * co - r.y * s, r.x * s + r.y * co, r.z);
        }
        (x, tris)
    }

    /// The point [`turned`]'s upper layer turns about.
    fn turn_centre(shift: f64) -> Vector3<f64> {
        Vector3::new(0.01 + shift, 0.005, 0.0)
    }

    /// The sideways offset of [`turned`]'s upper layer in the tests below, m: a third of the gap, so
    /// that edges beside their twins are in range.
    const SHIFT: f64 = 3e-4;

    /// The rate of change of the energy as the upper layer of [`turned`] turns, from the gradient.
    fn turning_rate(term: &SelfContact, x: &[Vector3<f64>]) -> f64 {
        let mut g = vec![Vector3::zeros(); x.len()];
        term.add_gradient(x, &mut g);
        let c = turn_centre(SHIFT);
        (9..x.len())
            .map(|k| g[k].dot(&Vector3::z().cross(&(x[k] - c))))
            .sum()
    }

    /// The distance of two segments falls as |φ| when one turns through parallel beside the other,
    /// so the barrier alone has a V-shaped valley there (its slope jumping by as much across a turn
    /// of ±10⁻⁵ rad as across ±10⁻³); with the pairs within ~1.8° of parallel mollified the slope
    /// is continuous (its jump shrinks with the turn).
    #[test]
    fn layers_turning_through_parallel_have_no_kink_in_their_energy() {
        let (xi, band) = (5e-4, 1e-3);
        let (x0, tris) = turned(xi + 0.3 * band, 0.0, SHIFT);
        let term = SelfContact::new(tris, &x0, xi, band, 1e-3);
        let jump = |h: f64| {
            let rate = |phi: f64| turning_rate(&term, &turned(xi + 0.3 * band, phi, SHIFT).0);
            (rate(h) - rate(-h)).abs()
        };
        let (small, large) = (jump(1e-5), jump(1e-3));
        assert!(large > 0.0);
        assert!(
            small < 1e-2 * large,
            "jump {small:e} at 1e-7 rad, {large:e} at 1e-3"
        );
        // Within the thickness the energy is infinite, parallel edges or not (never 0 · ∞).
        let (inside, _) = turned(0.8 * xi, 0.0, SHIFT);
        assert_eq!(term.energy(&inside), f64::INFINITY);
        // Mollified pairs are there and active.
        let (y, _) = turned(xi + 0.3 * band, 0.01, SHIFT);
        let mollified = (term.contact_set_here(&y).pairs.iter())
            .filter(|p| {
                let corners = p.vertices.map(|k| y[k]);
                term.mollifier(p.is_point_triangle(), &corners).is_some()
            })
            .count();
        assert!(mollified >= 4, "{mollified}");
    }

    /// With mollified pairs active, the gradient is the energy's (central differences, relative to
    /// the largest component) and the exact Hessian is the gradient's.
    #[test]
    fn mollified_pairs_keep_gradient_and_exact_hessian_consistent() {
        let (xi, band) = (5e-4, 1e-3);
        let (x, tris) = turned(xi + 0.3 * band, 0.01, SHIFT);
        let term = SelfContact::new(tris, &x, xi, band, 1e-3);
        crate::physics::tests::check_gradient_scaled(&term, &x, 9..x.len(), (1e-9, 1e-5));
        let miss = hessian_miss(&term, &x, HessianMode::Newton(PairCurvature::All));
        assert!(miss < 1e-6, "{miss:e}");
        let mut h = HessianBlocks::default();
        term.add_hessian(&x, &mut h, HessianMode::Projected);
        // The projected Hessian is positive semi-definite.
        let n = x.len() * 3;
        let mut dense = nalgebra::DMatrix::<f64>::zeros(n, n);
        for (&(a, b), k) in h.all() {
            let (a, b) = (a as usize, b as usize);
            for i in 0..3 {
                for j in 0..3 {
                    dense[(3 * a + i, 3 * b + j)] += k[(i, j)];
                    if a != b {
                        dense[(3 * b + j, 3 * a + i)] += k[(i, j)];
                    }
                }
            }
        }
        let eig = dense.symmetric_eigen().eigenvalues;
        let (lowest, top) = (eig.min(), eig.max());
        assert!(lowest > -1e-9 * top, "{lowest:e} of {top:e}");
    }

    /// With mollified pairs active, the derivatives in the coefficients (ξ, d̂, κ) are the central
    /// differences of the energy and gradient with the coefficients moved.
    #[test]
    fn mollified_pairs_keep_their_coefficient_derivatives() {
        let (xi, band) = (5e-4, 1e-3);
        let (x, tris) = turned(xi + 0.3 * band, 0.01, SHIFT);
        let term = SelfContact::new(tris, &x, xi, band, 1e-3);
        let built = term.coefficients();
        // As built, and with κ grown 4× where layers pressed: the coefficient is κ₀ (as built),
        // the growth held as it moves, so ∂/∂κ₀ carries the growth.
        for growth in [1.0, 4.0] {
            let mut term = SelfContact::new(term.topo.triangles.clone(), &x, xi, band, 1e-3);
            term.kappa_J *= growth;
            assert_eq!(term.coefficients(), built);
            assert_eq!(term.kappa_growth(), growth);
            check_coefficient_derivatives(&mut term, &x);
        }
    }

    /// ∂g/∂c and ∂E/∂c of `term` at `x` against central differences through `set_coefficients`.
    fn check_coefficient_derivatives(term: &mut SelfContact, x: &[Vector3<f64>]) {
        let c = term.coefficients();
        let size = |v: &[Vector3<f64>]| v.iter().map(|a| a.norm_squared()).sum::<f64>().sqrt();
        for dc in [
            [0.1 * c[0], 0.0, 0.0],
            [0.0, 0.1 * c[1], 0.0],
            [0.0, 0.0, 0.1 * c[2]],
            [0.05 * c[0], -0.1 * c[1], 0.2 * c[2]],
        ] {
            let mut an = vec![Vector3::zeros(); x.len()];
            assert!(term.add_coefficient_gradient(x, &dc, &mut an));
            let de = term.coefficient_energy(x, &dc).expect("∂E/∂c");
            let eps = 1e-6;
            let mut at = |s: f64| {
                let moved: Vec<f64> = c.iter().zip(&dc).map(|(a, d)| a + d * s).collect();
                term.set_coefficients(&moved);
                let mut g = vec![Vector3::zeros(); x.len()];
                term.add_gradient(x, &mut g);
                (g, term.energy(x))
            };
            let ((gp, ep), (gm, em)) = (at(eps), at(-eps));
            term.set_coefficients(&c);
            let fd: Vec<Vector3<f64>> = gp
                .iter()
                .zip(&gm)
                .map(|(a, b)| (a - b) / (2.0 * eps))
                .collect();
            let diff: Vec<Vector3<f64>> = fd.iter().zip(&an).map(|(a, b)| a - b).collect();
            assert!(
                size(&diff) < 1e-6 * size(&fd),
                "{dc:?}: ∂g/∂c off by {:e}",
                size(&diff) / size(&fd)
            );
            let fde = (ep - em) / (2.0 * eps);
            assert!(
                (fde - de).abs() < 1e-6 * fde.abs(),
                "{dc:?}: ∂E/∂c {de:e} vs {fde:e}"
            );
        }
    }

    #[test]
    fn a_step_through_the_other_layer_is_cut_before_the_thickness() {
        let (x, tris) = stacked(3e-3);
        let term = SelfContact::new(tris, &x, 5e-4, 1e-3, 1e-3);
        let dx: Vec<Vector3<f64>> = (0..18)
            .map(|p| Vector3::new(0.0, 0.0, if p >= 9 { -6e-3 } else { 0.0 }))
            .collect();
        let a = term.max_step(&x, &dx);
        assert!(a < 0.5 && a > 0.3, "{a}");
        let y: Vec<Vector3<f64>> = x.iter().zip(&dx).map(|(p, d)| p + d * a).collect();
        assert!(term.state(&y).min_distance_m > 5e-4);
        assert!(term.energy(&y).is_finite());
    }

    /// The pairs the step bound passes over without measuring them are ones additive CCD finds no
    /// impact for: over steps of every size and direction, from a state moved off the list's
    /// anchor, the bound equals additive CCD run on every candidate pair.
    #[test]
    fn the_step_bound_passes_over_only_pairs_without_an_impact() {
        let (x, tris) = stacked(2.2e-3);
        let term = SelfContact::new(tris, &x, 5e-4, 1e-3, 1e-3);
        let mut set = CandidateSet::default();
        assert_eq!(measured(&term, &x, &mut set).0, 0.0);
        let y = lowered(&x);
        let (mut passed, mut cut) = (0, 0);
        for k in 0..200 {
            let f = |a: usize| ((k * 13 + a * 7) % 17) as f64 / 8.0 - 1.0;
            let size = 1e-4 * 1.05f64.powi(k as i32 % 60);
            let dx: Vec<Vector3<f64>> = (0..18)
                .map(|p| Vector3::new(f(p), f(p + 5), f(p + 11) - 0.5) * size)
                .collect();
            let bound = term.max_step_with(&y, &dx, &mut set);
            let every = (set.list)
                .pairs
                .iter()
                .map(|&pair| {
                    let idx = pair.vertices(&term.topo);
                    additive_ccd(
                        pair.is_point_triangle(),
                        &idx.map(|q| y[q]),
                        &idx.map(|q| dx[q]),
                        term.thickness_m,
                        0.1,
                        1.0,
                    )
                })
                .fold(f64::INFINITY, f64::min);
            if dx.iter().map(|d| d.norm()).fold(0.0, f64::max) <= term.piece_m {
                assert_eq!(bound, every, "step {k} of {size:.1e} m");
            }
            match bound.is_finite() {
                true => cut += 1,
                false => passed += 1,
            }
        }
        assert!(passed > 10 && cut > 10, "{passed} free steps, {cut} cut");
    }
    /// The contact set against a brute-force one: along a random walk of the upper layer (steps
    /// cut to 90 % of the term's own step bound, as a line search takes them), the pairs the term
    /// measures active at each state, with their distances, are exactly those of a check of every
    /// vertex–triangle and edge–edge pair, and no pair ever comes within the thickness; the barrier
    /// evaluated on that contact set gives the energy and gradient a fresh term measures there.
    #[test]
    fn the_contact_set_along_a_random_walk_is_the_brute_force_one() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let (mut x, tris) = stacked(4e-3);
        let term = SelfContact::new(tris.clone(), &x, 5e-4, 1e-3, 1e-3);
        // The same walk's term with the other broad phase: another candidate list, the same set.
        let tree = SelfContact::new(tris.clone(), &x, 5e-4, 1e-3, 1e-3)
            .with_broad_phase(Box::new(crate::proximity::Hierarchy));
        // Each carries its candidate set along the walk, as a solve does.
        let (mut on_hash, mut on_tree) = (CandidateSet::default(), CandidateSet::default());
        let mut seen_active = 0;
        for step in 0..60 {
            let drift = Vector3::new(
                rng.random_range(-2e-3..2e-3),
                rng.random_range(-2e-3..2e-3),
                rng.random_range(-1.5e-3..1e-3),
            );
            let dx: Vec<Vector3<f64>> = (0..x.len())
                .map(|k| match k >= 9 {
                    true => drift + Vector3::from_fn(|_, _| rng.random_range(-5e-4..5e-4)),
                    false => Vector3::from_fn(|_, _| rng.random_range(-2e-4..2e-4)),
                })
                .collect();
            let bound = term.max_step_with(&x, &dx, &mut on_hash);
            let tree_bound = tree.max_step_with(&x, &dx, &mut on_tree);
            assert_eq!(tree_bound, bound, "step {step}");
            assert_eq!(
                term.max_step(&x, &dx),
                bound,
                "step {step}: a set built here"
            );
            let alpha = (0.9 * bound).min(1.0);
            x.iter_mut().zip(&dx).for_each(|(p, d)| *p += d * alpha);
            let set = term.contact_set(&x, &mut on_hash);
            assert_eq!(tree.contact_set(&x, &mut on_tree), set, "step {step}");
            let mut active: Vec<([usize; 4], f64)> = set
                .pairs
                .iter()
                .map(|p| (p.vertices, p.distance_m))
                .collect();
            active.sort_by_key(|a| a.0);
            // The barrier on the set is the energy and gradient a fresh term measures at x.
            let fresh = SelfContact::new(tris.clone(), &x, 5e-4, 1e-3, 1e-3);
            let (e, e_fresh) = (term.energy_of(&set, &x), fresh.energy(&x));
            assert!(
                (e - e_fresh).abs() <= 1e-12 * e.abs(),
                "step {step}: {e} {e_fresh}"
            );
            let (mut g, mut g_fresh) = (
                vec![Vector3::zeros(); x.len()],
                vec![Vector3::zeros(); x.len()],
            );
            term.add_gradient_of(&set, &x, &mut g);
            fresh.add_gradient(&x, &mut g_fresh);
            let scale = g_fresh.iter().map(|v| v.norm()).fold(0.0, f64::max);
            let miss = g
                .iter()
                .zip(&g_fresh)
                .map(|(a, b)| (a - b).norm())
                .fold(0.0, f64::max);
            assert!(miss <= 1e-12 * scale, "step {step}: {miss:e} of {scale:e}");
            let topo = term.topology();
            let mut brute: Vec<([usize; 4], f64)> =
                crate::proximity::brute_force_pairs(topo, &x, term.activation_m())
                    .into_iter()
                    .map(|(p, d)| (p.vertices(topo), d))
                    .collect();
            brute.sort_by_key(|a| a.0);
            assert_eq!(active, brute, "step {step}");
            let closest = crate::proximity::brute_force_pairs(topo, &x, f64::INFINITY);
            let least = closest.iter().map(|p| p.1).fold(f64::INFINITY, f64::min);
            assert!(least > term.thickness_m, "step {step}: {least}");
            seen_active += usize::from(!active.is_empty());
        }
        assert!(
            seen_active > 20,
            "the walk pressed the layers ({seen_active} states)"
        );
    }
}
