//! The parts of a static Newton step as values (argmin's habit: a solver is put together from
//! small strategies, none of them a boolean): how an indefinite Hessian is made positive definite
//! ([`Regularization`]), which path a step follows ([`Direction`]), whether a factor at hand is used
//! again ([`FactorReuse`]), when a trial point is accepted ([`Acceptance`], searched by
//! [`Backtracking`]), and where a static solve starts ([`Start`]).

use serde::{Deserialize, Serialize};

/// How an iteration whose exact Hessian is not positive definite gets a factorization
/// (`solver.static.regularization`). Change it only to reproduce the Cusick drape's validated path.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Regularization {
    /// The exact Hessian shifted tenfold from the damping up to `shift_max_rel` of its mean
    /// diagonal, for this iteration only, then the projected Hessian with the damping raised
    /// tenfold while it fails (seed 003 §10.2's damped Newton with a ladder). Default.
    #[default]
    ShiftLadder,
    /// The shift that worked carried on as the damping, the projected Hessian once it reaches
    /// [`super::newton::CARRIED_DAMPING_MAX`] (drapelab's first schedule: a quasi-static path of short
    /// steps after every indefinite point; the Cusick drape keeps it, its fold counts converge with
    /// the mesh on that path).
    CarriedDamping,
}

/// The path a Newton step follows from x (`solver.static.direction`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Direction {
    /// The straight line x + α dx. Cheaper per iteration (no acceleration: two gradients and a
    /// triangular solve less); what a warm start next to the answer wants.
    Straight,
    /// The curve x + α dx + ½ α² a, a the geodesic acceleration (Transtrum & Sethna 2012), where
    /// |½ a| ≤ |dx| and the Hessian is the exact one; straight otherwise. Bends the step along the
    /// arcs an inextensible sheet allows (a hang, an overhang swinging down). Default.
    #[default]
    Curved,
}

/// The steps of a grid's solve that starts from a coarser grid's drape (`solver.static.nested_path`,
/// with `start = "nested"`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum NestedPath {
    /// The options as given, on every grid. Default.
    #[default]
    AsGiven,
    /// On every grid that starts from a coarser one's drape, straight steps with the shift
    /// carried on as damping ([`Direction::Straight`], [`Regularization::CarriedDamping`]): the
    /// path of a warm start next to the answer, as the calibration's solves take.
    Warm,
}

/// Whether a factorization is used for more than one step (`solver.static.factor_reuse`,
/// `solver.dynamic.factor_reuse`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum FactorReuse {
    /// Every iteration factorizes its own Hessian (Newton's quadratic convergence throughout).
    /// Default of static solves.
    #[default]
    Fresh,
    /// Shamanskii's modified Newton: after a whole step that cut the largest residual force at
    /// least in half, the next step is the chord step −H₀⁻¹ g with the factor at hand, taken whole
    /// when it lowers the energy; the Hessian is factorized afresh as soon as one does not. The same
    /// equilibrium to the tolerance, fewer factorizations, possibly more iterations. Default of
    /// implicit Euler's steps; the calibration's warm-started solves use it.
    Chord,
}

/// Where a static solve of a scene starts (`solver.static.start`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Start {
    /// From the interpolated solution on the grid with every other line (nested iteration), where
    /// that grid exists (both sides odd ≥ 21, no obstacle, hold or point load); else as `shaped`.
    /// Default.
    #[default]
    Nested,
    /// As `nested` where the coarser grid exists; else from the sheet as built (`flat`).
    NestedFlat,
    /// Without obstacles, from the sheet folded down about the line of its pins when they lie on
    /// one ([`super::folded_start`]), else from the sagged sheet ([`super::sagged_start`]); with
    /// obstacles, from the sheet as built.
    Shaped,
    /// From the sheet as built (flat, with its initial perturbation).
    Flat,
}

impl Start {
    /// Whether a solve starts from a coarser grid's solution where one exists.
    pub fn is_nested(self) -> bool {
        matches!(self, Start::Nested | Start::NestedFlat)
    }
    /// Whether a solve that does not start from a coarser grid starts from a shaped sheet.
    pub fn is_shaped(self) -> bool {
        matches!(self, Start::Nested | Start::Shaped)
    }
    /// The start of the coarser grid's own solve: the same.
    pub fn from_flags(nested: bool, shaped: bool) -> Start {
        match (nested, shaped) {
            (true, true) => Start::Nested,
            (true, false) => Start::NestedFlat,
            (false, true) => Start::Shaped,
            (false, false) => Start::Flat,
        }
    }
}

/// A line search's verdict on a trial point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// The trial is accepted.
    Accept,
    /// The energy changed by round-off only: accepted when it lowers the largest residual force.
    Flat,
    /// The trial is rejected.
    Reject,
}

