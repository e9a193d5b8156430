//! The files a scene names (`cloth.mesh`, `obstacles.N.mesh`, `material.fabric`), found from the
//! scene file's folder: one resolver for every reader of the scene, imported by them and importing
//! none of them.

use crate::error::InputError;
use std::path::Path;

/// The file a scene names under `key` (`cloth.mesh`, `obstacles.N.mesh`, `material.fabric`): read
/// from the scene file's folder when relative. An error naming the scene file and the key when it
/// is not a file.
pub(super) fn named_file(
    scene_path: &Path,
    file: &Path,
    key: &str,
) -> Result<std::path::PathBuf, InputError> {
    let path = match scene_path.parent() {
        Some(dir) if file.is_relative() => dir.join(file),
        _ => file.to_path_buf(),
    };
    if !path.is_file() {
        let m = format!(
            "{} is not a file (a relative path is read from the scene file's folder)",
            path.display()
        );
        return Err(InputError::new(scene_path, key, m));
    }
    Ok(path)
}

/// Rewrites the files a scene's table names (`cloth.mesh`, `obstacles.N.mesh`,
/// `material.fabric`) as absolute paths from the folder of `scene_path`: the table then means the
/// same scene wherever it is used (a notebook's dict handed back to `simulate`).
pub fn absolute_file_keys(table: &mut toml::Table, scene_path: &Path) {
    let dir = scene_path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let dir = std::fs::canonicalize(dir).unwrap_or_else(|_| dir.to_path_buf());
    let absolute = |v: &mut toml::Value| {
        if let Some(s) = v.as_str()
            && Path::new(s).is_relative()
        {
            *v = toml::Value::String(dir.join(s).display().to_string());
        }
    };
    for (section, key) in [
        ("cloth", "mesh"),
        ("cloth", "pattern"),
        ("material", "fabric"),
    ] {
        if let Some(v) = table
            .get_mut(section)
            .and_then(|t| t.as_table_mut())
            .and_then(|t| t.get_mut(key))
        {
            absolute(v);
        }
    }
    if let Some(list) = table.get_mut("obstacles").and_then(|o| o.as_array_mut()) {
        for v in list.iter_mut().filter_map(|o| o.get_mut("mesh")) {
            absolute(v);
        }
    }
}
