//! A scene's grid: its lines (uniform or graded), its particles' start, and the scene moved to
//! another grid.

use super::Scene;
use crate::cloth::Spacing;

impl Scene {
    /// The grid count out of 2..=2049 (`cloth.nx` first) and what is wrong with it; absent reads as
    /// 0 (a mesh sheet has none), which is said as missing rather than "got 0".
    pub(super) fn grid_count_error(&self) -> Option<(&'static str, String)> {
        let c = &self.cloth;
        let Some((key, n)) = [("cloth.nx", c.nx), ("cloth.ny", c.ny)]
            .into_iter()
            .find(|(_, n)| !(2..=2049).contains(n))
        else {
            let key = if c.nx >= c.ny { "cloth.nx" } else { "cloth.ny" };
            return crate::memory::too_large((c.nx * c.ny) as f64).map(|m| (key, m));
        };
        let got = match n {
            0 => "it is missing (a grid sheet needs nx and ny; a mesh sheet gives `mesh`)".into(),
            n => format!("got {n}"),
        };
        Some((key, format!("must be in 2..=2049, {got}")))
    }

    /// The grid of the scene (uniform or graded, refined towards `cloth.refine_x_m`/`refine_y_m`);
    /// of a mesh sheet, its vertices as one row ([`Grid::vertex_row`](crate::cloth::Grid::vertex_row)).
    pub fn grid(&self) -> crate::cloth::Grid {
        if let Some(p) = self.pattern() {
            return crate::cloth::Grid::vertex_row(p.vertex_count());
        }
        let c = &self.cloth;
        let local =
            |lines: &[f64], origin: f64| lines.iter().map(|v| v - origin).collect::<Vec<_>>();
        let (rx, ry) = (
            local(&c.refine_x_m, c.origin_m[0]),
            local(&c.refine_y_m, c.origin_m[1]),
        );
        crate::cloth::Grid::new(
            c.nx,
            c.ny,
            c.size_x_m,
            c.size_y_m,
            c.spacing,
            if c.spacing == Spacing::Graded {
                c.grading
            } else {
                0.0
            },
            [&rx, &ry],
        )
    }

    /// Initial positions of the grid particles: the flat sheet at `cloth.origin_m`, with the optional
    /// perturbation z += a·sin(πu)·sin(πw)·w (u, w the fractions along x and y); of a mesh sheet, its
    /// placed vertices.
    pub fn initial_positions(&self) -> Vec<nalgebra::Vector3<f64>> {
        if let Some(p) = self.pattern() {
            return self.mesh_positions(p);
        }
        let c = &self.cloth;
        let o = nalgebra::Vector3::new(c.origin_m[0], c.origin_m[1], c.origin_m[2]);
        self.grid()
            .flat_positions()
            .into_iter()
            .map(|p| {
                let (u, w) = (p.x / c.size_x_m, p.y / c.size_y_m);
                let dz = c.initial_perturbation_m
                    * (std::f64::consts::PI * u).sin()
                    * (std::f64::consts::PI * w).sin()
                    * w;
                p + o + nalgebra::Vector3::new(0.0, 0.0, dz)
            })
            .collect()
    }

    /// The scene on an `nx × ny` grid: every particle named by grid indices (pins, holds, point loads)
    /// moves to the same material point, index i → round(i (nx − 1)/(nx₀ − 1)) (exact when the new
    /// grid's lines fall on the old one's, as in 2n − 1 refinement).
    pub fn regridded(&self, nx: usize, ny: usize) -> Scene {
        let mut s = self.clone();
        let (nx0, ny0) = (self.cloth.nx, self.cloth.ny);
        let map = |p: [usize; 2]| {
            let f = |i: usize, n0: usize, n: usize| {
                if n0 > 1 {
                    ((i * (n - 1)) as f64 / (n0 - 1) as f64).round() as usize
                } else {
                    i.min(n - 1)
                }
            };
            [f(p[0], nx0, nx), f(p[1], ny0, ny)]
        };
        s.cloth.nx = nx;
        s.cloth.ny = ny;
        for p in &mut s.boundary.pin_particles {
            *p = map(*p);
        }
        for h in &mut s.boundary.holds {
            for p in &mut h.particles {
                *p = map(*p);
            }
        }
        for l in &mut s.loads {
            if let Some(p) = &mut l.particle {
                *p = map(*p);
            }
        }
        s
    }
}
