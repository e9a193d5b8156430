//! How a solved drape moves when a parameter moves: the sensitivities dx*/dθ of a converged minimum
//! to the scene's continuous parameters ([`crate::params`]) and the adjoint gradient dJ/dθ of a
//! scalar measure J(x*), both from one factor of the exact Hessian at the equilibrium
//! ([`EquilibriumFactor`]).
//!
//! The equilibrium satisfies g(x*(θ), θ) = 0 over the free coordinates, so H dx*/dθ = −∂g/∂θ. The
//! mixed derivative ∂g/∂θ is taken term by term ([`crate::physics::Kernel`]): the scene is rebuilt
//! at θ ± h (h = 10⁻⁶ θ, [`PARAM_STEP_REL`]), each term's coefficients (stiffnesses, rest lengths,
//! weights) differenced into dc/dθ, and the term's analytic mixed derivative ∂g/∂c · dc/dθ taken at
//! x*: analytic for the elastic terms, loads, friction, self-contact and the obstacles' barrier in
//! κ and d̂, a per-particle difference of the barrier's force for an obstacle's shape. A term that
//! gives no coefficients would contribute the central difference of its rebuilt gradients at x*. The fixed particles' motion (a pin moved by
//! `cloth.size_x_m`) enters through the coupling blocks of the exact Hessian, H dx_fixed/dθ. No
//! solve is needed, and the coefficients' difference is exact for coefficients linear in θ.
//!
//! The barriers' κ is held where the solve left it (a static solve may have doubled it where layers
//! press): the sensitivity is that of the solved model's equilibrium, κ being the solver's choice.

use crate::build::build_scene;
use crate::error::InputError;
use crate::params::{self, Parameterized};
use crate::physics::{EnergyTerm, Model, Vecs};
use crate::scene::ValidatedScene;
use crate::solve::{EquilibriumFactor, NoFactor, SolveReport};
use nalgebra::Vector3;

/// The relative step of the mixed derivative's central difference in a parameter (h = 10⁻⁶ |θ|;
/// an absolute 10⁻⁸ for a parameter that is zero). Small because a sheet's soft modes amplify the
/// difference's O(h²) error: on hang2 (a sheet swinging about two pins) the sensitivity to
/// `cloth.size_y_m` is 10⁻³ off at h = 10⁻⁴ |θ| and 10⁻⁷ at 10⁻⁶ (its round-off is 10⁻⁹ there).
pub const PARAM_STEP_REL: f64 = 1e-6;

/// A key's value, its mixed derivative ∂g/∂θ, its fixed particles' motion dx/dθ and the energy's
/// derivative dE*/dθ.
type Mixed = (f64, Vec<Vector3<f64>>, Vec<Vector3<f64>>, f64);

/// The step of the central differences in θ.
fn param_step(theta: f64) -> f64 {
    if theta == 0.0 {
        1e-8
    } else {
        PARAM_STEP_REL * theta.abs()
    }
}

/// The largest relative residual ‖H dx + ∂g/∂θ‖/‖∂g/∂θ‖ a sensitivity may leave; beyond, the key
/// pushes along a neutral mode and has none.
pub const MAX_RESIDUAL_REL: f64 = 1e-6;

/// The sensitivity of an equilibrium to one parameter.
#[derive(Debug, Clone)]
pub struct KeySensitivity {
    /// The dotted scene key.
    pub key: String,
    /// Its value, in the scene file's unit.
    pub value: f64,
    /// dx*/dθ of every particle (virtual ones included), m per unit of the key.
    pub dx: Vec<Vector3<f64>>,
    /// ∂g/∂θ at x* (the total derivative along the fixed particles' motion), N per unit of the key;
    /// the adjoint contracts it.
    pub dg: Vec<Vector3<f64>>,
    /// dE*/dθ, the equilibrium energy's derivative, J per unit of the key: by the envelope theorem
    /// ∂E/∂θ at x* plus the fixed particles' forces along their motion (the drape's own motion does
    /// no work at a minimum), with no solve.
    pub d_energy: f64,
}

