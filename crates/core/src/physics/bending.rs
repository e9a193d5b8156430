//! Continuum bending along grid lines, quadratic in positions (an isometric-bending energy):
//! for three consecutive particles a, b, c on a line with rest intervals h₁, h₂,
//! u = (x_c − x_b)/h₂ − (x_b − x_a)/h₁ ≈ θ (the turning angle) and the curvature is κ ≈ |u|/h̄,
//! h̄ = (h₁ + h₂)/2. The energy ½ D κ² over the tributary length h̄ and width w is
//! E = D w |u|² / (2 h̄) = ½ k |u|², k = D w / h̄. It converges to the elastica ½∫D κ² ds as the grid
//! is refined for an inextensible sheet, and its Hessian is constant.

use super::kernel::{Kernel, Local, Potential};
use nalgebra::{Matrix3, Vector3};

/// An energy ½ k |u|² per stencil, u = Σₘ cₘ x_{pₘ} a fixed linear combination of N particles:
/// its gradient is linear and its Hessian constant. Bending along grid lines uses three-particle
/// stencils ([`LinearBending`]) and the twist of a grid cell four ([`CellTwist`]).
pub struct QuadraticKernel<const N: usize> {
    name: &'static str,
    stencils: Vec<[u32; N]>,
    coef: Vec<[f64; N]>,
    stiffness: Vec<f64>,
    /// Per stencil, the |u| at which the energy turns from quadratic to linear (empty: quadratic
    /// throughout): E = k u₀² (√(1 + |u|²/u₀²) − 1), a convex (pseudo-Huber) energy whose force
    /// saturates at k u₀ (see [`QuadraticStencil::with_saturation`]).
    saturation: Vec<f64>,
}

/// The term of [`QuadraticKernel`]s.
pub type QuadraticStencil<const N: usize> = Potential<QuadraticKernel<N>, N>;

/// Quadratic bending on triples (a, b, c) of consecutive particles of a grid line.
pub type LinearBending = QuadraticStencil<3>;

/// Quadratic twist of grid cells (p₀₀, p₁₀, p₀₁, p₁₁): w = p₁₁ − p₁₀ − p₀₁ + p₀₀ ≈ h_x h_y ∂²x/∂u∂v,
/// whose normal part is h_x h_y κ_xy. A plate with Poisson's ratio 0 stores D_t κ_xy² per unit area
/// (U = ½D[κ_xx² + κ_yy² + 2κ_xy²]), so a cell holds E = D_t |w|²/(h_x h_y) = ½ k |w|²,
/// k = 2 D_t/(h_x h_y). Without it a sheet bent about a diagonal (κ_xx = κ_yy = κ_xy = κ/2)
/// would be half as stiff as one bent along a grid line.
pub type CellTwist = QuadraticStencil<4>;

impl LinearBending {
    /// Triples (a, b, c), coefficients (1/h₁, −1/h₁ − 1/h₂, 1/h₂) and stiffnesses k = D w / h̄ (N·m).
    pub fn new(triples: Vec<[usize; 3]>, coef: Vec<[f64; 3]>, stiffness_N_m: Vec<f64>) -> Self {
        Self::from_stencils("bending/continuum", triples, coef, stiffness_N_m)
    }
}

impl CellTwist {
    /// Cells (p₀₀, p₁₀, p₀₁, p₁₁), their rest sides (h_x, h_y) in m and the twist rigidity D_t in N·m.
    pub fn cells(cells: Vec<[usize; 4]>, sides_m: &[(f64, f64)], twist_N_m: f64) -> Self {
        let n = cells.len();
        let stiffness = sides_m
            .iter()
            .map(|(hx, hy)| 2.0 * twist_N_m / (hx * hy))
            .collect();
        Self::from_stencils(
            "twist/continuum",
            cells,
            vec![[1.0, -1.0, -1.0, 1.0]; n],
            stiffness,
        )
    }
}

impl<const N: usize> QuadraticStencil<N> {
    /// Stencils of particle indices, their coefficients cₘ and each stencil's k (E = ½ k |u|²).
    pub fn from_stencils(
        name: &'static str,
        stencils: Vec<[usize; N]>,
        coef: Vec<[f64; N]>,
        stiffness: Vec<f64>,
    ) -> Self {
        Potential::of(QuadraticKernel {
            name,
            stencils: stencils.into_iter().map(|t| t.map(|v| v as u32)).collect(),
            coef,
            stiffness,
            saturation: Vec::new(),
        })
    }
    /// The same stencils with an energy that saturates: quadratic ½ k |u|² for |u| ≪ u₀, linear
    /// k u₀ |u| beyond (a bending moment that levels off at large curvature, as inter-fibre friction
    /// makes it in fabric). `u0` holds one u₀ per stencil (m); an infinite u₀ keeps it quadratic.
    pub fn with_saturation(mut self, u0: Vec<f64>) -> Self {
        assert_eq!(u0.len(), self.kernel.stencils.len(), "one u₀ per stencil");
        self.kernel.saturation = u0;
        self
    }
}

