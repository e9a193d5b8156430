//! Linear springs, seed 000 Eq. 2: F = K (|L| − L0) L/|L|, energy ½K(|L| − L0)².

use super::Vecs;
use super::kernel::{Kernel, Local, Potential};
use nalgebra::{Matrix3, Vector3};

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

/// The kernel of a set of springs of one family: per spring (a, b) the energy ½k(|x_b − x_a| − L0)²,
/// its coefficients (L0 in m, k in N/m).
pub struct SpringKernel {
    family: SpringFamily,
    pairs: Vec<[u32; 2]>,
    rest_m: Vec<f64>,
    stiffness_N_per_m: Vec<f64>,
}

/// A set of springs of one family.
pub type Springs = Potential<SpringKernel, 2>;

impl Springs {
    /// Springs between `pairs` with rest lengths (m) and stiffnesses (N/m).
    pub fn new(
        family: SpringFamily,
        pairs: Vec<(usize, usize)>,
        rest_m: Vec<f64>,
        stiffness_N_per_m: Vec<f64>,
    ) -> Self {
        assert!(pairs.len() == rest_m.len() && pairs.len() == stiffness_N_per_m.len());
        Potential::of(SpringKernel {
            family,
            pairs: pairs
                .into_iter()
                .map(|(a, b)| [a as u32, b as u32])
                .collect(),
            rest_m,
            stiffness_N_per_m,
        })
    }
}

impl Kernel<2> for SpringKernel {
    const COEFFICIENTS: usize = 2;
    fn name(&self) -> String {
        format!("springs/{:?}", self.family).to_lowercase()
    }
    fn stencils(&self) -> &[[u32; 2]] {
        &self.pairs
    }
    #[inline]
    fn energy(&self, k: usize, x: &Local<2>) -> f64 {
        let l = (x[1] - x[0]).norm();
        let d = l - self.rest_m[k];
        0.5 * self.stiffness_N_per_m[k] * d * d
    }
    #[inline]
    fn gradient(&self, k: usize, x: &Local<2>) -> Local<2> {
        let d = x[1] - x[0];
        let l = d.norm();
        if l == 0.0 {
            return [Vector3::zeros(); 2];
        }
        let f = d * (self.stiffness_N_per_m[k] * (l - self.rest_m[k]) / l);
        [-f, f]
    }
    fn hessian(
        &self,
        k: usize,
        x: &Local<2>,
        project: bool,
        push: &mut impl FnMut(usize, usize, Matrix3<f64>),
    ) {
        let d = x[1] - x[0];
        let l = d.norm().max(1e-12 * self.rest_m[k]);
        let u = d / l;
        let uu = u * u.transpose();
        // K = k[ûûᵀ + (1 − L0/l)(I − ûûᵀ)]; projected, the transverse factor is clamped at 0:
        // a compressed spring contributes no negative stiffness.
        let t = 1.0 - self.rest_m[k] / l;
        let t = if project { t.max(0.0) } else { t };
        let kk = (uu + (Matrix3::identity() - uu) * t) * self.stiffness_N_per_m[k];
        push(0, 0, kk);
        push(1, 1, kk);
        push(1, 0, -kk);
    }
    fn coefficients(&self, k: usize, out: &mut Vec<f64>) {
        out.extend([self.rest_m[k], self.stiffness_N_per_m[k]]);
    }
    fn set_coefficients(&mut self, k: usize, c: &[f64]) {
        (self.rest_m[k], self.stiffness_N_per_m[k]) = (c[0], c[1]);
    }
    /// ∂f/∂k = (l − L0) d/l, ∂f/∂L0 = −k d/l for the force f = k (l − L0) d/l on b.
    #[inline]
    fn coefficient_gradient(&self, k: usize, x: &Local<2>, dc: &[f64]) -> Local<2> {
        let d = x[1] - x[0];
        let l = d.norm();
        if l == 0.0 {
            return [Vector3::zeros(); 2];
        }
        let f = d * (((l - self.rest_m[k]) * dc[1] - self.stiffness_N_per_m[k] * dc[0]) / l);
        [-f, f]
    }
    /// ∂E/∂k = ½ (l − L0)², ∂E/∂L0 = −k (l − L0).
    #[inline]
    fn coefficient_energy(&self, k: usize, x: &Local<2>, dc: &[f64]) -> f64 {
        let d = (x[1] - x[0]).norm() - self.rest_m[k];
        0.5 * d * d * dc[1] - self.stiffness_N_per_m[k] * d * dc[0]
    }
    fn stiffness_scale(&self) -> f64 {
        self.stiffness_N_per_m.iter().copied().fold(0.0, f64::max)
    }
    #[inline]
    fn strain(&self, k: usize, x: &Local<2>) -> f64 {
        let l0 = self.rest_m[k];
        (((x[1] - x[0]).norm() - l0) / l0).abs()
    }
    fn provot_correct(&self, x: &mut Vecs, free: &[bool], rate: f64) {
        if !matches!(self.family, SpringFamily::Structural | SpringFamily::Shear) {
            return;
        }
        for (k, &[a, b]) in self.pairs.iter().enumerate() {
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
