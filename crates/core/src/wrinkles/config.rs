//! The wrinkles config: TOML with `[defaults]`, `[[cases]]` and optional `[[sweeps]]` (one key of a
//! base case over a list of values). Every key carries its unit; every value is checked once here.

use super::WrinkleInputs;
use crate::error::InputError;
use crate::error::KeyError;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Values shared by every case unless the case gives its own.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Defaults {
    /// Poisson's ratio ν (the seed gives none). Default 0.3.
    #[serde(default = "d_nu")]
    pub poisson_ratio: f64,
    /// Load constant c of Eq. 7 (the seed gives none). Default 135: Q_c = 1.29 for Table I's middle
    /// row (h = 140 cm) with ν = 0.3 and the plate's E t³, the seed's reading. The bundled config
    /// reads Eq. 7 for a fabric (`bending_length_m` 14.3 mm) with c = 7197, the reading the full
    /// simulations of the twelve sheets as fabric support (reports/wrinkles.md).
    #[serde(default = "d_c")]
    pub buckling_constant: f64,
    /// Relative tolerance on the length L' of Eq. 8 against L. Default 0.05 (the seed's).
    #[serde(default = "d_tol")]
    pub tolerance_rel: f64,
    /// Iterations allowed. Default 50.
    #[serde(default = "d_iter")]
    pub max_iterations: usize,
    /// Tentative z_max to start from, m. Default 0.014 (the seed's "0.014").
    #[serde(default = "d_z")]
    pub initial_zmax_m: f64,
    /// Simpson intervals for Eq. 8. Default 200.
    #[serde(default = "d_simpson")]
    pub simpson_intervals: usize,
    /// Eq. 7 read for a fabric (issue 50): the sheet's bending length c_b, m, whose bending rigidity
    /// w c_b³ stands for the plate's E t³/(12(1 − ν²)). None (the default): Eq. 7 as the seed writes
    /// it, the plate. Set it when the sheet is a woven or knitted fabric, whose yarns slide.
    #[serde(default)]
    pub bending_length_m: Option<f64>,
}

fn d_nu() -> f64 {
    0.3
}
fn d_c() -> f64 {
    135.0
}
fn d_tol() -> f64 {
    0.05
}
fn d_iter() -> usize {
    50
}
fn d_z() -> f64 {
    0.014
}
fn d_simpson() -> usize {
    200
}

impl Default for Defaults {
    fn default() -> Self {
        Self {
            poisson_ratio: d_nu(),
            buckling_constant: d_c(),
            tolerance_rel: d_tol(),
            max_iterations: d_iter(),
            initial_zmax_m: d_z(),
            simpson_intervals: d_simpson(),
            bending_length_m: None,
        }
    }
}

/// The seed's published result for a case, for the side-by-side report.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SeedResult {
    /// Number of wrinkles.
    pub n: usize,
    /// z_max, cm (none where the seed gives only a count, as for its photograph, Fig. 4).
    #[serde(default)]
    pub zmax_cm: Option<f64>,
    /// Ratio Q (none where the seed gives only a count).
    #[serde(default)]
    pub q: Option<f64>,
}

/// One case as written in the file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WrinkleCase {
    /// Name of the case.
    pub case: String,
    /// Horizontal length L, m.
    pub length_m: f64,
    /// Height h, m.
    pub height_m: f64,
    /// Thickness t, m.
    pub thickness_m: f64,
    /// Young's modulus E, Pa.
    pub youngs_modulus_Pa: f64,
    /// Weight per area w, N/m².
    pub weight_N_per_m2: f64,
    /// Inward displacement of each support d, m.
    pub support_displacement_m: f64,
    /// Overrides of the defaults.
    #[serde(default)]
    pub poisson_ratio: Option<f64>,
    /// Override of the load constant c.
    #[serde(default)]
    pub buckling_constant: Option<f64>,
    /// Override of the fabric's bending length of Eq. 7, m (see [`Defaults::bending_length_m`]).
    #[serde(default)]
    pub bending_length_m: Option<f64>,
    /// The seed's result, if it gives one.
    #[serde(default)]
    pub seed: Option<SeedResult>,
}

/// One key of a base case over a list of values.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sweep {
    /// The case to start from.
    pub base: String,
    /// The key to vary: one of the numeric keys of a case.
    pub key: String,
    /// Its values.
    pub values: Vec<f64>,
}

/// A wrinkles config file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WrinkleConfig {
    /// Shared values.
    #[serde(default)]
    pub defaults: Defaults,
    /// The cases.
    #[serde(default)]
    pub cases: Vec<WrinkleCase>,
    /// Sweeps adding cases.
    #[serde(default)]
    pub sweeps: Vec<Sweep>,
    /// Sheets the seed shows in a photograph rather than a table (Fig. 4's cloth): simulated by
    /// `wrinkles-simulate` read as fabric, their counts beside the photograph's; not tabulated.
    #[serde(default)]
    pub photographs: Vec<WrinkleCase>,
}

