//! The one model builder of a sheet, whatever its mesh: a grid scene (`crate::build`) and the
//! Cusick disc (`crate::cusick::drape_model`) each add their material's terms, and the terms every
//! sheet gets the same way (gravity, the obstacles' barrier, self-contact) and the model itself are
//! put together here, in this order.

use super::{EnergyTerm, Gravity, Model, ObstacleBarrier, SelfContact, Vecs};
use crate::obstacle::Obstacle;

/// A model under construction: the particles' masses and pins, the terms so far.
pub struct ModelBuilder {
    /// Lumped mass of each particle, kg (zero for virtual points and absent particles).
    pub masses: Vec<f64>,
    /// Whether each particle is fixed.
    pub fixed: Vec<bool>,
    /// Per particle, which of its components (x, y, z) are held (empty: none anywhere).
    pub held: Vec<[bool; 3]>,
    /// The number of real (mesh) particles; virtual points come after them.
    pub n_mesh: usize,
    /// Gravitational acceleration, m/s².
    pub g_m_per_s2: f64,
    /// The terms so far, in the order they were added.
    pub terms: Vec<Box<dyn EnergyTerm>>,
    damping_Ns_per_m: f64,
    elongation_rate: Option<f64>,
}

impl ModelBuilder {
    /// A sheet of `masses` (kg), `fixed` pins, under gravity `g_m_per_s2`, with no terms yet.
    pub fn new(masses: Vec<f64>, fixed: Vec<bool>, g_m_per_s2: f64) -> Self {
        Self {
            n_mesh: masses.len(),
            masses,
            fixed,
            held: Vec::new(),
            g_m_per_s2,
            terms: Vec::new(),
            damping_Ns_per_m: 0.0,
            elongation_rate: None,
        }
    }

    /// Adds a term.
    pub fn term(&mut self, t: Box<dyn EnergyTerm>) {
        self.terms.push(t);
    }

    /// Mass-spring dynamics: the damping (N·s/m) and Provot's elongation rate.
    pub fn mass_spring_dynamics(&mut self, damping_Ns_per_m: f64, elongation_rate: Option<f64>) {
        self.damping_Ns_per_m = damping_Ns_per_m;
        self.elongation_rate = elongation_rate;
    }

    /// Gravity on the lumped masses, when there is any.
    pub fn gravity(&mut self) {
        if self.g_m_per_s2 > 0.0 {
            let g = Gravity::new(self.masses.clone(), self.g_m_per_s2);
            self.terms.push(Box::new(g));
        }
    }

    /// The barrier between every free particle with mass and `obstacles`, activation distance
    /// `d_hat_m`, each particle's κ from its weight under `g_kappa` (m/s²;
    /// [`ObstacleBarrier::kappa_for_weight`]).
    pub fn obstacles(&mut self, obstacles: Vec<Obstacle>, d_hat_m: f64, g_kappa: f64) {
        let b =
            ObstacleBarrier::for_particles(obstacles, d_hat_m, &self.masses, &self.fixed, g_kappa);
        self.terms.push(Box::new(b));
    }

    /// Self-contact of the sheet's `triangles` at rest positions `rest` (thickness `thickness_m`,
    /// band `band_m`), κ from the mean weight of the mesh's particles with mass under `g_kappa`
    /// (m/s²). Nothing when no triangle or no particle with mass.
    pub fn self_contact(
        &mut self,
        triangles: Vec<[u32; 3]>,
        rest: &Vecs,
        distances: (f64, f64),
        g_kappa: f64,
    ) {
        self.self_contact_twinned(triangles, rest, distances, g_kappa, Vec::new());
    }

    /// [`Self::self_contact`] where `twins[v]` is vertex v's class: vertices of one class (a seam's
    /// sides being sewn) are to become one and pairs joined through a class do not repel
    /// ([`SelfContact::with_twins`]).
    pub fn self_contact_twinned(
        &mut self,
        triangles: Vec<[u32; 3]>,
        rest: &Vecs,
        (thickness_m, band_m): (f64, f64),
        g_kappa: f64,
        twins: Vec<u32>,
    ) {
        let heavy: Vec<f64> = self.masses[..self.n_mesh]
            .iter()
            .copied()
            .filter(|m| *m > 0.0)
            .collect();
        if triangles.is_empty() || heavy.is_empty() {
            return;
        }
        let weight = g_kappa * heavy.iter().sum::<f64>() / heavy.len() as f64;
        let t = SelfContact::new(triangles, rest, thickness_m, band_m, weight).with_twins(twins);
        self.terms.push(Box::new(t));
    }

    /// The model.
    pub fn build(self) -> Model {
        Model {
            masses: self.masses,
            fixed: self.fixed,
            held_components: self.held,
            n_grid: self.n_mesh,
            terms: self.terms,
            gravity_m_per_s2: self.g_m_per_s2,
            damping_Ns_per_m: self.damping_Ns_per_m,
            elongation_rate: self.elongation_rate,
            constant_hessian: Default::default(),
        }
    }
}
