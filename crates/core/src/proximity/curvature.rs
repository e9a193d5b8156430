//! Analytic second derivatives of a pair's distance and of the edge–edge mollifier over the pair's
//! 12 coordinates (four vertices × xyz), for the exact curvature of a barrier κ m b(d − ξ).
//!
//! The distance between two primitives is the minimum over the closest points' free parameters λ
//! (barycentric weights on a triangle, a segment's parameter) of f(x, λ) = |r|², r = Σ cₖ(λ) xₖ with
//! cₖ affine in λ. Where the minimiser is inside its region (the features the closest points lie
//! on: a vertex, an edge's line, the triangle's plane), the envelope theorem and the implicit
//! function theorem give ∇²D = f_xx − f_xλ f_λλ⁻¹ f_λx for D = d², exact in every region
//! (ipc-toolkit's point–point, point–line, point–plane and line–line distance Hessians in one form).

use super::pair_distance;
use nalgebra::{Matrix2, SMatrix, SVector, Vector3};

type V3 = Vector3<f64>;
/// A 12 × 12 matrix over a pair's four vertices' coordinates (vertex-major, then x, y, z).
pub type Mat12 = SMatrix<f64, 12, 12>;
/// A 12-vector over a pair's four vertices' coordinates.
pub type Vec12 = SVector<f64, 12>;

/// The distance d between the pair's primitives at `x`, its gradient and its Hessian over the 12
/// coordinates (closest points moving with `x`). Exact inside each region of the closest points;
/// at a region's border d is C¹ and the Hessian is one side's.
pub fn pair_distance_hessian(point_triangle: bool, x: &[V3; 4]) -> (f64, Vec12, Mat12) {
    let (d, c) = pair_distance(point_triangle, x);
    let r: V3 = (0..4).map(|k| x[k] * c[k]).sum();
    let free = free_directions(point_triangle, &c);
    let mut gd = Vec12::zeros();
    let mut hd = Mat12::zeros();
    for k in 0..4 {
        gd.fixed_rows_mut::<3>(3 * k).copy_from(&(r * (2.0 * c[k])));
        for l in 0..4 {
            for i in 0..3 {
                hd[(3 * k + i, 3 * l + i)] = 2.0 * c[k] * c[l];
            }
        }
    }
    hd -= closest_points_motion(x, &r, &c, &free);
    // d = √D: ∇d = ∇D / 2d, ∇²d = ∇²D / 2d − ∇d ∇dᵀ / d.
    let g = gd / (2.0 * d);
    let h = hd / (2.0 * d) - g * g.transpose() / d;
    (d, g, h)
}

/// The directions Bⱼ (coefficients' change per unit of the j-th free parameter) of the closest
/// points within their region: none on a vertex, one on an edge's line, two on a triangle's plane.
fn free_directions(point_triangle: bool, c: &[f64; 4]) -> Vec<[f64; 4]> {
    let unit = |a: usize, b: usize, sa: f64| {
        let mut v = [0.0; 4];
        v[a] = sa;
        v[b] = -sa;
        v
    };
    if point_triangle {
        // c = (1, −w₀, −w₁, −w₂): with w of the first active vertex 1 − Σ the others', each other
        // active vertex's weight is a free parameter.
        let active: Vec<usize> = (1..4).filter(|&k| c[k] != 0.0).collect();
        active[1..]
            .iter()
            .map(|&a| unit(active[0], a, 1.0))
            .collect()
    } else {
        // c = (1 − s, s, −(1 − t), −t): s and t free strictly inside their segments.
        let mut out = Vec::new();
        if c[1] > 0.0 && c[1] < 1.0 {
            out.push(unit(1, 0, 1.0));
        }
        if c[3] < 0.0 && c[3] > -1.0 {
            out.push(unit(3, 2, -1.0));
        }
        out
    }
}

/// f_xλ f_λλ⁻¹ f_λx for f = |r|², r = Σ cₖ xₖ, over the free directions `free` (the part of D's
/// Hessian that the closest points' motion takes away); zero where f_λλ is singular (a collapsed
/// edge or triangle, where the region has no free parameter to move).
fn closest_points_motion(x: &[V3; 4], r: &V3, c: &[f64; 4], free: &[[f64; 4]]) -> Mat12 {
    let e: Vec<V3> = free
        .iter()
        .map(|b| (0..4).map(|k| x[k] * b[k]).sum())
        .collect();
    // f_xλ, column j, block k: 2(Bₖⱼ r + cₖ eⱼ); f_λλ = 2 eᵢ·eⱼ.
    let col = |j: usize| {
        let mut v = Vec12::zeros();
        for k in 0..4 {
            v.fixed_rows_mut::<3>(3 * k)
                .copy_from(&((r * free[j][k] + e[j] * c[k]) * 2.0));
        }
        v
    };
    match free.len() {
        1 => {
            let a = 2.0 * e[0].norm_squared();
            let v = col(0);
            if a > 0.0 {
                v * v.transpose() / a
            } else {
                Mat12::zeros()
            }
        }
        2 => {
            let m = Matrix2::new(
                e[0].norm_squared(),
                e[0].dot(&e[1]),
                e[1].dot(&e[0]),
                e[1].norm_squared(),
            ) * 2.0;
            let Some(inv) = m.try_inverse() else {
                return Mat12::zeros();
            };
            let (v0, v1) = (col(0), col(1));
            v0 * v0.transpose() * inv[(0, 0)]
                + v0 * v1.transpose() * inv[(0, 1)]
                + v1 * v0.transpose() * inv[(1, 0)]
                + v1 * v1.transpose() * inv[(1, 1)]
        }
        _ => Mat12::zeros(),
    }
}

