//! Linear springs, seed 000 Eq. 2: F = K (|L| − L0) L/|L|, energy ½K(|L| − L0)².

use super::{EnergyTerm, HessianBlocks, Vecs};
use nalgebra::Matrix3;

/// Which family a set of springs belongs to (seed 000, Fig. 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SpringFamily {
    /// Between grid neighbours (i, j)–(i+1, j) and (i, j)–(i, j+1).
    Structural,
    /// Cell diagonals.
    Shear,
    /// Skip-one neighbours (i, j)–(i+2, j) and (i, j)–(i, j+2).
    Bend,
    /// Axial springs of the continuum model (tensile rigidity).
    Tensile,
}

/// A set of springs of one family.
pub struct Springs {
    family: SpringFamily,
    pairs: Vec<(u32, u32)>,
    rest_m: Vec<f64>,
    stiffness_N_per_m: Vec<f64>,
}

impl Springs {
    /// Springs between `pairs` with rest lengths (m) and stiffnesses (N/m).
    pub fn new(
        family: SpringFamily,
        pairs: Vec<(usize, usize)>,
        rest_m: Vec<f64>,
        stiffness_N_per_m: Vec<f64>,
    ) -> Self {
        assert!(pairs.len() == rest_m.len() && pairs.len() == stiffness_N_per_m.len());
        Self {
            family,
            pairs: pairs
                .into_iter()
                .map(|(a, b)| (a as u32, b as u32))
                .collect(),
            rest_m,
            stiffness_N_per_m,
        }
    }
    /// Number of springs.
    pub fn len(&self) -> usize {
        self.pairs.len()
    }
    /// Whether there are no springs.
    pub fn is_empty(&self) -> bool {
        self.pairs.is_empty()
    }
}

impl EnergyTerm for Springs {
    fn name(&self) -> String {
        format!("springs/{:?}", self.family).to_lowercase()
    }
    fn energy(&self, x: &Vecs) -> f64 {
        let mut e = 0.0;
        for (k, &(a, b)) in self.pairs.iter().enumerate() {
            let l = (x[b as usize] - x[a as usize]).norm();
            let d = l - self.rest_m[k];
            e += 0.5 * self.stiffness_N_per_m[k] * d * d;
        }
        e
    }
    fn add_gradient(&self, x: &Vecs, g: &mut Vecs) {
        for (k, &(a, b)) in self.pairs.iter().enumerate() {
            let (a, b) = (a as usize, b as usize);
            let d = x[b] - x[a];
            let l = d.norm();
            if l == 0.0 {
                continue;
            }
            let f = d * (self.stiffness_N_per_m[k] * (l - self.rest_m[k]) / l);
            g[b] += f;
            g[a] -= f;
        }
    }
    fn add_hessian(&self, x: &Vecs, h: &mut HessianBlocks, project: bool) {
        for (k, &(a, b)) in self.pairs.iter().enumerate() {
            let (a, b) = (a as usize, b as usize);
            let d = x[b] - x[a];
            let l = d.norm().max(1e-12 * self.rest_m[k]);
            let u = d / l;
            let uu = u * u.transpose();
            // K = k[ûûᵀ + (1 − L0/l)(I − ûûᵀ)]; projected, the transverse factor is clamped at 0:
            // a compressed spring contributes no negative stiffness.
            let t = 1.0 - self.rest_m[k] / l;
            let t = if project { t.max(0.0) } else { t };
            let kk = (uu + (Matrix3::identity() - uu) * t) * self.stiffness_N_per_m[k];
            h.push(a, a, kk);
            h.push(b, b, kk);
            h.push(b, a, -kk);
        }
    }
    fn stiffness_scale(&self) -> f64 {
        self.stiffness_N_per_m.iter().copied().fold(0.0, f64::max)
    }
    fn max_strain(&self, x: &Vecs) -> f64 {
        self.pairs
            .iter()
            .zip(&self.rest_m)
            .map(|(&(a, b), &l0)| (((x[b as usize] - x[a as usize]).norm() - l0) / l0).abs())
            .fold(0.0, f64::max)
    }
    fn provot_correct(&self, x: &mut Vecs, free: &[bool], rate: f64) {
        if !matches!(self.family, SpringFamily::Structural | SpringFamily::Shear) {
            return;
        }
        for (k, &(a, b)) in self.pairs.iter().enumerate() {
            let (a, b) = (a as usize, b as usize);
            let d = x[b] - x[a];
            let l = d.norm();
            let lmax = (1.0 + rate) * self.rest_m[k];
            if l <= lmax || l == 0.0 {
                continue;
            }
            let excess = d * ((l - lmax) / l);
            match (free[a], free[b]) {
                (true, true) => {
                    x[a] += excess * 0.5;
                    x[b] -= excess * 0.5;
                }
                (true, false) => x[a] += excess,
                (false, true) => x[b] -= excess,
                (false, false) => {}
            }
        }
    }
}