/// Why a key has no sensitivity.
#[derive(Debug, Clone, PartialEq)]
pub enum NoSensitivity {
    /// The equilibrium has no factor.
    NoFactor(NoFactor),
    /// The key is not a continuous parameter, or its perturbed scene is out of range.
    Input(InputError),
    /// The scene rebuilt at θ ± h has other particles or other terms: the key changes the model's
    /// structure, not its values.
    Structural(String),
    /// The key pushes the drape along a motion it is free to make (the equilibrium is not
    /// isolated in that direction): the linear system has no solution; the relative residual.
    NotIsolated(String, f64),
}

impl std::fmt::Display for NoSensitivity {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            NoSensitivity::NoFactor(r) => write!(f, "no sensitivities: {}", r.as_str()),
            NoSensitivity::Input(e) => write!(f, "{e}"),
            NoSensitivity::Structural(k) => write!(
                f,
                "key `{k}`: changing it changes which particles or terms the model has; no sensitivity"
            ),
            NoSensitivity::NotIsolated(k, r) => write!(
                f,
                "key `{k}`: it pushes the drape along a motion the equilibrium is free to make (a \
neutral mode; residual {r:.1e}): the drape does not move smoothly with it"
            ),
        }
    }
}

/// A scene's continuous keys that it lets change as parameters ([`params::free_keys`]); `source` names
/// where the keys come from in errors (a flag, a file).
pub struct SceneParameters<'a> {
    /// The scene.
    pub scene: &'a ValidatedScene,
    /// Where the keys come from.
    pub source: String,
}

impl Parameterized for SceneParameters<'_> {
    fn keys(&self) -> Vec<String> {
        params::free_keys(self.scene)
    }
    fn value(&self, key: &str) -> Result<f64, InputError> {
        params::value(self.scene, key, &self.source)
    }
    fn model_with(&self, key: &str, v: f64) -> Result<(Model, Vec<Vector3<f64>>), InputError> {
        let s = params::with_value(self.scene, key, v, &self.source)?;
        let b = build_scene(&s);
        Ok((b.model, b.x0))
    }
    fn model(&self) -> (Model, Vec<Vector3<f64>>) {
        let b = build_scene(self.scene);
        (b.model, b.x0)
    }
}

/// The equilibrium of a solved model with its factor, ready for sensitivities and adjoints.
pub struct Equilibrium<'a> {
    params: Box<dyn Parameterized + 'a>,
    model: &'a Model,
    x: &'a [Vector3<f64>],
    factor: EquilibriumFactor,
}

impl<'a> Equilibrium<'a> {
    /// The factor of the exact Hessian at the equilibrium.
    pub fn factor(&self) -> &EquilibriumFactor {
        &self.factor
    }

    /// The factor, for solves with it (a Newton correction of the equilibrium).
    pub fn factor_mut(&mut self) -> &mut EquilibriumFactor {
        &mut self.factor
    }

    /// The factor of the solved scene's `model` at `x`; none unless the report says converged.
    /// `source` names where the keys come from in errors (a flag, a file).
    pub fn new(
        scene: &'a ValidatedScene,
        model: &'a Model,
        x: &'a [Vector3<f64>],
        report: &SolveReport,
        source: &str,
    ) -> Result<Self, NoSensitivity> {
        let params = SceneParameters {
            scene,
            source: source.to_string(),
        };
        Self::of(Box::new(params), model, x, report)
    }

    /// The factor of `model` solved at `x` over the parameters `params` (a scene, a Cusick
    /// specimen); none unless the report says converged.
    pub fn of(
        params: Box<dyn Parameterized + 'a>,
        model: &'a Model,
        x: &'a [Vector3<f64>],
        report: &SolveReport,
    ) -> Result<Self, NoSensitivity> {
        if !report.is_converged() {
            return Err(NoSensitivity::NoFactor(NoFactor::NotConverged));
        }
        let factor = EquilibriumFactor::new(model, x).map_err(NoSensitivity::NoFactor)?;
        Ok(Self {
            params,
            model,
            x,
            factor,
        })
    }

