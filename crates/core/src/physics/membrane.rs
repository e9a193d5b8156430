//! The continuum material's membrane on triangles: an orthotropic St Venant–Kirchhoff sheet over
//! any flat pattern (seed 003 §10.2's tensile and shear rigidities, in the warp frame). Per
//! triangle of rest area A, with F the deformation gradient of its rest shape in the (warp, weft)
//! frame and E = ½(FᵀF − I) its Green strain,
//!
//! W = A [½ Y_warp E₁₁² + ½ Y_weft E₂₂² + ½ G γ²],  γ = 2 E₁₂,
//!
//! so that a small stretch ε along the warp carries a force Y_warp ε per unit width (N/m) and a
//! small shear angle γ a shear force G γ — the rigidities of the grid's tensile springs and cell
//! shear. The Hessian's geometric part (the second Piola stress S as a 2 × 2 matrix times I) is
//! indefinite in compression; projected, S is clamped to its positive part, which with the
//! Gauss–Newton part leaves every block matrix positive semi-definite.

use super::kernel::{Kernel, Local, Potential};
use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};

/// Per triangle: rest area and the weights β_warp, β_weft with F e_k = Σ_i β_k,i x_i.
#[derive(Debug, Clone, Copy)]
struct RestShape {
    area_m2: f64,
    beta: [[f64; 3]; 2],
}

/// The kernel of an orthotropic membrane; coefficients per triangle [Y_warp, Y_weft, G] in N/m,
/// then its rest shape: the area A (m²) and the weights β of the deformation gradient's two
/// columns on its three vertices (1/m), so that a parameter that moves the pattern (its unit,
/// its size) has its mixed derivative here too.
pub struct MembraneKernel {
    triangles: Vec<[u32; 3]>,
    rest: Vec<RestShape>,
    rigidity_N_per_m: Vec<[f64; 3]>,
}

/// The membrane term: [`MembraneKernel`] over every triangle.
pub type Membrane = Potential<MembraneKernel, 3>;

/// Why a membrane cannot be built on a pattern.
#[derive(Debug, Clone, PartialEq)]
pub enum MembraneError {
    /// Triangle `k` has (nearly) no area in the pattern's plane.
    Degenerate(usize),
}

impl Membrane {
    /// The membrane of `triangles` over flat rest positions `rest` (m, pattern plane), warp at
    /// `warp_angle_rad` from the pattern's +x, rigidities [Y_warp, Y_weft, G] (N/m).
    pub fn new(
        rest: &[[f64; 2]],
        triangles: &[[usize; 3]],
        warp_angle_rad: f64,
        rigidity_N_per_m: [f64; 3],
    ) -> Result<Self, MembraneError> {
        let sheet = super::SewnSheet {
            rest,
            rest_triangles: triangles,
            triangles,
        };
        Self::sewn(&sheet, warp_angle_rad, rigidity_N_per_m)
    }

    /// [`Self::new`] for a sewn sheet: each triangle's rest shape from its piece (over rest
    /// vertices, a seam's vertex having one in each piece), its particles from the sheet's.
    pub fn sewn(
        sheet: &super::SewnSheet<'_>,
        warp_angle_rad: f64,
        rigidity_N_per_m: [f64; 3],
    ) -> Result<Self, MembraneError> {
        let (rest, triangles) = (sheet.rest, sheet.triangles);
        let (s, c) = warp_angle_rad.sin_cos();
        let frame = |p: [f64; 2]| Vector2::new(c * p[0] + s * p[1], -s * p[0] + c * p[1]);
        let mut shapes = Vec::with_capacity(triangles.len());
        for (k, t) in sheet.rest_triangles.iter().enumerate() {
            let [a, b, cc] = t.map(|v| frame(rest[v]));
            let dm = Matrix2::from_columns(&[b - a, cc - a]);
            let area = 0.5 * dm.determinant().abs();
            let scale = (b - a).norm_squared().max((cc - a).norm_squared());
            let inv = dm.try_inverse().filter(|_| area > 1e-12 * scale);
            let Some(inv) = inv else {
                return Err(MembraneError::Degenerate(k));
            };
            // F = [x_b − x_a, x_c − x_a] Dm⁻¹: column k weights (−inv₀ₖ − inv₁ₖ, inv₀ₖ, inv₁ₖ).
            let beta = [0, 1].map(|col| {
                let (p, q) = (inv[(0, col)], inv[(1, col)]);
                [-p - q, p, q]
            });
            shapes.push(RestShape {
                area_m2: area,
                beta,
            });
        }
        Ok(Potential::of(MembraneKernel {
            triangles: triangles.iter().map(|t| t.map(|v| v as u32)).collect(),
            rest: shapes,
            rigidity_N_per_m: vec![rigidity_N_per_m; triangles.len()],
        }))
    }
}

