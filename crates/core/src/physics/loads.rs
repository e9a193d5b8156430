//! Fixed forces on particles: E = −Σ f·x. Linear, so no Hessian; an external load, raised with the
//! load factor of incremental loading. Gravity (E = Σ m g z, f = −m g ẑ) and concentrated forces
//! (seed 003's perturbation forces Q_p) are both of this kind.

use super::kernel::{Kernel, Local, Potential};
use nalgebra::{Matrix3, Vector3};

/// The kernel of fixed forces: one particle a stencil, its force's components (N) the coefficients.
pub struct LoadKernel {
    name: &'static str,
    particles: Vec<[u32; 1]>,
    forces_N: Vec<Vector3<f64>>,
}

/// Fixed forces on particles ([`PointLoads`], [`Gravity`]).
pub type PointLoads = Potential<LoadKernel, 1>;

/// Uniform gravity along −z on lumped masses: the fixed force −m g ẑ on each particle.
pub type Gravity = Potential<LoadKernel, 1>;

impl PointLoads {
    /// Forces `(particle, force in N)`.
    pub fn forces(loads: Vec<(usize, Vector3<f64>)>) -> Self {
        Potential::of(LoadKernel {
            name: "point-loads",
            particles: loads.iter().map(|(p, _)| [*p as u32]).collect(),
            forces_N: loads.into_iter().map(|(_, f)| f).collect(),
        })
    }
    /// Gravity on particles of masses `masses_kg` under acceleration `g_m_per_s2` (E = Σ m g z).
    pub fn new(masses_kg: Vec<f64>, g_m_per_s2: f64) -> Self {
        Potential::of(LoadKernel {
            name: "gravity",
            particles: (0..masses_kg.len() as u32).map(|p| [p]).collect(),
            forces_N: masses_kg
                .into_iter()
                .map(|m| Vector3::new(0.0, 0.0, -(m * g_m_per_s2)))
                .collect(),
        })
    }
}

impl Kernel<1> for LoadKernel {
    const COEFFICIENTS: usize = 3;
    fn name(&self) -> String {
        self.name.into()
    }
    fn stencils(&self) -> &[[u32; 1]] {
        &self.particles
    }
    #[inline]
    fn energy(&self, k: usize, x: &Local<1>) -> f64 {
        -self.forces_N[k].dot(&x[0])
    }
    #[inline]
    fn gradient(&self, k: usize, _x: &Local<1>) -> Local<1> {
        [-self.forces_N[k]]
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
        out.extend(self.forces_N[k].iter());
    }
    fn set_coefficients(&mut self, k: usize, c: &[f64]) {
        self.forces_N[k] = Vector3::new(c[0], c[1], c[2]);
    }
    #[inline]
    fn coefficient_gradient(&self, _k: usize, _x: &Local<1>, dc: &[f64]) -> Local<1> {
        [-Vector3::new(dc[0], dc[1], dc[2])]
    }
    #[inline]
    fn coefficient_energy(&self, _k: usize, x: &Local<1>, dc: &[f64]) -> f64 {
        -Vector3::new(dc[0], dc[1], dc[2]).dot(&x[0])
    }
    fn is_external_load(&self) -> bool {
        true
    }
}
