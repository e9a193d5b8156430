//! An equilibrium's neutral modes (issue 78): the rigid motions of its free particles — slides
//! along x, y and z, turns about the axes through the held point — that leave the energy unchanged
//! to second order (φᵀHφ below 10⁻⁹ of the Hessian's mean diagonal, H the exact Hessian). A sheet
//! held at one point on a frictionless sphere may turn about the vertical through it: its
//! equilibria form a family, a sensitivity is the one orthogonal to the family, and two drapes
//! solved apart may differ along it.

use crate::physics::{HessianBlocks, Model, Vecs};
use nalgebra::Vector3;
use serde::Serialize;

/// φᵀHφ / (|φ|² × the mean diagonal) below which a rigid motion is neutral.
pub const NEUTRAL_REL: f64 = 1e-9;

/// A neutral mode as run.json and the Python result give it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NeutralMode {
    /// "slide" (a translation) or "turn" (a rotation).
    pub kind: &'static str,
    /// The slide's direction or the turn's axis (unit).
    pub axis: [f64; 3],
    /// A point of a turn's axis, m (the first held particle, else the free particles' centroid).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub through_m: Option<[f64; 3]>,
    /// The motion's curvature φᵀHφ relative to |φ|² and the Hessian's mean diagonal.
    pub curvature_rel: f64,
}

/// The neutral modes of `model` at its equilibrium `x` (none for a model with no free particle).
pub fn neutral_modes(model: &Model, x: &Vecs) -> Vec<NeutralMode> {
    let free: Vec<usize> = (0..x.len()).filter(|&p| !model.fixed[p]).collect();
    if free.is_empty() {
        return Vec::new();
    }
    let centre = (0..x.len()).find(|&p| model.fixed[p]).map_or_else(
        || free.iter().map(|&p| x[p]).sum::<Vector3<f64>>() / free.len() as f64,
        |p| x[p],
    );
    let mut h = HessianBlocks::default();
    model.hessian(x, &mut h, crate::physics::HessianMode::Exact);
    let diagonal = h.diagonal(x.len());
    let scale = free.iter().map(|&p| diagonal[p].trace()).sum::<f64>() / (3 * free.len()) as f64;
    let mut kept: Vec<Vec<Vector3<f64>>> = Vec::new();
    let mut modes = Vec::new();
    for k in 0..6 {
        let e = Vector3::ith(k % 3, 1.0);
        let motion = |p: usize| if k < 3 { e } else { e.cross(&(x[p] - centre)) };
        let mut phi: Vec<Vector3<f64>> = (0..x.len())
            .map(|p| {
                held_out(
                    model,
                    p,
                    if model.fixed[p] {
                        Vector3::zeros()
                    } else {
                        motion(p)
                    },
                )
            })
            .collect();
        // Orthogonal to the modes kept: a turn about z through the held point is not a slide.
        for m in &kept {
            let a = dot(&phi, m);
            phi.iter_mut().zip(m).for_each(|(q, r)| *q -= r * a);
        }
        let n = dot(&phi, &phi).sqrt();
        if n == 0.0 || scale <= 0.0 {
            continue;
        }
        phi.iter_mut().for_each(|q| *q /= n);
        let mut hphi = vec![Vector3::zeros(); x.len()];
        h.mul_add(&phi, &mut hphi);
        let curvature_rel = dot(&phi, &hphi) / scale;
        if curvature_rel < NEUTRAL_REL {
            modes.push(NeutralMode {
                kind: if k < 3 { "slide" } else { "turn" },
                axis: [e.x, e.y, e.z],
                through_m: (k >= 3).then_some([centre.x, centre.y, centre.z]),
                curvature_rel,
            });
            kept.push(phi);
        }
    }
    modes
}

/// `v` with the components model holds at particle `p` (symmetry planes) set to zero.
fn held_out(model: &Model, p: usize, mut v: Vector3<f64>) -> Vector3<f64> {
    for c in 0..3 {
        if model.is_held(p, c) {
            v[c] = 0.0;
        }
    }
    v
}

fn dot(a: &[Vector3<f64>], b: &[Vector3<f64>]) -> f64 {
    a.iter().zip(b).map(|(p, q)| p.dot(q)).sum()
}
