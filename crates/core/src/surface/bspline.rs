//! Bicubic B-spline interpolation of a grid of points (seed 003 §10.8): a tensor-product surface
//! through every node, its knots from the nodes' parameters by averaging (Piegl & Tiller, The NURBS
//! Book, Eq. 9.8), the interpolation systems solved per direction (Eq. 9.4 row by row, then column by
//! column). Cubic with simple interior knots: C² everywhere, so curvature has no jump across a knot.

use nalgebra::{DMatrix, DVector, Vector3};

/// How the nodes' parameters are spaced along a direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Parametrization {
    /// Equidistant parameters (the seed's choice): uniform interior knots.
    Uniform,
    /// Parameters proportional to the accumulated chord length, averaged over the grid's lines.
    ChordLength,
}

/// A clamped cubic B-spline basis on [0, 1].
#[derive(Debug, Clone, PartialEq)]
pub struct Basis {
    /// Knot vector, 4 zeros and 4 ones at the ends.
    pub knots: Vec<f64>,
    /// Number of basis functions (= control points).
    pub n: usize,
}

const DEGREE: usize = 3;

impl Basis {
    /// The basis interpolating at the parameters `u` (increasing, from 0 to 1, at least 2): knots by
    /// averaging every 3 consecutive interior parameters. Two or three parameters give a lower-order
    /// fit of the same cubic form (its knots are the clamped ends only).
    pub fn interpolating(u: &[f64]) -> Self {
        let n = u.len();
        let mut knots = vec![0.0; DEGREE + 1];
        for j in 1..n.saturating_sub(DEGREE) {
            knots.push(u[j..j + DEGREE].iter().sum::<f64>() / DEGREE as f64);
        }
        knots.extend([1.0; DEGREE + 1]);
        Self {
            n: knots.len() - DEGREE - 1,
            knots,
        }
    }

