//! Terms as local kernels (ipc-toolkit's habit: a potential is a per-stencil kernel, the loop over
//! the mesh is written once). A [`Kernel`] gives, for one stencil of N particles, the energy, its
//! gradient, its Hessian blocks and the mixed derivative of its gradient in the stencil's
//! coefficients (the stiffnesses, rest lengths and weights the scene's parameters become);
//! [`Potential`] runs it over all stencils and scatters into the whole mesh.

use super::{EnergyTerm, HessianBlocks, HessianMode, Vecs};
use nalgebra::{Matrix3, Vector3};

/// Positions (or vectors) of one stencil's particles.
pub type Local<const N: usize> = [Vector3<f64>; N];

/// One energy term's per-stencil kernel.
pub trait Kernel<const N: usize>: Send + Sync {
    /// Coefficients per stencil (the length of [`Kernel::coefficients`]).
    const COEFFICIENTS: usize;
    /// A short name for reports.
    fn name(&self) -> String;
    /// The stencils: particle indices.
    fn stencils(&self) -> &[[u32; N]];
    /// Energy of stencil `s` at its particles' positions `x`, J.
    fn energy(&self, s: usize, x: &Local<N>) -> f64;
    /// ∂E_s/∂x, N.
    fn gradient(&self, s: usize, x: &Local<N>) -> Local<N>;
    /// Hands the Hessian blocks ∂²E_s/∂x_a∂x_b (N/m) to `push(a, b, block)` for b ≤ a (stencil-local
    /// indices), exact or, with `project`, positive semi-definite. The blocks pushed must not depend
    /// on `project`.
    fn hessian(
        &self,
        s: usize,
        x: &Local<N>,
        project: bool,
        push: &mut impl FnMut(usize, usize, Matrix3<f64>),
    );
    /// The exact Hessian blocks of stencil `s` for derivatives of an equilibrium (see
    /// [`HessianMode::Exact`]): the unprojected [`Kernel::hessian`] unless the solver's
    /// Hessian leaves a curvature out.
    fn exact_hessian(
        &self,
        s: usize,
        x: &Local<N>,
        push: &mut impl FnMut(usize, usize, Matrix3<f64>),
    ) {
        self.hessian(s, x, false, push);
    }
    /// Stencil `s`'s coefficients, appended to `out` (SI units; [`Kernel::COEFFICIENTS`] of them).
    fn coefficients(&self, s: usize, out: &mut Vec<f64>);
    /// Sets stencil `s`'s coefficients (the layout of [`Kernel::coefficients`]).
    fn set_coefficients(&mut self, s: usize, c: &[f64]);
    /// The mixed derivative Σ_c ∂(∂E_s/∂x)/∂c · dc: how the stencil's gradient changes along a
    /// change `dc` of its coefficients, N per unit of the parameter `dc` is a derivative in.
    fn coefficient_gradient(&self, s: usize, x: &Local<N>, dc: &[f64]) -> Local<N>;
    /// ∂E_s/∂c · dc: how the stencil's energy changes along `dc`, J per unit of the parameter.
    fn coefficient_energy(&self, s: usize, x: &Local<N>, dc: &[f64]) -> f64;
    /// The largest stiffness (N/m) the kernel couples particles with (see
    /// [`EnergyTerm::stiffness_scale`]).
    fn stiffness_scale(&self) -> f64 {
        0.0
    }
    /// Whether the term is an external load (see [`EnergyTerm::is_external_load`]).
    fn is_external_load(&self) -> bool {
        false
    }
    /// Whether the Hessian is constant (see [`EnergyTerm::hessian_is_constant`]).
    fn hessian_is_constant(&self) -> bool {
        false
    }
    /// Relative elongation of stencil `s` (springs; 0 for others).
    fn strain(&self, _s: usize, _x: &Local<N>) -> f64 {
        0.0
    }
    /// Provot's position correction (see [`EnergyTerm::provot_correct`]); springs only.
    fn provot_correct(&self, _x: &mut Vecs, _free: &[bool], _rate: f64) {}
}

