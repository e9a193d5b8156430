//! The factor of an equilibrium: the exact Hessian H of the energy at a converged minimum over the
//! free coordinates, Cholesky-factorized once. Whether it factorizes says whether the equilibrium
//! is a minimum ([`super::is_minimum`]); its solves give the equilibrium's derivatives, by the
//! implicit function theorem on g(x*(θ), θ) = 0:
//!
//! dx*/dθ = −H⁻¹ ∂g/∂θ (a sensitivity, one back-substitution per parameter), and for a scalar
//! measure J(x*), dJ/dθ = −λᵀ ∂g/∂θ with H λ = ∂J/∂x (an adjoint, one back-substitution for all
//! parameters). H is symmetric, so the same factor serves both.

use super::linear::{DofMap, SparseSpd};
use crate::physics::{HessianBlocks, Model, Vecs};
use nalgebra::Vector3;

/// The neutral-direction shift of the exact Hessian, relative to its mean diagonal: large enough
/// that a sheet's rigid in-plane rotation about its pins (zero stiffness at a flat state) does not
/// fail the factorization on round-off, small enough (1e-10) that every derivative it gives is
/// unchanged to 1e-10 relative.
pub const NEUTRAL_SHIFT_REL: f64 = 1e-10;

/// The shift that decouples a held position component (a particle on a symmetry plane keeps its
/// coordinate normal to the plane), relative to the mean diagonal.
pub const HELD_SHIFT_REL: f64 = 1e12;

/// Steps of iterative refinement of each solve against the unshifted Hessian (each multiplies the
/// shift's bias by σ/λ_min).
pub const REFINEMENTS: usize = 2;

/// Why an equilibrium has no factor (and so no sensitivities).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum NoFactor {
    /// The solve did not converge: the state is no equilibrium.
    NotConverged,
    /// The exact Hessian is not positive definite: a saddle or a maximum, where the equilibrium
    /// does not move smoothly with the parameters.
    NotAMinimum,
    /// Every particle is fixed: there is nothing to differentiate.
    NothingFree,
}

impl NoFactor {
    /// In words, for run reports.
    pub fn as_str(self) -> &'static str {
        match self {
            NoFactor::NotConverged => "the solve did not converge: the state is no equilibrium",
            NoFactor::NotAMinimum => {
                "the equilibrium is not a minimum (its exact Hessian is indefinite)"
            }
            NoFactor::NothingFree => "every particle is fixed",
        }
    }
}

/// The Cholesky factor of the exact Hessian at an equilibrium, over the free coordinates.
pub struct EquilibriumFactor {
    dofs: DofMap,
    spd: SparseSpd,
    /// The exact Hessian, for the refinement of solves against the unshifted matrix.
    h: HessianBlocks,
    /// Free (particle, component) that are held: their derivative is zero.
    held: Vec<(usize, usize)>,
    n: usize,
}

impl EquilibriumFactor {
    /// Factorizes the exact Hessian of `model` at `x` ([`crate::physics::HessianMode::Exact`]); fails where it
    /// is not positive definite.
    pub fn new(model: &Model, x: &Vecs) -> Result<Self, NoFactor> {
        let mut h = HessianBlocks::default();
        model.hessian(x, &mut h, crate::physics::HessianMode::Exact);
        Self::of(model, h)
    }

    /// Factorizes the given Hessian blocks of `model` (the solver's unprojected Hessian for the
    /// minimum check, [`super::is_minimum`]).
    pub fn of(model: &Model, h: HessianBlocks) -> Result<Self, NoFactor> {
        let dofs = DofMap::new(&model.fixed);
        if dofs.n == 0 {
            return Err(NoFactor::NothingFree);
        }
        let scale = super::step::mean_free_diagonal(&h, &dofs);
        let mut shift = vec![NEUTRAL_SHIFT_REL * scale; dofs.n];
        let mut held = Vec::new();
        for p in 0..model.len() {
            let Some(d) = dofs.dof(p) else { continue };
            for c in 0..3 {
                if model.is_held(p, c) {
                    shift[d + c] += HELD_SHIFT_REL * scale.max(1e-300);
                    held.push((p, c));
                }
            }
        }
        let mut spd = SparseSpd::new();
        if !spd.factorize(&dofs, &h, &shift) {
            return Err(NoFactor::NotAMinimum);
        }
        Ok(Self {
            dofs,
            spd,
            h,
            held,
            n: model.len(),
        })
    }

