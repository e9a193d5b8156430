//! Concentrated forces on particles: E = −Σ f·x. Linear, so no Hessian; an external load, raised with
//! the load factor of incremental loading like gravity (seed 003's perturbation forces Q_p).

use super::{EnergyTerm, HessianBlocks, Vecs};
use nalgebra::Vector3;

/// Fixed forces on particles.
pub struct PointLoads {
    loads: Vec<(u32, Vector3<f64>)>,
}

impl PointLoads {
    /// Forces `(particle, force in N)`.
    pub fn new(loads: Vec<(usize, Vector3<f64>)>) -> Self {
        Self {
            loads: loads.into_iter().map(|(p, f)| (p as u32, f)).collect(),
        }
    }
}

impl EnergyTerm for PointLoads {
    fn name(&self) -> String {
        "point-loads".into()
    }
    fn energy(&self, x: &Vecs) -> f64 {
        -self
            .loads
            .iter()
            .map(|(p, f)| f.dot(&x[*p as usize]))
            .sum::<f64>()
    }
    fn add_gradient(&self, _x: &Vecs, g: &mut Vecs) {
        for (p, f) in &self.loads {
            g[*p as usize] -= f;
        }
    }
    fn add_hessian(&self, _x: &Vecs, _h: &mut HessianBlocks, _project: bool) {}
    fn is_external_load(&self) -> bool {
        true
    }
}
