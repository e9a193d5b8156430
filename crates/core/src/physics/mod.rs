//! Physics as energy terms (softy's habit): each term gives its value, gradient and a positive
//! semi-definite (projected) Hessian as 3×3 blocks. A [`Model`] is the sum of the terms a scene needs,
//! the lumped masses and the pinned particles; solvers see nothing else.

mod adapted;
mod assembly;
mod barrier;
mod bending;
mod body_edges;
mod contacts;
mod curl;
mod friction;
mod hessian_mode;
mod kernel;
mod loads;
mod membrane;
mod mesh_bending;
mod obstacle_barrier;
mod patch_bending;
mod pattern_sheet;
mod seam;
mod self_contact;
mod shear;
mod springs;
#[cfg(test)]
pub(crate) mod testing;

pub use adapted::{Adapted, KAPPA_GROWTH_KEY};
pub use assembly::ModelBuilder;
pub use bending::{
    CellTwist, LinearBending, MirrorBending, MirrorKernel, QuadraticKernel, QuadraticStencil,
};
pub use body_edges::BodyEdgeBarrier;
pub use contacts::Contacts;
pub use curl::{Curl, CurlKernel, hinge_curl};
pub use friction::{FrictionAnchor, FrictionKernel, LaggedFriction};
pub use hessian_mode::{HessianMode, PairCurvature};
pub use kernel::{Kernel, Local, Potential};
pub use loads::{Gravity, LoadKernel, PointLoads};
pub use membrane::{Membrane, MembraneError, MembraneKernel};
pub use mesh_bending::{
    SewnSheet, hinge_bending, orthotropic_hinge_bending, saturating_hinge_bending,
    seam_hinge_bending, sewn_hinge_bending,
};
pub use obstacle_barrier::{ObstacleBarrier, max_penetration_m};
pub use patch_bending::{patch_bending, reads_creases};
pub use pattern_sheet::{PatternSheet, pattern_builder};
pub use seam::{SeamKernel, Seams};
pub use self_contact::{
    CandidateSet, ContactPair, ContactSet, PairKind, SelfContact, SelfContactState,
};
pub use shear::{CellShear, ShearKernel};
pub use springs::{SpringFamily, SpringKernel, Springs};

use nalgebra::{Matrix3, Vector3};
use std::sync::Arc;

/// Positions or vectors of all particles.
pub type Vecs = [Vector3<f64>];

/// 3×3 Hessian blocks `(p, q, block)` with `p >= q` (the lower triangle), pushed in the same order
/// at every call so that the sparsity pattern is analysed once.
#[derive(Debug, Default, Clone)]
pub struct HessianBlocks {
    /// Row particle, column particle (p ≥ q).
    pub pairs: Vec<(u32, u32)>,
    /// The blocks, parallel to `pairs`.
    pub blocks: Vec<Matrix3<f64>>,
    /// The blocks of the terms whose Hessian is constant ([`EnergyTerm::hessian_is_constant`]),
    /// computed once per model and shared by every evaluation: part of the matrix, summed before
    /// `pairs` ([`Self::all`]); a factorization keeps their assembled values between iterations.
    pub constant: Option<Arc<HessianBlocks>>,
    /// Blocks that are not in the matrix now but may come soon (self-contact's candidate pairs
    /// near range): a sparsity structure analysed anyway for a new block takes them in too, so
    /// that the contact set can grow into them without another analysis. Never entries.
    pub hints: Vec<(u32, u32)>,
}

