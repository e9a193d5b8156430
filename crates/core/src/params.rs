//! A scene's continuous parameters as data: every real-valued key of a scene (the material's
//! stiffnesses, the areal density, gravity, contact distances, obstacle sizes, loads, the sheet's
//! size) named by its dotted path as the scene file writes it (`material.mass_spring.stiffness_N_per_m`,
//! `obstacles.0.radius_m`), read and changed in the scene's own units, the changed scene checked
//! again. The sensitivities ([`crate::sensitivity`]) differentiate the equilibrium in these.

use crate::error::InputError;
use crate::physics::Model;
use crate::scene::{Scene, ValidatedScene};
use nalgebra::Vector3;

/// A model built over named continuous parameters (parameters as data): a grid scene's keys
/// ([`continuous_keys`]; `crate::sensitivity::SceneParameters`), a Cusick specimen's
/// (`crate::cusick::SpecimenParameters`). The sensitivities differentiate an equilibrium through
/// this alone.
pub trait Parameterized {
    /// Every continuous parameter's key.
    fn keys(&self) -> Vec<String>;
    /// The value of `key`, in the unit its source writes it; an error names the key.
    fn value(&self, key: &str) -> Result<f64, InputError>;
    /// The model with `key` set to `v`, and its start positions (the fixed particles where the
    /// changed parameters put them); an error (naming the key) where `v` is out of its range.
    fn model_with(&self, key: &str, v: f64) -> Result<(Model, Vec<Vector3<f64>>), InputError>;
    /// The model at the parameters as they are.
    fn model(&self) -> (Model, Vec<Vector3<f64>>);
}

/// Top-level sections whose numbers steer the solver or the recording, not the physics: they are
/// not parameters of the equilibrium.
const NOT_PHYSICS: [&str; 4] = ["solver", "record", "name", "description"];

/// Keys that lay out the mesh (where the grid lines fall), not the fabric: changing one relabels
/// material points, so a particle's derivative in it means nothing physical. A mesh obstacle's
/// file unit (`obstacles.N.mesh_unit_m`) is read as one too: the body moves by `offset_m`.
const MESH_LAYOUT: [&str; 3] = ["cloth.grading", "cloth.refine_x_m", "cloth.refine_y_m"];

/// Whether `key` is (or lies under) a mesh-layout key.
fn is_mesh_layout(key: &str) -> bool {
    let body_unit = key.starts_with("obstacles.") && key.ends_with(".mesh_unit_m");
    body_unit
        || MESH_LAYOUT
            .iter()
            .any(|m| key == *m || key.starts_with(&format!("{m}.")))
}

/// Every continuous parameter of `scene`: the dotted keys of its real-valued entries (integers,
/// booleans and strings are not continuous), solver and recording options left out. In the
/// scene's serialization order.
pub fn continuous_keys(scene: &Scene) -> Vec<String> {
    let Ok(toml::Value::Table(t)) = toml::Value::try_from(scene) else {
        return Vec::new();
    };
    let mut keys = Vec::new();
    for (k, v) in &t {
        if !NOT_PHYSICS.contains(&k.as_str()) {
            collect_floats(k, v, &mut keys);
        }
    }
    keys
}

/// The continuous keys of a validated scene that it lets move from their value: [`continuous_keys`]
/// less those its checks refuse to change (a flat pattern's `cloth.initial_perturbation_m` on a
/// garment placed in 3D, which must stay 0). Each key is nudged by 10⁻⁹ of its value (10⁻⁹ where
/// it is 0) and the changed scene validated.
pub fn free_keys(scene: &ValidatedScene) -> Vec<String> {
    continuous_keys(scene)
        .into_iter()
        .filter(|k| {
            value(scene, k, "").is_ok_and(|v| {
                let nudged = if v == 0.0 { 1e-9 } else { v * (1.0 + 1e-9) };
                with_value(scene, k, nudged, "").is_ok()
            })
        })
        .collect()
}

fn collect_floats(prefix: &str, v: &toml::Value, out: &mut Vec<String>) {
    match v {
        toml::Value::Float(_) if !is_mesh_layout(prefix) => out.push(prefix.to_string()),
        toml::Value::Table(t) => {
            for (k, v) in t {
                collect_floats(&format!("{prefix}.{k}"), v, out);
            }
        }
        toml::Value::Array(a) => {
            for (i, v) in a.iter().enumerate() {
                collect_floats(&format!("{prefix}.{i}"), v, out);
            }
        }
        _ => {}
    }
}

