//! Bending of a triangle mesh from each triangle's quadratic patch: the plate's curvatures
//! κ₁₁, κ₂₂, κ₁₂ (warp, weft, twist) on a triangle are the second derivatives of the quadratic that
//! interpolates six particles around it — its corners and the three across its edges (Oñate and
//! Zárate's rotation-free plate triangle; further neighbours at a hem) — and the triangle stores
//! the orthotropic plate's ½ A (B_warp |x₁₁|² + B_weft |x₂₂|² + 2 B_t |x₁₂|²), the energy density of
//! the grid's finite-volume bending (seed 003 eq. 10.5 with Poisson's ratio 0). Each xₐᵦ is a fixed
//! combination of the six positions, so the energy is quadratic with a constant Hessian, and for
//! an isometric bending xₐᵦ = IIₐᵦ n exactly: the plate on any mesh whose patches hold a quadratic.

use super::mesh_bending::{SewnSheet, unfolded};
use nalgebra::{DMatrix, Matrix6, Vector3};
use std::collections::{BTreeMap, BTreeSet};

/// A patch is accepted when its scaled Vandermonde matrix keeps its smallest singular value above
/// this (the six points hold a quadratic well, not near one conic).
const UNISOLVENT: f64 = 1e-3;

/// Neighbour rings searched at a hem for the points a triangle's patch lacks.
const HEM_RINGS: usize = 3;

/// Patch bending of a sewn sheet with rigidities [B_warp, B_weft, B_t] (N·m), the warp at
/// `warp_angle_rad` from the pattern's +x: per triangle one stencil per curvature whose B is not
/// zero. A seam's neighbour is unfolded beside the triangle as the hinges' is. None where a
/// triangle has no six points that hold a quadratic around it (a pattern one or two triangles
/// wide): hinges bend such a sheet.
pub fn patch_bending(
    sheet: &SewnSheet<'_>,
    rigidity_N_m: [f64; 3],
    warp_angle_rad: f64,
) -> Option<super::QuadraticStencil<6>> {
    let (mut stencils, mut coef, mut stiff) = (Vec::new(), Vec::new(), Vec::new());
    let near = Neighbours::of(sheet);
    for t in 0..sheet.triangles.len() {
        let points = near.patch(sheet, t)?;
        let (area, weights) = curvature_weights(sheet, t, &points, warp_angle_rad);
        let particles = std::array::from_fn(|m| points[m].0);
        for (c, b) in rigidity_N_m.iter().enumerate() {
            if *b > 0.0 {
                stencils.push(particles);
                coef.push(weights[c]);
                stiff.push(area * b * if c == 2 { 2.0 } else { 1.0 });
            }
        }
    }
    Some(super::QuadraticStencil::from_stencils(
        "bending/patch",
        stencils,
        coef,
        stiff,
    ))
}

/// How far a crease may be misread: the tangential and twist parts of the curvature a patch
/// reads from a crease along one of its triangle's edges, against its normal part. A grid split
/// along one diagonal misreads none uniform and 0.08 graded to a 5.8× spacing ratio; alternating
/// diagonals misread their diagonal creases wholly (1.0), the bundled ring mesh up to 4.4.
const CREASE_FIDELITY: f64 = 0.25;

/// Whether every patch reads a crease along each of its triangle's interior edges as curvature
/// across that edge (a fold of the sheet about the edge, z = max(0, distance beyond it), seen
/// within [`CREASE_FIDELITY`] as x_nn with no x_ττ or x_nτ). Six interpolating points cannot tell
/// a crease along an edge from the quadratics through the same values: on a grid split along one
/// diagonal they read it exactly, but on alternating diagonals a crease along a diagonal is read
/// as pure twist, and a twist-free plate (seed 003's KES keys have no twist rigidity) then folds
/// there for nothing. Where this is false, hinges, which charge every crease, bend the sheet;
/// false too where a triangle has no patch (a pattern one or two triangles wide).
pub fn reads_creases(sheet: &SewnSheet<'_>) -> bool {
    let near = Neighbours::of(sheet);
    (0..sheet.triangles.len()).all(|t| {
        let Some(points) = near.patch(sheet, t) else {
            return false;
        };
        let (_, w) = curvature_weights(sheet, t, &points, 0.0);
        (0..3).all(|k| match near.across(sheet, t, k) {
            Some((_, q)) => reads_crease(sheet, t, k, q, &points, &w),
            None => true,
        })
    })
}

