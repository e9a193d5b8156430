//! The path of a Newton step: its geodesic acceleration (a curved step) and the backtracking line
//! search along it, every state it looks at measured over the run's candidate set.

use super::*;

impl Workspace {
    /// The step's geodesic acceleration into `acc` (Transtrum & Sethna 2012): a = −(H + μD)⁻¹ T, T
    /// the second derivative of the gradient along dx by central differences, so that the path
    /// x + α dx + ½ α² a also cancels the gradient's second-order change. False when that is not
    /// finite or |½ a| > [`ACCELERATION_MAX`] |dx|.
    pub(super) fn acceleration(&mut self, model: &Model, x: &[Vector3<f64>], load: f64) -> bool {
        let h = ACCELERATION_FD;
        for (p, xp) in x.iter().enumerate() {
            self.trial[p] = xp + self.dx[p] * h;
        }
        let candidates = &mut self.candidates;
        gradient_over(model, (&self.trial, load), candidates, &mut self.g_trial);
        for (p, xp) in x.iter().enumerate() {
            self.trial[p] = xp - self.dx[p] * h;
        }
        gradient_over(model, (&self.trial, load), candidates, &mut self.g_back);
        // T into g_trial (its buffer, so nothing is allocated per iteration).
        for ((t, g), b) in self.g_trial.iter_mut().zip(&self.g).zip(&self.g_back) {
            *t = (*t - g * 2.0 + b) / (h * h);
        }
        let (t, mut acc) = (
            std::mem::take(&mut self.g_trial),
            std::mem::take(&mut self.acc),
        );
        self.solve_for(&t, &mut acc);
        (self.g_trial, self.acc) = (t, acc);
        let norm = |v: &[Vector3<f64>]| v.iter().map(|a| a.norm_squared()).sum::<f64>().sqrt();
        let na = norm(&self.acc);
        na.is_finite() && 0.5 * na <= ACCELERATION_MAX * norm(&self.dx)
    }

    /// Backtracking (Armijo) line search along `dx` from the step length `alpha` (below 1 where a
    /// term bounds the step: contact). Near the solution the energy change falls below round-off:
    /// there a step that lowers the largest residual force is accepted instead. Returns the accepted
    /// step length, if any.
    pub(super) fn line_search(
        &mut self,
        model: &Model,
        x: &mut [Vector3<f64>],
        load: f64,
        (e, r): (&mut f64, f64),
        (alpha, slope): (f64, f64),
    ) -> Option<f64> {
        let Self {
            trial,
            g_trial,
            dx,
            acc,
            stats,
            parts,
            contacts,
            candidates,
            ..
        } = self;
        let trial = std::cell::RefCell::new(trial);
        let candidates = std::cell::RefCell::new(candidates);
        // The last trial's contact set: the accepted state's, once the search returns.
        let at_trial = std::cell::RefCell::new(Contacts::default());
        let energy_at = |alpha: f64| {
            let half = 0.5 * alpha * alpha;
            let mut t = trial.borrow_mut();
            for (p, xp) in x.iter().enumerate() {
                t[p] = xp + dx[p] * alpha + acc[p] * half;
            }
            let contacts = model.contacts_with(&t[..], &mut candidates.borrow_mut());
            let et = model.energy_on(&t[..], &contacts, load);
            *at_trial.borrow_mut() = contacts;
            et
        };
        let lowers_residual = || {
            model.gradient_on(&trial.borrow()[..], &at_trial.borrow(), load, g_trial);
            model.max_residual(g_trial) < r
        };
        let found = parts.search.search(
            (*e, slope),
            alpha,
            energy_at,
            lowers_residual,
            &mut stats.rejected_trials,
        );
        let (alpha, et) = found?;
        x.copy_from_slice(&trial.borrow()[..]);
        *contacts = at_trial.into_inner();
        *e = et;
        Some(alpha)
    }
}

/// The gradient at `y` under `load` into `g` (overwritten), its contact set measured over the
/// run's `candidates`: for states a run looks at without moving to them.
fn gradient_over(
    model: &Model,
    (y, load): (&[Vector3<f64>], f64),
    candidates: &mut CandidateSet,
    g: &mut Vec<Vector3<f64>>,
) {
    let contacts = model.contacts_with(y, candidates);
    model.gradient_on(y, &contacts, load, g);
}
