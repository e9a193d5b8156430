//! Implicit Euler as an optimisation (issue 19): each step minimises the incremental potential
//!
//!   Φ(x) = Σ_p m_p/(2h²)|x_p − x̃_p|² + Σ_p d_p/(2h)|x_p − xₙ,p|² + β/(2h) Δxᵀ Kₙ Δx + W(x),
//!
//! x̃ = xₙ + h vₙ, d_p = c + α m_p (seed 000's −c·v, Eq. 4, and Rayleigh's mass-proportional part), Kₙ
//! the projected Hessian at xₙ (Rayleigh's stiffness-proportional part), W the scene's potential
//! (elastic, gravity, barrier contact), with the static solver's Newton (projected Hessian where the
//! exact one is indefinite, a line search bounded by the barrier's step bound, so no particle enters
//! an obstacle at any step). Its stationarity condition M(v − vₙ)/h = −∇W(x) − D v − βKₙ v with
//! v = (x − xₙ)/h is backward Euler. Steps adapt: they grow while Newton converges in few iterations
//! and are halved and retried when it does not, and land on every frame time a recorder asks for.

use super::FactorReuse;
use super::clock::StepBounds;
use super::static_options::StaticOptions;
use super::{DivergenceReason, SolveReport};
use crate::physics::{
    CandidateSet, Contacts, EnergyTerm, HessianBlocks, HessianMode, Model, PairCurvature, Vecs,
};
use nalgebra::{Matrix3, Vector3};

/// The inertia and damping part of the incremental potential: Σ w_p/2 |x_p − c_p|² (the two
/// quadratics about x̃ and xₙ merged: w = m/h² + d/h, c = (m/h² x̃ + d/h xₙ)/w) plus β/(2h) Δxᵀ Kₙ Δx.
pub struct Inertia {
    weight: Vec<f64>,
    centre: Vec<Vector3<f64>>,
    x_n: Vec<Vector3<f64>>,
    /// Kₙ (projected) and β/h, when stiffness-proportional damping is on.
    stiffness: Option<(HessianBlocks, f64)>,
}

impl Inertia {
    /// The term for a step of `h` s from (`x_n`, `v_n`) (`contacts` the contact set at `x_n`),
    /// particle damping `c` (N·s/m), Rayleigh `alpha` (1/s) and `beta` (s); fixed particles get no
    /// weight.
    pub fn new(
        model: &Model,
        (x_n, contacts): (&[Vector3<f64>], &Contacts),
        v_n: &[Vector3<f64>],
        h: f64,
        (c, alpha, beta): (f64, f64, f64),
    ) -> Self {
        let (mut weight, mut centre) = (Vec::with_capacity(x_n.len()), Vec::new());
        for p in 0..x_n.len() {
            let (m, free) = (model.masses[p], !model.fixed[p]);
            let (a, b) = if free {
                (m / (h * h), (c + alpha * m) / h)
            } else {
                (0.0, 0.0)
            };
            weight.push(a + b);
            let predicted = x_n[p] + v_n[p] * h;
            centre.push(if a + b > 0.0 {
                (predicted * a + x_n[p] * b) / (a + b)
            } else {
                x_n[p]
            });
        }
        let stiffness = (beta > 0.0).then(|| {
            let mut k = HessianBlocks::default();
            model.hessian_on(x_n, contacts, &mut k, HessianMode::Projected);
            (k, beta / h)
        });
        Self {
            weight,
            centre,
            x_n: x_n.to_vec(),
            stiffness,
        }
    }

    fn delta(&self, x: &Vecs) -> Vec<Vector3<f64>> {
        x.iter().zip(&self.x_n).map(|(a, b)| a - b).collect()
    }
}

