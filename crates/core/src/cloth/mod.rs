//! The cloth: particles on a rectangular grid (uniform or graded spacing) in the plane z = 0,
//! with area-lumped masses and the boundary conditions (pins, clamped edges).

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// Spacing of grid lines along one side.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Spacing {
    /// Equal intervals.
    #[default]
    Uniform,
    /// Intervals graded towards both ends (cosine clustering): finer where a sheet bends most, at its edges.
    Graded,
}

/// Grid coordinates of `n` lines over `[0, length]`.
///
/// Graded spacing without `refine_at` clusters lines towards both ends (cosine spacing). With
/// interior lines `refine_at` (sheet coordinates in m, e.g. a table's edges, seed 003 Figs. 10.3
/// and 10.7) each becomes a grid line, the segments between them and the edges get intervals in
/// proportion to their lengths (at least one each), and lines cluster towards the interior lines
/// only (quarter-cosine spacing in the outer segments). The spacing is a blend of uniform and
/// clustered, `grading` in [0, 1) (0 = uniform). Uniform spacing ignores `refine_at`.
pub fn line_coordinates(
    n: usize,
    length: f64,
    spacing: Spacing,
    grading: f64,
    refine_at: &[f64],
) -> Vec<f64> {
    let intervals = n - 1;
    if spacing == Spacing::Uniform {
        return (0..n)
            .map(|k| k as f64 / intervals as f64 * length)
            .collect();
    }
    let mut breaks = vec![0.0];
    breaks.extend(refine_at.iter().copied().filter(|&b| b > 0.0 && b < length));
    breaks.push(length);
    breaks.sort_by(f64::total_cmp);
    breaks.dedup();
    let segments = breaks.len() - 1;
    // Interval index of each breakpoint: cumulative rounding, kept strictly increasing.
    let mut at: Vec<usize> = breaks
        .iter()
        .map(|b| (b / length * intervals as f64).round() as usize)
        .collect();
    for k in 1..=segments {
        at[k] = at[k].max(at[k - 1] + 1).min(intervals - (segments - k));
    }
    at[segments] = intervals;
    // With interior lines, the sheet's own edges are not refined towards.
    let refined = |k: usize| segments == 1 || (k > 0 && k < segments);
    let half_pi = std::f64::consts::FRAC_PI_2;
    let mut xs = Vec::with_capacity(n);
    for k in 0..segments {
        let (a, b) = (breaks[k], breaks[k + 1]);
        let c = at[k + 1] - at[k];
        for m in 0..c {
            let t = m as f64 / c as f64;
            let clustered = match (refined(k), refined(k + 1)) {
                (true, true) => 0.5 * (1.0 - (2.0 * half_pi * t).cos()),
                (true, false) => 1.0 - (half_pi * t).cos(),
                (false, true) => (half_pi * t).sin(),
                (false, false) => t,
            };
            xs.push(a + (b - a) * ((1.0 - grading) * t + grading * clustered));
        }
    }
    xs.push(length);
    xs
}

/// Half-interval ("tributary") lengths of grid lines: the share of the side each line represents.
pub fn tributary_lengths(coords: &[f64]) -> Vec<f64> {
    let n = coords.len();
    (0..n)
        .map(|k| {
            let left = if k > 0 {
                coords[k] - coords[k - 1]
            } else {
                0.0
            };
            let right = if k + 1 < n {
                coords[k + 1] - coords[k]
            } else {
                0.0
            };
            0.5 * (left + right)
        })
        .collect()
}

/// A rectangular grid of particles; particle `(i, j)` has index `j * nx + i`, `i` along x.
#[derive(Debug, Clone, PartialEq)]
pub struct Grid {
    /// Particles along x.
    pub nx: usize,
    /// Particles along y.
    pub ny: usize,
    /// x coordinates of the grid lines in m.
    pub xs: Vec<f64>,
    /// y coordinates of the grid lines in m.
    pub ys: Vec<f64>,
}

impl Grid {
    /// A grid over `lx × ly` metres with uniform spacing.
    pub fn uniform(nx: usize, ny: usize, lx: f64, ly: f64) -> Self {
        Self::new(nx, ny, lx, ly, Spacing::Uniform, 0.0, [&[], &[]])
    }