impl<const N: usize> QuadraticKernel<N> {
    /// (E, dE/d|u|² ·2 = ∂E/∂u / u factor s₁, and s₃ = the factor of u uᵀ in ∂²E/∂u²) of stencil k at u.
    fn law(&self, k: usize, u: &Vector3<f64>) -> (f64, f64, f64) {
        let kk = self.stiffness[k];
        let u2 = u.norm_squared();
        match self.saturation.get(k) {
            Some(&u0) if u0.is_finite() => {
                let q = (1.0 + u2 / (u0 * u0)).sqrt();
                (
                    kk * u0 * u0 * (q - 1.0),
                    kk / q,
                    -kk / (u0 * u0 * q * q * q),
                )
            }
            _ => (0.5 * kk * u2, kk, 0.0),
        }
    }
    fn u(&self, k: usize, x: &Local<N>) -> Vector3<f64> {
        let c = self.coef[k];
        (0..N).map(|m| x[m] * c[m]).sum()
    }
}

impl<const N: usize> Kernel<N> for QuadraticKernel<N> {
    /// The stencil's cₘ, then k, then u₀ (infinite without saturation).
    const COEFFICIENTS: usize = N + 2;
    fn name(&self) -> String {
        self.name.into()
    }
    fn stencils(&self) -> &[[u32; N]] {
        &self.stencils
    }
    #[inline]
    fn energy(&self, k: usize, x: &Local<N>) -> f64 {
        self.law(k, &self.u(k, x)).0
    }
    #[inline]
    fn gradient(&self, k: usize, x: &Local<N>) -> Local<N> {
        let u = self.u(k, x);
        let u = u * self.law(k, &u).1;
        let c = self.coef[k];
        std::array::from_fn(|m| u * c[m])
    }
    /// Quadratic throughout (no saturation, or none finite): the block k I at every x.
    fn hessian_is_constant(&self) -> bool {
        self.saturation.iter().all(|u0| !u0.is_finite())
    }
    fn stiffness_scale(&self) -> f64 {
        self.coef
            .iter()
            .zip(&self.stiffness)
            .map(|(c, k)| k * c.iter().map(|v| v * v).fold(0.0, f64::max))
            .fold(0.0, f64::max)
    }
    fn hessian(
        &self,
        k: usize,
        x: &Local<N>,
        _project: bool,
        push: &mut impl FnMut(usize, usize, Matrix3<f64>),
    ) {
        // ∂²E/∂u² = s₁ I + s₃ u uᵀ, positive definite (s₁ + s₃|u|² = k/q³ > 0): no projection needed.
        let block = if self.hessian_is_constant() {
            Matrix3::identity() * self.stiffness[k]
        } else {
            let u = self.u(k, x);
            let (_, s1, s3) = self.law(k, &u);
            Matrix3::identity() * s1 + u * u.transpose() * s3
        };
        let coef = &self.coef[k];
        for a in 0..N {
            for b in 0..=a {
                push(a, b, block * (coef[a] * coef[b]));
            }
        }
    }
    fn coefficients(&self, k: usize, out: &mut Vec<f64>) {
        out.extend(self.coef[k]);
        out.push(self.stiffness[k]);
        out.push(self.saturation.get(k).copied().unwrap_or(f64::INFINITY));
    }
    fn set_coefficients(&mut self, k: usize, c: &[f64]) {
        self.coef[k].copy_from_slice(&c[..N]);
        self.stiffness[k] = c[N];
        if let Some(u0) = self.saturation.get_mut(k) {
            *u0 = c[N + 1];
        }
    }
    /// g_m = c_m f(u), f = ∂E/∂u = s₁ u, u = Σ c_m x_m: dg_m = dc_m f + c_m (∂f/∂u du + ∂f/∂k dk
    /// + ∂f/∂u₀ du₀), du = Σ dc_m x_m, ∂f/∂k = f/k, ∂f/∂u₀ = k |u|² u/(q³ u₀³).
    #[inline]
    fn coefficient_gradient(&self, k: usize, x: &Local<N>, dc: &[f64]) -> Local<N> {
        let u = self.u(k, x);
        let (_, s1, s3) = self.law(k, &u);
        let f = u * s1;
        let du: Vector3<f64> = (0..N).map(|m| x[m] * dc[m]).sum();
        let kk = self.stiffness[k];
        let mut df = u * (s3 * u.dot(&du)) + du * s1 + f * (dc[N] / kk);
        match self.saturation.get(k) {
            Some(&u0) if u0.is_finite() && dc[N + 1] != 0.0 => {
                let q = (1.0 + u.norm_squared() / (u0 * u0)).sqrt();
                df += u * (kk * u.norm_squared() / (q * q * q * u0 * u0 * u0) * dc[N + 1]);
            }
            _ => {}
        }
        let c = self.coef[k];
        std::array::from_fn(|m| f * dc[m] + df * c[m])
    }
    /// dE = ∂E/∂u · du + E/k dk + ∂E/∂u₀ du₀, ∂E/∂u₀ = 2 k u₀ (q − 1) − k |u|²/(q u₀).
    #[inline]
    fn coefficient_energy(&self, k: usize, x: &Local<N>, dc: &[f64]) -> f64 {
        let u = self.u(k, x);
        let (e, s1, _) = self.law(k, &u);
        let du: Vector3<f64> = (0..N).map(|m| x[m] * dc[m]).sum();
        let kk = self.stiffness[k];
        let mut de = (u * s1).dot(&du) + e / kk * dc[N];
        match self.saturation.get(k) {
            Some(&u0) if u0.is_finite() && dc[N + 1] != 0.0 => {
                let u2 = u.norm_squared();
                let q = (1.0 + u2 / (u0 * u0)).sqrt();
                de += (2.0 * kk * u0 * (q - 1.0) - kk * u2 / (q * u0)) * dc[N + 1];
            }
            _ => {}
        }
        de
    }
}

