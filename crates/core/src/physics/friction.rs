//! Lagged frictional contact (in the manner of incremental potential contact): each particle in
//! contact at the lagged state xᵏ keeps its contact force λ and tangent plane (normal n); moving
//! tangentially by u = P(x − xᵏ), P = I − nnᵀ, costs D = μ λ f₀(|u|) with f₀ smoothing Coulomb's law over
//! a slip of ε: f₀(y) = y²/ε − y³/(3ε²) below ε, y − ε/3 beyond. The solver refreshes the anchors
//! (lags) between load increments.

use super::{EnergyTerm, HessianBlocks, Vecs};
use nalgebra::{Matrix3, Vector3};

/// One anchored contact.
#[derive(Debug, Clone, Copy)]
pub struct FrictionAnchor {
    /// Particle.
    pub particle: usize,
    /// Its position at the lagged state, m.
    pub anchor_m: Vector3<f64>,
    /// Outward normal of the obstacle there.
    pub normal: Vector3<f64>,
    /// μ λ: the friction coefficient times the lagged contact force, N.
    pub limit_N: f64,
}

/// Lagged friction on a set of anchored contacts.
pub struct LaggedFriction {
    /// The contacts.
    pub anchors: Vec<FrictionAnchor>,
    /// Slip over which static friction turns into sliding, m.
    pub eps_m: f64,
}

impl LaggedFriction {
    fn slip(&self, a: &FrictionAnchor, x: &Vecs) -> Vector3<f64> {
        let d = x[a.particle] - a.anchor_m;
        d - a.normal * a.normal.dot(&d)
    }
    fn f0(&self, y: f64) -> f64 {
        let e = self.eps_m;
        if y < e {
            y * y / e - y * y * y / (3.0 * e * e)
        } else {
            y - e / 3.0
        }
    }
    /// f₁(y)/y, the factor of the force along u (finite at y = 0).
    fn f1_over_y(&self, y: f64) -> f64 {
        let e = self.eps_m;
        if y < e {
            2.0 / e - y / (e * e)
        } else {
            1.0 / y
        }
    }
}

impl EnergyTerm for LaggedFriction {
    fn name(&self) -> String {
        "contact/friction".into()
    }
    fn energy(&self, x: &Vecs) -> f64 {
        self.anchors
            .iter()
            .map(|a| a.limit_N * self.f0(self.slip(a, x).norm()))
            .sum()
    }
    fn add_gradient(&self, x: &Vecs, g: &mut Vecs) {
        for a in &self.anchors {
            let u = self.slip(a, x);
            g[a.particle] += u * (a.limit_N * self.f1_over_y(u.norm()));
        }
    }
    fn add_hessian(&self, x: &Vecs, h: &mut HessianBlocks, _project: bool) {
        // The positive part: μλ f₁(y)/y P (the curvature term along u is negative below ε and dropped).
        for a in &self.anchors {
            let y = self.slip(a, x).norm();
            let p = Matrix3::identity() - a.normal * a.normal.transpose();
            h.push(a.particle, a.particle, p * (a.limit_N * self.f1_over_y(y)));
        }
    }
}