/// [`reads_creases`] for the crease along edge k of triangle t, folding towards `q`.
fn reads_crease(
    sheet: &SewnSheet<'_>,
    t: usize,
    k: usize,
    q: [f64; 2],
    points: &[(usize, [f64; 2])],
    w: &[[f64; 6]; 3],
) -> bool {
    let r = sheet.rest_triangles[t];
    let (a, b) = (sheet.rest[r[k]], sheet.rest[r[(k + 1) % 3]]);
    let len = (b[0] - a[0]).hypot(b[1] - a[1]);
    let tau = [(b[0] - a[0]) / len, (b[1] - a[1]) / len];
    let mut n = [-tau[1], tau[0]];
    if (q[0] - a[0]) * n[0] + (q[1] - a[1]) * n[1] < 0.0 {
        n = [tau[1], -tau[0]];
    }
    let fold: Vec<f64> = points
        .iter()
        .map(|p| ((p.1[0] - a[0]) * n[0] + (p.1[1] - a[1]) * n[1]).max(0.0))
        .collect();
    let h = |c: usize| (0..6).map(|m| w[c][m] * fold[m]).sum::<f64>();
    let (h11, h22, h12) = (h(0), h(1), h(2));
    let along = |u: [f64; 2], v: [f64; 2]| {
        h11 * u[0] * v[0] + h12 * (u[0] * v[1] + u[1] * v[0]) + h22 * u[1] * v[1]
    };
    along(tau, tau).abs() + along(n, tau).abs() <= CREASE_FIDELITY * along(n, n).abs()
}

/// Which triangles share each particle edge and each rest vertex.
struct Neighbours {
    by_edge: BTreeMap<(usize, usize), Vec<usize>>,
    by_rest: Vec<Vec<usize>>,
}

impl Neighbours {
    fn of(sheet: &SewnSheet<'_>) -> Self {
        let mut by_edge: BTreeMap<(usize, usize), Vec<usize>> = BTreeMap::new();
        let mut by_rest = vec![Vec::new(); sheet.rest.len()];
        for (t, (p, r)) in sheet.triangles.iter().zip(sheet.rest_triangles).enumerate() {
            for k in 0..3 {
                let (i, j) = (p[k], p[(k + 1) % 3]);
                by_edge.entry((i.min(j), i.max(j))).or_default().push(t);
                by_rest[r[k]].push(t);
            }
        }
        Self { by_edge, by_rest }
    }

    /// Six (particle, rest position) around triangle `t`: its corners, the vertices across its
    /// edges, then the nearest of its rest neighbours within [`HEM_RINGS`] rings, each taken only
    /// where it keeps the points unisolvent for a quadratic; None where fewer than six are found.
    fn patch(&self, sheet: &SewnSheet<'_>, t: usize) -> Option<Vec<(usize, [f64; 2])>> {
        let (p, r) = (sheet.triangles[t], sheet.rest_triangles[t]);
        let corner = |k: usize| (p[k], sheet.rest[r[k]]);
        let mut candidates: Vec<(usize, [f64; 2])> = (0..3).map(corner).collect();
        for k in 0..3 {
            if let Some(across) = self.across(sheet, t, k) {
                candidates.push(across);
            }
        }
        let centre = centroid(sheet, t);
        candidates.extend(self.rings(sheet, t, centre));
        let mut chosen: Vec<(usize, [f64; 2])> = Vec::new();
        let scale = area_of(sheet, t).sqrt();
        for c in candidates {
            if chosen.len() == 6 || chosen.iter().any(|q| q.0 == c.0) {
                continue;
            }
            chosen.push(c);
            if smallest_singular(&chosen, centre, scale) < UNISOLVENT {
                chosen.pop();
            }
        }
        (chosen.len() == 6).then_some(chosen)
    }

    /// The vertex across edge k of triangle t (from corner k to k + 1), in t's rest plane.
    fn across(&self, sheet: &SewnSheet<'_>, t: usize, k: usize) -> Option<(usize, [f64; 2])> {
        let (p, r) = (sheet.triangles[t], sheet.rest_triangles[t]);
        let (i, j) = (p[k], p[(k + 1) % 3]);
        let u = *self.by_edge[&(i.min(j), i.max(j))]
            .iter()
            .find(|&&u| u != t)?;
        let (pu, ru) = (sheet.triangles[u], sheet.rest_triangles[u]);
        let slot = |v: usize| pu.iter().position(|&q| q == v).expect("shared edge");
        let o = (0..3).find(|&m| pu[m] != i && pu[m] != j)?;
        let p3 = |q: [f64; 2]| Vector3::new(q[0], q[1], 0.0);
        let mine = [r[k], r[(k + 1) % 3], r[(k + 2) % 3]].map(|v| p3(sheet.rest[v]));
        let theirs = [ru[slot(i)], ru[slot(j)], ru[o]].map(|v| p3(sheet.rest[v]));
        let at = unfolded(&mine, &theirs);
        Some((pu[o], [at.x, at.y]))
    }

