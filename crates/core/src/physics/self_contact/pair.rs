//! One self-contact pair's energy derivatives: its gradient with the edge–edge mollifier and its
//! exact Hessian blocks (central differences of the gradient).

use super::SelfContact;
use crate::physics::HessianBlocks;
use crate::physics::barrier::barrier;
use crate::proximity::{edge_edge_mollifier, pair_distance};
use nalgebra::{Matrix3, Vector3};

impl SelfContact {
    /// The gradient of one pair's energy κ m b(d − ξ) with respect to its four vertices `y`.
    pub(super) fn pair_gradient(&self, pt: bool, y: &[Vector3<f64>; 4]) -> [Vector3<f64>; 4] {
        let (d, coef) = pair_distance(pt, y);
        let (b, db, _) = barrier(d - self.thickness_m, self.band_m);
        let moll = self.mollifier(pt, y);
        pair_force(
            y,
            d,
            &coef,
            moll.as_ref(),
            self.kappa_J * db,
            self.kappa_J * b,
        )
    }

    /// The mollifier of a nearly parallel edge–edge pair at `y` ([`edge_edge_mollifier`], within
    /// [`MOLLIFIER_SIN2`]): m and ∇m, None for point–triangle pairs and where m = 1. The pair's
    /// energy is κ m b(d − ξ).
    pub(super) fn mollifier(
        &self,
        pt: bool,
        y: &[Vector3<f64>; 4],
    ) -> Option<(f64, [Vector3<f64>; 4])> {
        (!pt)
            .then(|| edge_edge_mollifier(y, MOLLIFIER_SIN2))
            .flatten()
    }

    /// The exact Hessian blocks of one pair at `y` (distance `d`), `[a][b]` for a ≥ b: central
    /// differences of the analytic gradient over its 12 coordinates, step 10⁻⁴ of the gap beyond
    /// the thickness (relative error ~10⁻⁸ of the barrier's curvature), symmetrized.
    pub(super) fn pair_exact_blocks(
        &self,
        pt: bool,
        y: &[Vector3<f64>; 4],
        d: f64,
    ) -> [[Matrix3<f64>; 4]; 4] {
        let step = 1e-4 * (d - self.thickness_m).max(1e-12);
        let mut k = [[Matrix3::<f64>::zeros(); 4]; 4];
        for a in 0..4 {
            for c in 0..3 {
                let (mut yp, mut ym) = (*y, *y);
                yp[a][c] += step;
                ym[a][c] -= step;
                let (gp, gm) = (self.pair_gradient(pt, &yp), self.pair_gradient(pt, &ym));
                for b in 0..4 {
                    k[b][a].set_column(c, &((gp[b] - gm[b]) / (2.0 * step)));
                }
            }
        }
        let mut out = [[Matrix3::<f64>::zeros(); 4]; 4];
        for a in 0..4 {
            for b in 0..=a {
                out[a][b] = (k[a][b] + k[b][a].transpose()) * 0.5;
            }
        }
        out
    }
}

/// A pair's force-like vector slope·m ∇d + value·∇m at `y` (distance `d`, closest-point
/// coefficients `coef`, mollifier `moll`): its energy's gradient for (κ b′, κ b), its derivative
/// along a change of ξ, d̂ and κ for their derivatives.
pub(super) fn pair_force(
    y: &[Vector3<f64>; 4],
    d: f64,
    coef: &[f64; 4],
    moll: Option<&(f64, [Vector3<f64>; 4])>,
    slope: f64,
    value: f64,
) -> [Vector3<f64>; 4] {
    let r: Vector3<f64> = (0..4).map(|k| y[k] * coef[k]).sum();
    let n = r / d;
    let (m, gm) = moll.map_or((1.0, [Vector3::zeros(); 4]), |&(m, gm)| (m, gm));
    [0, 1, 2, 3].map(|k| n * (m * slope * coef[k]) + gm[k] * value)
}

/// The squared sine below which an edge–edge pair is mollified (ipc-toolkit's 10⁻³ of the
/// product of the squared edge lengths: pairs within ~1.8° of parallel).
pub(super) const MOLLIFIER_SIN2: f64 = 1e-3;

/// Pushes one pair's blocks `k[a][b]` (a ≥ b) of its vertices `idx`.
pub(super) fn push_pair(h: &mut HessianBlocks, idx: &[usize; 4], k: &[[Matrix3<f64>; 4]; 4]) {
    for a in 0..4 {
        for b in 0..=a {
            h.push(idx[a], idx[b], k[a][b]);
        }
    }
}
