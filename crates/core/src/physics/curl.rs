//! A fabric's natural curl (issue 51): the curvature κ_r a free strip of it rolls up to, toward
//! one face. Knits curl at their edges and many wovens do too; turned over, the curl changes side,
//! which is why ISO 9073-9 and BS 5058 drape every specimen face up and face down.
//!
//! A sheet whose bending energy is ½B(2H − κ_r)² per area (the mean-curvature form of Bergou et al.
//! 2006's hinge bending with a spontaneous curvature, so that a free strip rolls to κ_r) differs
//! from the hinges' ½B(2H)² by the linear term −B κ_r ∫2H dA and a constant. Over a triangle mesh
//! ∫2H dA = Σ_e θ_e |e| (Steiner's formula: θ_e the dihedral angle of edge e, positive folding
//! toward the sheet's upper side), and for a hinge Bergou's u = Σ Kᵢ xᵢ has u·n̂ = −θ|e| to first
//! order. So this term stores, per hinge,
//! E = B κ_r (u·m) / |m_rest|,  m = (x₁ − x₀) × (x₂ − x₃),
//! m the sum of the two triangles' area normals (|m| = 2(A₀ + A₁) on a flat hinge), oriented up
//! (+z of the pattern's plane) at rest — a cubic polynomial in the positions, invariant under
//! rigid motions, whose derivatives are exact and short.

use super::kernel::{Kernel, Local, Potential};
use super::mesh_bending::{SewnSheet, hinges};
use nalgebra::{Matrix3, Vector3};

/// The curl term's kernel: per hinge, Bergou's K (u = Σ Kᵢ xᵢ) and the moment weight
/// w = B κ_r / |m_rest| (J per m³ of u·m; its sign orients m up at rest).
pub struct CurlKernel {
    stencils: Vec<[u32; 4]>,
    coef: Vec<[f64; 4]>,
    weight: Vec<f64>,
}

/// The curl term.
pub type Curl = Potential<CurlKernel, 4>;

/// The natural curl of a sheet of bending rigidity `rigidity_N_m` (N·m; the geometric mean of warp
/// and weft) that a free strip rolls up to `curl_per_m` (1/m, positive toward +z of the pattern's
/// plane: the rim of a specimen laid that side up lifts).
pub fn hinge_curl(sheet: &SewnSheet<'_>, rigidity_N_m: f64, curl_per_m: f64) -> Curl {
    let (mut stencils, mut coef, mut weight) = (Vec::new(), Vec::new(), Vec::new());
    for h in hinges(sheet) {
        let [x0, x1, x2, x3] = h.rest;
        let m = (x1 - x0).cross(&(x2 - x3));
        if m.norm() == 0.0 {
            continue;
        }
        stencils.push(h.stencil.map(|v| v as u32));
        coef.push(h.coef);
        weight.push(rigidity_N_m * curl_per_m * m.z.signum() / m.norm());
    }
    Potential::of(CurlKernel {
        stencils,
        coef,
        weight,
    })
}

/// The cross-product matrix [a]×: [a]× b = a × b.
fn cross_matrix(a: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -a.z, a.y, a.z, 0.0, -a.x, -a.y, a.x, 0.0)
}

impl CurlKernel {
    /// (u, e = x₁ − x₀, d = x₂ − x₃, m = e × d) of stencil `s` at `x`.
    fn parts(&self, s: usize, x: &Local<4>) -> [Vector3<f64>; 4] {
        let k = self.coef[s];
        let u = (0..4).map(|i| x[i] * k[i]).sum();
        let (e, d) = (x[1] - x[0], x[2] - x[3]);
        [u, e, d, e.cross(&d)]
    }

    /// ∂m/∂xᵢ (m = e × d): [d]×, −[d]×, [e]×, −[e]×.
    fn dm(e: &Vector3<f64>, d: &Vector3<f64>) -> [Matrix3<f64>; 4] {
        let (cd, ce) = (cross_matrix(d), cross_matrix(e));
        [cd, -cd, ce, -ce]
    }
}