impl HessianBlocks {
    /// Removes all blocks, keeping capacity.
    pub fn clear(&mut self) {
        self.pairs.clear();
        self.blocks.clear();
        self.constant = None;
        self.hints.clear();
    }
    /// Every block of the matrix: the constant part's, then this list's.
    pub fn all(&self) -> impl Iterator<Item = (&(u32, u32), &Matrix3<f64>)> {
        let constant = self
            .constant
            .as_deref()
            .map(|c| c.pairs.iter().zip(&c.blocks));
        constant
            .into_iter()
            .flatten()
            .chain(self.pairs.iter().zip(&self.blocks))
    }
    /// The particle pairs of the constant part (empty without one).
    pub fn constant_pairs(&self) -> &[(u32, u32)] {
        self.constant.as_deref().map_or(&[], |c| &c.pairs)
    }
    /// Adds a block at (p, q); for p < q the transpose is stored at (q, p).
    #[inline]
    pub fn push(&mut self, p: usize, q: usize, b: Matrix3<f64>) {
        if p >= q {
            self.pairs.push((p as u32, q as u32));
            self.blocks.push(b);
        } else {
            self.pairs.push((q as u32, p as u32));
            self.blocks.push(b.transpose());
        }
    }
    /// Adds the blocks of an interaction whose Hessian is `coef[a] coef[b] K` between particles `idx`.
    #[inline]
    pub fn push_outer(&mut self, idx: &[usize], coef: &[f64], k: &Matrix3<f64>) {
        for a in 0..idx.len() {
            for b in 0..=a {
                self.push(idx[a], idx[b], k * (coef[a] * coef[b]));
            }
        }
    }
    /// y += H x for the full symmetric matrix.
    pub fn mul_add(&self, x: &Vecs, y: &mut Vecs) {
        for (&(p, q), b) in self.all() {
            let (p, q) = (p as usize, q as usize);
            y[p] += b * x[q];
            if p != q {
                y[q] += b.transpose() * x[p];
            }
        }
    }
    /// The same matrix with its diagonal blocks summed per particle (first, one per particle of
    /// `n`) and its off-diagonal blocks as they are: a cheaper [`Self::mul_add`] for a solver that
    /// multiplies by one Hessian several times (every spring pushes two diagonal blocks).
    pub fn compacted(&self, n: usize) -> HessianBlocks {
        let mut out = HessianBlocks {
            pairs: (0..n as u32).map(|p| (p, p)).collect(),
            blocks: self.diagonal(n),
            constant: None,
            hints: Vec::new(),
        };
        for (&(p, q), b) in self.all() {
            if p != q {
                out.pairs.push((p, q));
                out.blocks.push(*b);
            }
        }
        out
    }
    /// The 3×3 diagonal blocks summed per particle.
    pub fn diagonal(&self, n: usize) -> Vec<Matrix3<f64>> {
        let mut d = vec![Matrix3::zeros(); n];
        for (&(p, q), b) in self.all() {
            if p == q {
                d[p as usize] += b;
            }
        }
        d
    }
}

/// A term as [`std::any::Any`]: how a solver that needs one kind of term (the sheet's
/// self-contact, for its candidate sets and report) finds it by type, with no hook for it on
/// every term.
pub trait AsAny {
    /// The term as `Any`, to downcast.
    fn as_any(&self) -> &dyn std::any::Any;
    /// The term as mutable `Any`, to downcast.
    fn as_any_mut(&mut self) -> &mut dyn std::any::Any;
}

impl<T: std::any::Any> AsAny for T {
    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
    fn as_any_mut(&mut self) -> &mut dyn std::any::Any {
        self
    }
}

/// The collision-free step size of a contact term, a query apart from its energy (ipc-toolkit's
/// `compute_collision_free_stepsize`): how far along a step the term's primitives can go without
/// touching.
pub trait StepBound {
    /// The largest fraction of the step `dx` from `x` that the term allows (a step that cannot
    /// carry a particle into an obstacle, or the sheet through itself); infinite when nothing is
    /// in reach.
    fn max_step(&self, x: &Vecs, dx: &Vecs) -> f64;
}