    /// y = H⁻¹ r over the free coordinates; zero on fixed particles and held components. The factor
    /// is of H + σI (σ = [`NEUTRAL_SHIFT_REL`] of the mean diagonal); [`REFINEMENTS`] steps of
    /// iterative refinement against H itself remove the shift's bias, which near a soft mode (a
    /// sheet hung from two corners swings freely) is σ/λ_min of the answer.
    pub fn solve(&mut self, r: &Vecs) -> Vec<Vector3<f64>> {
        self.solve_checked(r).0
    }

    /// [`Self::solve`] and the relative residual ‖H y − r‖/‖r‖ it leaves: near round-off for a
    /// right-hand side H can answer, of order one when `r` pushes along a motion the equilibrium
    /// is free to make (a neutral mode: a sheet held at one point on a frictionless sphere turning
    /// about it), where no finite y exists.
    pub fn solve_checked(&mut self, r: &Vecs) -> (Vec<Vector3<f64>>, f64) {
        let r = self.free_part(r);
        let mut y = self.shifted_solve(&r);
        let mut res = self.residual(&r, &y);
        for _ in 0..REFINEMENTS {
            let dy = self.shifted_solve(&res);
            for (a, b) in y.iter_mut().zip(&dy) {
                *a += b;
            }
            res = self.residual(&r, &y);
        }
        let size = |v: &[Vector3<f64>]| v.iter().map(|p| p.norm_squared()).sum::<f64>().sqrt();
        let rel = size(&res) / size(&r).max(f64::MIN_POSITIVE);
        (y, if size(&r) == 0.0 { 0.0 } else { rel })
    }

    /// r − H y over the free coordinates.
    fn residual(&self, r: &[Vector3<f64>], y: &[Vector3<f64>]) -> Vec<Vector3<f64>> {
        let mut hy = vec![Vector3::zeros(); self.n];
        self.h.mul_add(y, &mut hy);
        let hy = self.free_part(&hy);
        r.iter().zip(&hy).map(|(a, b)| a - b).collect()
    }

    /// `r` with its fixed particles' and held components' entries zeroed.
    fn free_part(&self, r: &Vecs) -> Vec<Vector3<f64>> {
        let mut out: Vec<Vector3<f64>> = (0..self.n)
            .map(|p| {
                if self.dofs.dof(p).is_some() {
                    r.get(p).copied().unwrap_or_else(Vector3::zeros)
                } else {
                    Vector3::zeros()
                }
            })
            .collect();
        for &(p, c) in &self.held {
            out[p][c] = 0.0;
        }
        out
    }

    /// (H + σI)⁻¹ r with the factor.
    fn shifted_solve(&mut self, r: &Vecs) -> Vec<Vector3<f64>> {
        let mut rhs = vec![0.0; self.dofs.n];
        for (p, v) in r.iter().enumerate().take(self.n) {
            if let Some(d) = self.dofs.dof(p) {
                rhs[d..d + 3].copy_from_slice(v.as_slice());
            }
        }
        for &(p, c) in &self.held {
            if let Some(d) = self.dofs.dof(p) {
                rhs[d + c] = 0.0;
            }
        }
        self.spd.solve_in_place(&mut rhs);
        let mut y = vec![Vector3::zeros(); self.n];
        for (p, v) in y.iter_mut().enumerate() {
            if let Some(d) = self.dofs.dof(p) {
                *v = Vector3::new(rhs[d], rhs[d + 1], rhs[d + 2]);
            }
        }
        for &(p, c) in &self.held {
            y[p][c] = 0.0;
        }
        y
    }

    /// The equilibrium's sensitivity dx*/dθ = −H⁻¹ ∂g/∂θ for the total derivative ∂g/∂θ of the
    /// gradient (fixed particles' motion included), plus the fixed particles' own motion
    /// `dx_fixed` (zero on free ones). Metres per unit of θ.
    pub fn sensitivity(&mut self, dg: &Vecs, dx_fixed: &Vecs) -> Vec<Vector3<f64>> {
        self.sensitivity_checked(dg, dx_fixed).0
    }