/// The bending of the grid lines that cross a symmetry plane, in a model that keeps one side of it
/// (a quarter or half model): the triple (p₁', p₀, p₁) centred on the plane, p₁' the mirror image of
/// p₁, has u = (p₁ + p₁' − 2p₀)/h = (2/h) P(p₁ − p₀), P dropping the component normal to the plane
/// (p₀ is held on it). Half of that triple's energy belongs to the kept side:
/// E = ½ · ½ k |u|², k = D w / h.
pub struct MirrorKernel {
    pairs: Vec<[u32; 2]>,
    normal_axis: usize,
    /// ½ k (2/h)² per pair, N/m.
    stiffness_N_per_m: Vec<f64>,
}

/// The term of [`MirrorKernel`]s.
pub type MirrorBending = Potential<MirrorKernel, 2>;

impl MirrorBending {
    /// Pairs (p₀ on the plane, p₁ its neighbour off it), the axis (0 = x, 1 = y) normal to the plane,
    /// spacings h (m) and bending stiffnesses k = D w / h (N·m).
    pub fn new(pairs: Vec<(usize, usize)>, normal_axis: usize, h_m: &[f64], k_N_m: &[f64]) -> Self {
        Potential::of(MirrorKernel {
            pairs: pairs.iter().map(|&(a, b)| [a as u32, b as u32]).collect(),
            normal_axis,
            stiffness_N_per_m: h_m
                .iter()
                .zip(k_N_m)
                .map(|(h, k)| 0.5 * k * (2.0 / h).powi(2))
                .collect(),
        })
    }
}

impl MirrorKernel {
    fn v(&self, x: &Local<2>) -> Vector3<f64> {
        let mut v = x[1] - x[0];
        v[self.normal_axis] = 0.0;
        v
    }
}

impl Kernel<2> for MirrorKernel {
    /// The pair's stiffness ½ k (2/h)², N/m.
    const COEFFICIENTS: usize = 1;
    fn name(&self) -> String {
        "bending/symmetry-plane".into()
    }
    fn stencils(&self) -> &[[u32; 2]] {
        &self.pairs
    }
    #[inline]
    fn energy(&self, k: usize, x: &Local<2>) -> f64 {
        0.5 * self.stiffness_N_per_m[k] * self.v(x).norm_squared()
    }
    #[inline]
    fn gradient(&self, k: usize, x: &Local<2>) -> Local<2> {
        let f = self.v(x) * self.stiffness_N_per_m[k];
        [-f, f]
    }
    fn hessian(
        &self,
        k: usize,
        _x: &Local<2>,
        _project: bool,
        push: &mut impl FnMut(usize, usize, Matrix3<f64>),
    ) {
        let mut p = Matrix3::identity();
        p[(self.normal_axis, self.normal_axis)] = 0.0;
        let block = p * self.stiffness_N_per_m[k];
        let coef = [-1.0, 1.0];
        for a in 0..2 {
            for b in 0..=a {
                push(a, b, block * (coef[a] * coef[b]));
            }
        }
    }
    fn coefficients(&self, k: usize, out: &mut Vec<f64>) {
        out.push(self.stiffness_N_per_m[k]);
    }
    fn set_coefficients(&mut self, k: usize, c: &[f64]) {
        self.stiffness_N_per_m[k] = c[0];
    }
    #[inline]
    fn coefficient_gradient(&self, _k: usize, x: &Local<2>, dc: &[f64]) -> Local<2> {
        let f = self.v(x) * dc[0];
        [-f, f]
    }
    #[inline]
    fn coefficient_energy(&self, _k: usize, x: &Local<2>, dc: &[f64]) -> f64 {
        0.5 * self.v(x).norm_squared() * dc[0]
    }
    fn stiffness_scale(&self) -> f64 {
        self.stiffness_N_per_m.iter().copied().fold(0.0, f64::max)
    }
}
