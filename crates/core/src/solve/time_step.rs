//! One step of the fixed-step integrators of [`super::dynamic`]: explicit and symplectic Euler (seed
//! 000 Eq. 4, Provot's correction) and Baraff & Witkin's linearised implicit Euler (conjugate
//! gradients with a block-Jacobi preconditioner), each cut short where it would enter an obstacle.

use super::SolveReport;
use super::kind::Integrator;
use super::linear::DofMap;
use crate::physics::{CandidateSet, Contacts, HessianBlocks, Model};
use nalgebra::{Matrix3, Vector3};

/// One integrator's steps, cut short where a step would enter an obstacle.
pub(super) struct Stepper {
    integrator: Integrator,
    c: f64,
    dt: f64,
    free: Vec<bool>,
    inv_m: Vec<f64>,
    implicit: ImplicitState,
    /// Terms bound a step (contact): each step is cut so that no particle enters an obstacle
    /// (continuous collision detection, as the static solver's line search does), and the
    /// velocities with it (the approach is stopped, not reflected).
    bounded: bool,
    x_old: Vec<Vector3<f64>>,
    dx: Vec<Vector3<f64>>,
    pub(super) cut_steps: usize,
    /// The broad phase's candidate set the integration carries from step to step: the contact
    /// sets and step bounds of every step are measured over it.
    pub(super) candidates: CandidateSet,
}

impl Stepper {
    pub(super) fn new(
        model: &Model,
        integrator: Integrator,
        x: &[Vector3<f64>],
        c: f64,
        dt: f64,
        free: Vec<bool>,
    ) -> Self {
        let inv_m = model
            .masses
            .iter()
            .zip(&free)
            .map(|(m, f)| if *f && *m > 0.0 { 1.0 / m } else { 0.0 })
            .collect();
        Self {
            integrator,
            c,
            dt,
            free,
            inv_m,
            implicit: ImplicitState::new(model),
            bounded: model
                .max_step(x, &vec![Vector3::new(0.0, 0.0, -1.0); model.len()])
                .is_finite(),
            x_old: Vec::new(),
            dx: Vec::new(),
            cut_steps: 0,
            candidates: CandidateSet::default(),
        }
    }

    /// The contact set at `x`, over the integration's candidate set.
    pub(super) fn contacts(&mut self, model: &Model, x: &[Vector3<f64>]) -> Contacts {
        model.contacts_with(x, &mut self.candidates)
    }

    /// Advances `x`, `v` by one step from the gradient `g` at `x` (`contacts` its contact set).
    pub(super) fn step(
        &mut self,
        model: &Model,
        (x, contacts): (&mut [Vector3<f64>], &Contacts),
        v: &mut [Vector3<f64>],
        g: &[Vector3<f64>],
        cg_tol_rel: f64,
        report: &mut SolveReport,
    ) {
        let (n, c, dt) = (model.len(), self.c, self.dt);
        let (free, inv_m) = (&self.free, &self.inv_m);
        if self.bounded {
            self.x_old.clear();
            self.x_old.extend_from_slice(x);
        }
        match self.integrator {
            Integrator::ExplicitEuler => {
                for p in 0..n {
                    if free[p] {
                        let a = (-g[p] - v[p] * c) * inv_m[p];
                        x[p] += v[p] * dt;
                        v[p] += a * dt;
                    }
                }
                if let Some(rate) = model.elongation_rate {
                    for t in &model.terms {
                        t.provot_correct(x, free, rate);
                    }
                }
            }
            Integrator::SymplecticEuler => {
                for p in 0..n {
                    if free[p] {
                        v[p] += (-g[p] - v[p] * c) * (inv_m[p] * dt);
                        x[p] += v[p] * dt;
                    }
                }
            }
            Integrator::ImplicitEuler | Integrator::BaraffWitkin => {
                let iters = (self.implicit).step((model, contacts), x, v, g, c, dt, cg_tol_rel);
                report.linear_solves += 1;
                report.inner_iterations += iters;
            }
        }
        if self.bounded {
            self.cut_by_contact(model, x, v);
        }
    }

    /// Cuts the step just taken from `x_old` to `x` where contact bounds it (the collision-free
    /// step over the integration's candidate set), and the velocities `v` with it.
    fn cut_by_contact(&mut self, model: &Model, x: &mut [Vector3<f64>], v: &mut [Vector3<f64>]) {
        self.dx.clear();
        self.dx
            .extend(x.iter().zip(&self.x_old).map(|(a, b)| a - b));
        let alpha = model.max_step_with(&self.x_old, &self.dx, &mut self.candidates);
        if alpha < 1.0 {
            self.cut_steps += 1;
            for p in 0..x.len() {
                x[p] = self.x_old[p] + self.dx[p] * alpha;
                v[p] *= alpha;
            }
        }
    }
}