/// The deformation gradient's columns (warp, weft) of a triangle.
fn columns(r: &RestShape, x: &Local<3>) -> [Vector3<f64>; 2] {
    r.beta.map(|b| x[0] * b[0] + x[1] * b[1] + x[2] * b[2])
}

/// Green strain [E₁₁, E₂₂, E₁₂] from the columns.
fn green(f: &[Vector3<f64>; 2]) -> [f64; 3] {
    [
        0.5 * (f[0].norm_squared() - 1.0),
        0.5 * (f[1].norm_squared() - 1.0),
        0.5 * f[0].dot(&f[1]),
    ]
}

/// ∂E/∂x_i for vertex i: [∂E₁₁, ∂E₂₂, ∂E₁₂] as vectors.
fn strain_gradient(r: &RestShape, f: &[Vector3<f64>; 2], i: usize) -> [Vector3<f64>; 3] {
    let (b1, b2) = (r.beta[0][i], r.beta[1][i]);
    [f[0] * b1, f[1] * b2, (f[1] * b1 + f[0] * b2) * 0.5]
}

impl MembraneKernel {
    /// Second Piola stress [S₁₁, S₂₂, S₁₂] = ∂W/∂E per unit area, with rigidities `y`.
    fn stress(y: &[f64; 3], e: &[f64; 3]) -> [f64; 3] {
        [y[0] * e[0], y[1] * e[1], 4.0 * y[2] * e[2]]
    }

    /// The gradient of stencil `k` with the rigidities `y` (the mixed derivative passes dY).
    fn gradient_with(&self, k: usize, x: &Local<3>, y: &[f64; 3]) -> Local<3> {
        let r = &self.rest[k];
        let f = columns(r, x);
        let s = Self::stress(y, &green(&f));
        std::array::from_fn(|i| {
            let d = strain_gradient(r, &f, i);
            (d[0] * s[0] + d[1] * s[1] + d[2] * s[2]) * r.area_m2
        })
    }
}

/// The rest shape's change along a coefficient direction dc and what it moves: the columns f and
/// the Green strain.
struct Dc {
    area: f64,
    beta: [[f64; 3]; 2],
    f: [Vector3<f64>; 2],
    e: [f64; 3],
}

impl Dc {
    fn of(x: &Local<3>, f: &[Vector3<f64>; 2], dc: &[f64]) -> Self {
        let beta = [[dc[4], dc[5], dc[6]], [dc[7], dc[8], dc[9]]];
        let df = beta.map(|b| x[0] * b[0] + x[1] * b[1] + x[2] * b[2]);
        Dc {
            area: dc[3],
            beta,
            f: df,
            e: [
                f[0].dot(&df[0]),
                f[1].dot(&df[1]),
                0.5 * (df[0].dot(&f[1]) + f[0].dot(&df[1])),
            ],
        }
    }
}

