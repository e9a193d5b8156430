//! TOML input shared by scenes, wrinkle configs and pipelines: reading a file with the line of a
//! syntax error, deserializing with the dotted key of the first bad value, and `--set KEY=VALUE`
//! overrides by dotted path.

use crate::error::InputError;
use std::path::Path;

/// Parses `KEY=VALUE`; VALUE is read as TOML (number, bool, array, quoted string), else as a bare string.
pub fn parse_override(s: &str) -> Result<(String, toml::Value), InputError> {
    let Some((k, v)) = s.split_once('=') else {
        return Err(InputError::new(
            "--set",
            s,
            "expected KEY=VALUE, e.g. --set cloth.nx=41",
        ));
    };
    let k = k.trim().to_string();
    let v = v.trim();
    let value = match toml::from_str::<toml::Table>(&format!("v = {v}")) {
        Ok(mut t) => t
            .remove("v")
            .unwrap_or_else(|| toml::Value::String(v.into())),
        Err(_) => toml::Value::String(v.into()),
    };
    Ok((k, value))
}

/// Sets `key` (dotted path) in `table`, creating tables on the way.
/// Which of `overrides` (dotted key, value) caused an error at `key`: the override of that key, of
/// a table above it, or of a key inside it.
pub fn override_culprit(key: &str, overrides: &[(String, toml::Value)]) -> Option<usize> {
    overrides.iter().position(|(k, _)| {
        key == k || key.starts_with(&format!("{k}.")) || k.starts_with(&format!("{key}."))
    })
}

/// Sets `key` (dotted) in `table`.
pub fn set_dotted(table: &mut toml::Table, key: &str, value: toml::Value) -> Result<(), String> {
    let parts: Vec<&str> = key.split('.').collect();
    let (last, path) = parts.split_last().ok_or("empty key")?;
    let mut root = toml::Value::Table(std::mem::take(table));
    let result = (|| {
        let mut v = &mut root;
        for part in path {
            v = child(v, part)?;
        }
        match v {
            toml::Value::Table(t) => {
                t.insert(last.to_string(), value);
                Ok(())
            }
            other => {
                *child(other, last)? = value;
                Ok(())
            }
        }
    })();
    if let toml::Value::Table(t) = root {
        *table = t;
    }
    result
}

/// The entry `part` of a table (created as a table when missing) or the element of an array at the
/// index `part` (`loads.0.magnitude_N`).
fn child<'a>(v: &'a mut toml::Value, part: &str) -> Result<&'a mut toml::Value, String> {
    match v {
        toml::Value::Table(t) => Ok(t
            .entry(part.to_string())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()))),
        toml::Value::Array(a) => {
            let n = a.len();
            let i: usize = part
                .parse()
                .map_err(|_| format!("`{part}` is not an index of an array"))?;
            a.get_mut(i)
                .ok_or_else(|| format!("index {i} is beyond the array's {n} entries"))
        }
        _ => Err(format!(
            "`{part}`: its parent is neither a table nor an array"
        )),
    }
}

/// Reads a TOML file into a table, with the file named in errors.
pub fn read_toml_table(path: &Path) -> Result<toml::Table, InputError> {
    let text = crate::textfile::read_text(path, crate::textfile::NonUtf8::Refuse)
        .map_err(|e| InputError::new(path, "", e))?;
    text.parse::<toml::Table>().map_err(|e| {
        let msg = e.message().to_string();
        let line = e.span().map(|s| text[..s.start].lines().count().max(1));
        let at = line.map(|l| format!(" (line {l})")).unwrap_or_default();
        InputError::new(path, "", format!("malformed TOML{at}: {msg}"))
    })
}

/// A key path as `--set` takes it: a list's entry as `.N`, not `[N]` (`loads[0].magnitude_N` →
/// `loads.0.magnitude_N`), so that errors and flags spell every key alike.
pub fn dotted(key: &str) -> String {
    let mut out = String::with_capacity(key.len());
    for c in key.chars() {
        match c {
            '[' => out.push('.'),
            ']' => {}
            c => out.push(c),
        }
    }
    out
}

/// Deserializes a table into `T`, naming the dotted key of the first error.
pub fn from_table<T: serde::de::DeserializeOwned>(
    path: &Path,
    prefix: &str,
    table: toml::Table,
) -> Result<T, InputError> {
    serde_path_to_error::deserialize(toml::Value::Table(table)).map_err(|e| {
        let key = dotted(&e.path().to_string());
        let key = if key == "." {
            prefix.trim_end_matches('.').to_string()
        } else {
            format!("{prefix}{key}")
        };
        let inner = e.into_inner().to_string();
        InputError::new(
            path,
            key,
            inner.lines().next().unwrap_or("invalid value").to_string(),
        )
    })
}
