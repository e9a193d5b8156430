//! In-plane shear of the continuum model, per grid cell: with the cell's mean edge vectors
//! e_x = ((p₁₀ − p₀₀) + (p₁₁ − p₀₁))/2 and e_y = ((p₀₁ − p₀₀) + (p₁₁ − p₁₀))/2 and rest sides
//! h_x, h_y, the shear strain is s = e_x·e_y/(h_x h_y) (≈ sin γ for small stretch) and the energy is
//! E = ½ G A s², A = h_x h_y. Its projected Hessian is the Gauss–Newton part G A ∇s∇sᵀ (positive semi-definite).

use super::kernel::{Kernel, Local, Potential};
use nalgebra::{Matrix3, Vector3};

/// Coefficients of the corners (p₀₀, p₁₀, p₀₁, p₁₁) in e_x and e_y.
const CX: [f64; 4] = [-0.5, 0.5, -0.5, 0.5];
const CY: [f64; 4] = [-0.5, -0.5, 0.5, 0.5];

/// The kernel of the shear energy of grid cells: coefficients (h_x, h_y) in m and G in N/m.
pub struct ShearKernel {
    cells: Vec<[u32; 4]>,
    sides_m: Vec<(f64, f64)>,
    shear_N_per_m: Vec<f64>,
}

/// Shear energy of grid cells.
pub type CellShear = Potential<ShearKernel, 4>;

impl CellShear {
    /// Cells as corner indices (p₀₀, p₁₀, p₀₁, p₁₁), their rest sides (h_x, h_y) in m, and the shear rigidity G in N/m.
    pub fn new(cells: Vec<[usize; 4]>, sides_m: Vec<(f64, f64)>, shear_N_per_m: f64) -> Self {
        let n = cells.len();
        Potential::of(ShearKernel {
            cells: cells.into_iter().map(|c| c.map(|v| v as u32)).collect(),
            sides_m,
            shear_N_per_m: vec![shear_N_per_m; n],
        })
    }
}

impl ShearKernel {
    /// (s, ∂s/∂p for the four corners, e_x·e_y).
    #[inline]
    fn strain(&self, k: usize, c: &Local<4>) -> (f64, [Vector3<f64>; 4]) {
        let ex = ((c[1] - c[0]) + (c[3] - c[2])) * 0.5;
        let ey = ((c[2] - c[0]) + (c[3] - c[1])) * 0.5;
        let (hx, hy) = self.sides_m[k];
        let inv = 1.0 / (hx * hy);
        let s = ex.dot(&ey) * inv;
        let grads = [0, 1, 2, 3].map(|m| (ey * CX[m] + ex * CY[m]) * inv);
        (s, grads)
    }
}

impl Kernel<4> for ShearKernel {
    const COEFFICIENTS: usize = 3;
    fn name(&self) -> String {
        "shear/continuum".into()
    }
    fn stencils(&self) -> &[[u32; 4]] {
        &self.cells
    }
    #[inline]
    fn energy(&self, k: usize, x: &Local<4>) -> f64 {
        let (hx, hy) = self.sides_m[k];
        let (s, _) = self.strain(k, x);
        0.5 * self.shear_N_per_m[k] * hx * hy * s * s
    }
    #[inline]
    fn gradient(&self, k: usize, x: &Local<4>) -> Local<4> {
        let (hx, hy) = self.sides_m[k];
        let (s, gr) = self.strain(k, x);
        let f = self.shear_N_per_m[k] * hx * hy * s;
        gr.map(|g| g * f)
    }
    fn stiffness_scale(&self) -> f64 {
        self.shear_N_per_m.iter().copied().fold(0.0, f64::max)
    }
    fn hessian(
        &self,
        k: usize,
        x: &Local<4>,
        project: bool,
        push: &mut impl FnMut(usize, usize, Matrix3<f64>),
    ) {
        let (hx, hy) = self.sides_m[k];
        let (s, gr) = self.strain(k, x);
        let w = self.shear_N_per_m[k] * hx * hy;
        // Exact: w (∇s∇sᵀ + s ∇²s), ∇²s = (cx_a cy_b + cy_a cx_b) I / (hx hy); projected: Gauss–Newton.
        let curv = if project { 0.0 } else { w * s / (hx * hy) };
        for a in 0..4 {
            for b in 0..=a {
                let blk: Matrix3<f64> = gr[a] * gr[b].transpose() * w
                    + Matrix3::identity() * (curv * (CX[a] * CY[b] + CY[a] * CX[b]));
                push(a, b, blk);
            }
        }
    }
    fn coefficients(&self, k: usize, out: &mut Vec<f64>) {
        let (hx, hy) = self.sides_m[k];
        out.extend([hx, hy, self.shear_N_per_m[k]]);
    }
    fn set_coefficients(&mut self, k: usize, c: &[f64]) {
        self.sides_m[k] = (c[0], c[1]);
        self.shear_N_per_m[k] = c[2];
    }
    /// g = G (e_x·e_y)/(h_x h_y) ∂(e_x·e_y): dg = g (dG/G − dh_x/h_x − dh_y/h_y).
    #[inline]
    fn coefficient_gradient(&self, k: usize, x: &Local<4>, dc: &[f64]) -> Local<4> {
        let (hx, hy) = self.sides_m[k];
        let rate = dc[2] / self.shear_N_per_m[k] - dc[0] / hx - dc[1] / hy;
        self.gradient(k, x).map(|g| g * rate)
    }
    /// E = ½ G (e_x·e_y)²/(h_x h_y): dE = E (dG/G − dh_x/h_x − dh_y/h_y).
    #[inline]
    fn coefficient_energy(&self, k: usize, x: &Local<4>, dc: &[f64]) -> f64 {
        let (hx, hy) = self.sides_m[k];
        let rate = dc[2] / self.shear_N_per_m[k] - dc[0] / hx - dc[1] / hy;
        self.energy(k, x) * rate
    }
}
