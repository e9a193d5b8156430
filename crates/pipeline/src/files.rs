//! Small file helpers of the engine: paths relative to the project root and the temporary files a
//! killed run leaves.

use std::path::Path;

/// `p` relative to `root`, with forward slashes.
pub fn rel(root: &Path, p: &Path) -> String {
    p.strip_prefix(root)
        .unwrap_or(p)
        .to_string_lossy()
        .replace('\\', "/")
}

/// Removes temporary files and staging folders left in `dir` by a killed run (`.NAME.*.partial`;
/// the pipeline's lock keeps any other run of the plan out of `dir` meanwhile).
pub fn remove_partials(dir: &Path) {
    if let Ok(entries) = std::fs::read_dir(dir) {
        for e in entries.flatten() {
            let name = e.file_name().to_string_lossy().to_string();
            if name.starts_with('.') && name.ends_with(".partial") {
                match e.file_type().is_ok_and(|t| t.is_dir()) {
                    true => std::fs::remove_dir_all(e.path()).ok(),
                    false => std::fs::remove_file(e.path()).ok(),
                };
            }
        }
    }
}
