//! Options of the static solver ([`StaticOptions`]), each with its meaning, unit, default and
//! when to change it, checked once at load ([`StaticOptions::check`]), and the warm start a
//! calibration hands a solve ([`NeighbourFactor`]).

use super::linear::FillOrdering;
use super::strategy::{Direction, FactorReuse, NestedPath, Regularization, Start};
use serde::{Deserialize, Serialize};
/// Options of the static solver.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StaticOptions {
    /// Convergence when the largest residual force on a free particle is below this fraction of the
    /// lightest free particle's weight. Default 1e-8.
    #[serde(default = "default_tol")]
    pub residual_tol_rel: f64,
    /// Newton iterations allowed over all load steps. Default 500.
    #[serde(default = "default_max_iter")]
    pub max_iterations: usize,
    /// Number of equal load increments (1 = full load at once). Default 1.
    #[serde(default = "default_steps")]
    pub load_steps: usize,
    /// Initial Levenberg–Marquardt damping relative to the mean Hessian diagonal. Default 1e-3.
    #[serde(default = "default_lm")]
    pub lm_damping_initial: f64,
    /// A strain (relative elongation) beyond which the solve is reported as diverged. Default 10.
    #[serde(default = "default_strain")]
    pub strain_bound: f64,
    /// Where a solve of a scene starts: from a coarser grid's solution, a shaped sheet or the flat
    /// one ([`Start`]). Default `"nested"`. The old booleans `coarse_start` and `sag_start` are
    /// read as this key.
    #[serde(default)]
    pub start: Start,
    /// The path a step follows: `"curved"` (along the geodesic acceleration, where it is at most
    /// twice the step and the Hessian is exact) or `"straight"` ([`Direction`]). Default `"curved"`;
    /// `"straight"` next to the answer (a warm start). The old boolean `curvilinear` is read as this.
    #[serde(default)]
    pub direction: Direction,
    /// The largest shift of an indefinite exact Hessian, relative to its mean diagonal, tried
    /// (tenfold from 1e-8) before the projected Hessian is used. Default 1e-5.
    #[serde(default = "default_shift_max")]
    pub shift_max_rel: f64,
    /// How an indefinite exact Hessian is made positive definite: `"shift-ladder"` (shifts for the
    /// iteration only, then the projected Hessian) or `"carried-damping"` (the shift carried on as
    /// damping: the Cusick drape's validated path) ([`Regularization`]). Default `"shift-ladder"`.
    /// The old boolean `carried_damping` is read as this key.
    #[serde(default)]
    pub regularization: Regularization,
    /// Whether a factorization serves more than one step: `"fresh"` or `"chord"` (Shamanskii's
    /// modified Newton while the residual halves per step) ([`FactorReuse`]). Default `"fresh"`
    /// (the calibration's warm-started solves and each step of implicit Euler use `"chord"`). The
    /// old boolean `reuse_factorization` is read as this key.
    #[serde(default)]
    pub factor_reuse: FactorReuse,
    /// Whether a converged solve checks that its equilibrium is a minimum: one more factorization,
    /// of the exact Hessian ([`super::is_minimum`]; the report's `minimum`, absent when not checked).
    /// Default true. Off only where the status alone is read and the start is a stable
    /// neighbour's drape: the calibration's warm-started evaluations, where the check was a third
    /// of the factorizations.
    #[serde(default = "default_check_minimum")]
    pub check_minimum: bool,
    /// Newton iterations after which self-contact's active pairs carry their exact curvature in
    /// Newton's Hessian, the distance's own κ b′∇²d with the barrier's κ b″∇d∇dᵀ
    /// ([`crate::physics::PairCurvature::All`]): where folds press many pairs
    /// together, the normal-only curvature leaves Newton's steps across them too short and the
    /// solve crawls (the limp table on a 61 × 61 grid: 3,000 iterations, 1.7e-3 of a particle's
    /// weight off; 1,186 iterations and converged with it after 500). Default 500: the bundled
    /// touching drapes converge within 330 iterations without it, and from the first iteration
    /// it slowed one (l_panel_sphere: 197 → 577). Lower it for a touching drape that stops at its
    /// iteration budget; 0 from the start.
    #[serde(default = "default_exact_contact_after")]
    pub exact_contact_after: usize,
    /// The gap (beyond a barrier's limit, as a fraction of its band) below which a static solve
    /// stiffens the barriers: after an accepted step whose closest barrier pair is within it and
    /// closer than after the step before, κ doubles (up to 1024 times its start), as incremental
    /// potential contact adapts κ (Li et al. 2020, §4.3 and its supplement). A pair pressed that
    /// deep carries thousands of particle weights at a barrier curvature of F²/(κ d̂²): with κ as
    /// built, layers stacked by a large limp sheet crushed pairs to 10⁻¹⁰ m and the solve crept at
    /// hundreds of newtons of residual; a stiffer barrier makes crushing cost energy, so the line
    /// search refuses it. Default 0.1, the implicit integrator's threshold, chosen by
    /// leave-one-out over the bundled and the larger, finer and limper touching drapes
    /// (`docs/src/benchmarks.md`); 0 keeps κ as built. Raise it towards 1 for a drape whose pairs
    /// end pressed deep (run.json's `self_contact.min_distance_m` at the thickness) and whose
    /// residual stalls; lower it where the drape's layers should rest closer.
    #[serde(default = "default_kappa_adapt_gap")]
    pub kappa_adapt_gap_rel: f64,
    /// In a run of Newton iterations whose exact Hessian stayed indefinite (each stepped on the
    /// projected Hessian), the exact one is tried again only every this many iterations; in between
    /// the iteration factorizes the projected Hessian at once (`"shift-ladder"` regularization
    /// only). Each iteration in such a run otherwise factorizes twice in vain (the damping, then
    /// the ladder's top) before the projected Hessian: where folds keep a drape's Hessian
    /// indefinite for hundreds of iterations (the skirt on 121 × 121: 905 of 1,042) that was two
    /// thirds of the factorizations. 8 (chosen by leave-one-out over the bundled scenes, criterion
    /// factorizations; `docs/src/benchmarks.md`) converged the skirt on 121 × 121 in 655 iterations
    /// and 95 s against 1,042 and 261 s, at the cost of up to 7 projected steps where an exact one
    /// would have served; the path changes, and a drape with many nearby minima (a sphere's folds)
    /// may settle in another. Default 1 (the exact Hessian at every iteration): the path that the
    /// bundled pipelines' fold counts and tables were measured on; the skirt scene sets 8. Set 8
    /// for a large drape that folds (a garment) whose run.json shows most steps projected.
    #[serde(default = "default_exact_retry_every")]
    pub exact_retry_every: usize,
    /// The steps of each grid's solve that starts from a coarser grid's drape (`start =
    /// "nested"`, a sheet without obstacles): `"as-given"` (this table's `direction` and
    /// `regularization` on every grid) or `"warm"` (straight steps with the shift carried on as
    /// damping on the finer grids, [`NestedPath`]). Default `"as-given"`, the path the bundled
    /// pipelines were measured on. `"warm"` halves the factorizations of a large hang (hang4 on
    /// 161 × 161: 158 → 68, the same energy to 14 digits; `docs/src/benchmarks.md`, "Scale"): set
    /// it for sheets of 10⁴ particles and more hung without obstacles.
    #[serde(default)]
    pub nested_path: NestedPath,
    /// The fill-reducing ordering of each Newton step's Cholesky factor: `"amd"` (approximate
    /// minimum degree), `"nested-dissection"` (of the free particles' graph) or `"by-size"`
    /// (nested dissection from 25,000 free particles, AMD below; [`FillOrdering`]). Default
    /// `"by-size"`: on hang4 at 321 × 321 (103,037 free particles) nested dissection factorizes in
    /// 1.5 s against AMD's 2.5 s; at 161 × 161 they are within 5 %, and on the skirt, whose
    /// contact pairs join distant rows, AMD is as fast (`cargo bench --bench ordering`). The
    /// equilibrium is the same to round-off where the path is unique; a drape with many nearby
    /// minima may settle in another. Change it only to compare the orderings.
    #[serde(default)]
    pub ordering: FillOrdering,
}

