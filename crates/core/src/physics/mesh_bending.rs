//! Isotropic bending of a triangle mesh, quadratic in positions (Bergou et al. 2006; Wardetzky et al.
//! 2007): exact for isometric bending, with a constant Hessian. (A vertex-based cotangent Laplacian
//! was tried first and removed: it has no term at the hem's vertices, whose strip then droops
//! without rigidity and the drape does not converge with the mesh.)

use nalgebra::Vector3;
use std::collections::BTreeMap;

/// Hinge bending (Bergou et al. 2006, "A quadratic bending model for inextensible surfaces"): per
/// interior edge (x₀, x₁) with opposite vertices x₂, x₃, u = Σ Kᵢ xᵢ with
/// K = (c₀₃ + c₀₄, c₀₁ + c₀₂, −c₀₁ − c₀₃, −c₀₂ − c₀₄) (cotangents of the rest angles at the edge's ends),
/// and E = ½ k |u|², k = B/(A₀ + A₁) (so that a sheet rolled on a cylinder stores ½Bκ² per area):
/// zero for a flat sheet, and reaching every edge next to the hem.
pub fn hinge_bending(
    rest: &[[f64; 2]],
    triangles: &[[usize; 3]],
    rigidity_N_m: f64,
) -> super::QuadraticStencil<4> {
    let p3 = |v: usize| Vector3::new(rest[v][0], rest[v][1], 0.0);
    let cot = |a: Vector3<f64>, b: Vector3<f64>| a.dot(&b) / a.cross(&b).norm().max(1e-300);
    // Each undirected edge → (opposite vertex, triangle area) of its triangles.
    let mut sides: BTreeMap<(usize, usize), Vec<(usize, f64)>> = BTreeMap::new();
    for t in triangles {
        let a = 0.5 * (p3(t[1]) - p3(t[0])).cross(&(p3(t[2]) - p3(t[0]))).norm();
        for k in 0..3 {
            let (i, j, o) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
            sides.entry((i.min(j), i.max(j))).or_default().push((o, a));
        }
    }
    let (mut stencils, mut coef, mut stiff) = (Vec::new(), Vec::new(), Vec::new());
    for (&(i0, i1), opp) in &sides {
        let [(i2, a0), (i3, a1)] = opp.as_slice() else {
            continue;
        };
        let (x0, x1, x2, x3) = (p3(i0), p3(i1), p3(*i2), p3(*i3));
        let (e0, e1, e2, e3, e4) = (x1 - x0, x2 - x0, x3 - x0, x2 - x1, x3 - x1);
        let (c01, c02, c03, c04) = (cot(e0, e1), cot(e0, e2), cot(-e0, e3), cot(-e0, e4));
        stencils.push([i0, i1, *i2, *i3]);
        coef.push([c03 + c04, c01 + c02, -c01 - c03, -c02 - c04]);
        stiff.push(rigidity_N_m / (a0 + a1));
    }
    super::QuadraticStencil::from_stencils("bending/hinge", stencils, coef, stiff)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat rectangle `lx` × `ly` of `nx` × `ny` points, cells cut along alternating diagonals.
    fn sheet(nx: usize, ny: usize, lx: f64, ly: f64) -> (Vec<[f64; 2]>, Vec<[usize; 3]>) {
        let mut rest = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                rest.push([
                    lx * i as f64 / (nx - 1) as f64,
                    ly * j as f64 / (ny - 1) as f64,
                ]);
            }
        }
        let id = |i: usize, j: usize| j * nx + i;
        let mut tris = Vec::new();
        for j in 0..ny - 1 {
            for i in 0..nx - 1 {
                if (i + j) % 2 == 0 {
                    tris.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                    tris.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
                } else {
                    tris.push([id(i, j), id(i + 1, j), id(i, j + 1)]);
                    tris.push([id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
                }
            }
        }
        (rest, tris)
    }

    #[test]
    fn a_sheet_rolled_on_a_cylinder_stores_half_b_kappa_squared_per_area() {
        use crate::physics::{EnergyTerm, HessianBlocks};
        let (b, radius) = (2e-5, 0.1);
        let (nx, ny, lx, ly) = (61, 21, 0.2, 0.1);
        let (rest, tris) = sheet(nx, ny, lx, ly);
        let term = hinge_bending(&rest, &tris, b);
        let flat: Vec<Vector3<f64>> = rest.iter().map(|p| Vector3::new(p[0], p[1], 0.0)).collect();
        assert!(
            term.energy(&flat).abs() < 1e-18,
            "flat: {}",
            term.energy(&flat)
        );
        let rolled: Vec<Vector3<f64>> = rest
            .iter()
            .map(|p| {
                let t = p[0] / radius;
                Vector3::new(radius * t.sin(), p[1], radius * (1.0 - t.cos()))
            })
            .collect();
        // Every interior edge bends, so the whole sheet but a half-triangle strip at the hem counts.
        let exact = 0.5 * b / (radius * radius) * lx * ly;
        let e = term.energy(&rolled);
        assert!((e / exact - 1.0).abs() < 0.03, "{e} vs {exact}");
        // A rigid motion of the rolled sheet changes nothing; the gradient is E's derivative.
        let r = nalgebra::Rotation3::from_euler_angles(0.3, -0.2, 0.7);
        let moved: Vec<Vector3<f64>> = rolled
            .iter()
            .map(|p| r * p + Vector3::new(1.0, 2.0, 3.0))
            .collect();
        assert!((term.energy(&moved) / e - 1.0).abs() < 1e-9);
        let mut g = vec![Vector3::zeros(); rolled.len()];
        term.add_gradient(&rolled, &mut g);
        let (p, h) = (nx * 10 + 30, 1e-7);
        let mut plus = rolled.clone();
        plus[p].z += h;
        let mut minus = rolled.clone();
        minus[p].z -= h;
        let fd = (term.energy(&plus) - term.energy(&minus)) / (2.0 * h);
        assert!(
            (fd - g[p].z).abs() < 1e-6 * g[p].norm().max(1e-12),
            "{fd} vs {}",
            g[p].z
        );
        // Hessian · dx equals the gradient's change (the energy is quadratic).
        let mut hb = HessianBlocks::default();
        term.add_hessian(&rolled, &mut hb, false);
        let dx: Vec<Vector3<f64>> = (0..rolled.len())
            .map(|k| Vector3::new((k as f64).sin(), (k as f64 * 0.7).cos(), 0.1))
            .collect();
        let mut hdx = vec![Vector3::zeros(); rolled.len()];
        hb.mul_add(&dx, &mut hdx);
        let shifted: Vec<Vector3<f64>> = rolled.iter().zip(&dx).map(|(a, b)| a + b).collect();
        let mut g2 = vec![Vector3::zeros(); rolled.len()];
        term.add_gradient(&shifted, &mut g2);
        for k in 0..rolled.len() {
            assert!((g2[k] - g[k] - hdx[k]).norm() < 1e-9 * (1.0 + hdx[k].norm()));
        }
    }
}
