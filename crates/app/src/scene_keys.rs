//! The scene keys, listed from the schema as the bundled scenes fill it: every dotted key a
//! validated scene serializes (defaults filled in), with its type and an example value. The book's
//! Scene keys page is this listing (`tests/it/docs.rs` checks it).

use anyhow::Result;
use std::collections::BTreeMap;
use std::path::PathBuf;

/// Flattens `v` into `out` as dotted keys (`[]` for the elements of a list of tables).
fn flatten(prefix: &str, v: &serde_json::Value, out: &mut BTreeMap<String, serde_json::Value>) {
    match v {
        serde_json::Value::Object(map) => {
            for (k, x) in map {
                let key = if prefix.is_empty() {
                    k.clone()
                } else {
                    format!("{prefix}.{k}")
                };
                flatten(&key, x, out);
            }
        }
        serde_json::Value::Array(items) if items.iter().any(|i| i.is_object()) => {
            for i in items {
                flatten(&format!("{prefix}[]"), i, out);
            }
        }
        _ => {
            let slot = out
                .entry(prefix.to_string())
                .or_insert(serde_json::Value::Null);
            if slot.is_null() {
                *slot = v.clone();
            }
        }
    }
}

/// The JSON type of a value, in TOML's words.
fn type_name(v: &serde_json::Value) -> &'static str {
    match v {
        serde_json::Value::Null => "optional",
        serde_json::Value::Bool(_) => "boolean",
        serde_json::Value::Number(n) if n.is_f64() => "float",
        serde_json::Value::Number(_) => "integer",
        serde_json::Value::String(_) => "string",
        serde_json::Value::Array(_) => "array",
        serde_json::Value::Object(_) => "table",
    }
}

/// Every key of the validated scenes `files` (their defaults filled in) as a Markdown table: key,
/// type and the first non-null value met (scenes in the order given).
pub fn scene_keys_markdown(files: &[PathBuf]) -> Result<String> {
    let mut keys = BTreeMap::new();
    for f in files {
        let scene = drapelab_core::scene::Scene::load(f, &[])?;
        flatten("", &serde_json::to_value(&*scene.scene)?, &mut keys);
    }
    let mut s = String::from("| key | type | example |\n|---|---|---|\n");
    for (k, v) in &keys {
        let example = if v.is_null() {
            "–".to_string()
        } else {
            format!("`{v}`")
        };
        s += &format!("| `{k}` | {} | {example} |\n", type_name(v));
    }
    Ok(s)
}
