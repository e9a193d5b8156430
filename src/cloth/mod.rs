//! The cloth: particles on a rectangular grid (uniform or graded spacing) in the plane z = 0,
//! with area-lumped masses and the boundary conditions (pins, clamped edges).

mod build;
pub use build::{BuiltScene, absent_particles, barrier_contact, build_scene, initial_positions};

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
pub fn line_coordinates(n: usize, length: f64, spacing: Spacing, grading: f64) -> Vec<f64> {
    (0..n)
        .map(|k| {
            let s = k as f64 / (n - 1) as f64;
            match spacing {
                Spacing::Uniform => s * length,
                Spacing::Graded => {
                    // Blend of uniform and cosine spacing; grading in [0, 1): 0 = uniform.
                    let c = 0.5 * (1.0 - (std::f64::consts::PI * s).cos());
                    length * ((1.0 - grading) * s + grading * c)
                }
            }
        })
        .collect()
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
    /// A grid over `lx × ly` metres.
    pub fn new(nx: usize, ny: usize, lx: f64, ly: f64, spacing: Spacing, grading: f64) -> Self {
        Self {
            nx,
            ny,
            xs: line_coordinates(nx, lx, spacing, grading),
            ys: line_coordinates(ny, ly, spacing, grading),
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lumped_masses_follow_seed_000_and_sum_to_sheet_mass() {
        let g = Grid::new(11, 11, 0.5, 0.5, Spacing::Uniform, 0.0);
        let m = g.lumped_masses(0.045);
        let h: f64 = 0.05;
        let rho_h2 = 0.045 * h * h;
        assert!((m[g.index(5, 5)] - rho_h2).abs() < 1e-15);
        assert!((m[g.index(0, 5)] - rho_h2 / 2.0).abs() < 1e-15);
        assert!((m[g.index(0, 0)] - rho_h2 / 4.0).abs() < 1e-15);
        let total: f64 = m.iter().sum();
        assert!((total - 0.045 * 0.25).abs() < 1e-12);
        let gg = Grid::new(9, 7, 0.2, 0.1, Spacing::Graded, 0.7);
        let tot: f64 = gg.lumped_masses(2.0).iter().sum();
        assert!((tot - 2.0 * 0.02).abs() < 1e-12);
    }
}
