//! Sewing springs (Blender's cloth sewing springs, GarmentCode's stitches before they are merged):
//! a zero-rest-length spring between the two vertices a stitch pairs, its force capped far apart —
//! E = ½ k d² for d ≤ c and k c (d − c/2) beyond (Huber's loss: the pull is k d up to c, then the
//! constant k c), so that a seam across a body pulls its sides together at a bounded force.

use super::kernel::{Kernel, Local, Potential};
use nalgebra::{Matrix3, Vector3};

/// The kernel of a garment's seams: per pair, stiffness `k` (N/m) and the distance `c` (m) beyond
/// which the pull stays at k c.
pub struct SeamKernel {
    pairs: Vec<[u32; 2]>,
    stiffness_N_per_m: f64,
    cap_m: f64,
}

/// A garment's sewing springs.
pub type Seams = Potential<SeamKernel, 2>;

impl Seams {
    /// Springs between `pairs`, stiffness `k` N/m, pull capped beyond `cap_m`.
    pub fn new(pairs: &[[usize; 2]], stiffness_N_per_m: f64, cap_m: f64) -> Self {
        Potential::of(SeamKernel {
            pairs: pairs.iter().map(|p| p.map(|v| v as u32)).collect(),
            stiffness_N_per_m,
            cap_m,
        })
    }
}

impl Kernel<2> for SeamKernel {
    const COEFFICIENTS: usize = 1;
    fn name(&self) -> String {
        "seams".into()
    }
    fn stencils(&self) -> &[[u32; 2]] {
        &self.pairs
    }
    fn energy(&self, _s: usize, x: &Local<2>) -> f64 {
        let (k, c, d) = (self.stiffness_N_per_m, self.cap_m, (x[1] - x[0]).norm());
        if d <= c {
            0.5 * k * d * d
        } else {
            k * c * (d - 0.5 * c)
        }
    }
    fn gradient(&self, _s: usize, x: &Local<2>) -> Local<2> {
        let v = x[1] - x[0];
        let d = v.norm();
        let scale = if d <= self.cap_m { 1.0 } else { self.cap_m / d };
        let f = v * (self.stiffness_N_per_m * scale);
        [-f, f]
    }
    /// k I within the cap; k c/d (I − ûûᵀ) beyond (positive semi-definite either way).
    fn hessian(
        &self,
        _s: usize,
        x: &Local<2>,
        _project: bool,
        push: &mut impl FnMut(usize, usize, Matrix3<f64>),
    ) {
        let v = x[1] - x[0];
        let d = v.norm();
        let k = self.stiffness_N_per_m;
        let kk = if d <= self.cap_m {
            Matrix3::identity() * k
        } else {
            let u = v / d;
            (Matrix3::identity() - u * u.transpose()) * (k * self.cap_m / d)
        };
        push(0, 0, kk);
        push(1, 1, kk);
        push(1, 0, -kk);
    }
    fn coefficients(&self, _s: usize, out: &mut Vec<f64>) {
        out.push(self.stiffness_N_per_m);
    }
    fn set_coefficients(&mut self, _s: usize, c: &[f64]) {
        self.stiffness_N_per_m = c[0];
    }
    fn coefficient_gradient(&self, _s: usize, x: &Local<2>, dc: &[f64]) -> Local<2> {
        let g = self.gradient(0, x);
        let k = self.stiffness_N_per_m;
        g.map(|v: Vector3<f64>| v * (dc[0] / k))
    }
    fn coefficient_energy(&self, _s: usize, x: &Local<2>, dc: &[f64]) -> f64 {
        self.energy(0, x) * dc[0] / self.stiffness_N_per_m
    }
    fn stiffness_scale(&self) -> f64 {
        self.stiffness_N_per_m
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_seam_force_is_the_energy_gradient_and_capped() {
        let s = Seams::new(&[[0, 1]], 10.0, 0.1);
        let k = &s.kernel;
        for d in [0.05, 0.3] {
            let x = [Vector3::zeros(), Vector3::new(d, 0.02, -0.01)];
            let g = k.gradient(0, &x);
            let h = 1e-7;
            for i in 0..3 {
                let mut xp = x;
                xp[1][i] += h;
                let mut xm = x;
                xm[1][i] -= h;
                let fd = (k.energy(0, &xp) - k.energy(0, &xm)) / (2.0 * h);
                assert!(
                    (fd - g[1][i]).abs() < 1e-6,
                    "d {d} component {i}: {fd} vs {}",
                    g[1][i]
                );
            }
        }
        // The Hessian blocks against central differences of the gradient, within the cap and
        // beyond it; the derivative in k against differences of the gradient and energy in k.
        for d in [0.05, 0.3] {
            let x = [Vector3::zeros(), Vector3::new(d, 0.02, -0.01)];
            let mut blocks = Vec::new();
            k.hessian(0, &x, false, &mut |a, b, m| blocks.push((a, b, m)));
            let h11 = blocks
                .iter()
                .find(|(a, b, _)| (*a, *b) == (1, 1))
                .unwrap()
                .2;
            for j in 0..3 {
                let (mut xp, mut xm) = (x, x);
                xp[1][j] += 1e-7;
                xm[1][j] -= 1e-7;
                let col = (k.gradient(0, &xp)[1] - k.gradient(0, &xm)[1]) / 2e-7;
                assert!(
                    (col - h11.column(j)).norm() < 1e-5,
                    "d {d}: {col} vs {}",
                    h11.column(j)
                );
            }
            let stiffer = Seams::new(&[[0, 1]], 10.0 + 1e-6, 0.1);
            let dg = (stiffer.kernel.gradient(0, &x)[1] - k.gradient(0, &x)[1]) / 1e-6;
            assert!((dg - k.coefficient_gradient(0, &x, &[1.0])[1]).norm() < 1e-6);
            let de = (stiffer.kernel.energy(0, &x) - k.energy(0, &x)) / 1e-6;
            assert!((de - k.coefficient_energy(0, &x, &[1.0])).abs() < 1e-6);
        }
        // Far apart the pull is k c = 1 N whatever the distance.
        let far = k.gradient(0, &[Vector3::zeros(), Vector3::new(5.0, 0.0, 0.0)]);
        assert!((far[1].norm() - 1.0).abs() < 1e-12);
    }
}
