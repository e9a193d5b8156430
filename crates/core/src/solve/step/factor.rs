//! The factorization of a Newton iteration: the Hessian shifted while it is indefinite, then
//! projected, then damped (Levenberg–Marquardt), the shift carried between iterations; the
//! damping's scale, the mean free diagonal.

use super::*;

impl Workspace {
    /// The damping's scale: the mean free diagonal of the Hessian in `h` ([`mean_free_diagonal`],
    /// its constant part's sum kept).
    pub(super) fn damping_scale(&mut self) -> f64 {
        let constant = match (&self.h.constant, &self.constant_trace) {
            (Some(c), Some((k, s))) if std::sync::Arc::ptr_eq(c, k) => *s,
            (Some(c), _) => {
                let s = free_trace(-0.0, c, &self.dofs);
                self.constant_trace = Some((c.clone(), s));
                s
            }
            (None, _) => -0.0,
        };
        mean_of(free_trace(constant, &self.h, &self.dofs), &self.dofs)
    }

    /// Factorizes the Hessian in `h` (computed at `x`), shifted by the damping: the exact Hessian
    /// (quadratic convergence; projected Newton stalls on a hanging net whose compressed springs'
    /// transverse stiffness it drops), shifted further tenfold while it is indefinite up to
    /// `shift_max` of the diagonal (for this iteration only), then the projected Hessian (every
    /// term's indefinite part clamped) with the damping, raised tenfold while it fails. False when no
    /// damping helps.
    pub(super) fn factorize(
        &mut self,
        model: &Model,
        x: &[Vector3<f64>],
        hessian: &mut Hessian,
        scale: f64,
        report: &mut SolveReport,
    ) -> bool {
        let mut shift = self.mu;
        for attempt in 0..FACTORIZE_ATTEMPTS {
            if self.try_shift(shift, scale, report) {
                report.linear_solves += 1;
                self.last_hessian = *hessian;
                return true;
            }
            shift = match self.parts.regularization {
                Regularization::CarriedDamping => self.carry_shift(model, x, hessian),
                Regularization::ShiftLadder => {
                    self.climb(model, x, hessian, (shift, attempt == 0, scale), report)
                }
            };
        }
        false
    }

    /// [`Regularization::ShiftLadder`]'s next shift after `shift` failed: straight to the projected
    /// Hessian when the last iteration ended on it and the ladder's top fails too (tried on the
    /// first failure only); else the shift tenfold up to the ladder's top; then the projected
    /// Hessian with the damping; then the damping tenfold.
    pub(super) fn climb(
        &mut self,
        model: &Model,
        x: &[Vector3<f64>],
        hessian: &mut Hessian,
        (shift, first, scale): (f64, bool, f64),
        report: &mut SolveReport,
    ) -> f64 {
        let exact = !hessian.is_projected();
        if first
            && exact
            && self.last_hessian.is_projected()
            && self.top_fails(shift, scale, report)
        {
            *hessian = Hessian::Projected;
            self.hessian(model, x, Hessian::Projected);
            shift
        } else if exact && shift * DAMPING_GROWTH <= self.parts.shift_max {
            (shift * DAMPING_GROWTH).max(MU_MIN)
        } else if exact {
            *hessian = Hessian::Projected;
            self.hessian(model, x, Hessian::Projected);
            self.mu
        } else {
            self.mu = (shift * DAMPING_GROWTH).max(MU_MIN);
            self.mu
        }
    }

    /// Factorizes the Hessian in `h` shifted by `shift` × `scale` on the diagonal (held components
    /// decoupled); counts it. False when that is not positive definite.
    pub(super) fn try_shift(&mut self, shift: f64, scale: f64, report: &mut SolveReport) -> bool {
        self.shift.iter_mut().for_each(|s| *s = shift * scale);
        // Held components (symmetry planes): a diagonal far above the rest decouples them, and
        // their step is set to zero.
        for &(d, c) in &self.held {
            self.shift[d + c] += crate::solve::equilibrium::HELD_SHIFT_REL * scale.max(1e-300);
        }
        report.factorizations += 1;
        if self.assembled
            && let Some(ok) = self.spd.refactorize(&self.shift)
        {
            return ok;
        }
        self.assembled = true;
        self.spd.factorize(&self.dofs, &self.h, &self.shift)
    }

    /// The Hessian at `x` (the run's current state, its contact set at hand) into `h`, projected
    /// or not: a new matrix to assemble.
    pub(super) fn hessian(&mut self, model: &Model, x: &[Vector3<f64>], kind: Hessian) {
        let mode = match kind {
            Hessian::Projected => HessianMode::Projected,
            Hessian::Exact => HessianMode::Newton(self.pairs),
        };
        model.hessian_on(x, &self.contacts, &mut self.h, mode);
        self.assembled = false;
    }

    /// After the damping `shift` alone failed, where the iteration before ended on the projected
    /// Hessian: whether the top of the ladder of shifts fails too. Positive definiteness only grows
    /// with a diagonal shift, so then every shift in between fails as well and the ladder can be
    /// skipped — the same step as climbing it, in one factorization instead of each rung's.
    pub(super) fn top_fails(&mut self, shift: f64, scale: f64, report: &mut SolveReport) -> bool {
        let mut top = shift;
        while top * DAMPING_GROWTH <= self.parts.shift_max {
            top = (top * DAMPING_GROWTH).max(MU_MIN);
        }
        if top == shift {
            return false;
        }
        let fails = !self.try_shift(top, scale, report);
        self.stats.skipped_shifts += usize::from(fails);
        fails
    }

    /// [`Regularization::CarriedDamping`]: the damping raised tenfold, or the projected Hessian
    /// with the damping back at its initial value once it reaches 1e-3; the
    /// next shift.
    pub(super) fn carry_shift(
        &mut self,
        model: &Model,
        x: &[Vector3<f64>],
        hessian: &mut Hessian,
    ) -> f64 {
        if !hessian.is_projected() && self.mu >= CARRIED_DAMPING_MAX {
            *hessian = Hessian::Projected;
            self.hessian(model, x, Hessian::Projected);
            self.mu = self.parts.mu_initial.min(self.mu);
        } else {
            self.mu = (self.mu * DAMPING_GROWTH).max(MU_MIN);
        }
        self.mu
    }
}

/// Mean of the Hessian's diagonal over the free DOFs (the scale of the damping), 1 if empty.
pub(in crate::solve) fn mean_free_diagonal(h: &HessianBlocks, dofs: &DofMap) -> f64 {
    let constant = h
        .constant
        .as_deref()
        .map_or(-0.0, |c| free_trace(-0.0, c, dofs));
    mean_of(free_trace(constant, h, dofs), dofs)
}

/// The free diagonal blocks' traces of `h`'s own list (not its constant part) added to `acc` in
/// order: continuing the constant part's sum, this is the whole matrix's sum bit for bit.
fn free_trace(acc: f64, h: &HessianBlocks, dofs: &DofMap) -> f64 {
    // Summed block by block (no per-particle buffer: it was 4 % of a Cusick drape's solve).
    h.pairs
        .iter()
        .zip(&h.blocks)
        .filter(|&(&(p, q), _)| p == q && dofs.dof(p as usize).is_some())
        .fold(acc, |s, (_, b)| s + b.trace())
}

/// The mean over the free DOFs of a diagonal summing to `sum`, 1 if empty.
fn mean_of(sum: f64, dofs: &DofMap) -> f64 {
    if dofs.n > 0 && sum > 0.0 {
        sum / dofs.n as f64
    } else {
        1.0
    }
}