    /// A grid over `lx × ly` metres; graded spacing is refined towards `refine_at` = (lines x =
    /// const, lines y = const) in sheet coordinates (m), or towards the edges where a side has no
    /// such lines ([`line_coordinates`]).
    pub fn new(
        nx: usize,
        ny: usize,
        lx: f64,
        ly: f64,
        spacing: Spacing,
        grading: f64,
        refine_at: [&[f64]; 2],
    ) -> Self {
        Self {
            nx,
            ny,
            xs: line_coordinates(nx, lx, spacing, grading, refine_at[0]),
            ys: line_coordinates(ny, ly, spacing, grading, refine_at[1]),
        }
    }
    /// A mesh sheet's particles as one row: particle p is (p, 0), so that tables keyed by grid
    /// indices read `i` as the mesh's vertex (0-based). Its lines are the indices themselves, not
    /// positions: a mesh sheet's geometry is its pattern's ([`crate::pattern::Pattern`]).
    pub fn vertex_row(n: usize) -> Self {
        Self {
            nx: n,
            ny: 1,
            xs: (0..n).map(|i| i as f64).collect(),
            ys: vec![0.0],
        }
    }
    /// Number of particles.
    pub fn len(&self) -> usize {
        self.nx * self.ny
    }
    /// Whether the grid is empty (never, for a validated scene).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// The smallest distance between neighbouring grid lines in m.
    pub fn min_spacing_m(&self) -> f64 {
        self.xs
            .windows(2)
            .chain(self.ys.windows(2))
            .map(|w| w[1] - w[0])
            .fold(f64::INFINITY, f64::min)
    }
    /// Particle index of grid point `(i, j)`.
    pub fn index(&self, i: usize, j: usize) -> usize {
        j * self.nx + i
    }
    /// Grid indices of particle `p`.
    pub fn ij(&self, p: usize) -> (usize, usize) {
        (p % self.nx, p / self.nx)
    }
    /// Flat initial positions at z = 0.
    pub fn flat_positions(&self) -> Vec<Vector3<f64>> {
        let mut x = Vec::with_capacity(self.len());
        for &y in &self.ys {
            for &xx in &self.xs {
                x.push(Vector3::new(xx, y, 0.0));
            }
        }
        x
    }
    /// Area-lumped masses in kg: density × tributary area, i.e. ρh² inside, ρh²/2 on edges, ρh²/4 at
    /// corners on a uniform grid (seed 000).
    pub fn lumped_masses(&self, areal_density_kg_per_m2: f64) -> Vec<f64> {
        let tx = tributary_lengths(&self.xs);
        let ty = tributary_lengths(&self.ys);
        let mut m = Vec::with_capacity(self.len());
        for wy in &ty {
            for wx in &tx {
                m.push(areal_density_kg_per_m2 * wx * wy);
            }
        }
        m
    }
}

/// A named corner of the sheet.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Corner {
    /// (i, j) = (0, 0), at x = 0, y = 0.
    XminYmin,
    /// (nx − 1, 0).
    XmaxYmin,
    /// (0, ny − 1).
    XminYmax,
    /// (nx − 1, ny − 1).
    XmaxYmax,
}

impl Corner {
    /// The grid indices of this corner.
    pub fn ij(self, grid: &Grid) -> (usize, usize) {
        match self {
            Corner::XminYmin => (0, 0),
            Corner::XmaxYmin => (grid.nx - 1, 0),
            Corner::XminYmax => (0, grid.ny - 1),
            Corner::XmaxYmax => (grid.nx - 1, grid.ny - 1),
        }
    }
}

/// A named edge of the sheet.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Edge {
    /// The line i = 0.
    Xmin,
    /// The line i = nx − 1.
    Xmax,
    /// The line j = 0.
    Ymin,
    /// The line j = ny − 1.
    Ymax,
}