    /// The rest vertices of t's piece within [`HEM_RINGS`] rings of its corners, nearest first.
    fn rings(&self, sheet: &SewnSheet<'_>, t: usize, centre: [f64; 2]) -> Vec<(usize, [f64; 2])> {
        let mut seen: BTreeSet<usize> = sheet.rest_triangles[t].into_iter().collect();
        let mut front: Vec<usize> = seen.iter().copied().collect();
        for _ in 0..HEM_RINGS {
            let mut next = Vec::new();
            for v in front {
                for &u in &self.by_rest[v] {
                    for w in sheet.rest_triangles[u] {
                        if seen.insert(w) {
                            next.push(w);
                        }
                    }
                }
            }
            front = next;
        }
        let particle = |w: usize| -> usize {
            self.by_rest[w]
                .iter()
                .find_map(|&u| {
                    let m = sheet.rest_triangles[u].iter().position(|&q| q == w)?;
                    Some(sheet.triangles[u][m])
                })
                .expect("a rest vertex of a triangle")
        };
        let mut out: Vec<(f64, usize, [f64; 2])> = seen
            .into_iter()
            .map(|w| {
                let q = sheet.rest[w];
                let d = (q[0] - centre[0]).hypot(q[1] - centre[1]);
                (d, particle(w), q)
            })
            .collect();
        out.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        out.into_iter().map(|(_, p, q)| (p, q)).collect()
    }
}

fn area_of(sheet: &SewnSheet<'_>, t: usize) -> f64 {
    let [a, b, c] = sheet.rest_triangles[t].map(|v| sheet.rest[v]);
    0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])).abs()
}

fn centroid(sheet: &SewnSheet<'_>, t: usize) -> [f64; 2] {
    let [a, b, c] = sheet.rest_triangles[t].map(|v| sheet.rest[v]);
    [(a[0] + b[0] + c[0]) / 3.0, (a[1] + b[1] + c[1]) / 3.0]
}

/// The quadratic basis (1, s, t, s²/2, st, t²/2) at a point, its coordinates taken from `centre`
/// in units of `scale`.
fn basis(q: [f64; 2], centre: [f64; 2], scale: f64) -> [f64; 6] {
    let (s, t) = ((q[0] - centre[0]) / scale, (q[1] - centre[1]) / scale);
    [1.0, s, t, 0.5 * s * s, s * t, 0.5 * t * t]
}

/// The smallest singular value of the points' basis rows.
fn smallest_singular(points: &[(usize, [f64; 2])], centre: [f64; 2], scale: f64) -> f64 {
    let rows: Vec<f64> = points
        .iter()
        .flat_map(|p| basis(p.1, centre, scale))
        .collect();
    let m = DMatrix::from_row_slice(points.len(), 6, &rows);
    m.singular_values().min()
}