impl Kernel<4> for CurlKernel {
    /// The stencil's Kᵢ, then w.
    const COEFFICIENTS: usize = 5;
    fn name(&self) -> String {
        "bending/curl".into()
    }
    fn stencils(&self) -> &[[u32; 4]] {
        &self.stencils
    }
    fn energy(&self, s: usize, x: &Local<4>) -> f64 {
        let [u, _, _, m] = self.parts(s, x);
        self.weight[s] * u.dot(&m)
    }
    /// ∂(u·m)/∂xᵢ = Kᵢ m + (∂m/∂xᵢ)ᵀ u.
    fn gradient(&self, s: usize, x: &Local<4>) -> Local<4> {
        let [u, e, d, m] = self.parts(s, x);
        let (k, w) = (self.coef[s], self.weight[s]);
        let dm = Self::dm(&e, &d);
        std::array::from_fn(|i| (m * k[i] + dm[i].transpose() * u) * w)
    }
    /// ∂²(u·m)/∂xᵢ∂xⱼ = Kᵢ ∂m/∂xⱼ + Kⱼ (∂m/∂xᵢ)ᵀ + Cᵢⱼ, where C couples the edge's ends with the
    /// opposite particles through [u]× (the second derivative of m is constant). Indefinite: the
    /// projected Hessian leaves the term out (zero blocks, positive semi-definite), the curl being
    /// a small moment beside the bending it shifts.
    fn hessian(
        &self,
        s: usize,
        x: &Local<4>,
        project: bool,
        push: &mut impl FnMut(usize, usize, Matrix3<f64>),
    ) {
        let [u, e, d, _] = self.parts(s, x);
        let (k, w) = (self.coef[s], self.weight[s]);
        let dm = Self::dm(&e, &d);
        let cu = cross_matrix(&u);
        // C_ij for i > j: (2,0) −[u]×, (2,1) [u]×, (3,0) [u]×, (3,1) −[u]×.
        let c = |i: usize, j: usize| match (i, j) {
            (2, 0) | (3, 1) => -cu,
            (2, 1) | (3, 0) => cu,
            _ => Matrix3::zeros(),
        };
        for i in 0..4 {
            for j in 0..=i {
                let block = if project {
                    Matrix3::zeros()
                } else {
                    (dm[j] * k[i] + dm[i].transpose() * k[j] + c(i, j)) * w
                };
                push(i, j, block);
            }
        }
    }
    fn coefficients(&self, s: usize, out: &mut Vec<f64>) {
        out.extend(self.coef[s]);
        out.push(self.weight[s]);
    }
    fn set_coefficients(&mut self, s: usize, c: &[f64]) {
        self.coef[s].copy_from_slice(&c[..4]);
        self.weight[s] = c[4];
    }
    /// ∂gᵢ/∂Kⱼ = w (δᵢⱼ m + (∂m/∂xᵢ)ᵀ xⱼ), ∂gᵢ/∂w = gᵢ / w.
    fn coefficient_gradient(&self, s: usize, x: &Local<4>, dc: &[f64]) -> Local<4> {
        let [u, e, d, m] = self.parts(s, x);
        let (k, w) = (self.coef[s], self.weight[s]);
        let dm = Self::dm(&e, &d);
        let du: Vector3<f64> = (0..4).map(|j| x[j] * dc[j]).sum();
        std::array::from_fn(|i| {
            let by_k = (m * dc[i] + dm[i].transpose() * du) * w;
            let by_w = (m * k[i] + dm[i].transpose() * u) * dc[4];
            by_k + by_w
        })
    }
    fn coefficient_energy(&self, s: usize, x: &Local<4>, dc: &[f64]) -> f64 {
        let [u, _, _, m] = self.parts(s, x);
        let du: Vector3<f64> = (0..4).map(|j| x[j] * dc[j]).sum();
        self.weight[s] * du.dot(&m) + dc[4] * u.dot(&m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::EnergyTerm;

    /// A 6 × 6 grid of 1 cm squares, each cut along alternating diagonals.
    fn sheet() -> (Vec<[f64; 2]>, Vec<[usize; 3]>) {
        crate::physics::testing::grid(6, 0.01, true)
    }

    fn curl(rest: &[[f64; 2]], tris: &[[usize; 3]], kappa: f64) -> Curl {
        let s = SewnSheet {
            rest,
            rest_triangles: tris,
            triangles: tris,
        };
        hinge_curl(&s, 1e-5, kappa)
    }

    /// The sheet rolled onto a cylinder of curvature κ about the y axis (z up for κ > 0).
    fn rolled(rest: &[[f64; 2]], kappa: f64) -> Vec<Vector3<f64>> {
        rest.iter()
            .map(|p| {
                let (x, r) = (p[0] - 0.025, 1.0 / kappa);
                Vector3::new(r * (x / r).sin(), p[1], r * (1.0 - (x / r).cos()))
            })
            .collect()
    }

    #[test]
    fn a_rolled_sheet_stores_minus_b_kappa_r_times_its_integrated_curvature() {
        // Steiner's Σ θ|e| of the facets: the turning from the first column's facets to the last's,
        // κ (W − h), along the length L (a continuum's κ W L less the hem's half cells).
        let (rest, tris) = sheet();
        let (b, kr, kappa) = (1e-5, 4.0, 3.0);
        let term = curl(&rest, &tris, kr);
        let e = term.energy(&rolled(&rest, kappa));
        let expected = -b * kr * kappa * (0.05 - 0.01) * 0.05;
        assert!(e < 0.0, "a roll toward the curl lowers the energy: {e}");
        assert!(
            (e - expected).abs() < 0.03 * expected.abs(),
            "{e} against −Bκ_rκA = {expected}"
        );
        // Rolled the other way, the energy is as high as it was low.
        let other = term.energy(&rolled(&rest, -kappa));
        assert!((other + e).abs() < 1e-3 * e.abs(), "{other} vs {e}");
        // Flat: nothing.
        let flat: Vec<Vector3<f64>> = rest.iter().map(|p| Vector3::new(p[0], p[1], 0.0)).collect();
        assert!(term.energy(&flat).abs() < 1e-18);
    }

    #[test]
    fn gradient_and_hessian_match_finite_differences() {
        let (rest, tris) = sheet();
        let term = curl(&rest, &tris, -7.0);
        let wobble = |k: usize, a: f64| a * ((k * 7 % 5) as f64 - 2.0);
        let x: Vec<Vector3<f64>> = rolled(&rest, 9.0)
            .iter()
            .enumerate()
            .map(|(k, p)| p + Vector3::new(wobble(k, 5e-4), 0.0, wobble(k + 1, 2e-3)))
            .collect();
        let grad = |x: &[Vector3<f64>]| {
            let mut g = vec![Vector3::zeros(); x.len()];
            term.add_gradient(x, &mut g);
            g
        };
        let step = 1e-6;
        crate::physics::tests::check_gradient_scaled(&term, &x, [0, 7, 14, 20, 35], (step, 1e-6));
        // H v against the central difference of the gradient along v.
        let v: Vec<Vector3<f64>> = (0..x.len())
            .map(|k| Vector3::new(wobble(k, 1.0), wobble(k + 2, 1.0), wobble(k + 3, 1.0)))
            .collect();
        let mut h = crate::physics::HessianBlocks::default();
        term.add_hessian(&x, &mut h, crate::physics::HessianMode::NEWTON);
        let mut hv = vec![Vector3::zeros(); x.len()];
        h.mul_add(&v, &mut hv);
        let shifted =
            |t: f64| -> Vec<Vector3<f64>> { x.iter().zip(&v).map(|(a, b)| a + b * t).collect() };
        let (gp, gm) = (grad(&shifted(step)), grad(&shifted(-step)));
        let hscale = hv.iter().map(|v| v.amax()).fold(0.0, f64::max);
        for k in 0..x.len() {
            let fd = (gp[k] - gm[k]) / (2.0 * step);
            assert!(
                (fd - hv[k]).amax() < 1e-6 * hscale,
                "H v at {k}: {fd} vs {}",
                hv[k]
            );
        }
        // The projected Hessian leaves the term out.
        let mut hp = crate::physics::HessianBlocks::default();
        term.add_hessian(&x, &mut hp, crate::physics::HessianMode::Projected);
        let mut hpv = vec![Vector3::zeros(); x.len()];
        hp.mul_add(&v, &mut hpv);
        assert!(hpv.iter().all(|w| w.amax() == 0.0));
    }

    #[test]
    fn the_energy_ignores_rigid_motions() {
        let (rest, tris) = sheet();
        let term = curl(&rest, &tris, 5.0);
        let x = rolled(&rest, 8.0);
        let turn = nalgebra::Rotation3::from_euler_angles(0.3, -1.1, 2.0);
        let moved: Vec<Vector3<f64>> = x
            .iter()
            .map(|p| turn * p + Vector3::new(1.0, 2.0, -3.0))
            .collect();
        let (a, b) = (term.energy(&x), term.energy(&moved));
        assert!((a - b).abs() < 1e-12 * a.abs(), "{a} vs {b}");
    }
}
