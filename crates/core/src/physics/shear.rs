//! In-plane shear of the continuum model, per grid cell: with the cell's mean edge vectors
//! e_x = ((p₁₀ − p₀₀) + (p₁₁ − p₀₁))/2 and e_y = ((p₀₁ − p₀₀) + (p₁₁ − p₁₀))/2 and rest sides
//! h_x, h_y, the shear strain is s = e_x·e_y/(h_x h_y) (≈ sin γ for small stretch) and the energy is
//! E = ½ G A s², A = h_x h_y. Its projected Hessian is the Gauss–Newton part G A ∇s∇sᵀ (positive semi-definite).

use super::{EnergyTerm, HessianBlocks, Vecs};
use nalgebra::{Matrix3, Vector3};

/// Coefficients of the corners (p₀₀, p₁₀, p₀₁, p₁₁) in e_x and e_y.
const CX: [f64; 4] = [-0.5, 0.5, -0.5, 0.5];
const CY: [f64; 4] = [-0.5, -0.5, 0.5, 0.5];

/// Shear energy of grid cells.
pub struct CellShear {
    cells: Vec<[u32; 4]>,
    sides_m: Vec<(f64, f64)>,
    shear_N_per_m: f64,
}

impl CellShear {
    /// Cells as corner indices (p₀₀, p₁₀, p₀₁, p₁₁), their rest sides (h_x, h_y) in m, and the shear rigidity G in N/m.
    pub fn new(cells: Vec<[usize; 4]>, sides_m: Vec<(f64, f64)>, shear_N_per_m: f64) -> Self {
        Self {
            cells: cells.into_iter().map(|c| c.map(|v| v as u32)).collect(),
            sides_m,
            shear_N_per_m,
        }
    }
    /// (s, ∂s/∂p for the four corners).
    fn strain(&self, k: usize, x: &Vecs) -> (f64, [Vector3<f64>; 4]) {
        let c = self.cells[k].map(|v| x[v as usize]);
        let ex = ((c[1] - c[0]) + (c[3] - c[2])) * 0.5;
        let ey = ((c[2] - c[0]) + (c[3] - c[1])) * 0.5;
        let (hx, hy) = self.sides_m[k];
        let inv = 1.0 / (hx * hy);
        let s = ex.dot(&ey) * inv;
        let grads = [0, 1, 2, 3].map(|m| (ey * CX[m] + ex * CY[m]) * inv);
        (s, grads)
    }
}

impl EnergyTerm for CellShear {
    fn name(&self) -> String {
        "shear/continuum".into()
    }
    fn energy(&self, x: &Vecs) -> f64 {
        (0..self.cells.len())
            .map(|k| {
                let (hx, hy) = self.sides_m[k];
                let (s, _) = self.strain(k, x);
                0.5 * self.shear_N_per_m * hx * hy * s * s
            })
            .sum()
    }
    fn add_gradient(&self, x: &Vecs, g: &mut Vecs) {
        for k in 0..self.cells.len() {
            let (hx, hy) = self.sides_m[k];
            let (s, gr) = self.strain(k, x);
            let f = self.shear_N_per_m * hx * hy * s;
            for m in 0..4 {
                g[self.cells[k][m] as usize] += gr[m] * f;
            }
        }
    }
    fn stiffness_scale(&self) -> f64 {
        self.shear_N_per_m
    }
    fn add_hessian(&self, x: &Vecs, h: &mut HessianBlocks, project: bool) {
        for k in 0..self.cells.len() {
            let (hx, hy) = self.sides_m[k];
            let (s, gr) = self.strain(k, x);
            let w = self.shear_N_per_m * hx * hy;
            // Exact: w (∇s∇sᵀ + s ∇²s), ∇²s = (cx_a cy_b + cy_a cx_b) I / (hx hy); projected: Gauss–Newton.
            let curv = if project { 0.0 } else { w * s / (hx * hy) };
            for a in 0..4 {
                for b in 0..=a {
                    let blk: Matrix3<f64> = gr[a] * gr[b].transpose() * w
                        + Matrix3::identity() * (curv * (CX[a] * CY[b] + CY[a] * CX[b]));
                    h.push(self.cells[k][a] as usize, self.cells[k][b] as usize, blk);
                }
            }
        }
    }
}