/// Work arrays of implicit Euler.
struct ImplicitState {
    dofs: DofMap,
    h: HessianBlocks,
    r: Vec<Vector3<f64>>,
    z: Vec<Vector3<f64>>,
    p: Vec<Vector3<f64>>,
    ap: Vec<Vector3<f64>>,
    dv: Vec<Vector3<f64>>,
    precond: Vec<Matrix3<f64>>,
}

impl ImplicitState {
    fn new(model: &Model) -> Self {
        let n = model.len();
        let z = vec![Vector3::zeros(); n];
        Self {
            dofs: DofMap::new(&model.fixed),
            h: HessianBlocks::default(),
            r: z.clone(),
            z: z.clone(),
            p: z.clone(),
            ap: z.clone(),
            dv: z,
            precond: Vec::new(),
        }
    }

    /// A x for A = M + Δt c I + Δt² K on free particles (fixed rows and columns are zero).
    fn apply(&self, model: &Model, c: f64, dt: f64, x: &[Vector3<f64>], out: &mut [Vector3<f64>]) {
        out.iter_mut().for_each(|o| *o = Vector3::zeros());
        self.h.mul_add(x, out);
        for (p, o) in out.iter_mut().enumerate() {
            if self.dofs.dof(p).is_some() {
                *o = *o * (dt * dt) + x[p] * (model.masses[p] + dt * c);
            } else {
                *o = Vector3::zeros();
            }
        }
    }

    /// The block-Jacobi preconditioner of A = M + Δt c I + Δt² K: each free particle's diagonal
    /// block inverted.
    fn precondition(&mut self, model: &Model, c: f64, dt: f64) {
        let n = model.len();
        let diag = self.h.diagonal(n);
        self.precond = (0..n)
            .map(|p| {
                let a = diag[p] * (dt * dt) + Matrix3::identity() * (model.masses[p] + dt * c);
                if self.dofs.dof(p).is_some() {
                    a.try_inverse().unwrap_or_else(Matrix3::identity)
                } else {
                    Matrix3::zeros()
                }
            })
            .collect();
    }

    /// One Baraff–Witkin step; returns the CG iterations used.
    #[allow(clippy::too_many_arguments, clippy::needless_range_loop)]
    fn step(
        &mut self,
        (model, contacts): (&Model, &Contacts),
        x: &mut [Vector3<f64>],
        v: &mut [Vector3<f64>],
        g: &[Vector3<f64>],
        c: f64,
        dt: f64,
        tol: f64,
    ) -> usize {
        let n = model.len();
        model.hessian_on(
            x,
            contacts,
            &mut self.h,
            crate::physics::HessianMode::Projected,
        );
        // b = Δt (f − Δt K v), f = −∇E − c v
        let mut kv = vec![Vector3::zeros(); n];
        self.h.mul_add(v, &mut kv);
        let masked = |p: usize, val: Vector3<f64>| {
            if self.dofs.dof(p).is_some() {
                val
            } else {
                Vector3::zeros()
            }
        };
        let b: Vec<Vector3<f64>> = (0..n)
            .map(|p| masked(p, (-g[p] - v[p] * c - kv[p] * dt) * dt))
            .collect();
        self.precondition(model, c, dt);
        // Preconditioned conjugate gradients from Δv = 0.
        let dot = |a: &[Vector3<f64>], b: &[Vector3<f64>]| {
            a.iter().zip(b).map(|(x, y)| x.dot(y)).sum::<f64>()
        };
        self.dv.iter_mut().for_each(|d| *d = Vector3::zeros());
        self.r.copy_from_slice(&b);
        for p in 0..n {
            self.z[p] = self.precond[p] * self.r[p];
        }
        self.p.copy_from_slice(&self.z);
        let b_norm = dot(&b, &b).sqrt();
        let mut rz = dot(&self.r, &self.z);
        let mut it = 0;
        while it < 10 * n.max(10) && dot(&self.r, &self.r).sqrt() > tol * b_norm && b_norm > 0.0 {
            let mut ap = std::mem::take(&mut self.ap);
            self.apply(model, c, dt, &self.p, &mut ap);
            let pap = dot(&self.p, &ap);
            if pap.is_nan() || pap <= 0.0 {
                self.ap = ap;
                break;
            }
            let alpha = rz / pap;
            for p in 0..n {
                self.dv[p] += self.p[p] * alpha;
                self.r[p] -= ap[p] * alpha;
                self.z[p] = self.precond[p] * self.r[p];
            }
            self.ap = ap;
            let rz_new = dot(&self.r, &self.z);
            let beta = rz_new / rz;
            rz = rz_new;
            for p in 0..n {
                self.p[p] = self.z[p] + self.p[p] * beta;
            }
            it += 1;
        }
        for p in 0..n {
            if self.dofs.dof(p).is_some() {
                v[p] += self.dv[p];
                x[p] += v[p] * dt;
            }
        }
        it
    }
}
