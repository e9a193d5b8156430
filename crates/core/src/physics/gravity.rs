//! Gravity: E = Σ m g z (z up). Linear, so it has no Hessian.

use super::kernel::{Kernel, Local, Potential};
use nalgebra::{Matrix3, Vector3};

/// The kernel of gravity: one particle a stencil, its weight m g (N) the coefficient.
pub struct GravityKernel {
    particles: Vec<[u32; 1]>,
    weights_N: Vec<f64>,
}

/// Uniform gravity along −z on lumped masses.
pub type Gravity = Potential<GravityKernel, 1>;

impl Gravity {
    /// Gravity on particles of masses `masses_kg` under acceleration `g_m_per_s2`.
    pub fn new(masses_kg: Vec<f64>, g_m_per_s2: f64) -> Self {
        Potential::of(GravityKernel {
            particles: (0..masses_kg.len() as u32).map(|p| [p]).collect(),
            weights_N: masses_kg.into_iter().map(|m| m * g_m_per_s2).collect(),
        })
    }
}

impl Kernel<1> for GravityKernel {
    const COEFFICIENTS: usize = 1;
    fn name(&self) -> String {
        "gravity".into()
    }
    fn stencils(&self) -> &[[u32; 1]] {
        &self.particles
    }
    #[inline]
    fn energy(&self, k: usize, x: &Local<1>) -> f64 {
        self.weights_N[k] * x[0].z
    }
    #[inline]
    fn gradient(&self, k: usize, _x: &Local<1>) -> Local<1> {
        [Vector3::new(0.0, 0.0, self.weights_N[k])]
    }
    fn hessian(
        &self,
        _k: usize,
        _x: &Local<1>,
        _project: bool,
        _push: &mut impl FnMut(usize, usize, Matrix3<f64>),
    ) {
    }
    fn coefficients(&self, k: usize, out: &mut Vec<f64>) {
        out.push(self.weights_N[k]);
    }
    fn set_coefficients(&mut self, k: usize, c: &[f64]) {
        self.weights_N[k] = c[0];
    }
    #[inline]
    fn coefficient_gradient(&self, _k: usize, _x: &Local<1>, dc: &[f64]) -> Local<1> {
        [Vector3::new(0.0, 0.0, dc[0])]
    }
    #[inline]
    fn coefficient_energy(&self, _k: usize, x: &Local<1>, dc: &[f64]) -> f64 {
        x[0].z * dc[0]
    }
    fn is_external_load(&self) -> bool {
        true
    }
}
