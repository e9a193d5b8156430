//! Steps that reuse a factor at hand instead of factorizing: conjugate gradients preconditioned
//! with a neighbour's factor (an inexact Newton step) and the chord step with the last factor.

use super::*;

impl Workspace {
    /// The Newton step by conjugate gradients on this iteration's exact Hessian, preconditioned by
    /// the factor at hand (a neighbour's), then the line search. False (and `x` as it was) on
    /// negative curvature, no convergence in [`KRYLOV_ITERATIONS`] or no accepted step; a step the
    /// line search shortens is taken and ends the Krylov steps of this solve.
    pub(super) fn krylov_step(
        &mut self,
        model: &Model,
        x: &mut [Vector3<f64>],
        load: f64,
        e: &mut f64,
        r: f64,
        report: &mut SolveReport,
    ) -> bool {
        self.hessian(model, x, Hessian::Exact);
        let Some(d) = self.krylov_direction(model) else {
            return false;
        };
        report.linear_solves += 1;
        let slope: f64 = self.g.iter().zip(&d).map(|(a, b)| a.dot(b)).sum();
        if slope.is_nan() || slope >= 0.0 {
            return false;
        }
        self.dx = d;
        self.acc.iter_mut().for_each(|a| *a = Vector3::zeros());
        let bound = model.max_step_with(x, &self.dx, &mut self.candidates);
        match self.line_search(model, x, load, (e, r), (bound.min(1.0), slope)) {
            Some(alpha) => {
                self.count(alpha, bound, (false, false));
                self.stats.krylov_steps += 1;
                // A step the line search shortened: the neighbour's factor (an undamped Newton
                // step) no longer fits, and the damped, factorized iteration takes over. Kept on,
                // pressed layers in the stress box took 25 shortened steps a time step, the step
                // was rejected and halved, over and over (point 70: 18,262 steps, not settled).
                if alpha < 1.0 {
                    self.krylov = false;
                }
                true
            }
            None => false,
        }
    }

    /// Preconditioned conjugate gradients for H d = −g (H in `h`), over the free, unheld
    /// components, to [`KRYLOV_FORCING`]; None on negative curvature or no convergence.
    pub(super) fn krylov_direction(&mut self, model: &Model) -> Option<Vec<Vector3<f64>>> {
        let n = self.g.len();
        let free = |p: usize, c: usize| self.dofs.dof(p).is_some() && !model.is_held(p, c);
        let mask: Vec<[bool; 3]> = (0..n).map(|p| [0, 1, 2].map(|c| free(p, c))).collect();
        let masked = |v: &mut [Vector3<f64>]| {
            for (vp, m) in v.iter_mut().zip(&mask) {
                (0..3).filter(|&c| !m[c]).for_each(|c| vp[c] = 0.0);
            }
        };
        let dot = |a: &[Vector3<f64>], b: &[Vector3<f64>]| -> f64 {
            a.iter().zip(b).map(|(u, v)| u.dot(v)).sum()
        };
        // solve_for gives −M⁻¹ f: M⁻¹ r is solve_for(−r).
        let mut res: Vec<Vector3<f64>> = self.g.iter().map(|v| -v).collect();
        masked(&mut res);
        let goal = KRYLOV_FORCING * dot(&res, &res).sqrt();
        let mut neg: Vec<Vector3<f64>> = self.g.clone();
        let mut z = vec![Vector3::zeros(); n];
        self.solve_for(&neg, &mut z);
        let (mut d, mut p) = (vec![Vector3::zeros(); n], z.clone());
        let mut rz = dot(&res, &z);
        let h = self.h.compacted(n);
        for _ in 0..KRYLOV_ITERATIONS {
            let mut q = vec![Vector3::zeros(); n];
            h.mul_add(&p, &mut q);
            masked(&mut q);
            let pq = dot(&p, &q);
            if pq <= 0.0 || !pq.is_finite() {
                return None;
            }
            let alpha = rz / pq;
            for k in 0..n {
                d[k] += p[k] * alpha;
                res[k] -= q[k] * alpha;
            }
            if dot(&res, &res).sqrt() <= goal {
                return Some(d);
            }
            neg.iter_mut().zip(&res).for_each(|(a, b)| *a = -b);
            self.solve_for(&neg, &mut z);
            let rz_new = dot(&res, &z);
            let beta = rz_new / rz;
            rz = rz_new;
            for k in 0..n {
                p[k] = z[k] + p[k] * beta;
            }
        }
        None
    }

    /// The chord step −H₀⁻¹ g with the factorization at hand, taken whole when no term bounds it and
    /// it lowers the energy enough (Armijo) or leaves it flat to round-off. False (and `x` as it was)
    /// otherwise.
    pub(super) fn chord_step(
        &mut self,
        model: &Model,
        x: &mut [Vector3<f64>],
        load: f64,
        e: &mut f64,
        report: &mut SolveReport,
    ) -> bool {
        let slope = self.step(x.len());
        report.linear_solves += 1;
        if slope.is_nan()
            || slope >= 0.0
            || model.max_step_with(x, &self.dx, &mut self.candidates) < 1.0
        {
            return false;
        }
        for (p, xp) in x.iter().enumerate() {
            self.trial[p] = xp + self.dx[p];
        }
        let contacts = model.contacts_with(&self.trial, &mut self.candidates);
        let et = model.energy_on(&self.trial, &contacts, load);
        if self.parts.search.condition.verdict(*e, et, 1.0, slope) == Verdict::Reject {
            self.stats.rejected_trials += 1;
            return false;
        }
        x.copy_from_slice(&self.trial);
        self.contacts = contacts;
        *e = et;
        self.stats.full_steps += 1;
        self.stats.chord_steps += 1;
        true
    }
}