impl EnergyTerm for Inertia {
    fn name(&self) -> String {
        "inertia".into()
    }
    fn energy(&self, x: &Vecs) -> f64 {
        let mut e: f64 = (0..x.len())
            .map(|p| 0.5 * self.weight[p] * (x[p] - self.centre[p]).norm_squared())
            .sum();
        if let Some((k, s)) = &self.stiffness {
            let d = self.delta(x);
            let mut kd = vec![Vector3::zeros(); x.len()];
            k.mul_add(&d, &mut kd);
            e += 0.5 * s * d.iter().zip(&kd).map(|(a, b)| a.dot(b)).sum::<f64>();
        }
        e
    }
    fn add_gradient(&self, x: &Vecs, g: &mut Vecs) {
        for p in 0..x.len() {
            g[p] += (x[p] - self.centre[p]) * self.weight[p];
        }
        if let Some((k, s)) = &self.stiffness {
            let d = self.delta(x);
            let mut kd = vec![Vector3::zeros(); x.len()];
            k.mul_add(&d, &mut kd);
            for (gp, kdp) in g.iter_mut().zip(&kd) {
                *gp += kdp * *s;
            }
        }
    }
    fn add_hessian(&self, _x: &Vecs, h: &mut HessianBlocks, _mode: HessianMode) {
        for (p, &w) in self.weight.iter().enumerate() {
            if w > 0.0 {
                h.push(p, p, Matrix3::identity() * w);
            }
        }
        if let Some((k, s)) = &self.stiffness {
            for (&(p, q), b) in k.all() {
                h.push(p as usize, q as usize, b * *s);
            }
        }
    }
    fn stiffness_scale(&self) -> f64 {
        self.weight.iter().copied().fold(0.0, f64::max)
    }
}

/// How the steps of one implicit integration go.
pub struct ImplicitSettings {
    /// First step, s.
    pub dt_s: f64,
    /// Largest step, s (a recorder's frame interval caps it too).
    pub max_dt_s: f64,
    /// Below this step, s, the integration gives up (status diverged).
    pub min_dt_s: f64,
    /// Grow and shrink the step with Newton's iteration count.
    pub adaptive: bool,
    /// Particle damping c (N·s/m), Rayleigh α (1/s) and β (s).
    pub damping: (f64, f64, f64),
    /// Newton iterations allowed per step.
    pub newton_iterations: usize,
    /// Whether a step's Newton reuses its factorization ([`super::FactorReuse`]).
    pub factor_reuse: super::FactorReuse,
    /// Newton's tolerance per step, relative to the lightest particle's weight.
    pub newton_tol_rel: f64,
    /// A strain beyond which a step reports divergence.
    pub strain_bound: f64,
}

impl ImplicitSettings {
    /// The bounds of its adaptive steps.
    pub(super) fn bounds(&self) -> StepBounds {
        StepBounds {
            adaptive: self.adaptive,
            min_dt_s: self.min_dt_s,
            max_dt_s: self.max_dt_s,
        }
    }

    /// The settings of `opts` with viscous damping `c` (N·s/m; Rayleigh's α and β only with damping).
    pub fn of(opts: &super::DynamicOptions, c: f64) -> Self {
        let (alpha, beta) = if opts.damping {
            (opts.rayleigh_mass_per_s, opts.rayleigh_stiffness_s)
        } else {
            (0.0, 0.0)
        };
        Self {
            dt_s: opts.dt_s,
            max_dt_s: opts.max_dt_s,
            min_dt_s: opts.min_dt_s,
            adaptive: opts.adaptive_dt,
            damping: (c, alpha, beta),
            newton_iterations: opts.newton_iterations,
            factor_reuse: opts.factor_reuse,
            // Each step well below the settle tolerance: a step's leftover force would move a soft
            // mode by force/stiffness every step, a speed that never settles.
            newton_tol_rel: 1e-2 * opts.residual_tol_rel,
            strain_bound: opts.strain_bound,
        }
    }
}

/// The outcome of one step attempt.
pub(super) enum Attempt {
    /// Accepted after this many Newton iterations.
    Accepted(usize),
    /// Newton did not converge; the state is unchanged.
    Rejected,
    /// Newton diverged (non-finite, strain beyond bound): the integration stops.
    Diverged(DivergenceReason),
}

