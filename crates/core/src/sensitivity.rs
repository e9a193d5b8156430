//! How a solved drape moves when a parameter moves: the sensitivities dx*/dθ of a converged minimum
//! to the scene's continuous parameters ([`crate::params`]) and the adjoint gradient dJ/dθ of a
//! scalar measure J(x*), both from one factor of the exact Hessian at the equilibrium
//! ([`EquilibriumFactor`]).
//!
//! The equilibrium satisfies g(x*(θ), θ) = 0 over the free coordinates, so H dx*/dθ = −∂g/∂θ. The
//! mixed derivative ∂g/∂θ is taken on the model itself: the scene is rebuilt at θ ± h (h = 10⁻⁶ θ, [`PARAM_STEP_REL`])
//! and the gradient of every energy term evaluated at the same x*, with the fixed particles where
//! the rebuilt scene puts them (a pin moved by `cloth.size_x_m` moves the drape through the
//! coupling blocks of H). This central difference of an analytic gradient is exact for the terms
//! linear in their parameter (stiffnesses, weights, κ) up to round-off and O(h²) for the others
//! (contact distances, sizes); it needs two gradient assemblies per key and no solve.

use crate::build::build_scene;
use crate::error::InputError;
use crate::params;
use crate::physics::{Model, Vecs};
use crate::scene::ValidatedScene;
use crate::solve::{EquilibriumFactor, NoFactor, SolveReport};
use nalgebra::Vector3;

/// The relative step of the mixed derivative's central difference in a parameter (h = 10⁻⁶ |θ|;
/// an absolute 10⁻⁸ for a parameter that is zero). Small because a sheet's soft modes amplify the
/// difference's O(h²) error: on hang2 (a sheet swinging about two pins) the sensitivity to
/// `cloth.size_y_m` is 10⁻³ off at h = 10⁻⁴ |θ| and 10⁻⁷ at 10⁻⁶ (its round-off is 10⁻⁹ there).
pub const PARAM_STEP_REL: f64 = 1e-6;

/// The gradient of a rebuilt model at x* and the positions it was taken at (x* with the rebuilt
/// scene's pins).
type Side = (Vec<Vector3<f64>>, Vec<Vector3<f64>>);

/// A key's value, its mixed derivative ∂g/∂θ and its fixed particles' motion dx/dθ.
type Mixed = (f64, Vec<Vector3<f64>>, Vec<Vector3<f64>>);

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

/// The equilibrium of a solved scene with its factor, ready for sensitivities and adjoints.
pub struct Equilibrium<'a> {
    scene: &'a ValidatedScene,
    model: &'a Model,
    x: &'a [Vector3<f64>],
    factor: EquilibriumFactor,
    source: String,
}

impl<'a> Equilibrium<'a> {
    /// The factor of the solved `model` at `x`; none unless the report says converged. `source`
    /// names where the keys come from in errors (a flag, a file).
    pub fn new(
        scene: &'a ValidatedScene,
        model: &'a Model,
        x: &'a [Vector3<f64>],
        report: &SolveReport,
        source: &str,
    ) -> Result<Self, NoSensitivity> {
        if !report.is_converged() {
            return Err(NoSensitivity::NoFactor(NoFactor::NotConverged));
        }
        let factor = EquilibriumFactor::new(model, x).map_err(NoSensitivity::NoFactor)?;
        Ok(Self {
            scene,
            model,
            x,
            factor,
            source: source.to_string(),
        })
    }

    /// The mixed derivative ∂g/∂θ of `key` at x* and the fixed particles' motion dx/dθ.
    fn mixed(&self, key: &str) -> Result<Mixed, NoSensitivity> {
        let theta = params::value(self.scene, key, &self.source).map_err(NoSensitivity::Input)?;
        let h = param_step(theta);
        let side = |t: f64| -> Result<Side, NoSensitivity> {
            let s = params::with_value(self.scene, key, t, &self.source)
                .map_err(NoSensitivity::Input)?;
            let b = build_scene(&s);
            if !same_structure(&b.model, self.model) {
                return Err(NoSensitivity::Structural(key.to_string()));
            }
            let mut xs = self.x.to_vec();
            for (p, v) in xs.iter_mut().enumerate() {
                if b.model.fixed[p] {
                    *v = b.x0[p];
                }
            }
            let mut g = Vec::new();
            b.model.gradient(&xs, 1.0, &mut g);
            Ok((g, xs))
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
        let dg =
            hi.0.iter()
                .zip(&lo.0)
                .map(|(a, b)| (a - b) / span)
                .collect();
        let dxf =
            hi.1.iter()
                .zip(&lo.1)
                .map(|(a, b)| (a - b) / span)
                .collect();
        Ok((theta, dg, dxf))
    }

    /// dx*/dθ for the continuous parameter `key`.
    pub fn sensitivity(&mut self, key: &str) -> Result<KeySensitivity, NoSensitivity> {
        let (value, dg, dxf) = self.mixed(key)?;
        let (dx, residual) = self.factor.sensitivity_checked(&dg, &dxf);
        if residual > MAX_RESIDUAL_REL {
            return Err(NoSensitivity::NotIsolated(key.to_string(), residual));
        }
        Ok(KeySensitivity {
            key: key.to_string(),
            value,
            dx,
            dg,
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
                let (_, dg, dxf) = self.mixed(k)?;
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

/// Whether the `rebuilt` model has the particles, the fixed set and the terms of `solved` (which may
/// have more terms appended by its solve, such as lagged friction).
fn same_structure(rebuilt: &Model, solved: &Model) -> bool {
    rebuilt.len() == solved.len()
        && rebuilt.fixed == solved.fixed[..]
        && rebuilt.terms.len() <= solved.terms.len()
        && rebuilt
            .term_names()
            .iter()
            .zip(solved.term_names())
            .all(|(a, c)| *a == c)
}

/// Checks, before a solve, that `key` is a continuous parameter of `scene` whose neighbouring values
/// θ(1 ± 10⁻⁶) build a model with the same particles and terms. The error names `source` (the flag)
/// and the key, and says what to do.
pub fn check_key(scene: &ValidatedScene, key: &str, source: &str) -> Result<(), InputError> {
    let theta = params::value(scene, key, source)?;
    let h = param_step(theta);
    let base = build_scene(scene);
    let mut any = None;
    for t in [theta + h, theta - h] {
        // A side out of the key's range is the edge of the range, not an error.
        if let Ok(s) = params::with_value(scene, key, t, source) {
            let b = build_scene(&s);
            if !same_structure(&b.model, &base.model) {
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
