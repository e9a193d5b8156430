//! Values across the boundary: JSON text to TOML values (dict scenes and overrides), byte buffers
//! to and from numbers, a scene loaded with its errors naming the Python argument.

use crate::InputError;
use drapelab_core::scene::{LoadedScene, Scene};
use pyo3::PyResult;
use std::path::Path;

/// `v` as JSON text.
pub fn json<T: serde::Serialize>(v: &T) -> PyResult<String> {
    serde_json::to_string(v).map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string()))
}

/// A JSON value as a TOML value; `what` names it in the error (TOML has no null).
pub fn json_to_toml(v: serde_json::Value, what: &str) -> Result<toml::Value, String> {
    toml::Value::try_from(v)
        .map_err(|e| format!("{what}: not a TOML value ({e}); None has no TOML form"))
}

/// Little-endian bytes of `v`.
pub fn f64_bytes(v: &[f64]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

/// Little-endian bytes of `v`.
pub fn u32_bytes(v: &[u32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

/// Values of `N` little-endian bytes each, decoded by `from`; `what` names the argument.
fn from_le<const N: usize, T>(b: &[u8], what: &str, from: fn([u8; N]) -> T) -> PyResult<Vec<T>> {
    if !b.len().is_multiple_of(N) {
        return Err(InputError::new_err(format!(
            "{what}: not a whole number of {N}-byte values"
        )));
    }
    Ok(b.chunks(N)
        .map(|c| from(c.try_into().expect("N bytes")))
        .collect())
}

/// f64 values from little-endian bytes.
pub fn bytes_f64(b: &[u8]) -> PyResult<Vec<f64>> {
    from_le(b, "positions", f64::from_le_bytes)
}

/// u32 values from little-endian bytes.
pub fn bytes_to_u32(b: &[u8]) -> PyResult<Vec<u32>> {
    from_le(b, "triangles", u32::from_le_bytes)
}

/// The overrides of `set` (a JSON object of dotted keys), in its order.
fn overrides(set_json: &str) -> PyResult<Vec<(String, toml::Value)>> {
    let set: serde_json::Map<String, serde_json::Value> =
        serde_json::from_str(set_json).map_err(|e| InputError::new_err(format!("set: {e}")))?;
    set.into_iter()
        .map(|(k, v)| {
            let t = json_to_toml(v, &format!("set[{k:?}]")).map_err(InputError::new_err)?;
            Ok((k, t))
        })
        .collect()
}

/// A scene from its file or its table (JSON text) with the overrides of `set`; an error an override
/// causes names `set["KEY"]`, one of the table names `scene (dict)`.
pub fn load_scene(
    path: Option<&str>,
    table_json: Option<&str>,
    set_json: &str,
) -> PyResult<LoadedScene> {
    let overrides = overrides(set_json)?;
    let loaded = match (path, table_json) {
        (Some(p), None) => Scene::load(Path::new(p), &overrides),
        (None, Some(t)) => {
            let v: serde_json::Value =
                serde_json::from_str(t).map_err(|e| InputError::new_err(format!("scene: {e}")))?;
            let table = match json_to_toml(v, "scene").map_err(InputError::new_err)? {
                toml::Value::Table(t) => t,
                _ => return Err(InputError::new_err("scene: a dict of the scene's keys")),
            };
            Scene::load_table(Path::new("scene (dict)"), table, &overrides)
        }
        _ => {
            return Err(InputError::new_err(
                "scene: give a TOML file's path or a dict",
            ));
        }
    };
    let scene_file = Path::new(path.unwrap_or("scene (dict)"));
    loaded.map_err(|e| {
        let culprit = drapelab_core::config::override_culprit(&e.key, &overrides);
        // An error in another file (a fabric, a mesh) names that file.
        let msg = match culprit.filter(|_| e.file == scene_file) {
            Some(i) => format!(
                "set[{:?}] (over {}): key `{}`: {}",
                overrides[i].0,
                e.file.display(),
                e.key,
                e.message
            ),
            None => e.to_string(),
        };
        InputError::new_err(msg)
    })
}