impl Kernel<3> for MembraneKernel {
    const COEFFICIENTS: usize = 10;
    fn name(&self) -> String {
        "membrane".into()
    }
    fn stencils(&self) -> &[[u32; 3]] {
        &self.triangles
    }
    fn energy(&self, k: usize, x: &Local<3>) -> f64 {
        let r = &self.rest[k];
        let e = green(&columns(r, x));
        let y = &self.rigidity_N_per_m[k];
        r.area_m2 * (0.5 * y[0] * e[0] * e[0] + 0.5 * y[1] * e[1] * e[1] + 2.0 * y[2] * e[2] * e[2])
    }
    fn gradient(&self, k: usize, x: &Local<3>) -> Local<3> {
        self.gradient_with(k, x, &self.rigidity_N_per_m[k])
    }
    fn hessian(
        &self,
        k: usize,
        x: &Local<3>,
        project: bool,
        push: &mut impl FnMut(usize, usize, Matrix3<f64>),
    ) {
        let r = &self.rest[k];
        let y = &self.rigidity_N_per_m[k];
        let f = columns(r, x);
        let s = Self::stress(y, &green(&f));
        // The stress as a 2 × 2 matrix, clamped to its positive part when projected.
        let mut sm = Matrix2::new(s[0], 0.5 * s[2], 0.5 * s[2], s[1]);
        if project {
            let eig = sm.symmetric_eigen();
            let clamped = eig.eigenvalues.map(|v| v.max(0.0));
            sm = eig.eigenvectors * Matrix2::from_diagonal(&clamped) * eig.eigenvectors.transpose();
        }
        let d: [[Vector3<f64>; 3]; 3] = std::array::from_fn(|i| strain_gradient(r, &f, i));
        let stiff = [y[0], y[1], 4.0 * y[2]];
        for a in 0..3 {
            for b in 0..=a {
                let mut h = Matrix3::zeros();
                for m in 0..3 {
                    h += d[a][m] * d[b][m].transpose() * stiff[m];
                }
                let ba = Vector2::new(r.beta[0][a], r.beta[1][a]);
                let bb = Vector2::new(r.beta[0][b], r.beta[1][b]);
                h += Matrix3::identity() * ba.dot(&(sm * bb));
                push(a, b, h * r.area_m2);
            }
        }
    }
    fn coefficients(&self, k: usize, out: &mut Vec<f64>) {
        let r = &self.rest[k];
        out.extend(self.rigidity_N_per_m[k]);
        out.push(r.area_m2);
        out.extend(r.beta[0]);
        out.extend(r.beta[1]);
    }
    fn set_coefficients(&mut self, k: usize, c: &[f64]) {
        self.rigidity_N_per_m[k] = [c[0], c[1], c[2]];
        let r = &mut self.rest[k];
        r.area_m2 = c[3];
        r.beta = [[c[4], c[5], c[6]], [c[7], c[8], c[9]]];
    }
    /// The gradient A Σₘ (∂Eₘ/∂x) Sₘ along dc: through the stress (linear in Y and E), the strain's
    /// gradient (linear in β and the columns f) and the area.
    fn coefficient_gradient(&self, k: usize, x: &Local<3>, dc: &[f64]) -> Local<3> {
        let r = &self.rest[k];
        let y = &self.rigidity_N_per_m[k];
        let f = columns(r, x);
        let e = green(&f);
        let s = Self::stress(y, &e);
        let d = Dc::of(x, &f, dc);
        let ds: [f64; 3] = std::array::from_fn(|m| {
            Self::stress(&[dc[0], dc[1], dc[2]], &e)[m] + Self::stress(y, &d.e)[m]
        });
        std::array::from_fn(|i| {
            let g = strain_gradient(r, &f, i);
            let (b1, b2, db1, db2) = (r.beta[0][i], r.beta[1][i], d.beta[0][i], d.beta[1][i]);
            let dg = [
                d.f[0] * b1 + f[0] * db1,
                d.f[1] * b2 + f[1] * db2,
                (d.f[1] * b1 + f[1] * db1 + d.f[0] * b2 + f[0] * db2) * 0.5,
            ];
            let sum = |gm: &[Vector3<f64>; 3], sm: &[f64; 3]| -> Vector3<f64> {
                gm[0] * sm[0] + gm[1] * sm[1] + gm[2] * sm[2]
            };
            sum(&g, &s) * d.area + (sum(&dg, &s) + sum(&g, &ds)) * r.area_m2
        })
    }
    /// W = A [½ Y₁ E₁₁² + ½ Y₂ E₂₂² + 2 G E₁₂²] along dc.
    fn coefficient_energy(&self, k: usize, x: &Local<3>, dc: &[f64]) -> f64 {
        let r = &self.rest[k];
        let y = &self.rigidity_N_per_m[k];
        let f = columns(r, x);
        let e = green(&f);
        let d = Dc::of(x, &f, dc);
        let w = 0.5 * y[0] * e[0] * e[0] + 0.5 * y[1] * e[1] * e[1] + 2.0 * y[2] * e[2] * e[2];
        let dw = 0.5 * dc[0] * e[0] * e[0]
            + 0.5 * dc[1] * e[1] * e[1]
            + 2.0 * dc[2] * e[2] * e[2]
            + y[0] * e[0] * d.e[0]
            + y[1] * e[1] * d.e[1]
            + 4.0 * y[2] * e[2] * d.e[2];
        d.area * w + r.area_m2 * dw
    }
    fn stiffness_scale(&self) -> f64 {
        self.rigidity_N_per_m
            .iter()
            .flat_map(|y| y.iter().copied())
            .fold(0.0, f64::max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::EnergyTerm;

    /// Two triangles of a 2 × 1 cm rectangle.
    fn rectangle() -> (Vec<[f64; 2]>, Vec<[usize; 3]>) {
        (
            vec![[0.0, 0.0], [0.02, 0.0], [0.02, 0.01], [0.0, 0.01]],
            vec![[0, 1, 2], [0, 2, 3]],
        )
    }

    /// The whole Hessian as a dense 3n × 3n matrix, column by column (H e_k).
    fn dense(term: &dyn EnergyTerm, x: &[Vector3<f64>], project: bool) -> nalgebra::DMatrix<f64> {
        let mut h = crate::physics::HessianBlocks::default();
        let mode = match project {
            true => crate::physics::HessianMode::Projected,
            false => crate::physics::HessianMode::NEWTON,
        };
        term.add_hessian(x, &mut h, mode);
        let n = x.len();
        nalgebra::DMatrix::from_fn(3 * n, 3 * n, |r, c| {
            let mut e = vec![Vector3::zeros(); n];
            e[c / 3][c % 3] = 1.0;
            let mut y = vec![Vector3::zeros(); n];
            h.mul_add(&e, &mut y);
            y[r / 3][r % 3]
        })
    }

    /// The state the derivative checks use: stretched, sheared, lifted, one triangle compressed.
    fn bent() -> Vec<Vector3<f64>> {
        vec![
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(0.021, 0.001, 0.002),
            Vector3::new(0.0215, 0.0085, -0.001),
            Vector3::new(0.001, 0.0093, 0.003),
        ]
    }

    fn lift(rest: &[[f64; 2]]) -> Vec<Vector3<f64>> {
        rest.iter().map(|p| Vector3::new(p[0], p[1], 0.0)).collect()
    }

    #[test]
    fn gradient_and_hessian_match_finite_differences() {
        let (rest, tris) = rectangle();
        let m = Membrane::new(&rest, &tris, 0.3, [120.0, 60.0, 4.0]).unwrap();
        let x = bent();
        crate::physics::tests::check_gradient(&m, &x);
        // Each Hessian column against central differences of the gradient.
        let h = dense(&m, &x, false);
        let eps = 1e-8;
        for k in 0..12 {
            let (mut xp, mut xm) = (x.clone(), x.clone());
            xp[k / 3][k % 3] += eps;
            xm[k / 3][k % 3] -= eps;
            let (mut gp, mut gm) = (vec![Vector3::zeros(); 4], vec![Vector3::zeros(); 4]);
            m.add_gradient(&xp, &mut gp);
            m.add_gradient(&xm, &mut gm);
            for r in 0..12 {
                let fd = (gp[r / 3][r % 3] - gm[r / 3][r % 3]) / (2.0 * eps);
                assert!(
                    (fd - h[(r, k)]).abs() < 1e-5 * (1.0 + fd.abs()),
                    "H[{r},{k}] {fd} vs {}",
                    h[(r, k)]
                );
            }
        }
        assert!((h.clone() - h.transpose()).norm() < 1e-9 * h.norm());
    }

    #[test]
    fn a_uniaxial_stretch_costs_the_tensile_rigidity_and_rigid_motion_nothing() {
        let (rest, tris) = rectangle();
        let (yw, yf, g) = (120.0, 60.0, 4.0);
        let m = Membrane::new(&rest, &tris, 0.0, [yw, yf, g]).unwrap();
        let x0 = lift(&rest);
        // A rotation and a translation: no energy, no force.
        let (c, s) = (0.6f64, 0.8f64);
        let moved: Vec<Vector3<f64>> = x0
            .iter()
            .map(|p| Vector3::new(c * p.x - s * p.z + 1.0, p.y - 2.0, s * p.x + c * p.z))
            .collect();
        assert!(m.energy(&moved).abs() < 1e-18);
        // Stretched by ε along the warp (x): W = A ½ Y (ε + ½ε²)², the force on the right edge
        // Y E₁₁ (1 + ε) per unit width.
        let eps = 1e-3;
        let stretched: Vec<Vector3<f64>> = x0
            .iter()
            .map(|p| Vector3::new(p.x * (1.0 + eps), p.y, 0.0))
            .collect();
        let e11 = eps + 0.5 * eps * eps;
        let want = 0.02 * 0.01 * 0.5 * yw * e11 * e11;
        assert!(
            (m.energy(&stretched) - want).abs() < 1e-12 * want,
            "{} {want}",
            m.energy(&stretched)
        );
        let mut grad = vec![Vector3::zeros(); 4];
        m.add_gradient(&stretched, &mut grad);
        let edge_force = grad[1].x + grad[2].x;
        assert!((edge_force - yw * e11 * (1.0 + eps) * 0.01).abs() < 1e-9 * yw * 0.01);
        // The same stretch along the weft costs the weft's rigidity; with the warp turned 90° the
        // warp's.
        let along_y: Vec<Vector3<f64>> = x0
            .iter()
            .map(|p| Vector3::new(p.x, p.y * (1.0 + eps), 0.0))
            .collect();
        assert!((m.energy(&along_y) / m.energy(&stretched) - yf / yw).abs() < 1e-12);
        let turned = Membrane::new(&rest, &tris, std::f64::consts::FRAC_PI_2, [yw, yf, g]).unwrap();
        assert!((turned.energy(&along_y) / m.energy(&stretched) - 1.0).abs() < 1e-9);
    }

    #[test]
    fn a_simple_shear_costs_the_shear_rigidity_and_the_projected_hessian_is_psd() {
        let (rest, tris) = rectangle();
        let g = 4.0;
        let m = Membrane::new(&rest, &tris, 0.0, [120.0, 60.0, g]).unwrap();
        let gamma = 1e-3;
        let sheared: Vec<Vector3<f64>> = lift(&rest)
            .iter()
            .map(|p| Vector3::new(p.x + gamma * p.y, p.y, 0.0))
            .collect();
        // E₁₂ = ½γ, E₂₂ = ½γ²: W ≈ A ½ G γ² to first order in γ.
        let want = 0.02 * 0.01 * 0.5 * g * gamma * gamma;
        assert!((m.energy(&sheared) / want - 1.0).abs() < 1e-2);
        // Compressed to half along both directions: the exact Hessian is indefinite, the projected
        // one positive semi-definite.
        let squeezed: Vec<Vector3<f64>> = lift(&rest).iter().map(|p| p * 0.5).collect();
        let min_eig = |h: nalgebra::DMatrix<f64>| h.symmetric_eigen().eigenvalues.min();
        assert!(min_eig(dense(&m, &squeezed, false)) < -1e-6);
        assert!(min_eig(dense(&m, &squeezed, true)) > -1e-9);
    }

    #[test]
    fn coefficient_derivatives_match_finite_differences() {
        let (rest, tris) = rectangle();
        let mut m = Membrane::new(&rest, &tris, 0.4, [120.0, 60.0, 4.0]).unwrap();
        let x = bent();
        let c0 = m.coefficients();
        // One coefficient at a time, in every triangle: a rigidity by 1 N/m, the area by 10⁻⁴ m²,
        // a weight of the rest shape by 1 /m.
        for which in 0..10 {
            let unit = [1.0, 1.0, 1.0, 1e-4, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0][which];
            let dc: Vec<f64> = (0..c0.len())
                .map(|i| if i % 10 == which { unit } else { 0.0 })
                .collect();
            let mut g = vec![Vector3::zeros(); 4];
            assert!(m.add_coefficient_gradient(&x, &dc, &mut g));
            let de = m.coefficient_energy(&x, &dc).unwrap();
            let h = 1e-4;
            let at = |m: &mut Membrane, t: f64| {
                let c: Vec<f64> = c0.iter().zip(&dc).map(|(a, d)| a + t * d).collect();
                m.set_coefficients(&c);
                let mut g = vec![Vector3::zeros(); 4];
                m.add_gradient(&x, &mut g);
                (m.energy(&x), g)
            };
            let ((ep, gp), (em, gm)) = (at(&mut m, h), at(&mut m, -h));
            m.set_coefficients(&c0);
            let fd_e = (ep - em) / (2.0 * h);
            assert!(
                (de - fd_e).abs() < 1e-6 * de.abs().max(1e-12),
                "{which}: {de} against {fd_e}"
            );
            for p in 0..4 {
                let fd = (gp[p] - gm[p]) / (2.0 * h);
                assert!(
                    (fd - g[p]).norm() < 1e-6 * (1e-9 + fd.norm()),
                    "{which} {p}: {fd} against {}",
                    g[p]
                );
            }
        }
    }

    #[test]
    fn a_triangle_without_area_is_refused() {
        let rest = vec![[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]];
        let err = Membrane::new(&rest, &[[0, 1, 2]], 0.0, [1.0, 1.0, 1.0]).err();
        assert_eq!(err, Some(MembraneError::Degenerate(0)));
    }
}
