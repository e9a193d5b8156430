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

/// Removes temporary files left in `dir` by a killed run (`.NAME.*.partial`).
pub fn remove_partials(dir: &Path) {
    if let Ok(entries) = std::fs::read_dir(dir) {
        for e in entries.flatten() {
            let name = e.file_name().to_string_lossy().to_string();
            if name.starts_with('.') && name.ends_with(".partial") {
                std::fs::remove_file(e.path()).ok();
            }
        }
    }
}