    /// The mixed derivative ∂g/∂θ of `key` at x* and the fixed particles' motion dx/dθ.
    fn mixed(&self, key: &str) -> Result<Mixed, NoSensitivity> {
        let theta = self.params.value(key).map_err(NoSensitivity::Input)?;
        let h = param_step(theta);
        let side = |t: f64| -> Result<(Model, Vec<Vector3<f64>>), NoSensitivity> {
            let (model, x0) = self
                .params
                .model_with(key, t)
                .map_err(NoSensitivity::Input)?;
            if !same_structure(&model, self.model) {
                return Err(NoSensitivity::Structural(key.to_string()));
            }
            Ok((model, x0))
        };
        // Central where both sides are valid scenes, one-sided at the edge of a key's range.
        // A structural change on either side (a pin or a supported particle switching) is a kink of
        // the drape in θ, not the edge of a range: no derivative.
        let (hi, lo, span) = match (side(theta + h), side(theta - h)) {
            (Ok(a), Ok(b)) => (a, b, 2.0 * h),
            (Ok(a), Err(NoSensitivity::Input(_))) => (a, side(theta)?, h),
            (Err(NoSensitivity::Input(_)), Ok(b)) => (side(theta)?, b, h),
            (Err(e), _) | (_, Err(e)) => return Err(e),
        };
        let dxf: Vec<Vector3<f64>> = (0..self.x.len())
            .map(|p| match self.model.fixed[p] {
                true => (hi.1[p] - lo.1[p]) / span,
                false => Vector3::zeros(),
            })
            .collect();
        let mut dg = vec![Vector3::zeros(); self.x.len()];
        let mut de = 0.0;
        for ((t, th), tl) in self.model.terms.iter().zip(&hi.0.terms).zip(&lo.0.terms) {
            de += mixed_of_term(
                (t.as_ref(), th.as_ref(), tl.as_ref()),
                self.x,
                span,
                &mut dg,
            );
        }
        let mut g = Vec::new();
        self.model.gradient(self.x, 1.0, &mut g);
        de += g.iter().zip(&dxf).map(|(a, b)| a.dot(b)).sum::<f64>();
        // The fixed particles' motion moves the drape through the Hessian's coupling blocks.
        let mut hess = crate::physics::HessianBlocks::default();
        self.model
            .hessian(self.x, &mut hess, crate::physics::HessianMode::Exact);
        hess.mul_add(&dxf, &mut dg);
        Ok((theta, dg, dxf, de))
    }

    /// dx*/dθ for the continuous parameter `key`.
    pub fn sensitivity(&mut self, key: &str) -> Result<KeySensitivity, NoSensitivity> {
        let (value, dg, dxf, d_energy) = self.mixed(key)?;
        let (dx, residual) = self.factor.sensitivity_checked(&dg, &dxf);
        if residual > MAX_RESIDUAL_REL {
            return Err(NoSensitivity::NotIsolated(key.to_string(), residual));
        }
        Ok(KeySensitivity {
            key: key.to_string(),
            value,
            dx,
            dg,
            d_energy,
        })
    }

    /// The adjoint λ = H⁻¹ ∂J/∂x of a scalar measure with gradient `dj_dx` at x*.
    pub fn adjoint(&mut self, dj_dx: &Vecs) -> Vec<Vector3<f64>> {
        self.factor.solve(dj_dx)
    }

    /// dJ/dθ for each key by one adjoint solve: −λᵀ ∂g/∂θ over the free particles plus ∂J/∂x of
    /// the fixed ones along their own motion.
    pub fn gradient(&mut self, dj_dx: &Vecs, keys: &[&str]) -> Result<Vec<f64>, NoSensitivity> {
        let lambda = self.adjoint(dj_dx);
        keys.iter()
            .map(|k| {
                let (_, dg, dxf, _) = self.mixed(k)?;
                Ok((0..self.x.len())
                    .map(|p| {
                        if self.factor.is_free(p) {
                            -lambda[p].dot(&dg[p])
                        } else {
                            dj_dx[p].dot(&dxf[p])
                        }
                    })
                    .sum())
            })
            .collect()
    }
}

