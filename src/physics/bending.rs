//! Continuum bending along grid lines, quadratic in positions (an isometric-bending energy):
//! for three consecutive particles a, b, c on a line with rest intervals h₁, h₂,
//! u = (x_c − x_b)/h₂ − (x_b − x_a)/h₁ ≈ θ (the turning angle) and the curvature is κ ≈ |u|/h̄,
//! h̄ = (h₁ + h₂)/2. The energy ½ D κ² over the tributary length h̄ and width w is
//! E = D w |u|² / (2 h̄) = ½ k |u|², k = D w / h̄. It converges to the elastica ½∫D κ² ds as the grid
//! is refined for an inextensible sheet, and its Hessian is constant.

use super::{EnergyTerm, HessianBlocks, Vecs};
use nalgebra::{Matrix3, Vector3};

/// Quadratic bending on triples of particles.
pub struct LinearBending {
    triples: Vec<[u32; 3]>,
    coef: Vec<[f64; 3]>,
    stiffness_N_m: Vec<f64>,
}

impl LinearBending {
    /// Triples (a, b, c), coefficients (1/h₁, −1/h₁ − 1/h₂, 1/h₂) and stiffnesses k = D w / h̄ (N·m).
    pub fn new(triples: Vec<[usize; 3]>, coef: Vec<[f64; 3]>, stiffness_N_m: Vec<f64>) -> Self {
        Self {
            triples: triples
                .into_iter()
                .map(|t| [t[0] as u32, t[1] as u32, t[2] as u32])
                .collect(),
            coef,
            stiffness_N_m,
        }
    }
    fn u(&self, k: usize, x: &Vecs) -> Vector3<f64> {
        let t = self.triples[k];
        let c = self.coef[k];
        x[t[0] as usize] * c[0] + x[t[1] as usize] * c[1] + x[t[2] as usize] * c[2]
    }
}

impl EnergyTerm for LinearBending {
    fn name(&self) -> String {
        "bending/continuum".into()
    }
    fn energy(&self, x: &Vecs) -> f64 {
        (0..self.triples.len())
            .map(|k| 0.5 * self.stiffness_N_m[k] * self.u(k, x).norm_squared())
            .sum()
    }
    fn add_gradient(&self, x: &Vecs, g: &mut Vecs) {
        for k in 0..self.triples.len() {
            let u = self.u(k, x) * self.stiffness_N_m[k];
            for m in 0..3 {
                g[self.triples[k][m] as usize] += u * self.coef[k][m];
            }
        }
    }
    fn stiffness_scale(&self) -> f64 {
        self.coef
            .iter()
            .zip(&self.stiffness_N_m)
            .map(|(c, k)| k * c[1] * c[1])
            .fold(0.0, f64::max)
    }
    fn add_hessian(&self, _x: &Vecs, h: &mut HessianBlocks, _project: bool) {
        for k in 0..self.triples.len() {
            let t = self.triples[k];
            let idx = [t[0] as usize, t[1] as usize, t[2] as usize];
            h.push_outer(
                &idx,
                &self.coef[k],
                &(Matrix3::identity() * self.stiffness_N_m[k]),
            );
        }
    }
}
