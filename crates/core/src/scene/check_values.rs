//! The checks of values as a file gives them, shared by scenes and fabric files: every number
//! finite and of a size drapelab computes in, and a material model's own values under the keys
//! its table gives (`material.…` in a scene, `fabric.…` in a fabric file).

use crate::error::InputError;
use std::path::Path;

/// The sizes drapelab computes in: every physical number of a scene is zero or between these in
/// size, in SI units (10⁻¹² to 10¹²): beyond them sums of forces and energies lose their digits or
/// overflow, and a solve would end in NaN as if the physics had failed.
pub const MAGNITUDES: (f64, f64) = (1e-12, 1e12);

/// The range checks of [`Scene::validate`], naming the file and the key.
pub(super) struct Check<'a> {
    pub(super) path: &'a Path,
}

impl Check<'_> {
    pub(super) fn err(&self, key: &str, message: String) -> Result<(), InputError> {
        Err(InputError::new(self.path, key, message))
    }
    pub(super) fn pos(&self, key: &str, v: f64) -> Result<(), InputError> {
        if !v.is_finite() || v <= 0.0 {
            return self.err(key, format!("must be a finite number > 0, got {v}"));
        }
        Ok(())
    }
    pub(super) fn nonneg(&self, key: &str, v: f64) -> Result<(), InputError> {
        if !v.is_finite() || v < 0.0 {
            return self.err(key, format!("must be a finite number ≥ 0, got {v}"));
        }
        Ok(())
    }
    /// `v` within the physical bounds `(lo, hi)` of the key (in its unit).
    pub(super) fn within(&self, key: &str, v: f64, (lo, hi): (f64, f64)) -> Result<(), InputError> {
        if !(v.is_finite() && (lo..=hi).contains(&v)) {
            return self.err(key, format!("must be in {lo} to {hi}, got {v}"));
        }
        Ok(())
    }
}

/// A material model's own values, each under the key its table gives (`PREFIX.continuum.KEY`,
/// `PREFIX.mass_spring.KEY`): exactly one model; stiffnesses, rigidities and the thickness > 0;
/// shear, twist and damping ≥ 0. A scene's prefix is `material`, a fabric file's `fabric`.
pub(super) fn check_material_model(
    m: &crate::material::Material,
    ck: &Check<'_>,
    prefix: &str,
) -> Result<(), InputError> {
    match (&m.mass_spring, &m.continuum) {
        (Some(_), Some(_)) => ck.err(
            prefix,
            format!("give either [{prefix}.mass_spring] or [{prefix}.continuum], not both"),
        ),
        (None, None) => ck.err(
            prefix,
            format!("missing: add [{prefix}.mass_spring] or [{prefix}.continuum]"),
        ),
        (Some(ms), None) => {
            let key = |k: &str| format!("{prefix}.mass_spring.{k}");
            ck.pos(&key("stiffness_N_per_m"), ms.stiffness_N_per_m)?;
            for (k, v) in [
                (
                    "structural_stiffness_N_per_m",
                    ms.structural_stiffness_N_per_m,
                ),
                ("shear_stiffness_N_per_m", ms.shear_stiffness_N_per_m),
                ("bend_stiffness_N_per_m", ms.bend_stiffness_N_per_m),
                ("natural_length_m", ms.natural_length_m),
            ] {
                if let Some(v) = v {
                    ck.pos(&key(k), v)?;
                }
            }
            ck.nonneg(&key("damping_Ns_per_m"), ms.damping_Ns_per_m)?;
            ck.pos(&key("elongation_rate"), ms.elongation_rate)
        }
        (None, Some(cont)) => check_continuum(cont, ck, &format!("{prefix}.continuum")),
    }
}

/// The continuum's keys as given (never a converted value under an invented name): every key of
/// both units present or missing as [`crate::material::Continuum::rigidities`] says, tensile and
/// bending rigidities and the thickness > 0, shear and twist ≥ 0.
fn check_continuum(
    cont: &crate::material::Continuum,
    ck: &Check<'_>,
    prefix: &str,
) -> Result<(), InputError> {
    cont.rigidities()
        .map_err(|e| InputError::new(ck.path, format!("{prefix}.{}", e.key), e.message))?;
    let Ok(toml::Value::Table(t)) = toml::Value::try_from(cont) else {
        return Ok(());
    };
    for (k, v) in &t {
        let Some(v) = v.as_float().or_else(|| v.as_integer().map(|i| i as f64)) else {
            continue;
        };
        let key = format!("{prefix}.{k}");
        if k.starts_with("shear") || k.starts_with("bending_twist") {
            ck.nonneg(&key, v)?;
        } else if k.starts_with("tensile")
            || k.starts_with("bending_warp")
            || k.starts_with("bending_weft")
            || k == "thickness_m"
        {
            ck.pos(&key, v)?;
        }
    }
    Ok(())
}

/// Every number under `v` (named by `key`, spelled only for an error: a scene is checked once
/// per solve, and a calibration solves tens of thousands) finite and zero or within [`MAGNITUDES`].
pub(super) fn magnitudes(
    ck: &Check<'_>,
    key: &dyn Fn() -> String,
    v: &toml::Value,
) -> Result<(), InputError> {
    match v {
        toml::Value::Float(f) if !f.is_finite() => {
            ck.err(&key(), format!("must be a finite number, got {f}"))
        }
        toml::Value::Float(f) if *f != 0.0 && !(MAGNITUDES.0..=MAGNITUDES.1).contains(&f.abs()) => {
            ck.err(
                &key(),
                format!(
                    "{f} is outside the sizes drapelab computes in: zero, or {:e} to {:e} \
in the key's unit (SI)",
                    MAGNITUDES.0, MAGNITUDES.1
                ),
            )
        }
        toml::Value::Table(t) => t
            .iter()
            .try_for_each(|(k, v)| magnitudes(ck, &|| format!("{}.{k}", key()), v)),
        // A list of tables names its entry as the other checks do (`loads[0].magnitude_N`);
        // a list of numbers (a point, a profile) is named as a whole.
        toml::Value::Array(a) => a.iter().enumerate().try_for_each(|(i, v)| match v {
            toml::Value::Table(_) => magnitudes(ck, &|| format!("{}.{i}", key()), v),
            _ => magnitudes(ck, key, v),
        }),
        _ => Ok(()),
    }
}