/// Adds one term's ∂g/∂θ at `x` to `dg` and returns its ∂E/∂θ, from the term of the solved model
/// `t` and its rebuilds `hi`, `lo` at θ ± `span`/2: the analytic mixed derivatives in the term's
/// coefficients along their change (dc/dθ by the difference of the rebuilt coefficients: exact for
/// coefficients linear in θ, as stiffnesses, weights and rest lengths are), or, for a term that
/// does not give them, the differences of its rebuilt gradient and energy.
fn mixed_of_term(
    (t, hi, lo): (&dyn EnergyTerm, &dyn EnergyTerm, &dyn EnergyTerm),
    x: &Vecs,
    span: f64,
    dg: &mut [Vector3<f64>],
) -> f64 {
    let (ch, cl) = (hi.coefficients(), lo.coefficients());
    if !ch.is_empty() && ch.len() == cl.len() {
        // Equal coefficients (an infinite saturation on both sides too) do not move.
        let dc: Vec<f64> = ch
            .iter()
            .zip(&cl)
            .map(|(a, b)| if a == b { 0.0 } else { (a - b) / span })
            .collect();
        if let Some(de) = t.coefficient_energy(x, &dc)
            && t.add_coefficient_gradient(x, &dc, dg)
        {
            return de;
        }
    }
    let n = x.len();
    let (mut gh, mut gl) = (vec![Vector3::zeros(); n], vec![Vector3::zeros(); n]);
    hi.add_gradient(x, &mut gh);
    lo.add_gradient(x, &mut gl);
    for ((d, a), b) in dg.iter_mut().zip(&gh).zip(&gl) {
        *d += (a - b) / span;
    }
    (hi.energy(x) - lo.energy(x)) / span
}

/// Whether the `rebuilt` model has the particles, the fixed set and the terms of `solved` (which may
/// have more terms appended by its solve, such as lagged friction).
fn same_structure(rebuilt: &Model, solved: &Model) -> bool {
    rebuilt.len() == solved.len()
        && rebuilt.fixed == solved.fixed[..]
        && rebuilt.term_names() == solved.term_names()
}

/// Checks, before a solve, that `key` is a continuous parameter of `scene` whose neighbouring values
/// θ(1 ± 10⁻⁶) build a model with the same particles and terms. The error names `source` (the flag)
/// and the key, and says what to do.
///
/// A drape with friction is refused: its equilibrium is that of lagged friction (the normal forces
/// and anchors of the last lag held, `simulate::friction`), which the sensitivity does not
/// differentiate; its derivative would leave friction's dependence out (for μ itself, zero).
pub fn check_key(scene: &ValidatedScene, key: &str, source: &str) -> Result<(), InputError> {
    let mu = scene.contact.friction_coefficient;
    if mu > 0.0 && !scene.obstacles.is_empty() {
        return Err(InputError::new(
            source,
            key,
            format!(
                "the drape has friction (contact.friction_coefficient = {mu}) and the sensitivity \
                 of a lagged-friction equilibrium is not computed; set \
                 contact.friction_coefficient=0 for a frictionless drape's sensitivities, or \
                 difference two drapes"
            ),
        ));
    }
    let params = SceneParameters {
        scene,
        source: source.to_string(),
    };
    check_parameter(&params, key, source)
}

/// [`check_key`] for any parameterized model; errors name `source` and the key.
pub fn check_parameter(
    params: &dyn Parameterized,
    key: &str,
    source: &str,
) -> Result<(), InputError> {
    let theta = params.value(key)?;
    let h = param_step(theta);
    let (base, _) = params.model();
    let mut any = None;
    for t in [theta + h, theta - h] {
        // A side out of the key's range is the edge of the range, not an error.
        if let Ok((model, _)) = params.model_with(key, t) {
            if !same_structure(&model, &base) {
                return Err(InputError::new(
                    source,
                    key,
                    "changing it changes which particles or energy terms the model has, so the \
drape has no derivative in it; give a key whose change only changes values",
                ));
            }
            any = Some(());
        }
    }
    any.ok_or_else(|| {
        InputError::new(
            source,
            key,
            format!("no valid scene within 1e-6 of {theta}: the value is at the edge of its range"),
        )
    })
}

/// ∂J/∂x of the mean height of the free particles with mass (the drape's sag): 1/n on each z.
pub fn mean_height_gradient(model: &Model) -> Vec<Vector3<f64>> {
    let free: Vec<bool> = (0..model.len())
        .map(|p| !model.fixed[p] && model.masses[p] > 0.0)
        .collect();
    let n = free.iter().filter(|f| **f).count().max(1) as f64;
    free.iter()
        .map(|&f| Vector3::new(0.0, 0.0, if f { 1.0 / n } else { 0.0 }))
        .collect()
}