impl WrinkleCase {
    /// The solver inputs with the defaults filled in.
    pub fn inputs(&self, d: &Defaults) -> WrinkleInputs {
        WrinkleInputs {
            length_m: self.length_m,
            height_m: self.height_m,
            thickness_m: self.thickness_m,
            youngs_modulus_Pa: self.youngs_modulus_Pa,
            poisson_ratio: self.poisson_ratio.unwrap_or(d.poisson_ratio),
            weight_N_per_m2: self.weight_N_per_m2,
            support_displacement_m: self.support_displacement_m,
            buckling_constant: self.buckling_constant.unwrap_or(d.buckling_constant),
            tolerance_rel: d.tolerance_rel,
            max_iterations: d.max_iterations,
            initial_zmax_m: d.initial_zmax_m,
            simpson_intervals: d.simpson_intervals,
            bending_length_m: self.bending_length_m.or(d.bending_length_m),
        }
    }

    fn set(&mut self, key: &str, v: f64) -> bool {
        match key {
            "length_m" => self.length_m = v,
            "height_m" => self.height_m = v,
            "thickness_m" => self.thickness_m = v,
            "youngs_modulus_Pa" => self.youngs_modulus_Pa = v,
            "weight_N_per_m2" => self.weight_N_per_m2 = v,
            "support_displacement_m" => self.support_displacement_m = v,
            "poisson_ratio" => self.poisson_ratio = Some(v),
            "buckling_constant" => self.buckling_constant = Some(v),
            "bending_length_m" => self.bending_length_m = Some(v),
            _ => return false,
        }
        true
    }

    /// Checks the values: Err(KeyError::new(key, message)).
    fn check(&self, d: &Defaults) -> Result<(), KeyError> {
        let inp = self.inputs(d);
        let positive = [
            ("length_m", inp.length_m),
            ("height_m", inp.height_m),
            ("thickness_m", inp.thickness_m),
            ("youngs_modulus_Pa", inp.youngs_modulus_Pa),
            ("weight_N_per_m2", inp.weight_N_per_m2),
            ("buckling_constant", inp.buckling_constant),
            ("bending_length_m", inp.bending_length_m.unwrap_or(1.0)),
        ];
        for (k, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                return Err(KeyError::new(
                    k,
                    format!("must be a finite number > 0, got {v}"),
                ));
            }
        }
        let nu = inp.poisson_ratio;
        if !(nu.is_finite() && (0.0..0.5).contains(&nu)) {
            return Err(KeyError::new(
                "poisson_ratio",
                format!("must be in [0, 0.5), got {nu}"),
            ));
        }
        let d_m = inp.support_displacement_m;
        if !(d_m.is_finite() && d_m > 0.0 && 2.0 * d_m < inp.length_m) {
            return Err(KeyError::new(
                "support_displacement_m",
                format!(
                    "must be > 0 and leave the supports apart (2d < length_m = {}), got {d_m}",
                    inp.length_m
                ),
            ));
        }
        Ok(())
    }
}

/// Reads and validates a wrinkles config; sweeps are expanded into cases named `BASE/KEY=VALUE`.
pub fn load_config(path: &Path) -> Result<WrinkleConfig, InputError> {
    let table = crate::config::read_toml_table(path)?;
    let mut cfg: WrinkleConfig = crate::config::from_table(path, "", table)?;
    let d = &cfg.defaults;
    for (key, ok, what) in [
        (
            "defaults.tolerance_rel",
            d.tolerance_rel.is_finite() && d.tolerance_rel > 0.0,
            "a finite number > 0",
        ),
        ("defaults.max_iterations", d.max_iterations > 0, "≥ 1"),
        (
            "defaults.initial_zmax_m",
            d.initial_zmax_m.is_finite() && d.initial_zmax_m >= 0.0,
            "a finite number ≥ 0",
        ),
        (
            "defaults.simpson_intervals",
            d.simpson_intervals >= 2,
            "≥ 2",
        ),
    ] {
        if !ok {
            return Err(InputError::new(path, key, format!("must be {what}")));
        }
    }
    let mut extra = Vec::new();
    for (k, s) in cfg.sweeps.iter().enumerate() {
        let Some(base) = cfg.cases.iter().find(|c| c.case == s.base) else {
            return Err(InputError::new(
                path,
                format!("sweeps.{k}.base"),
                format!("no case named `{}`", s.base),
            ));
        };
        for &v in &s.values {
            let mut c = base.clone();
            if !c.set(&s.key, v) {
                return Err(InputError::new(
                    path,
                    format!("sweeps.{k}.key"),
                    format!("`{}` is not a numeric key of a case", s.key),
                ));
            }
            c.case = format!("{}/{}={v}", s.base, s.key);
            c.seed = None;
            extra.push(c);
        }
    }
    cfg.cases.extend(extra);
    if cfg.cases.is_empty() {
        return Err(InputError::new(path, "cases", "no case given"));
    }
    for (list, cases) in [("cases", &cfg.cases), ("photographs", &cfg.photographs)] {
        for (k, c) in cases.iter().enumerate() {
            c.check(&cfg.defaults)
                .map_err(|e| InputError::new(path, format!("{list}.{k}.{}", e.key), e.message))?;
        }
    }
    Ok(cfg)
}
