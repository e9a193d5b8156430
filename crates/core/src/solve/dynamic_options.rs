//! The dynamic solvers' options (`[solver.dynamic]`): each key's meaning, unit and default, and
//! their checks.

use serde::{Deserialize, Serialize};

/// Options of the dynamic solvers.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DynamicOptions {
    /// Time step in s; implicit Euler's first step (it adapts from there). Default 1e-4.
    #[serde(default = "default_dt")]
    pub dt_s: f64,
    /// Implicit Euler: grow the step (×2) while Newton converges within 6 iterations, halve it beyond
    /// 12 and retry a step Newton cannot finish. Default true.
    #[serde(default = "default_true")]
    pub adaptive_dt: bool,
    /// Implicit Euler: the largest step, s (a recording's frame interval caps it too). Default 100:
    /// backward Euler is stable at any step, and an overdamped sheet (seed 000's c/m ≈ 200 1/s)
    /// creeps into its slowest modes over hundreds of seconds of simulated time.
    #[serde(default = "default_max_dt")]
    pub max_dt_s: f64,
    /// Implicit Euler: below this step, s, the integration stops (status max-iterations, reason
    /// step-too-small). Default 1e-7.
    #[serde(default = "default_min_dt")]
    pub min_dt_s: f64,
    /// Rayleigh damping, mass-proportional part α: a force −α m v on every particle, 1/s. Adds to the
    /// material's particle damping c (seed 000's −c v, Eq. 4). Implicit Euler only. Default 0.
    #[serde(default)]
    pub rayleigh_mass_per_s: f64,
    /// Rayleigh damping, stiffness-proportional part β: a force −β K v (K the projected Hessian at the
    /// step's start), s. Implicit Euler only. Default 0.
    #[serde(default)]
    pub rayleigh_stiffness_s: f64,
    /// Implicit Euler: Newton iterations allowed per step before the step is halved and retried.
    /// Default 25 (a step in contact takes 10 to 20: the barrier's step bound shortens Newton's steps).
    #[serde(default = "default_newton_iterations")]
    pub newton_iterations: usize,
    /// Implicit Euler: whether each step's Newton reuses its factorization while it converges
    /// (`"chord"`, see `solver.static.factor_reuse`; the step then grows with the iterations that
    /// factorized) or factorizes every iteration (`"fresh"`, the behaviour before issue 34's last
    /// step). Default `"chord"`. The old boolean `reuse_factorization` is read as this key.
    #[serde(default = "default_chord")]
    pub factor_reuse: super::FactorReuse,
    /// When > 0, explicit and symplectic Euler use this fraction of their estimated stability limit
    /// ([`stability_limit_dt`] at the initial state) instead of `dt_s`. Default 0 (use `dt_s`).
    #[serde(default)]
    pub auto_dt_fraction: f64,
    /// Simulated time after which the solve stops with status max-iterations, in s. Default 60.
    #[serde(default = "default_max_time")]
    pub max_time_s: f64,
    /// Equilibrium when the largest residual force is below this fraction of the lightest particle's
    /// weight ... Default 1e-6.
    #[serde(default = "default_tol")]
    pub residual_tol_rel: f64,
    /// ... and the largest speed is below this, in m/s. Default 1e-6.
    #[serde(default = "default_vtol")]
    pub speed_tol_m_per_s: f64,
    /// Steps between equilibrium and divergence checks. Default 10.
    #[serde(default = "default_check")]
    pub check_every: usize,
    /// A strain beyond which the solve is reported as diverged. Default 10.
    #[serde(default = "default_strain")]
    pub strain_bound: f64,
    /// Relative tolerance of the conjugate-gradient solves (implicit Euler). Default 1e-10.
    #[serde(default = "default_cg")]
    pub cg_tol_rel: f64,
    /// Whether damping applies (false: conservative dynamics, e.g. for energy checks). Default true.
    #[serde(default = "default_true")]
    pub damping: bool,
    /// Wall-clock budget in s: past it the solve stops with status max-iterations (benchmarks cap
    /// their slow points with it). Default none.
    #[serde(default)]
    pub max_wall_time_s: Option<f64>,
}

