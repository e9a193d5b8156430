//! Lagged frictional contact (in the manner of incremental potential contact): each particle in
//! contact at the lagged state xᵏ keeps its contact force λ and tangent plane (normal n); moving
//! tangentially by u = P(x − xᵏ), P = I − nnᵀ, costs D = μ λ f₀(|u|) with f₀ smoothing Coulomb's law over
//! a slip of ε: f₀(y) = y²/ε − y³/(3ε²) below ε, y − ε/3 beyond. The solver refreshes the anchors
//! (lags) between load increments. A per-stencil kernel ([`super::Kernel`]): one anchored particle a
//! stencil, its coefficients μλ and ε.

use super::kernel::{Kernel, Local, Potential};
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

/// The kernel of lagged friction: one anchored particle a stencil; its coefficients μλ (N) and the
/// smoothing slip ε (m), each the stencil's own.
pub struct FrictionKernel {
    stencils: Vec<[u32; 1]>,
    anchors: Vec<FrictionAnchor>,
    eps_m: Vec<f64>,
}

/// Lagged friction on a set of anchored contacts.
pub type LaggedFriction = Potential<FrictionKernel, 1>;

impl LaggedFriction {
    /// Friction on `anchors`, Coulomb's law smoothed over a slip of `eps_m` (m).
    pub fn anchored(anchors: Vec<FrictionAnchor>, eps_m: f64) -> Self {
        Potential::of(FrictionKernel {
            stencils: anchors.iter().map(|a| [a.particle as u32]).collect(),
            eps_m: vec![eps_m; anchors.len()],
            anchors,
        })
    }
}

impl FrictionKernel {
    /// The tangential slip u = P(x − xᵏ) of anchor `a` at `x`.
    fn slip(a: &FrictionAnchor, x: &Vector3<f64>) -> Vector3<f64> {
        let d = x - a.anchor_m;
        d - a.normal * a.normal.dot(&d)
    }
    /// f₀(y) and ∂f₀/∂ε at smoothing slip `e`.
    fn f0(e: f64, y: f64) -> (f64, f64) {
        if y < e {
            (
                y * y / e - y * y * y / (3.0 * e * e),
                -y * y / (e * e) + 2.0 * y * y * y / (3.0 * e * e * e),
            )
        } else {
            (y - e / 3.0, -1.0 / 3.0)
        }
    }
    /// f₁(y)/y, the factor of the force along u (finite at y = 0), and its derivative in ε, at
    /// smoothing slip `e`.
    fn f1_over_y(e: f64, y: f64) -> (f64, f64) {
        if y < e {
            (
                2.0 / e - y / (e * e),
                -2.0 / (e * e) + 2.0 * y / (e * e * e),
            )
        } else {
            (1.0 / y, 0.0)
        }
    }
}

impl Kernel<1> for FrictionKernel {
    const COEFFICIENTS: usize = 2;
    fn name(&self) -> String {
        "contact/friction".into()
    }
    fn stencils(&self) -> &[[u32; 1]] {
        &self.stencils
    }
    fn energy(&self, s: usize, x: &Local<1>) -> f64 {
        let a = &self.anchors[s];
        a.limit_N * Self::f0(self.eps_m[s], Self::slip(a, &x[0]).norm()).0
    }
    fn gradient(&self, s: usize, x: &Local<1>) -> Local<1> {
        let a = &self.anchors[s];
        let u = Self::slip(a, &x[0]);
        [u * (a.limit_N * Self::f1_over_y(self.eps_m[s], u.norm()).0)]
    }
    /// The positive part: μλ f₁(y)/y P (the curvature term along u is negative below ε and is
    /// dropped, projected or not).
    fn hessian(
        &self,
        s: usize,
        x: &Local<1>,
        _project: bool,
        push: &mut impl FnMut(usize, usize, Matrix3<f64>),
    ) {
        let a = &self.anchors[s];
        let y = Self::slip(a, &x[0]).norm();
        let p = Matrix3::identity() - a.normal * a.normal.transpose();
        push(0, 0, p * (a.limit_N * Self::f1_over_y(self.eps_m[s], y).0));
    }
    /// With the curvature along the slip: μλ (φ P + φ′(y)/y u uᵀ), φ = f₁(y)/y (φ′ = −1/ε² below
    /// ε, −1/y² beyond).
    fn exact_hessian(
        &self,
        s: usize,
        x: &Local<1>,
        push: &mut impl FnMut(usize, usize, Matrix3<f64>),
    ) {
        let a = &self.anchors[s];
        let u = Self::slip(a, &x[0]);
        let y = u.norm();
        let p = Matrix3::identity() - a.normal * a.normal.transpose();
        let mut h = p * Self::f1_over_y(self.eps_m[s], y).0;
        if y > 0.0 {
            let dphi = if y < self.eps_m[s] {
                -1.0 / (self.eps_m[s] * self.eps_m[s])
            } else {
                -1.0 / (y * y)
            };
            h += u * u.transpose() * (dphi / y);
        }
        push(0, 0, h * a.limit_N);
    }
    fn coefficients(&self, s: usize, out: &mut Vec<f64>) {
        out.extend([self.anchors[s].limit_N, self.eps_m[s]]);
    }
    fn set_coefficients(&mut self, s: usize, c: &[f64]) {
        self.anchors[s].limit_N = c[0];
        self.eps_m[s] = c[1];
    }
    fn coefficient_gradient(&self, s: usize, x: &Local<1>, dc: &[f64]) -> Local<1> {
        let a = &self.anchors[s];
        let u = Self::slip(a, &x[0]);
        let (f, df) = Self::f1_over_y(self.eps_m[s], u.norm());
        [u * (dc[0] * f + a.limit_N * df * dc[1])]
    }
    fn coefficient_energy(&self, s: usize, x: &Local<1>, dc: &[f64]) -> f64 {
        let a = &self.anchors[s];
        let (f, df) = Self::f0(self.eps_m[s], Self::slip(a, &x[0]).norm());
        dc[0] * f + a.limit_N * df * dc[1]
    }
}