impl Edge {
    /// Particle indices on this edge, and those on the next line inwards.
    pub fn lines(self, grid: &Grid) -> (Vec<usize>, Vec<usize>) {
        let (nx, ny) = (grid.nx, grid.ny);
        match self {
            Edge::Xmin => (
                (0..ny).map(|j| grid.index(0, j)).collect(),
                (0..ny).map(|j| grid.index(1, j)).collect(),
            ),
            Edge::Xmax => (
                (0..ny).map(|j| grid.index(nx - 1, j)).collect(),
                (0..ny).map(|j| grid.index(nx - 2, j)).collect(),
            ),
            Edge::Ymin => (
                (0..nx).map(|i| grid.index(i, 0)).collect(),
                (0..nx).map(|i| grid.index(i, 1)).collect(),
            ),
            Edge::Ymax => (
                (0..nx).map(|i| grid.index(i, ny - 1)).collect(),
                (0..nx).map(|i| grid.index(i, ny - 2)).collect(),
            ),
        }
    }
}

/// Triangle indices of the grid (two per cell), for meshes.
pub fn grid_triangles(grid: &Grid) -> Vec<[u32; 3]> {
    cell_triangles(grid.nx, grid.ny)
}

/// Two triangles per cell of a row-major `nx` × `ny` point array (point (i, j) at j·nx + i).
pub fn cell_triangles(nx: usize, ny: usize) -> Vec<[u32; 3]> {
    let mut t = Vec::with_capacity(2 * (nx - 1) * (ny - 1));
    for j in 0..ny - 1 {
        for i in 0..nx - 1 {
            let (a, b, c, d) = (
                j * nx + i,
                j * nx + i + 1,
                (j + 1) * nx + i,
                (j + 1) * nx + i + 1,
            );
            t.push([a as u32, b as u32, d as u32]);
            t.push([a as u32, d as u32, c as u32]);
        }
    }
    t
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn lumped_masses_follow_seed_000_and_sum_to_sheet_mass() {
        let g = Grid::new(11, 11, 0.5, 0.5, Spacing::Uniform, 0.0, [&[], &[]]);
        let m = g.lumped_masses(0.045);
        let h: f64 = 0.05;
        let rho_h2 = 0.045 * h * h;
        assert!((m[g.index(5, 5)] - rho_h2).abs() < 1e-15);
        assert!((m[g.index(0, 5)] - rho_h2 / 2.0).abs() < 1e-15);
        assert!((m[g.index(0, 0)] - rho_h2 / 4.0).abs() < 1e-15);
        let total: f64 = m.iter().sum();
        assert!((total - 0.045 * 0.25).abs() < 1e-12);
        let gg = Grid::new(9, 7, 0.2, 0.1, Spacing::Graded, 0.7, [&[], &[]]);
        let tot: f64 = gg.lumped_masses(2.0).iter().sum();
        assert!((tot - 2.0 * 0.02).abs() < 1e-12);
    }

    #[test]
    fn graded_lines_put_a_grid_line_on_each_refined_line_and_cluster_towards_it() {
        // A 20 cm side refined at 5 and 15 cm (a 10 cm table under a 20 cm sheet).
        let xs = line_coordinates(41, 0.2, Spacing::Graded, 0.5, &[0.05, 0.15]);
        assert_eq!(xs.len(), 41);
        assert!((xs[10] - 0.05).abs() < 1e-15 && (xs[30] - 0.15).abs() < 1e-15);
        assert!(xs.windows(2).all(|w| w[1] > w[0]));
        // Mirror symmetric, finest next to the refined lines, coarsest at the free edges.
        for k in 0..41 {
            assert!((xs[k] + xs[40 - k] - 0.2).abs() < 1e-14, "{k}");
        }
        let h: Vec<f64> = xs.windows(2).map(|w| w[1] - w[0]).collect();
        assert!(h[9] < h[0] && h[10] < h[19] && h[9] < 0.005 && h[0] > 0.005);
        // Doubling the intervals keeps every line (grid-convergence studies compare material points).
        let fine = line_coordinates(81, 0.2, Spacing::Graded, 0.5, &[0.05, 0.15]);
        for k in 0..41 {
            assert!((fine[2 * k] - xs[k]).abs() < 1e-15, "{k}");
        }
        // Without refined lines: cosine towards both edges, as before; uniform ignores them.
        let both = line_coordinates(5, 1.0, Spacing::Graded, 0.5, &[]);
        assert!((both[1] - (0.5 * 0.25 + 0.5 * 0.5 * (1.0 - (PI / 4.0).cos()))).abs() < 1e-15);
        assert_eq!(
            line_coordinates(3, 1.0, Spacing::Uniform, 0.5, &[0.3]),
            vec![0.0, 0.5, 1.0]
        );
    }
}