    /// The knot span holding `t`: the index s with knots[s] ≤ t < knots[s+1] (the last span at t = 1).
    fn span(&self, t: f64) -> usize {
        let last = self.n - 1;
        if t >= self.knots[self.n] {
            return last;
        }
        let (mut lo, mut hi) = (DEGREE, self.n);
        while hi - lo > 1 {
            let mid = (lo + hi) / 2;
            if t < self.knots[mid] {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        lo
    }

    /// The span s and the values and first two derivatives of the 4 basis functions s−3..=s at `t`
    /// (The NURBS Book, algorithm A2.3).
    pub fn eval(&self, t: f64) -> (usize, [[f64; 4]; 3]) {
        let t = t.clamp(0.0, 1.0);
        let s = self.span(t);
        let k = &self.knots;
        // ndu: triangular table of basis values (upper) and knot differences (lower).
        let mut ndu = [[0.0f64; 4]; 4];
        let (mut left, mut right) = ([0.0f64; 4], [0.0f64; 4]);
        ndu[0][0] = 1.0;
        for j in 1..=DEGREE {
            left[j] = t - k[s + 1 - j];
            right[j] = k[s + j] - t;
            let mut saved = 0.0;
            for r in 0..j {
                ndu[j][r] = right[r + 1] + left[j - r];
                let temp = if ndu[j][r] == 0.0 {
                    0.0
                } else {
                    ndu[r][j - 1] / ndu[j][r]
                };
                ndu[r][j] = saved + right[r + 1] * temp;
                saved = left[j - r] * temp;
            }
            ndu[j][j] = saved;
        }
        let mut ders = [[0.0f64; 4]; 3];
        for (j, d) in ders[0].iter_mut().enumerate() {
            *d = ndu[j][DEGREE];
        }
        for r in 0..=DEGREE {
            let mut a = [[0.0f64; 4]; 2];
            let (mut s1, mut s2) = (0usize, 1usize);
            a[0][0] = 1.0;
            for kk in 1..=2usize {
                let mut d = 0.0;
                let rk = r as isize - kk as isize;
                let pk = DEGREE - kk;
                if r >= kk {
                    let den = ndu[pk + 1][rk as usize];
                    a[s2][0] = if den == 0.0 { 0.0 } else { a[s1][0] / den };
                    d = a[s2][0] * ndu[rk as usize][pk];
                }
                let j1 = if rk >= -1 { 1 } else { (-rk) as usize };
                let j2 = if r as isize - 1 <= pk as isize {
                    kk - 1
                } else {
                    DEGREE - r
                };
                for j in j1..=j2 {
                    let idx = (rk + j as isize) as usize;
                    let den = ndu[pk + 1][idx];
                    a[s2][j] = if den == 0.0 {
                        0.0
                    } else {
                        (a[s1][j] - a[s1][j - 1]) / den
                    };
                    d += a[s2][j] * ndu[idx][pk];
                }
                if r <= pk {
                    let den = ndu[pk + 1][r];
                    a[s2][kk] = if den == 0.0 {
                        0.0
                    } else {
                        -a[s1][kk - 1] / den
                    };
                    d += a[s2][kk] * ndu[r][pk];
                }
                ders[kk][r] = d;
                std::mem::swap(&mut s1, &mut s2);
            }
        }
        let mut f = DEGREE as f64;
        for d in ders.iter_mut().skip(1) {
            d.iter_mut().for_each(|v| *v *= f);
            f *= (DEGREE - 1) as f64;
        }
        (s, ders)
    }

    /// The collocation matrix N[i][j] = N_j(u_i).
    fn collocation(&self, u: &[f64]) -> DMatrix<f64> {
        let mut m = DMatrix::zeros(u.len(), self.n);
        for (i, &t) in u.iter().enumerate() {
            let (s, d) = self.eval(t);
            for (r, v) in d[0].iter().enumerate() {
                if let Some(j) = (s + r).checked_sub(DEGREE).filter(|&j| j < self.n) {
                    m[(i, j)] = *v;
                }
            }
        }
        m
    }
}

/// A bicubic tensor-product B-spline surface S(u, v) on [0, 1]², u along the grid's i (x, warp) and v
/// along its j (y, weft).
#[derive(Debug, Clone, PartialEq)]
pub struct BSplineSurface {
    /// Basis along u.
    pub bu: Basis,
    /// Basis along v.
    pub bv: Basis,
    /// Control points, `ctrl[j * bu.n + i]`, m.
    pub ctrl: Vec<Vector3<f64>>,
    /// The nodes' parameters along u and v.
    pub params: (Vec<f64>, Vec<f64>),
}

/// Parameters of `n` nodes along a direction: uniform, or by chord length averaged over the lines.
fn parameters(lines: &[Vec<Vector3<f64>>], kind: Parametrization) -> Vec<f64> {
    let n = lines[0].len();
    let uniform = || {
        (0..n)
            .map(|i| i as f64 / (n - 1) as f64)
            .collect::<Vec<_>>()
    };
    if kind == Parametrization::Uniform {
        return uniform();
    }
    let mut acc = vec![0.0; n];
    let mut used = 0;
    for l in lines {
        let total: f64 = l.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
        if total <= 0.0 {
            continue;
        }
        used += 1;
        let mut s = 0.0;
        for i in 1..n {
            s += (l[i] - l[i - 1]).norm();
            acc[i] += s / total;
        }
    }
    if used == 0 {
        return uniform();
    }
    acc.iter_mut().for_each(|a| *a /= used as f64);
    acc[n - 1] = 1.0;
    acc
}

/// Solves N c = q for each of the point lists `rhs` (one per line) with one LU factorization.
fn solve_lines(
    basis: &Basis,
    u: &[f64],
    rhs: &[Vec<Vector3<f64>>],
) -> Option<Vec<Vec<Vector3<f64>>>> {
    let lu = basis.collocation(u).lu();
    rhs.iter()
        .map(|q| {
            let mut out = vec![Vector3::zeros(); basis.n];
            for c in 0..3 {
                let b = DVector::from_iterator(q.len(), q.iter().map(|p| p[c]));
                let x = lu.solve(&b)?;
                for (o, v) in out.iter_mut().zip(x.iter()) {
                    o[c] = *v;
                }
            }
            Some(out)
        })
        .collect()
}

/// For fewer than four parameters `u`, the lines' Lagrange polynomial (degree 1 or 2 in the
/// parameter) sampled at thirds (two nodes) or also at the midpoints (three); otherwise unchanged.
fn densify(u: &[f64], lines: Vec<Vec<Vector3<f64>>>) -> (Vec<f64>, Vec<Vec<Vector3<f64>>>) {
    let t: Vec<f64> = match u {
        [a, b] => vec![*a, a + (b - a) / 3.0, a + 2.0 * (b - a) / 3.0, *b],
        [a, b, c] => vec![*a, (a + b) / 2.0, *b, (b + c) / 2.0, *c],
        _ => return (u.to_vec(), lines),
    };
    let lagrange = |l: &[Vector3<f64>], x: f64| -> Vector3<f64> {
        (0..u.len())
            .map(|k| {
                let w: f64 = (0..u.len())
                    .filter(|&m| m != k)
                    .map(|m| (x - u[m]) / (u[k] - u[m]))
                    .product();
                l[k] * w
            })
            .sum()
    };
    let lines = lines
        .iter()
        .map(|l| t.iter().map(|&x| lagrange(l, x)).collect())
        .collect();
    (t, lines)
}

impl BSplineSurface {
    /// The surface through the `nx` × `ny` grid `nodes` (index j·nx + i), both at least 2. None when
    /// an interpolation system is singular (coincident parameters).
    pub fn interpolate(
        nodes: &[Vector3<f64>],
        nx: usize,
        ny: usize,
        kind: Parametrization,
    ) -> Option<Self> {
        if nx < 2 || ny < 2 || nodes.len() != nx * ny {
            return None;
        }
        let rows: Vec<Vec<Vector3<f64>>> = (0..ny)
            .map(|j| nodes[j * nx..(j + 1) * nx].to_vec())
            .collect();
        let cols: Vec<Vec<Vector3<f64>>> = (0..nx)
            .map(|i| (0..ny).map(|j| nodes[j * nx + i]).collect())
            .collect();
        let (u, v) = (parameters(&rows, kind), parameters(&cols, kind));
        Self::interpolate_at(nodes, nx, ny, u, v)
    }

    /// The surface through the `nx` × `ny` grid `nodes` (index j·nx + i) at the given node
    /// parameters `u` (nx, increasing from 0 to 1) and `v` (ny): e.g. a drape's rest positions at its
    /// deformed surface's parameters, for material coordinates. None when a system is singular.
    pub fn interpolate_at(
        nodes: &[Vector3<f64>],
        nx: usize,
        ny: usize,
        u: Vec<f64>,
        v: Vec<f64>,
    ) -> Option<Self> {
        if nx < 2 || ny < 2 || nodes.len() != nx * ny || u.len() != nx || v.len() != ny {
            return None;
        }
        let params = (u.clone(), v.clone());
        // Fewer than four nodes along a direction (a 3-line strip): the polynomial through them,
        // sampled at four or five parameters, which the cubic then reproduces exactly.
        let (u, rows) = densify(
            &u,
            (0..ny)
                .map(|j| nodes[j * nx..(j + 1) * nx].to_vec())
                .collect(),
        );
        let (v, cols) = densify(
            &v,
            (0..u.len())
                .map(|i| (0..ny).map(|j| rows[j][i]).collect())
                .collect(),
        );
        let (nx, ny) = (u.len(), v.len());
        let rows: Vec<Vec<Vector3<f64>>> = (0..ny)
            .map(|j| (0..nx).map(|i| cols[i][j]).collect())
            .collect();
        let (bu, bv) = (Basis::interpolating(&u), Basis::interpolating(&v));
        // Along u for every row, then along v for every column of those control points.
        let r = solve_lines(&bu, &u, &rows)?;
        let cols_r: Vec<Vec<Vector3<f64>>> = (0..bu.n)
            .map(|i| (0..ny).map(|j| r[j][i]).collect())
            .collect();
        let c = solve_lines(&bv, &v, &cols_r)?;
        let mut ctrl = vec![Vector3::zeros(); bu.n * bv.n];
        for (i, col) in c.iter().enumerate() {
            for (j, p) in col.iter().enumerate() {
                ctrl[j * bu.n + i] = *p;
            }
        }
        Some(Self {
            bu,
            bv,
            ctrl,
            params,
        })
    }

    /// S and its partial derivatives at (u, v): [[S, S_v, S_vv], [S_u, S_uv, –], [S_uu, –, –]]
    /// indexed [du][dv].
    pub fn derivatives(&self, u: f64, v: f64) -> [[Vector3<f64>; 3]; 3] {
        let (su, nu) = self.bu.eval(u);
        let (sv, nv) = self.bv.eval(v);
        let mut out = [[Vector3::zeros(); 3]; 3];
        for (a, i) in (su - DEGREE..=su).enumerate() {
            for (b, jj) in (sv - DEGREE..=sv).enumerate() {
                let p = self.ctrl[jj * self.bu.n + i];
                for (du, row) in out.iter_mut().enumerate() {
                    for (dv, o) in row.iter_mut().enumerate().take(3 - du) {
                        *o += p * (nu[du][a] * nv[dv][b]);
                    }
                }
            }
        }
        out
    }

    /// The point S(u, v), m.
    pub fn point(&self, u: f64, v: f64) -> Vector3<f64> {
        self.derivatives(u, v)[0][0]
    }

    /// The unit normal S_u × S_v at (u, v) (zero where the surface is degenerate).
    pub fn normal(&self, u: f64, v: f64) -> Vector3<f64> {
        let d = self.derivatives(u, v);
        d[1][0]
            .cross(&d[0][1])
            .try_normalize(1e-300)
            .unwrap_or_else(Vector3::zeros)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_strip_of_three_lines_is_interpolated_through_its_nodes() {
        // A cantilever's 41 × 3 grid: along v the quadratic through the three lines.
        let (nx, ny) = (9, 3);
        let nodes: Vec<Vector3<f64>> = (0..nx * ny)
            .map(|p| {
                let (i, j) = ((p % nx) as f64, (p / nx) as f64);
                Vector3::new(0.1 * i, 0.05 * j, -0.01 * i * i + 0.002 * j * j)
            })
            .collect();
        for n in [ny, 2] {
            let s = BSplineSurface::interpolate(&nodes[..nx * n], nx, n, Parametrization::Uniform)
                .expect("a surface");
            let (u, v) = &s.params;
            let worst = (0..nx * n)
                .map(|p| (s.point(u[p % nx], v[p / nx]) - nodes[p]).norm())
                .fold(0.0, f64::max);
            assert!(worst < 1e-12, "{n} lines: {worst:e}");
        }
    }

    /// A curved 9 × 7 grid: a draped-looking bump on an uneven grid.
    fn grid(nx: usize, ny: usize) -> Vec<Vector3<f64>> {
        let mut g = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                let (x, y) = (
                    (i as f64 / (nx - 1) as f64).powf(1.3) * 0.4,
                    j as f64 * 0.05,
                );
                g.push(Vector3::new(
                    x,
                    y,
                    0.1 * (6.0 * x).sin() * (8.0 * y).cos() - 0.2 * x * x,
                ));
            }
        }
        g
    }

    #[test]
    fn the_surface_passes_through_every_node() {
        for kind in [Parametrization::Uniform, Parametrization::ChordLength] {
            let (nx, ny) = (9, 7);
            let g = grid(nx, ny);
            let s = BSplineSurface::interpolate(&g, nx, ny, kind).unwrap();
            let mut worst = 0.0f64;
            for j in 0..ny {
                for i in 0..nx {
                    let p = s.point(s.params.0[i], s.params.1[j]);
                    worst = worst.max((p - g[j * nx + i]).norm());
                }
            }
            assert!(worst < 1e-10, "{kind:?}: {worst} m");
        }
    }

    #[test]
    fn second_derivatives_are_continuous_across_every_knot() {
        let (nx, ny) = (9, 7);
        let s =
            BSplineSurface::interpolate(&grid(nx, ny), nx, ny, Parametrization::Uniform).unwrap();
        let v = 0.37;
        // Just left and right of each interior knot: S_uu jumps by O(ε) only (C²); S_uuu would jump.
        for &k in &s.bu.knots[4..s.bu.knots.len() - 4] {
            let jump =
                |e: f64| (s.derivatives(k + e, v)[2][0] - s.derivatives(k - e, v)[2][0]).norm();
            let (j1, j2) = (jump(1e-5), jump(1e-7));
            assert!(
                j2 < 1e-4 && j2 < 0.05 * j1.max(1e-12) + 1e-9,
                "knot {k}: {j1:e}, {j2:e}"
            );
        }
        // The derivatives agree with finite differences of the points.
        let (u, h) = (0.41, 1e-5);
        let d = s.derivatives(u, v);
        let fd = (s.point(u + h, v) - s.point(u - h, v)) / (2.0 * h);
        let fdd = (s.point(u + h, v) - 2.0 * s.point(u, v) + s.point(u - h, v)) / (h * h);
        assert!((d[1][0] - fd).norm() < 1e-6 * fd.norm().max(1.0));
        assert!(
            (d[2][0] - fdd).norm() < 1e-3 * fdd.norm().max(1.0),
            "{} {}",
            d[2][0],
            fdd
        );
    }

    #[test]
    fn a_flat_sheet_gives_a_flat_surface_with_an_upward_normal() {
        let (nx, ny) = (6, 5);
        let g: Vec<_> = (0..nx * ny)
            .map(|k| Vector3::new((k % nx) as f64 * 0.1, (k / nx) as f64 * 0.1, 0.0))
            .collect();
        let s = BSplineSurface::interpolate(&g, nx, ny, Parametrization::ChordLength).unwrap();
        for a in 0..=10 {
            for b in 0..=10 {
                let (u, v) = (a as f64 / 10.0, b as f64 / 10.0);
                let p = s.point(u, v);
                assert!(p.z.abs() < 1e-14);
                // Equidistant nodes of a flat sheet: the map is affine, (u, v) ↦ (0.5 u, 0.4 v).
                assert!(
                    (p.x - 0.5 * u).abs() < 1e-12 && (p.y - 0.4 * v).abs() < 1e-12,
                    "{p}"
                );
                assert!((s.normal(u, v) - Vector3::z()).norm() < 1e-12);
            }
        }
    }
}
