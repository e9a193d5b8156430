//! Step 3 of seed 002: the 3D displacement of a grid. Column j sits at x ∈ [−l/2, l/2]; row k at a
//! fraction η = k/(ny − 1) of the way down the fibre, which crosses the n strips between wrinkle lines
//! n (top, a_n) … 0 (bottom, a₀). Within a strip the point is interpolated linearly between its two
//! wrinkle lines: y = a_i cos(πx/l) down from the supports (Eq. 6), z = (−1)^i z_max cos(πx/l) out of
//! plane (Eq. 4, alternating from line to line).

use super::{WrinkleInputs, WrinkleResult, support_span_m};

/// A deformed grid: `ny` rows of `nx` points, row-major from the top.
#[derive(Debug, Clone, PartialEq)]
pub struct WrinkleMesh {
    /// Points per row.
    pub nx: usize,
    /// Rows.
    pub ny: usize,
    /// Positions (x along the supports, y down from them, z out of plane), m.
    pub points: Vec<[f64; 3]>,
}

impl WrinkleMesh {
    /// Point of column i, row j.
    pub fn at(&self, i: usize, j: usize) -> [f64; 3] {
        self.points[j * self.nx + i]
    }
    /// Two triangles per cell, for renderers.
    pub fn triangles(&self) -> Vec<[u32; 3]> {
        crate::cloth::cell_triangles(self.nx, self.ny)
    }
}

/// The deformed grid of a solved case (`nx`, `ny` ≥ 2).
pub fn wrinkle_mesh(inp: &WrinkleInputs, res: &WrinkleResult, nx: usize, ny: usize) -> WrinkleMesh {
    let (nx, ny) = (nx.max(2), ny.max(2));
    let l = support_span_m(inp);
    let n = res.n;
    let mut points = Vec::with_capacity(nx * ny);
    for j in 0..ny {
        let eta = j as f64 / (ny - 1) as f64;
        for i in 0..nx {
            let x = -0.5 * l + l * i as f64 / (nx - 1) as f64;
            let c = (std::f64::consts::PI * x / l).cos();
            if n == 0 {
                // No wrinkles: the flat sheet hangs between the supports.
                points.push([x, eta * inp.height_m * c, 0.0]);
                continue;
            }
            let u = eta * n as f64;
            let k = (u.floor() as usize).min(n - 1);
            let f = u - k as f64;
            let (upper, lower) = (n - k, n - k - 1);
            let a = |line: usize| res.amplitudes_m[line];
            let sign = |line: usize| if line.is_multiple_of(2) { 1.0 } else { -1.0 };
            let y = ((1.0 - f) * a(upper) + f * a(lower)) * c;
            let z = ((1.0 - f) * sign(upper) + f * sign(lower)) * res.zmax_m * c;
            points.push([x, y, z]);
        }
    }
    WrinkleMesh { nx, ny, points }
}

/// Folds seen on the centre column of a mesh: the number of sign changes of z from top to bottom
/// (each strip turns the sheet from one side to the other once).
pub fn count_folds(mesh: &WrinkleMesh) -> usize {
    let col = mesh.nx / 2;
    let zs: Vec<f64> = (0..mesh.ny)
        .map(|j| mesh.at(col, j)[2])
        .filter(|z| z.abs() > 1e-12)
        .collect();
    zs.windows(2)
        .filter(|w| w[0].signum() != w[1].signum())
        .count()
}