/// When a backtracking line search accepts a trial point (argmin's habit: the search is generic
/// over its condition).
pub trait Acceptance {
    /// The verdict on a trial energy `et` (J) at step length `alpha` from energy `e` along a
    /// direction of directional derivative `slope` (J per unit step).
    fn verdict(&self, e: f64, et: f64, alpha: f64, slope: f64) -> Verdict;
}

/// Armijo's sufficient decrease, with a flat energy (a change below round-off) handed back as
/// [`Verdict::Flat`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Armijo {
    /// The fraction of the decrease the slope promises that the energy must fall by
    /// ([`super::newton::ARMIJO_DECREASE`]).
    pub decrease: f64,
    /// An energy change below this fraction of the energy is round-off
    /// ([`super::newton::ENERGY_FLAT_REL`]).
    pub flat_rel: f64,
}

impl Acceptance for Armijo {
    fn verdict(&self, e: f64, et: f64, alpha: f64, slope: f64) -> Verdict {
        if !et.is_finite() {
            Verdict::Reject
        } else if et <= e + self.decrease * alpha * slope {
            Verdict::Accept
        } else if (et - e).abs() <= self.flat_rel * e.abs().max(1e-300) {
            Verdict::Flat
        } else {
            Verdict::Reject
        }
    }
}

/// A backtracking line search: the step halved from its first length until the condition accepts
/// a trial, at most `halvings` times.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Backtracking<C: Acceptance> {
    /// When a trial is accepted.
    pub condition: C,
    /// Halvings tried before the search gives up ([`super::newton::LINE_SEARCH_HALVINGS`]).
    pub halvings: usize,
}

impl<C: Acceptance> Backtracking<C> {
    /// Searches from step length `alpha` along a direction of `slope` from energy `e`: `energy_at`
    /// gives a trial's energy, `flat_accepts` decides a flat trial (the one last evaluated),
    /// `rejected` counts the rejected trials. The accepted step length and its energy, if any.
    pub fn search(
        &self,
        (e, slope): (f64, f64),
        mut alpha: f64,
        mut energy_at: impl FnMut(f64) -> f64,
        mut flat_accepts: impl FnMut() -> bool,
        rejected: &mut usize,
    ) -> Option<(f64, f64)> {
        for _ in 0..self.halvings {
            let et = energy_at(alpha);
            let accepted = match self.condition.verdict(e, et, alpha, slope) {
                Verdict::Accept => true,
                Verdict::Flat => flat_accepts(),
                Verdict::Reject => false,
            };
            if accepted {
                return Some((alpha, et));
            }
            *rejected += 1;
            alpha *= 0.5;
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ARMIJO: Armijo = Armijo {
        decrease: 1e-4,
        flat_rel: 1e-11,
    };

    #[test]
    fn backtracking_halves_until_armijo_holds_on_a_parabola() {
        // E(α) = (α − 0.1)², slope −0.2 at 0: α = 1, ½, ¼ raise the energy; ⅛ lowers it enough.
        let search = Backtracking {
            condition: ARMIJO,
            halvings: 30,
        };
        let mut rejected = 0;
        let got = search.search(
            (0.01, -0.2),
            1.0,
            |a| (a - 0.1) * (a - 0.1),
            || false,
            &mut rejected,
        );
        let (alpha, e) = got.unwrap();
        assert_eq!(alpha, 0.125);
        assert!((e - 0.025f64.powi(2)).abs() < 1e-15);
        assert_eq!(rejected, 3);
    }

    #[test]
    fn a_flat_trial_is_accepted_only_when_the_residual_falls() {
        assert_eq!(ARMIJO.verdict(1.0, 1.0 + 1e-13, 1.0, -1.0), Verdict::Flat);
        assert_eq!(ARMIJO.verdict(1.0, 1.0 + 1e-9, 1.0, -1.0), Verdict::Reject);
        assert_eq!(ARMIJO.verdict(1.0, f64::NAN, 1.0, -1.0), Verdict::Reject);
        let search = Backtracking {
            condition: ARMIJO,
            halvings: 4,
        };
        let mut rejected = 0;
        let never = search.search((1.0, -1.0), 1.0, |_| 1.0 + 1e-13, || false, &mut rejected);
        assert_eq!((never, rejected), (None, 4));
        let flat = search.search((1.0, -1.0), 1.0, |_| 1.0 + 1e-13, || true, &mut rejected);
        assert_eq!(flat, Some((1.0, 1.0 + 1e-13)));
    }

    #[test]
    fn start_flags_round_trip() {
        for s in [Start::Nested, Start::NestedFlat, Start::Shaped, Start::Flat] {
            assert_eq!(Start::from_flags(s.is_nested(), s.is_shaped()), s);
        }
    }
}