/// An energy term made of a kernel: the loop over stencils, the gather of positions and the
/// scatter of gradients and Hessian blocks, written once for every kernel.
pub struct Potential<K, const N: usize> {
    pub(super) kernel: K,
}

impl<K: Kernel<N>, const N: usize> Potential<K, N> {
    /// The term of `kernel`.
    pub fn of(kernel: K) -> Self {
        Self { kernel }
    }
    /// Number of stencils.
    pub fn len(&self) -> usize {
        self.kernel.stencils().len()
    }
    /// Whether there are no stencils.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
    #[inline]
    fn gather(&self, s: usize, x: &Vecs) -> (Local<N>, [usize; N]) {
        let idx = self.kernel.stencils()[s].map(|v| v as usize);
        (idx.map(|p| x[p]), idx)
    }
}

impl<K: Kernel<N> + 'static, const N: usize> EnergyTerm for Potential<K, N> {
    fn name(&self) -> String {
        self.kernel.name()
    }
    fn energy(&self, x: &Vecs) -> f64 {
        (0..self.len())
            .map(|s| self.kernel.energy(s, &self.gather(s, x).0))
            .sum()
    }
    fn add_gradient(&self, x: &Vecs, g: &mut Vecs) {
        for s in 0..self.len() {
            let (xs, idx) = self.gather(s, x);
            let gs = self.kernel.gradient(s, &xs);
            for m in 0..N {
                g[idx[m]] += gs[m];
            }
        }
    }
    fn add_hessian(&self, x: &Vecs, h: &mut HessianBlocks, mode: HessianMode) {
        for s in 0..self.len() {
            let (xs, idx) = self.gather(s, x);
            let mut push = |a: usize, b: usize, blk| h.push(idx[a], idx[b], blk);
            match mode {
                HessianMode::Exact => self.kernel.exact_hessian(s, &xs, &mut push),
                _ => self.kernel.hessian(s, &xs, mode.is_projected(), &mut push),
            }
        }
    }
    fn stiffness_scale(&self) -> f64 {
        self.kernel.stiffness_scale()
    }
    fn is_external_load(&self) -> bool {
        self.kernel.is_external_load()
    }
    fn hessian_is_constant(&self) -> bool {
        self.kernel.hessian_is_constant()
    }
    fn max_strain(&self, x: &Vecs) -> f64 {
        (0..self.len())
            .map(|s| self.kernel.strain(s, &self.gather(s, x).0))
            .fold(0.0, f64::max)
    }
    fn provot_correct(&self, x: &mut Vecs, free: &[bool], rate: f64) {
        self.kernel.provot_correct(x, free, rate);
    }
    fn coefficients(&self) -> Vec<f64> {
        let mut c = Vec::with_capacity(self.len() * K::COEFFICIENTS);
        for s in 0..self.len() {
            self.kernel.coefficients(s, &mut c);
        }
        c
    }
    fn set_coefficients(&mut self, c: &[f64]) {
        let k = K::COEFFICIENTS;
        for s in 0..self.len() {
            self.kernel.set_coefficients(s, &c[s * k..(s + 1) * k]);
        }
    }
    fn add_coefficient_gradient(&self, x: &Vecs, dc: &[f64], g: &mut Vecs) -> bool {
        let k = K::COEFFICIENTS;
        if dc.len() != self.len() * k {
            return false;
        }
        for s in 0..self.len() {
            let (xs, idx) = self.gather(s, x);
            let gs = self
                .kernel
                .coefficient_gradient(s, &xs, &dc[s * k..(s + 1) * k]);
            for m in 0..N {
                g[idx[m]] += gs[m];
            }
        }
        true
    }
    fn coefficient_energy(&self, x: &Vecs, dc: &[f64]) -> Option<f64> {
        let k = K::COEFFICIENTS;
        (dc.len() == self.len() * k).then(|| {
            (0..self.len())
                .map(|s| {
                    let xs = self.gather(s, x).0;
                    self.kernel
                        .coefficient_energy(s, &xs, &dc[s * k..(s + 1) * k])
                })
                .sum()
        })
    }
}