/// The scene as a TOML table (its serialization).
fn as_table(scene: &Scene, path: &str) -> Result<toml::Table, InputError> {
    match toml::Value::try_from(scene) {
        Ok(toml::Value::Table(t)) => Ok(t),
        _ => Err(InputError::new(
            path,
            "",
            "the scene cannot be written as a table",
        )),
    }
}

/// The value of the continuous parameter `key` of `scene`. The error names `source` (the scene
/// file or the flag that asked) and the key: a key the scene does not have, or one that is not a
/// real number (an integer such as `cloth.nx` is not continuous).
pub fn value(scene: &Scene, key: &str, source: &str) -> Result<f64, InputError> {
    let t = as_table(scene, source)?;
    let mut v = &toml::Value::Table(t);
    for part in key.split('.') {
        v = match v {
            toml::Value::Table(t) => t.get(part),
            toml::Value::Array(a) => part.parse::<usize>().ok().and_then(|i| a.get(i)),
            _ => None,
        }
        .ok_or_else(|| {
            InputError::new(
                source,
                key,
                format!(
                    "the scene has no such key (its continuous parameters: {})",
                    continuous_keys(scene).join(", ")
                ),
            )
        })?;
    }
    match v {
        toml::Value::Float(_) if is_mesh_layout(key) => Err(InputError::new(
            source,
            key,
            "lays out a mesh (where grid lines fall, or a mesh file's unit), not the fabric: no physical derivative",
        )),
        toml::Value::Float(f) if NOT_PHYSICS.iter().all(|s| !key.starts_with(s)) => Ok(*f),
        toml::Value::Float(_) => Err(InputError::new(
            source,
            key,
            "a solver or recording option is not a parameter of the equilibrium",
        )),
        other => Err(InputError::new(
            source,
            key,
            format!(
                "not a continuous parameter (its TOML type is {}); give a real-valued key",
                other.type_str()
            ),
        )),
    }
}

/// `scene` with the continuous parameter `key` set to `v`, checked again (an out-of-range value is
/// an error naming the key).
pub fn with_value(
    scene: &Scene,
    key: &str,
    v: f64,
    source: &str,
) -> Result<ValidatedScene, InputError> {
    value(scene, key, source)?;
    let mut t = as_table(scene, source)?;
    crate::config::set_dotted(&mut t, key, toml::Value::Float(v))
        .map_err(|m| InputError::new(source, key, m))?;
    let mut changed: Scene = crate::config::from_table(std::path::Path::new(source), "", t)?;
    changed.cloth.carry_pattern(&scene.cloth);
    crate::scene::carry_bodies(&mut changed.obstacles, &scene.obstacles);
    changed.validate(std::path::Path::new(source))?;
    changed
        .validated()
        .map_err(|e| InputError::new(source, key, e.message))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hang4() -> Scene {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../datasets/scenes/hang4.toml");
        Scene::load(&path, &[]).unwrap().scene.into_inner()
    }

    #[test]
    fn the_continuous_keys_are_the_real_numbers_of_the_physics() {
        let s = hang4();
        let keys = continuous_keys(&s);
        for k in [
            "material.mass_spring.stiffness_N_per_m",
            "cloth.areal_density_kg_per_m2",
            "gravity.g_m_per_s2",
            "cloth.size_x_m",
        ] {
            assert!(keys.iter().any(|x| x == k), "{k} missing from {keys:?}");
        }
        assert!(keys.iter().all(|k| !k.starts_with("solver.")));
        assert!(!keys.iter().any(|k| k == "cloth.nx"));
        for k in &keys {
            assert!(value(&s, k, "test").is_ok(), "{k}");
        }
    }

    #[test]
    fn a_value_is_read_and_set_in_the_files_units_and_checked() {
        let s = hang4();
        let k = "material.mass_spring.stiffness_N_per_m";
        assert_eq!(value(&s, k, "t").unwrap(), 1000.0);
        let c = with_value(&s, k, 1234.5, "t").unwrap();
        assert_eq!(value(&c, k, "t").unwrap(), 1234.5);
        assert_eq!(c.cloth, s.cloth);
        let e = with_value(&s, k, -1.0, "--sensitivity").unwrap_err();
        assert_eq!(e.key, k);
        let e = value(&s, "cloth.nx", "--sensitivity").unwrap_err();
        assert!(e.message.contains("not a continuous"), "{e}");
        let e = value(&s, "material.nope", "--sensitivity").unwrap_err();
        assert!(e.message.contains("no such key"), "{e}");
        assert!(value(&s, "solver.static.residual_tol_rel", "f").is_err());
    }
}
