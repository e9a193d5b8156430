//! A Cusick specimen's continuous parameters as data: the keys of [`DrapeParams`] its physics is
//! built over (the bending length, its anisotropy and saturation, the areal density, the tensile
//! rigidity, gravity, the warp's direction, the self-contact thickness), read and set by name and
//! the model rebuilt by [`drape_model`], so that the sensitivities of a drape
//! ([`crate::sensitivity::Equilibrium::of`]) take them as they take a grid scene's keys. The start
//! (cone, perturbation, fall) is not physics and not a parameter.

use super::Tester;
use super::drape::{DiscMesh, DrapeParams, drape_model, drape_start};
use crate::error::InputError;
use crate::params::Parameterized;
use crate::physics::Model;
use nalgebra::Vector3;

/// The continuous keys of a specimen, as [`DrapeParams`] writes them.
pub const SPECIMEN_KEYS: [&str; 9] = [
    "bending_length_m",
    "areal_density_kg_per_m2",
    "tensile_N_per_m",
    "gravity_m_per_s2",
    "bending_ratio",
    "bending_saturation",
    "warp_angle_deg",
    "curl_per_m",
    "self_thickness_m",
];

/// A specimen of `mesh` on `tester` with the parameters `params` of the model that was solved (a
/// drape solved without self-contact, as [`super::solve_drape`] does when the folds stay apart, has
/// `self_thickness_m` none).
pub struct SpecimenParameters<'a> {
    /// The specimen's mesh.
    pub mesh: DiscMesh<'a>,
    /// Its parameters.
    pub params: DrapeParams,
    /// The tester.
    pub tester: &'a Tester,
}

impl SpecimenParameters<'_> {
    /// The slot of `key`, if the specimen has it (an optional key that is none has no value).
    fn slot<'p>(p: &'p mut DrapeParams, key: &str) -> Option<&'p mut f64> {
        match key {
            "bending_length_m" => Some(&mut p.bending_length_m),
            "areal_density_kg_per_m2" => Some(&mut p.areal_density_kg_per_m2),
            "tensile_N_per_m" => Some(&mut p.tensile_N_per_m),
            "gravity_m_per_s2" => Some(&mut p.gravity_m_per_s2),
            "bending_ratio" => Some(&mut p.bending_ratio),
            "bending_saturation" => p.bending_saturation.as_mut(),
            "warp_angle_deg" => Some(&mut p.warp_angle_deg),
            "curl_per_m" => p.curl_per_m.as_mut(),
            "self_thickness_m" => p.self_thickness_m.as_mut(),
            _ => None,
        }
    }
    fn unknown(&self, key: &str) -> InputError {
        InputError::new(
            "drape",
            key,
            format!(
                "the specimen has no such continuous parameter (its keys: {})",
                self.keys().join(", ")
            ),
        )
    }
}

impl Parameterized for SpecimenParameters<'_> {
    fn keys(&self) -> Vec<String> {
        let mut p = self.params.clone();
        SPECIMEN_KEYS
            .iter()
            .filter(|k| Self::slot(&mut p, k).is_some())
            .map(|k| k.to_string())
            .collect()
    }
    fn value(&self, key: &str) -> Result<f64, InputError> {
        let mut p = self.params.clone();
        Self::slot(&mut p, key)
            .map(|v| *v)
            .ok_or_else(|| self.unknown(key))
    }
    fn model_with(&self, key: &str, v: f64) -> Result<(Model, Vec<Vector3<f64>>), InputError> {
        let mut p = self.params.clone();
        let slot = Self::slot(&mut p, key).ok_or_else(|| self.unknown(key))?;
        // Every key but the warp's direction and the curl (signed: its side) is a positive quantity.
        let signed = matches!(key, "warp_angle_deg" | "curl_per_m");
        if !v.is_finite() || (!signed && v <= 0.0) {
            return Err(InputError::new(
                "drape",
                key,
                format!("must be a finite number > 0, got {v}"),
            ));
        }
        *slot = v;
        Ok((
            drape_model(self.mesh, &p, self.tester),
            drape_start(self.mesh, &p, self.tester),
        ))
    }
    fn model(&self) -> (Model, Vec<Vector3<f64>>) {
        (
            drape_model(self.mesh, &self.params, self.tester),
            drape_start(self.mesh, &self.params, self.tester),
        )
    }
}
