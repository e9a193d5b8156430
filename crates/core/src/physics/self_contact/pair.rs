//! One self-contact pair's energy derivatives: its gradient with the edge–edge mollifier and its
//! exact Hessian blocks (analytic: the distance's and the mollifier's own Hessians).

use super::SelfContact;
use crate::physics::HessianBlocks;
use crate::physics::barrier::barrier;
#[cfg(test)]
use crate::proximity::pair_distance;
use crate::proximity::{edge_edge_mollifier, edge_edge_mollifier_hessian, pair_distance_hessian};
use nalgebra::{Matrix3, Vector3};

impl SelfContact {
    /// The gradient of one pair's energy κ m b(d − ξ) with respect to its four vertices `y` (the
    /// oracle of the exact blocks' test; the term scatters [`pair_force`] itself).
    #[cfg(test)]
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

    /// The exact Hessian blocks of one pair at `y`, `[a][b]` for a ≥ b: of κ m b(d − ξ),
    /// κ[m b″∇d∇dᵀ + m b′∇²d + b′(∇m∇dᵀ + ∇d∇mᵀ) + b∇²m], with the distance's and the mollifier's
    /// Hessians analytic ([`pair_distance_hessian`], [`edge_edge_mollifier_hessian`]).
    pub(super) fn pair_exact_blocks(
        &self,
        pt: bool,
        y: &[Vector3<f64>; 4],
    ) -> [[Matrix3<f64>; 4]; 4] {
        let (d, gd, hd) = pair_distance_hessian(pt, y);
        let (b, db, ddb) = barrier(d - self.thickness_m, self.band_m);
        let mut h = gd * gd.transpose() * ddb + hd * db;
        let moll = (!pt)
            .then(|| edge_edge_mollifier_hessian(y, MOLLIFIER_SIN2))
            .flatten();
        if let Some((m, gm, hm)) = moll {
            h = h * m + (gm * gd.transpose() + gd * gm.transpose()) * db + hm * b;
        }
        h *= self.kappa_J;
        std::array::from_fn(|a| {
            std::array::from_fn(|c| match c <= a {
                true => h.fixed_view::<3, 3>(3 * a, 3 * c).into_owned(),
                false => Matrix3::zeros(),
            })
        })
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

#[cfg(test)]
mod tests {
    use super::*;

    type V3 = Vector3<f64>;

    /// The analytic blocks against central differences of the pair's gradient over its 12
    /// coordinates (step 10⁻⁴ of the gap beyond the thickness): point–triangle over the face and
    /// over an edge, edge–edge crossing and nearly parallel (mollified), all within the band.
    #[test]
    fn a_pairs_exact_blocks_are_the_central_differences_of_its_gradient() {
        let (xi, band) = (5e-4, 1e-3);
        let tri = vec![[0, 1, 2]];
        let x0 = [V3::zeros(), V3::x(), V3::y()];
        let term = SelfContact::new(tri, &x0, xi, band, 1e-3);
        let z = xi + 0.4 * band;
        let phi: f64 = 0.01;
        let cases = [
            (true, [V3::new(0.3, 0.2, z), V3::zeros(), V3::x(), V3::y()]),
            (
                true,
                [
                    V3::new(0.4, -z * 0.6, z * 0.8),
                    V3::zeros(),
                    V3::x(),
                    V3::y(),
                ],
            ),
            (
                false,
                [
                    V3::zeros(),
                    V3::x(),
                    V3::new(0.5, -0.5, z),
                    V3::new(0.4, 0.5, z),
                ],
            ),
            (
                false,
                [
                    V3::zeros(),
                    V3::x(),
                    V3::new(0.2, -0.5 * phi, z),
                    V3::new(0.2 + phi.cos(), 0.5 * phi + phi.sin(), z),
                ],
            ),
        ];
        for (k, (pt, y)) in cases.into_iter().enumerate() {
            assert_eq!(term.mollifier(pt, &y).is_some(), k == 3, "case {k}");
            let (d, _) = pair_distance(pt, &y);
            let step = 1e-4 * (d - xi);
            let blocks = term.pair_exact_blocks(pt, &y);
            let top = blocks
                .iter()
                .flatten()
                .map(|b| b.abs().max())
                .fold(0.0, f64::max);
            for a in 0..4 {
                for c in 0..3 {
                    let (mut yp, mut ym) = (y, y);
                    yp[a][c] += step;
                    ym[a][c] -= step;
                    let (gp, gm) = (term.pair_gradient(pt, &yp), term.pair_gradient(pt, &ym));
                    for b in 0..4 {
                        let fd = (gp[b] - gm[b]) / (2.0 * step);
                        let col: V3 = match b >= a {
                            true => blocks[b][a].column(c).into_owned(),
                            false => blocks[a][b].row(c).transpose(),
                        };
                        let err = (col - fd).abs().max() / top;
                        assert!(err < 1e-6, "case {k}, blocks [{b}][{a}] col {c}: {err:e}");
                    }
                }
            }
        }
    }
}