/// The edge–edge mollifier m of [`super::edge_edge_mollifier`] (IPC, Li et al. 2020, §4.3), its
/// gradient and Hessian over the pair's 12 coordinates, or None where m = 1. With c = |eₐ × e_b|²,
/// k = `sin2`·|eₐ|²|e_b|², s = c / k and m = (2 − s)s: ∇²m = m″∇s∇sᵀ + m′∇²s,
/// ∇²s = (∇²c − ∇s∇kᵀ − ∇k∇sᵀ − s∇²k) / k.
pub fn edge_edge_mollifier_hessian(x: &[V3; 4], sin2: f64) -> Option<(f64, Vec12, Mat12)> {
    let (ea, eb) = (x[1] - x[0], x[3] - x[2]);
    let (a, b, p) = (ea.norm_squared(), eb.norm_squared(), ea.dot(&eb));
    // c = ab − p² identically; the cross product's norm keeps its digits near parallel.
    let c = ea.cross(&eb).norm_squared();
    let k = sin2 * a * b;
    if c >= k || k <= 0.0 {
        return None;
    }
    let s = c / k;
    // Over (eₐ, e_b) ∈ ℝ⁶.
    let stack = |u: V3, v: V3| SVector::<f64, 6>::from_iterator(u.iter().chain(v.iter()).copied());
    let gc = stack(
        ea * (2.0 * b) - eb * (2.0 * p),
        eb * (2.0 * a) - ea * (2.0 * p),
    );
    let gk = stack(ea * (2.0 * sin2 * b), eb * (2.0 * sin2 * a));
    let eye = nalgebra::Matrix3::<f64>::identity();
    let mut hc = SMatrix::<f64, 6, 6>::zeros();
    let mut hk = SMatrix::<f64, 6, 6>::zeros();
    let cross = ea * eb.transpose() * 4.0 - eb * ea.transpose() * 2.0 - eye * (2.0 * p);
    hc.fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&(eye * (2.0 * b) - eb * eb.transpose() * 2.0));
    hc.fixed_view_mut::<3, 3>(3, 3)
        .copy_from(&(eye * (2.0 * a) - ea * ea.transpose() * 2.0));
    hc.fixed_view_mut::<3, 3>(0, 3).copy_from(&cross);
    hc.fixed_view_mut::<3, 3>(3, 0)
        .copy_from(&cross.transpose());
    hk.fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&(eye * (2.0 * sin2 * b)));
    hk.fixed_view_mut::<3, 3>(3, 3)
        .copy_from(&(eye * (2.0 * sin2 * a)));
    let kc = ea * eb.transpose() * (4.0 * sin2);
    hk.fixed_view_mut::<3, 3>(0, 3).copy_from(&kc);
    hk.fixed_view_mut::<3, 3>(3, 0).copy_from(&kc.transpose());
    let gs = (gc - gk * s) / k;
    let hs = (hc - gs * gk.transpose() - gk * gs.transpose() - hk * s) / k;
    let (dm, ddm) = (2.0 - 2.0 * s, -2.0);
    let (g6, h6) = (gs * dm, gs * gs.transpose() * ddm + hs * dm);
    // eₐ = x₁ − x₀, e_b = x₃ − x₂.
    let mut sel = SMatrix::<f64, 6, 12>::zeros();
    for i in 0..3 {
        sel[(i, i)] = -1.0;
        sel[(i, 3 + i)] = 1.0;
        sel[(3 + i, 6 + i)] = -1.0;
        sel[(3 + i, 9 + i)] = 1.0;
    }
    Some((
        (2.0 - s) * s,
        sel.transpose() * g6,
        sel.transpose() * h6 * sel,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::proximity::edge_edge_mollifier;

    fn v(x: f64, y: f64, z: f64) -> V3 {
        V3::new(x, y, z)
    }

    /// The gradient of d by its closed form (closest-point coefficients fixed).
    fn distance_gradient(pt: bool, x: &[V3; 4]) -> Vec12 {
        let (d, c) = pair_distance(pt, x);
        let r: V3 = (0..4).map(|k| x[k] * c[k]).sum();
        Vec12::from_iterator(
            (0..4).flat_map(|k| (r * (c[k] / d)).iter().copied().collect::<Vec<_>>()),
        )
    }

    /// Central differences of `grad` over the 12 coordinates, step `h`.
    fn fd_jacobian(x: &[V3; 4], h: f64, grad: impl Fn(&[V3; 4]) -> Vec12) -> Mat12 {
        let mut out = Mat12::zeros();
        for j in 0..12 {
            let (mut p, mut m) = (*x, *x);
            p[j / 3][j % 3] += h;
            m[j / 3][j % 3] -= h;
            out.set_column(j, &((grad(&p) - grad(&m)) / (2.0 * h)));
        }
        out
    }

    fn assert_close(a: &Mat12, b: &Mat12, tol: f64, what: &str) {
        let err = (a - b).abs().max() / b.abs().max().max(1e-300);
        assert!(err < tol, "{what}: relative error {err:e}\n{a}\n{b}");
    }

    /// Point–triangle pairs with the closest point on the face, on each edge and at each vertex,
    /// and edge–edge pairs inside both segments, clamped on one and on both.
    fn configurations() -> Vec<(bool, [V3; 4], &'static str)> {
        let tri = [v(0.0, 0.0, 0.0), v(1.0, 0.1, 0.05), v(0.2, 0.9, -0.1)];
        let pts = [
            (v(0.3, 0.3, 0.4), "face"),
            (v(0.5, -0.4, 0.3), "edge 01"),
            (v(0.9, 0.8, 0.2), "edge 12"),
            (v(-0.4, 0.5, 0.2), "edge 20"),
            (v(-0.5, -0.5, 0.3), "vertex 0"),
            (v(1.6, 0.0, 0.1), "vertex 1"),
            (v(0.2, 1.7, 0.3), "vertex 2"),
        ];
        let mut out: Vec<_> = pts
            .into_iter()
            .map(|(p, what)| (true, [p, tri[0], tri[1], tri[2]], what))
            .collect();
        let a = [v(0.0, 0.0, 0.0), v(1.0, 0.2, 0.0)];
        for (b, what) in [
            ([v(0.4, -0.5, 0.3), v(0.6, 0.7, 0.35)], "edges inside"),
            ([v(1.4, -0.5, 0.3), v(1.5, 0.7, 0.35)], "edges one clamped"),
            ([v(1.4, 0.5, 0.3), v(2.5, 0.7, 0.35)], "edges both clamped"),
        ] {
            out.push((false, [a[0], a[1], b[0], b[1]], what));
        }
        out
    }

    #[test]
    fn the_distance_hessian_is_the_central_difference_of_its_gradient_in_every_region() {
        for (pt, x, what) in configurations() {
            let (d, g, h) = pair_distance_hessian(pt, &x);
            assert!((d - pair_distance(pt, &x).0).abs() < 1e-15, "{what}");
            assert!((g - distance_gradient(pt, &x)).norm() < 1e-12, "{what}");
            let fd = fd_jacobian(&x, 1e-6, |y| distance_gradient(pt, y));
            assert_close(&h, &fd, 1e-6, what);
            assert_close(&h, &h.transpose(), 1e-14, what);
        }
    }

    #[test]
    fn a_point_over_a_face_has_no_curvature_and_over_a_vertex_that_of_a_sphere() {
        // Over the face d is affine in the point (its height above the plane): no curvature there.
        let x = [
            v(0.3, 0.3, 0.4),
            v(0.0, 0.0, 0.0),
            v(1.0, 0.0, 0.0),
            v(0.0, 1.0, 0.0),
        ];
        let (_, _, h) = pair_distance_hessian(true, &x);
        assert!(h.fixed_view::<3, 3>(0, 0).abs().max() < 1e-12);
        // Two points: ∇²d = (I − n nᵀ)/d on the first point.
        let x = [
            v(0.0, 0.0, 0.5),
            v(-0.5, -0.5, 0.0),
            v(-1.0, -0.2, 0.0),
            v(-0.2, -1.0, 0.0),
        ];
        let (d, g, h) = pair_distance_hessian(true, &x);
        let n = g.fixed_rows::<3>(0).into_owned();
        let want = (nalgebra::Matrix3::identity() - n * n.transpose()) / d;
        assert!((h.fixed_view::<3, 3>(0, 0) - want).abs().max() < 1e-12);
    }

    #[test]
    fn the_mollifier_hessian_is_the_central_difference_of_its_gradient() {
        let sin2 = 1e-3;
        let grad = |y: &[V3; 4]| {
            let (_, g) = edge_edge_mollifier(y, sin2).expect("mollified");
            Vec12::from_iterator(g.iter().flat_map(|v| v.iter().copied().collect::<Vec<_>>()))
        };
        for (phi, tilt) in [(0.01, 0.0), (0.02, 0.005), (0.005, -0.01)] {
            let x = [
                v(0.0, 0.0, 0.0),
                v(1.0, 0.0, 0.0),
                v(0.3, -0.5 * phi, 0.1),
                v(1.3, 0.5 * phi, 0.1 + tilt),
            ];
            let (m, g, h) = edge_edge_mollifier_hessian(&x, sin2).expect("mollified");
            let (m0, _) = edge_edge_mollifier(&x, sin2).expect("mollified");
            assert!((m - m0).abs() < 1e-14);
            assert!((g - grad(&x)).norm() <= 1e-10 * g.norm());
            assert_close(&h, &fd_jacobian(&x, 1e-7, grad), 1e-5, "mollifier");
        }
    }
}