impl StaticOptions {
    /// The options of a solve that starts from a coarser grid's drape (`from_coarse`) or not:
    /// [`StaticOptions::nested_path`] applied.
    pub fn nested_for(&self, from_coarse: bool) -> StaticOptions {
        let mut o = self.clone();
        if from_coarse && self.nested_path == NestedPath::Warm {
            o.direction = Direction::Straight;
            o.regularization = Regularization::CarriedDamping;
        }
        o
    }

    /// Checks every option (keys relative to `[solver.static]`).
    pub fn check(&self) -> Result<(), crate::error::KeyError> {
        use crate::error::KeyError;
        KeyError::positive("residual_tol_rel", self.residual_tol_rel)?;
        KeyError::positive("lm_damping_initial", self.lm_damping_initial)?;
        KeyError::positive("strain_bound", self.strain_bound)?;
        KeyError::positive("shift_max_rel", self.shift_max_rel)?;
        if !(0.0..1.0).contains(&self.kappa_adapt_gap_rel) {
            return Err(KeyError::new(
                "kappa_adapt_gap_rel",
                format!(
                    "must be in [0, 1) (a fraction of the barrier's band; 0 keeps κ as built), got {}",
                    self.kappa_adapt_gap_rel
                ),
            ));
        }
        super::dynamic_options::tolerance_below_one_weight(self.residual_tol_rel)?;
        if self.max_iterations == 0 {
            return Err(KeyError::new("max_iterations", "must be ≥ 1, got 0"));
        }
        if self.load_steps == 0 {
            return Err(KeyError::new("load_steps", "must be ≥ 1, got 0"));
        }
        Ok(())
    }
}

fn default_check_minimum() -> bool {
    true
}

fn default_exact_contact_after() -> usize {
    500
}

fn default_exact_retry_every() -> usize {
    1
}

fn default_kappa_adapt_gap() -> f64 {
    0.1
}

fn default_shift_max() -> f64 {
    1e-5
}

fn default_tol() -> f64 {
    1e-8
}
fn default_max_iter() -> usize {
    500
}
fn default_steps() -> usize {
    1
}
fn default_lm() -> f64 {
    1e-3
}
fn default_strain() -> f64 {
    10.0
}

impl Default for StaticOptions {
    fn default() -> Self {
        Self {
            residual_tol_rel: default_tol(),
            max_iterations: default_max_iter(),
            load_steps: default_steps(),
            lm_damping_initial: default_lm(),
            strain_bound: default_strain(),
            start: Start::default(),
            direction: Direction::default(),
            shift_max_rel: default_shift_max(),
            regularization: Regularization::default(),
            factor_reuse: FactorReuse::default(),
            check_minimum: default_check_minimum(),
            exact_contact_after: default_exact_contact_after(),
            kappa_adapt_gap_rel: default_kappa_adapt_gap(),
            exact_retry_every: default_exact_retry_every(),
            nested_path: NestedPath::default(),
            ordering: FillOrdering::default(),
        }
    }
}
