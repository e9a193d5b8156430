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