/// The triangle's rest area (m²) and, per curvature (warp, weft, twist), the weights wₘ with
/// xₐᵦ = Σ wₘ xₘ over the six points: rows of the inverse of their basis in the warp frame.
fn curvature_weights(
    sheet: &SewnSheet<'_>,
    t: usize,
    points: &[(usize, [f64; 2])],
    warp_angle_rad: f64,
) -> (f64, [[f64; 6]; 3]) {
    let area = area_of(sheet, t);
    let (scale, centre) = (area.sqrt(), centroid(sheet, t));
    let (ws, wc) = warp_angle_rad.sin_cos();
    // Rest coordinates along the warp and the weft, about the centroid.
    let frame = |q: [f64; 2]| {
        let (dx, dy) = (q[0] - centre[0], q[1] - centre[1]);
        [dx * wc + dy * ws, -dx * ws + dy * wc]
    };
    let v = Matrix6::from_fn(|m, c| basis(frame(points[m].1), [0.0, 0.0], scale)[c]);
    let inv = v.try_inverse().expect("a unisolvent patch");
    let row = |c: usize| std::array::from_fn(|m| inv[(c, m)] / (scale * scale));
    (area, [row(3), row(5), row(4)])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::EnergyTerm;
    use crate::physics::testing::grid;

    /// A sheet laid on a quadratic surface z = ½ (a s² + 2 b s t + c t²) in the warp frame stores
    /// exactly ½ A (B_warp a² + B_weft c² + 2 B_t b²) over every triangle whose patch lies on it
    /// (the plate to second order, each curvature with its own rigidity), on either triangulation,
    /// turned or not; a flat sheet moved rigidly stores nothing.
    #[test]
    fn a_sheet_on_a_quadratic_surface_stores_the_plates_energy() {
        let (b, h, n) = ([3e-5, 1e-5, 0.7e-5], 0.004, 12);
        for alternate in [false, true] {
            for warp in [0.0, 0.4] {
                let (rest, tris) = grid(n, h, alternate);
                let sheet = SewnSheet {
                    rest: &rest,
                    rest_triangles: &tris,
                    triangles: &tris,
                };
                let term = patch_bending(&sheet, b, warp).expect("a grid has patches");
                let (ws, wc) = f64::sin_cos(warp);
                let (ka, kb, kc) = (12.0, -5.0, 7.0);
                let x: Vec<Vector3<f64>> = rest
                    .iter()
                    .map(|q| {
                        let (s, t) = (q[0] * wc + q[1] * ws, -q[0] * ws + q[1] * wc);
                        Vector3::new(
                            q[0],
                            q[1],
                            0.5 * (ka * s * s + 2.0 * kb * s * t + kc * t * t),
                        )
                    })
                    .collect();
                let area = ((n - 1) as f64 * h).powi(2);
                let plate = 0.5 * area * (b[0] * ka * ka + b[1] * kc * kc + 2.0 * b[2] * kb * kb);
                let e = term.energy(&x);
                assert!(
                    (e - plate).abs() < 1e-9 * plate,
                    "alternate {alternate}, warp {warp}: {e} against {plate}"
                );
                let moved: Vec<Vector3<f64>> = rest
                    .iter()
                    .map(|q| {
                        Vector3::new(0.6 * q[0] - 0.8 * q[1] + 1.0, 0.8 * q[0] + 0.6 * q[1], 2.0)
                    })
                    .collect();
                assert!(term.energy(&moved) < 1e-12 * plate);
                crate::physics::tests::check_gradient(&term, &x);
            }
        }
    }

    /// A grid split along one diagonal reads creases, uniform or graded (a 5.8× spacing ratio
    /// across it); one with alternating
    /// diagonals does not (a crease along a diagonal is read as twist).
    #[test]
    fn patches_read_creases_on_one_diagonal_only() {
        for (alternate, reads) in [(false, true), (true, false)] {
            let (rest, tris) = grid(9, 0.01, alternate);
            let sheet = SewnSheet {
                rest: &rest,
                rest_triangles: &tris,
                triangles: &tris,
            };
            assert_eq!(reads_creases(&sheet), reads, "alternate {alternate}");
        }
        let (mut rest, tris) = grid(9, 0.01, false);
        rest.iter_mut()
            .for_each(|q| *q = [q[0] * q[0] * 30.0 + q[0], q[1] + 20.0 * q[1] * q[1]]);
        let sheet = SewnSheet {
            rest: &rest,
            rest_triangles: &tris,
            triangles: &tris,
        };
        assert!(reads_creases(&sheet), "graded");
    }
}

#[cfg(test)]
mod narrow {
    use super::*;

    /// Patterns one or two triangles wide (one triangle, two, a strip) have no six points that hold
    /// a quadratic around each triangle: no patch bending and no crease reading (hinges bend
    /// them), where a pattern three triangles wide has both.
    #[test]
    fn patterns_without_six_points_around_a_triangle_have_no_patch_bending() {
        let strip = |cells: usize| {
            let rest: Vec<[f64; 2]> = (0..=cells)
                .flat_map(|i| [[i as f64 * 0.01, 0.0], [i as f64 * 0.01, 0.01]])
                .collect();
            let tris: Vec<[usize; 3]> = (0..cells)
                .flat_map(|i| [[2 * i, 2 * i + 2, 2 * i + 3], [2 * i, 2 * i + 3, 2 * i + 1]])
                .collect();
            (rest, tris)
        };
        let one = (vec![[0.0, 0.0], [0.01, 0.0], [0.0, 0.01]], vec![[0, 1, 2]]);
        let two = strip(1);
        for (rest, tris) in [one, two, strip(6)] {
            let sheet = SewnSheet {
                rest: &rest,
                rest_triangles: &tris,
                triangles: &tris,
            };
            assert!(patch_bending(&sheet, [1e-5, 1e-5, 1e-5], 0.0).is_none());
            assert!(!reads_creases(&sheet));
        }
        let (rest, tris) = crate::physics::testing::grid(4, 0.01, false);
        let sheet = SewnSheet {
            rest: &rest,
            rest_triangles: &tris,
            triangles: &tris,
        };
        assert!(patch_bending(&sheet, [1e-5, 1e-5, 1e-5], 0.0).is_some());
    }
}