/// One energy term of the total potential energy.
pub trait EnergyTerm: Send + Sync + AsAny {
    /// A short name for reports ("springs/structural", "gravity", ...).
    fn name(&self) -> String;
    /// Energy in J.
    fn energy(&self, x: &Vecs) -> f64;
    /// Adds ∂E/∂x (N) to `g`.
    fn add_gradient(&self, x: &Vecs, g: &mut Vecs);
    /// Pushes the Hessian blocks (N/m) the solver asks for ([`HessianMode`]). The block pattern
    /// must not depend on the mode.
    fn add_hessian(&self, x: &Vecs, h: &mut HessianBlocks, mode: HessianMode);
    /// Whether the Hessian is the same at every x, projected or not (a quadratic energy: bending
    /// along grid lines, linear hinge bending): a [`Model`] then computes its blocks once.
    fn hessian_is_constant(&self) -> bool {
        false
    }
    /// Largest relative elongation of the term's springs, for divergence checks (0 if none).
    fn max_strain(&self, _x: &Vecs) -> f64 {
        0.0
    }
    /// Applies Provot's position correction at elongation rate `rate` (only spring terms do).
    fn provot_correct(&self, _x: &mut Vecs, _free: &[bool], _rate: f64) {}
    /// The largest stiffness (N/m) the term couples particles with: sets the round-off floor of forces.
    fn stiffness_scale(&self) -> f64 {
        0.0
    }
    /// Whether the term is an external load, scaled by the load factor of incremental loading.
    fn is_external_load(&self) -> bool {
        false
    }
    /// The term's collision-free step query, for a contact term ([`StepBound`]); None for others.
    fn step_bound(&self) -> Option<&dyn StepBound> {
        None
    }
    /// The term's coefficients, flat: the numbers its stencils are built over from the scene's
    /// parameters (stiffnesses, rest lengths, weights; SI units). Empty for a term that does not
    /// give them (its derivative in a parameter is then taken by differences of its gradient).
    fn coefficients(&self) -> Vec<f64> {
        Vec::new()
    }
    /// Sets the coefficients (the layout of [`EnergyTerm::coefficients`]).
    fn set_coefficients(&mut self, _c: &[f64]) {}
    /// Adds the mixed derivative ∂(∂E/∂x)/∂c · dc to `g`: how the gradient at `x` changes along a
    /// change `dc` of the coefficients (per unit of the parameter `dc` is a derivative in). False,
    /// with `g` untouched, when the term does not give it.
    fn add_coefficient_gradient(&self, _x: &Vecs, _dc: &[f64], _g: &mut Vecs) -> bool {
        false
    }
    /// ∂E/∂c · dc at `x` (J per unit of the parameter), None when the term does not give it.
    fn coefficient_energy(&self, _x: &Vecs, _dc: &[f64]) -> Option<f64> {
        None
    }
}

/// The assembled model: masses, pins and energy terms.
pub struct Model {
    /// Lumped masses in kg (zero for virtual clamp points).
    pub masses: Vec<f64>,
    /// `true` for particles whose position is fixed (pins, clamps, virtual clamp points).
    pub fixed: Vec<bool>,
    /// Per particle, the position components held where they are (a particle on a symmetry plane
    /// keeps its coordinate normal to the plane); empty when none. Static solves only.
    pub held_components: Vec<[bool; 3]>,
    /// Number of real grid particles; particles beyond are virtual (fixed) helpers.
    pub n_grid: usize,
    /// The energy terms; only those the scene needs.
    pub terms: Vec<Box<dyn EnergyTerm>>,
    /// Gravitational acceleration in m/s² (positive, acting along −z).
    pub gravity_m_per_s2: f64,
    /// Viscous damping per particle in N·s/m (dynamics only).
    pub damping_Ns_per_m: f64,
    /// Provot's elongation rate, applied by explicit Euler (None: no correction).
    pub elongation_rate: Option<f64>,
    /// The Hessian blocks of the terms whose Hessian is constant, made at the first
    /// [`Model::hessian`] (`Default::default()` when building; never set by hand).
    pub constant_hessian: std::sync::OnceLock<Option<Arc<HessianBlocks>>>,
}