fn default_dt() -> f64 {
    1e-4
}
impl DynamicOptions {
    /// Checks every option (keys relative to `[solver.dynamic]`); `adaptive`: the steps grow from
    /// `dt_s` to `max_dt_s` (implicit Euler with `adaptive_dt`), which bounds their count.
    pub fn check(&self, adaptive: bool) -> Result<(), crate::error::KeyError> {
        use crate::error::KeyError;
        for (k, v) in [
            ("dt_s", self.dt_s),
            ("max_time_s", self.max_time_s),
            ("max_dt_s", self.max_dt_s),
            ("min_dt_s", self.min_dt_s),
            ("residual_tol_rel", self.residual_tol_rel),
            ("speed_tol_m_per_s", self.speed_tol_m_per_s),
            ("strain_bound", self.strain_bound),
            ("cg_tol_rel", self.cg_tol_rel),
        ] {
            KeyError::positive(k, v)?;
        }
        if let Some(w) = self.max_wall_time_s {
            KeyError::positive("max_wall_time_s", w)?;
        }
        tolerance_below_one_weight(self.residual_tol_rel)?;
        if self.min_dt_s > self.max_dt_s {
            return Err(KeyError::new(
                "min_dt_s",
                format!(
                    "must not exceed max_dt_s ({} s), got {} s",
                    self.max_dt_s, self.min_dt_s
                ),
            ));
        }
        KeyError::non_negative("rayleigh_mass_per_s", self.rayleigh_mass_per_s)?;
        KeyError::non_negative("rayleigh_stiffness_s", self.rayleigh_stiffness_s)?;
        if self.newton_iterations == 0 {
            return Err(KeyError::new("newton_iterations", "must be ≥ 1"));
        }
        if self.check_every == 0 {
            return Err(KeyError::new("check_every", "must be ≥ 1"));
        }
        if !(0.0..=100.0).contains(&self.auto_dt_fraction) {
            return Err(KeyError::new(
                "auto_dt_fraction",
                format!(
                    "must be in [0, 100] (above 1 is beyond the estimated limit), got {}",
                    self.auto_dt_fraction
                ),
            ));
        }
        let step = if adaptive {
            self.max_dt_s.max(self.dt_s)
        } else {
            self.dt_s
        };
        if self.max_time_s / step > 1e9 {
            return Err(KeyError::new(
                "max_time_s",
                "more than 1e9 steps: raise dt_s or lower max_time_s",
            ));
        }
        Ok(())
    }
}

fn default_max_dt() -> f64 {
    100.0
}
fn default_min_dt() -> f64 {
    1e-7
}
fn default_newton_iterations() -> usize {
    25
}
fn default_max_time() -> f64 {
    60.0
}
fn default_tol() -> f64 {
    1e-6
}
fn default_vtol() -> f64 {
    1e-6
}
fn default_check() -> usize {
    10
}
fn default_strain() -> f64 {
    10.0
}
fn default_cg() -> f64 {
    1e-10
}
fn default_chord() -> super::FactorReuse {
    super::FactorReuse::Chord
}

fn default_true() -> bool {
    true
}

impl Default for DynamicOptions {
    fn default() -> Self {
        Self {
            dt_s: default_dt(),
            adaptive_dt: true,
            max_dt_s: default_max_dt(),
            min_dt_s: default_min_dt(),
            rayleigh_mass_per_s: 0.0,
            rayleigh_stiffness_s: 0.0,
            newton_iterations: default_newton_iterations(),
            factor_reuse: super::FactorReuse::Chord,
            auto_dt_fraction: 0.0,
            max_time_s: default_max_time(),
            residual_tol_rel: default_tol(),
            speed_tol_m_per_s: default_vtol(),
            check_every: default_check(),
            strain_bound: default_strain(),
            cg_tol_rel: default_cg(),
            damping: true,
            max_wall_time_s: None,
        }
    }
}

/// Ok when a residual tolerance relative to the lightest particle's weight is below 1: a residual
/// force as large as a particle's weight is no equilibrium, and any start would "converge".
pub(crate) fn tolerance_below_one_weight(tol: f64) -> Result<(), crate::error::KeyError> {
    if tol >= 1.0 {
        return Err(crate::error::KeyError::new(
            "residual_tol_rel",
            format!(
                "must be below 1 (a fraction of the lightest particle's weight; 1e-8 is the \
                 default), got {tol}"
            ),
        ));
    }
    Ok(())
}
