//! Gravity: E = Σ m g z (z up). Linear, so it has no Hessian.

use super::{EnergyTerm, HessianBlocks, Vecs};

/// Uniform gravity along −z on lumped masses.
pub struct Gravity {
    weights_N: Vec<f64>,
}

impl Gravity {
    /// Gravity on particles of masses `masses_kg` under acceleration `g_m_per_s2`.
    pub fn new(masses_kg: Vec<f64>, g_m_per_s2: f64) -> Self {
        Self {
            weights_N: masses_kg.into_iter().map(|m| m * g_m_per_s2).collect(),
        }
    }
}

impl EnergyTerm for Gravity {
    fn name(&self) -> String {
        "gravity".into()
    }
    fn energy(&self, x: &Vecs) -> f64 {
        self.weights_N.iter().zip(x).map(|(w, p)| w * p.z).sum()
    }
    fn add_gradient(&self, _x: &Vecs, g: &mut Vecs) {
        for (gi, w) in g.iter_mut().zip(&self.weights_N) {
            gi.z += w;
        }
    }
    fn add_hessian(&self, _x: &Vecs, _h: &mut HessianBlocks, _project: bool) {}
    fn is_external_load(&self) -> bool {
        true
    }
}