impl Model {
    /// Number of particles, virtual ones included.
    pub fn len(&self) -> usize {
        self.masses.len()
    }
    /// Whether the model has no particles.
    pub fn is_empty(&self) -> bool {
        self.masses.is_empty()
    }
    /// Total potential energy in J, external loads scaled by `load` (1 = full load), with the
    /// contact set measured at `x` ([`Model::energy_on`]).
    pub fn energy(&self, x: &Vecs, load: f64) -> f64 {
        self.energy_on(x, &self.contacts(x), load)
    }
    /// Gradient of the total energy (N) into `g` (overwritten), external loads scaled by `load`,
    /// with the contact set measured at `x` ([`Model::gradient_on`]).
    pub fn gradient(&self, x: &Vecs, load: f64, g: &mut Vec<Vector3<f64>>) {
        self.gradient_on(x, &self.contacts(x), load, g);
    }
    /// Hessian blocks of the total energy into `h` (cleared first), as `mode` asks, with the
    /// contact set measured at `x` ([`Model::hessian_on`]).
    pub fn hessian(&self, x: &Vecs, h: &mut HessianBlocks, mode: HessianMode) {
        self.hessian_on(x, &self.contacts(x), h, mode);
    }
    /// The largest fraction of the step `dx` that every contact term allows ([`StepBound`]), with
    /// a candidate set of its own ([`Model::max_step_with`] is a solve's).
    pub fn max_step(&self, x: &Vecs, dx: &Vecs) -> f64 {
        self.max_step_with(x, dx, &mut CandidateSet::default())
    }
    /// Largest residual force on a free particle in N, from the gradient.
    pub fn max_residual(&self, g: &Vecs) -> f64 {
        g.iter()
            .enumerate()
            .filter(|(p, _)| !self.fixed[*p])
            .map(|(p, v)| {
                let mut v = *v;
                if let Some(h) = self.held_components.get(p) {
                    for c in 0..3 {
                        if h[c] {
                            v[c] = 0.0;
                        }
                    }
                }
                v.norm()
            })
            .fold(0.0, f64::max)
    }
    /// Whether component `c` of particle `p` is held (see `held_components`).
    pub fn is_held(&self, p: usize, c: usize) -> bool {
        self.held_components.get(p).is_some_and(|h| h[c])
    }
    /// The weight of the lightest free particle in N, the reference of force tolerances.
    pub fn reference_weight(&self) -> f64 {
        let g = if self.gravity_m_per_s2 > 0.0 {
            self.gravity_m_per_s2
        } else {
            crate::STANDARD_GRAVITY_M_PER_S2
        };
        self.masses
            .iter()
            .zip(&self.fixed)
            .filter(|(m, f)| !**f && **m > 0.0)
            .map(|(m, _)| m * g)
            .fold(f64::INFINITY, f64::min)
    }
    /// The smallest residual force (N) that round-off lets a solver resolve at positions `x`: forces
    /// are sums of k·(l − L) where l carries an error of about ε·|x|, so r ≈ 16 ε k_max |x|_max.
    pub fn roundoff_force(&self, x: &Vecs) -> f64 {
        let k = self
            .terms
            .iter()
            .map(|t| t.stiffness_scale())
            .fold(0.0, f64::max);
        let xmax = x.iter().map(|p| p.amax()).fold(0.0, f64::max);
        16.0 * f64::EPSILON * k * xmax
    }
    /// Largest spring strain over all terms.
    pub fn max_strain(&self, x: &Vecs) -> f64 {
        self.terms
            .iter()
            .map(|t| t.max_strain(x))
            .fold(0.0, f64::max)
    }
    /// The sheet's self-contact term, when the model has one.
    pub fn self_contact_term(&self) -> Option<&SelfContact> {
        self.terms
            .iter()
            .find_map(|t| (**t).as_any().downcast_ref::<SelfContact>())
    }
    /// The sheet's self-contact term to change (its coefficients), when the model has one.
    pub fn self_contact_term_mut(&mut self) -> Option<&mut SelfContact> {
        self.terms
            .iter_mut()
            .find_map(|t| (**t).as_any_mut().downcast_mut::<SelfContact>())
    }
    /// Whether the model has the sheet's self-contact term (cheap: no state is computed).
    pub fn models_self_contact(&self) -> bool {
        self.self_contact_term().is_some()
    }
    /// The state of the sheet's self-contact at `x`, when the model has the term.
    pub fn self_contact(&self, x: &Vecs) -> Option<SelfContactState> {
        self.self_contact_term().map(|t| t.state(x))
    }
    /// Names of the terms that were built.
    pub fn term_names(&self) -> Vec<String> {
        self.terms.iter().map(|t| t.name()).collect()
    }
    /// The candidate set of the model's self-contact at `x`, valid while each vertex v stays within
    /// `spread[v]` (m) of it; None without self-contact.
    pub fn candidates_covering(&self, x: &Vecs, spread: &[f64]) -> Option<CandidateSet> {
        self.self_contact_term()
            .map(|t| t.candidates_covering(x, spread))
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// Central differences of `term`'s energy (step `step`) at the coordinates of `particles`
    /// against its gradient, within `tol` of the gradient's largest component anywhere.
    pub(crate) fn check_gradient_scaled(
        term: &dyn EnergyTerm,
        x: &[Vector3<f64>],
        particles: impl IntoIterator<Item = usize>,
        (step, tol): (f64, f64),
    ) {
        let mut g = vec![Vector3::zeros(); x.len()];
        term.add_gradient(x, &mut g);
        let largest = g.iter().map(|v| v.amax()).fold(0.0, f64::max);
        for p in particles {
            for c in 0..3 {
                let (mut xp, mut xm) = (x.to_vec(), x.to_vec());
                xp[p][c] += step;
                xm[p][c] -= step;
                let fd = (term.energy(&xp) - term.energy(&xm)) / (2.0 * step);
                assert!(
                    (fd - g[p][c]).abs() < tol * largest,
                    "{}: d/dx[{p}][{c}] fd {fd:e} vs {:e}",
                    term.name(),
                    g[p][c]
                );
            }
        }
    }

    /// Finite-difference check of every term's gradient and of the Hessian where it is exact.
    pub(crate) fn check_gradient(term: &dyn EnergyTerm, x: &[Vector3<f64>]) {
        let mut g = vec![Vector3::zeros(); x.len()];
        term.add_gradient(x, &mut g);
        let eps = 1e-7;
        for p in 0..x.len() {
            for c in 0..3 {
                let mut xp = x.to_vec();
                xp[p][c] += eps;
                let mut xm = x.to_vec();
                xm[p][c] -= eps;
                let fd = (term.energy(&xp) - term.energy(&xm)) / (2.0 * eps);
                assert!(
                    (fd - g[p][c]).abs() < 1e-5 * (1.0 + fd.abs()),
                    "{}: d/dx[{p}][{c}] fd {fd} vs {}",
                    term.name(),
                    g[p][c]
                );
            }
        }
    }

    fn wiggle(n: usize) -> Vec<Vector3<f64>> {
        (0..n)
            .map(|k| {
                let (i, j) = ((k % 3) as f64, (k / 3) as f64);
                Vector3::new(
                    0.1 * i + 0.01 * (k as f64).sin(),
                    0.1 * j + 0.013 * (k as f64 * 1.7).cos(),
                    0.02 * (k as f64 * 0.9).sin(),
                )
            })
            .collect()
    }

    #[test]
    fn gradients_match_finite_differences() {
        let x = wiggle(9);
        let springs = Springs::new(
            SpringFamily::Structural,
            vec![(0, 1), (1, 2), (3, 4), (0, 3)],
            vec![0.1, 0.12, 0.09, 0.1],
            vec![100.0; 4],
        );
        check_gradient(&springs, &x);
        let bend = LinearBending::new(
            vec![[0, 1, 2], [3, 4, 5]],
            vec![[10.0, -20.0, 10.0], [8.0, -18.0, 10.0]],
            vec![0.3, 0.5],
        );
        check_gradient(&bend, &x);
        let shear = CellShear::new(
            vec![[0, 1, 3, 4], [4, 5, 7, 8]],
            vec![(0.1, 0.1), (0.1, 0.12)],
            3.0,
        );
        check_gradient(&shear, &x);
        let grav = Gravity::new(vec![0.1; 9], 9.81);
        check_gradient(&grav, &x);
    }
}