    /// [`Self::sensitivity`] with the relative residual of its solve ([`Self::solve_checked`]).
    pub fn sensitivity_checked(&mut self, dg: &Vecs, dx_fixed: &Vecs) -> (Vec<Vector3<f64>>, f64) {
        let (mut dx, rel) = self.solve_checked(dg);
        for (p, v) in dx.iter_mut().enumerate() {
            if self.dofs.dof(p).is_some() {
                *v = -*v;
            } else {
                *v = dx_fixed.get(p).copied().unwrap_or_else(Vector3::zeros);
            }
        }
        (dx, rel)
    }

    /// Whether particle `p` is free (has coordinates in the factor).
    /// The Cholesky factor itself (of H + σI, held components decoupled).
    pub fn factor(&self) -> &SparseSpd {
        &self.spd
    }

    /// Whether particle `p` is free.
    pub fn is_free(&self, p: usize) -> bool {
        self.dofs.dof(p).is_some()
    }

    /// Numeric factorizations and back-substitutions this factor cost so far (1 and its solves).
    pub fn factorizations(&self) -> usize {
        self.spd.factorizations
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::{Gravity, SpringFamily, Springs};

    /// A chain of three springs between two fixed ends, two free particles under gravity: H is a
    /// known 6 × 6 matrix, dx*/dm is its inverse applied to the weight's derivative.
    fn chain(m: f64) -> (Model, Vec<Vector3<f64>>) {
        let x: Vec<Vector3<f64>> = (0..4)
            .map(|k| Vector3::new(0.1 * k as f64, 0.0, 0.0))
            .collect();
        let springs = Springs::new(
            SpringFamily::Structural,
            vec![(0, 1), (1, 2), (2, 3)],
            vec![0.09; 3],
            vec![100.0; 3],
        );
        let model = Model {
            masses: vec![m; 4],
            fixed: vec![true, false, false, true],
            held_components: Vec::new(),
            n_grid: 4,
            terms: vec![Box::new(springs), Box::new(Gravity::new(vec![m; 4], 9.81))],
            gravity_m_per_s2: 9.81,
            damping_Ns_per_m: 0.0,
            elongation_rate: None,
            constant_hessian: Default::default(),
        };
        (model, x)
    }

    fn equilibrium(model: &mut Model, x: &mut [Vector3<f64>]) {
        let opts = crate::solve::StaticOptions {
            residual_tol_rel: 1e-12,
            ..Default::default()
        };
        let r = crate::solve::solve_static(model, x, &opts, &mut crate::solve::NoObserver);
        assert!(r.is_converged(), "{}", r.message);
    }

    #[test]
    fn sensitivity_to_the_mass_matches_central_differences_of_the_equilibria() {
        let m = 0.01;
        let (mut model, mut x) = chain(m);
        equilibrium(&mut model, &mut x);
        let mut f = EquilibriumFactor::new(&model, &x).expect("a minimum");
        // ∂g/∂m at fixed x: the weight's gradient per kg, (0, 0, g) on each particle.
        let dg = vec![Vector3::new(0.0, 0.0, 9.81); 4];
        let s = f.sensitivity(&dg, &[Vector3::zeros(); 4]);
        let h = 1e-5;
        let solve_at = |mm: f64| {
            let (mut mo, mut xx) = chain(mm);
            xx.copy_from_slice(&x);
            equilibrium(&mut mo, &mut xx);
            xx
        };
        let (xp, xm) = (solve_at(m + h), solve_at(m - h));
        for p in 0..4 {
            let fd = (xp[p] - xm[p]) / (2.0 * h);
            assert!(
                (fd - s[p]).norm() <= 1e-6 * (1.0 + fd.norm()),
                "particle {p}: fd {fd:?}, sensitivity {:?}",
                s[p]
            );
        }
        assert_eq!(s[0], Vector3::zeros());
        assert!(s[1].z < 0.0, "more mass sags lower");
    }

    /// The chain at `m` solved from the 10 g chain's drape, with (report, drape) and without (drape)
    /// the 10 g chain's factor as the preconditioner.
    fn from_neighbour(
        m: f64,
    ) -> (
        crate::solve::SolveReport,
        Vec<Vector3<f64>>,
        Vec<Vector3<f64>>,
    ) {
        let (mut model, mut x) = chain(0.01);
        equilibrium(&mut model, &mut x);
        let f = EquilibriumFactor::new(&model, &x).expect("a minimum");
        let shared = std::sync::Arc::new(f.factor().copy());
        let (mut plain, mut xp) = chain(m);
        xp.copy_from_slice(&x);
        equilibrium(&mut plain, &mut xp);
        let (mut seeded, mut xs) = chain(m);
        xs.copy_from_slice(&x);
        let opts = crate::solve::StaticOptions {
            residual_tol_rel: 1e-12,
            ..Default::default()
        };
        let factor = crate::solve::NeighbourFactor(shared);
        let warm = crate::solve::WarmData {
            factor: Some(&factor),
            ..Default::default()
        };
        let mut obs = crate::solve::NoObserver;
        let r = crate::solve::solve_static_warm(&mut seeded, &mut xs, &opts, warm, &mut obs);
        assert!(r.is_converged(), "{}", r.message);
        (r, xs, xp)
    }

    #[test]
    fn a_neighbours_factor_solves_the_next_equilibrium_without_a_factorization() {
        // The chain at 10.5 g and at 40 g (farther, with more sag) from the 10 g chain's drape
        // with its factor as the preconditioner.
        for m in [0.0105, 0.04] {
            let (r, xs, xp) = from_neighbour(m);
            assert_eq!(r.factorizations, 0, "mass {m}: {r:?}");
            assert!(r.globalization.krylov_steps > 0);
            for p in 0..4 {
                assert!((xs[p] - xp[p]).norm() < 1e-9, "mass {m}, particle {p}");
            }
        }
    }

    #[test]
    fn a_neighbours_factor_hands_over_to_factorizations_once_the_line_search_shortens_its_step() {
        // The chain at 200 g (20 times heavier, far from the start): the undamped step the 10 g
        // chain's factor gives overshoots, the line search shortens it, and the damped, factorized
        // iteration finishes — to the same drape.
        let (r, xs, xp) = from_neighbour(0.2);
        let g = &r.globalization;
        eprintln!("{g:?}, {} factorizations", r.factorizations);
        assert_eq!(g.krylov_steps, 1, "{g:?}");
        assert!(g.shortened_steps >= 1 && r.factorizations > 0, "{r:?}");
        for p in 0..4 {
            assert!((xs[p] - xp[p]).norm() < 1e-9, "particle {p}");
        }
    }

    #[test]
    fn a_push_along_a_free_motion_leaves_a_residual_and_an_answerable_one_none() {
        // One free particle on a spring at its rest length, no weight: free to move sideways.
        let x = vec![Vector3::zeros(), Vector3::new(0.1, 0.0, 0.0)];
        let model = Model {
            masses: vec![0.0, 0.01],
            fixed: vec![true, false],
            held_components: Vec::new(),
            n_grid: 2,
            terms: vec![Box::new(Springs::new(
                SpringFamily::Structural,
                vec![(0, 1)],
                vec![0.1],
                vec![100.0],
            ))],
            gravity_m_per_s2: 0.0,
            damping_Ns_per_m: 0.0,
            elongation_rate: None,
            constant_hessian: Default::default(),
        };
        let mut f = EquilibriumFactor::new(&model, &x).expect("semi-definite, shifted");
        let (y, r) = f.solve_checked(&[Vector3::zeros(), Vector3::new(1.0, 0.0, 0.0)]);
        assert!(r < 1e-10, "{r}");
        assert!((y[1].x - 0.01).abs() < 1e-12, "{:?}", y[1]);
        let (_, r) = f.solve_checked(&[Vector3::zeros(), Vector3::new(0.0, 1.0, 0.0)]);
        assert!(r > 0.1, "{r}");
    }

    #[test]
    fn a_saddle_has_no_factor() {
        // The chain pulled straight and compressed: springs shorter than their rest lengths, a flat
        // state the lateral directions leave downhill.
        let (mut model, _) = chain(0.0);
        model.terms.truncate(1);
        let x: Vec<Vector3<f64>> = (0..4)
            .map(|k| Vector3::new(0.08 * k as f64, 0.0, 0.0))
            .collect();
        assert_eq!(
            EquilibriumFactor::new(&model, &x).err(),
            Some(NoFactor::NotAMinimum)
        );
    }
}
