//! The self-contact barrier evaluated on a contact set (ipc-toolkit's `BarrierPotential` over its
//! `Collisions`): energy, gradient and Hessian of the pairs a [`ContactSet`] holds, at the state it
//! was built for. The term's own energy and derivatives are these on the set it measures at x.

use super::pair::{pair_force, push_pair};
use super::{ContactSet, STIFFEN_GAP, SelfContact};
use crate::physics::barrier::barrier;
use crate::physics::{HessianBlocks, HessianMode, PairCurvature, Vecs};
use nalgebra::{Matrix3, Vector3};

impl SelfContact {
    /// Σ m·value(d − ξ) over the pairs of `set` at `x`, m each pair's mollifier (1 where the value
    /// is infinite, within the thickness: never 0 · ∞).
    pub(super) fn sum_pairs(&self, set: &ContactSet, x: &Vecs, value: impl Fn(f64) -> f64) -> f64 {
        let mut sum = 0.0;
        for p in &set.pairs {
            let v = value(p.distance_m - self.thickness_m);
            let m = match v.is_finite() {
                true => self
                    .mollifier(p.is_point_triangle(), &p.vertices.map(|k| x[k]))
                    .map_or(1.0, |m| m.0),
                false => 1.0,
            };
            sum += m * v;
        }
        sum
    }

    /// Adds every pair of `set`'s slope·m∇d + value·∇m at `x` to `g` ([`pair_force`]), (slope,
    /// value) = `along(d − ξ)`: the energy's gradient, or its derivative along a change of
    /// coefficients.
    pub(super) fn add_pair_forces(
        &self,
        set: &ContactSet,
        (x, g): (&Vecs, &mut Vecs),
        along: impl Fn(f64) -> (f64, f64),
    ) {
        for p in &set.pairs {
            let (idx, d) = (p.vertices, p.distance_m);
            let y = idx.map(|k| x[k]);
            let (slope, value) = along(d - self.thickness_m);
            let moll = self.mollifier(p.is_point_triangle(), &y);
            let f = pair_force(&y, d, &p.coefficients, moll.as_ref(), slope, value);
            for k in 0..4 {
                g[idx[k]] += f[k];
            }
        }
    }

    /// The barrier's curvature along the line between the closest points, κ b″ n nᵀ (positive
    /// semi-definite: the curvature of the distance itself is left out), for every pair in range
    /// but those [`HessianMode::Newton`]'s [`PairCurvature`] names, which get their exact
    /// curvature ([`Self::pair_exact_blocks`], the distance's own κ b′∇²d included). Only pairs in
    /// range push blocks: pushing every candidate's (zero) blocks to keep the pattern fixed made
    /// the factor denser and the drapes slower (skirt_wool 9.8 s against 5.9 s).
    ///
    /// [`PairCurvature::Pinned`], in implicit time steps: a pair pinned within [`STIFFEN_GAP`] of
    /// the band beyond the thickness, where b′ is large, and the curvature left out kept Newton
    /// from converging in the stress box's steps (a pair pinned at the thickness, every iteration
    /// cut by the collision bound; with the Krylov hand-over 46 → 48 of 50 settle). Not in
    /// equilibrium solves: there it slowed the touching drapes (l_panel_sphere 197 → 577
    /// iterations, ending a pair 1.5e-11 m from the thickness at 150) — but every active pair gets
    /// it ([`PairCurvature::All`]) once an equilibrium solve has run long without converging (the
    /// limp table at 61 × 61 converges with it). [`HessianMode::Exact`]: every active pair's
    /// κ b″ ∇d∇dᵀ + κ b′ ∇²d, ∇²d the curvature of the distance with the closest points moving.
    pub fn add_hessian_of(
        &self,
        set: &ContactSet,
        x: &Vecs,
        h: &mut HessianBlocks,
        mode: HessianMode,
    ) {
        let exact_within = match mode {
            HessianMode::Exact | HessianMode::Newton(PairCurvature::All) => f64::INFINITY,
            HessianMode::Projected | HessianMode::Newton(PairCurvature::NormalOnly) => {
                f64::NEG_INFINITY
            }
            HessianMode::Newton(PairCurvature::Pinned) => {
                self.thickness_m + STIFFEN_GAP * self.band_m
            }
        };
        for p in &set.pairs {
            let (idx, d, coef, pt) = (
                p.vertices,
                p.distance_m,
                p.coefficients,
                p.is_point_triangle(),
            );
            let y = idx.map(|v| x[v]);
            if d < exact_within {
                push_pair(h, &idx, &self.pair_exact_blocks(pt, &y));
                continue;
            }
            // A mollified pair's normal-only curvature is scaled by its mollifier (a stand-in, as
            // for the others: its exact Hessian, projected, slowed the 0.30 m limp table's
            // drape from 685 to 895 iterations).
            let m = self.mollifier(pt, &y).map_or(1.0, |m| m.0);
            let d2b = barrier(d - self.thickness_m, self.band_m).2;
            let r: Vector3<f64> = (0..4).map(|k| x[idx[k]] * coef[k]).sum();
            let n = r / d;
            let k: Matrix3<f64> = n * n.transpose() * (self.kappa_J * m * d2b);
            h.push_outer(&idx, &coef, &k);
        }
    }

    /// [`SelfContact::add_hessian_of`], then zero blocks for the candidate pairs near range that
    /// `set` names ([`ContactSet::hints`]: a factor's pattern that holds over the next steps),
    /// except for the exact Hessian of derivatives.
    pub fn add_hessian_with_hints(
        &self,
        set: &ContactSet,
        x: &Vecs,
        h: &mut HessianBlocks,
        mode: HessianMode,
    ) {
        self.add_hessian_of(set, x, h, mode);
        if mode != HessianMode::Exact {
            h.hints.extend_from_slice(&set.hints);
        }
    }

    /// The barrier's energy over the pairs of `set` at `x`, J: Σ κ m b(d − ξ).
    pub fn energy_of(&self, set: &ContactSet, x: &Vecs) -> f64 {
        self.sum_pairs(set, x, |gap| self.kappa_J * barrier(gap, self.band_m).0)
    }

    /// Adds the barrier's gradient over the pairs of `set` at `x` to `g`, N.
    pub fn add_gradient_of(&self, set: &ContactSet, x: &Vecs, g: &mut Vecs) {
        self.add_pair_forces(set, (x, g), |gap| {
            let (b, db, _) = barrier(gap, self.band_m);
            (self.kappa_J * db, self.kappa_J * b)
        });
    }
}