/// The options of one step's Newton solve at `x` (the step's inertia in `model`).
fn step_options(model: &Model, x: &[Vector3<f64>], s: &ImplicitSettings) -> StaticOptions {
    // Short steps make the inertia stiff (m/h²) and raise the round-off floor of forces with it:
    // the step's tolerance stays 100 times above that floor.
    let floor_rel = model.roundoff_force(x) / model.reference_weight();
    StaticOptions {
        residual_tol_rel: s.newton_tol_rel.max(100.0 * floor_rel),
        max_iterations: s.newton_iterations,
        lm_damping_initial: 1e-6,
        strain_bound: s.strain_bound,
        // The Hessian changes little over one step's iterations: chord steps save factorizations
        // (37 % over eight scenes, reports/newton_iterations.md).
        factor_reuse: s.factor_reuse,
        // κ stiffens between steps (below), not within one step's Newton: within a step it
        // changed which slowly creeping nets settle within their simulated time (the stress box's
        // point 88 settled at t = 95,746 s with κ held and not within 10⁵ s without).
        kappa_adapt_gap_rel: 0.0,
        ..StaticOptions::default()
    }
}

/// What one implicit step hands the next: its factor (the next step's preconditioner) and the
/// broad phase's candidate set its contact is measured over.
#[derive(Default)]
pub(super) struct Carried {
    pub(super) factor: Option<super::NeighbourFactor>,
    pub(super) candidates: CandidateSet,
}

/// One step of `h` from (`x`, `v`), both updated on success; `work` gets the report's counters.
pub(super) fn step(
    model: &mut Model,
    x: &mut [Vector3<f64>],
    v: &mut [Vector3<f64>],
    h: f64,
    s: &ImplicitSettings,
    carried: &mut Carried,
    report: &mut SolveReport,
) -> Attempt {
    let x_n = x.to_vec();
    let at_n = model.contacts_with(&x_n, &mut carried.candidates);
    let term = Inertia::new(model, (&x_n, &at_n), v, h, s.damping);
    // Start from the inertial prediction xₙ + h vₙ (as far along it as contact allows) or from xₙ,
    // whichever has the lower incremental potential: long steps of an overdamped sheet overshoot
    // their prediction by far.
    let dx: Vec<Vector3<f64>> = v.iter().map(|vp| vp * h).collect();
    let alpha = model
        .max_step_with(&x_n, &dx, &mut carried.candidates)
        .min(1.0);
    for p in 0..x.len() {
        if !model.fixed[p] {
            x[p] = x_n[p] + dx[p] * alpha;
        }
    }
    model.terms.push(Box::new(term));
    let predicted = model.contacts_with(x, &mut carried.candidates);
    if model.energy_on(&x_n, &at_n, 1.0) < model.energy_on(x, &predicted, 1.0) {
        x.copy_from_slice(&x_n);
    }
    let opts = step_options(model, x, s);
    // The last step's factor preconditions this step's Newton steps (conjugate gradients): one
    // step of a settling sheet changes its Hessian little, and the factorizations were most of
    // a step's cost (issue 47's stress box: 29,608 of them in 3,539 steps of one run).
    // Only where factors are reused at all (`"chord"`, the default).
    let last = (carried.factor.take()).filter(|_| s.factor_reuse == FactorReuse::Chord);
    let (r, factor) = super::newton::solve_static_keeping_factor(
        model,
        x,
        &opts,
        (last.as_ref(), &mut carried.candidates),
        PairCurvature::Pinned,
    );
    carried.factor = factor;
    model.terms.pop();
    report.merge(&r, super::Part::InnerSolve);
    if r.is_converged() && x.iter().all(|p| p.iter().all(|c| c.is_finite())) {
        for p in 0..x.len() {
            v[p] = if model.fixed[p] {
                Vector3::zeros()
            } else {
                (x[p] - x_n[p]) / h
            };
        }
        // Barriers stiffened where layers press (the factor then no longer serves the next step).
        let contacts = model.contacts_with(x, &mut carried.candidates);
        if model.stiffen_barriers(&contacts) {
            carried.factor = None;
        }
        // The step grows with Newton's factorizing iterations (its cost); chord and Krylov steps
        // are cheap.
        let g = &r.globalization;
        Attempt::Accepted(r.iterations.saturating_sub(g.chord_steps + g.krylov_steps))
    } else if let Some(d) = r.divergence.filter(|_| r.status == super::Status::Diverged) {
        Attempt::Diverged(d.reason)
    } else {
        x.copy_from_slice(&x_n);
        Attempt::Rejected
    }
}
