//! A saved drape to start a run from (`simulate --start FILE`, Python's `start=`): its positions
//! checked against the scene, and the state its run adapted (κ growth) from its metadata, so that
//! the restart continues the run that wrote it.

use crate::StartState;
use drapelab_core::error::InputError;
use drapelab_core::physics::Adapted;
use drapelab_core::scene::ValidatedScene;
use std::path::Path;

/// Reads `file` as the start of `scene`: the same particles in particles.parquet's order with
/// finite positions, passing [`drapelab_core::build::check_start`]. Errors name `flag` and the file
/// with the column at fault.
pub fn read_start(
    file: &Path,
    scene: &ValidatedScene,
    flag: &str,
) -> Result<StartState, InputError> {
    let bad = |key: &str, m: String| InputError::new(format!("{flag} {}", file.display()), key, m);
    drapelab_core::textfile::check_regular_file(file).map_err(|m| bad("", m))?;
    let (rows, meta) =
        crate::read_particles_with_metadata(file).map_err(|e| bad("", format!("{e:#}")))?;
    let grid = &scene.grid();
    if rows.len() != grid.len() {
        let what = match scene.cloth.is_mesh() {
            true => format!("the scene's mesh has {} vertices", grid.len()),
            false => format!(
                "the scene's grid has {} ({} × {})",
                grid.len(),
                grid.nx,
                grid.ny
            ),
        };
        return Err(bad(
            "",
            format!(
                "{} particles, {what}: start from a drape of the same scene",
                rows.len()
            ),
        ));
    }
    let mut x = Vec::with_capacity(rows.len());
    for (p, (i, j, v)) in rows.into_iter().enumerate() {
        if (i as usize, j as usize) != grid.ij(p) {
            return Err(bad(
                "i",
                format!(
                    "row {p} is particle ({i}, {j}), expected {:?}: not particles.parquet's order",
                    grid.ij(p)
                ),
            ));
        }
        // A drape's coordinates are finite and within a kilometre of the origin.
        if let Some(c) = (0..3).find(|&c| !v[c].is_finite() || v[c].abs() > 1e3) {
            return Err(bad(
                ["x_m", "y_m", "z_m"][c],
                format!(
                    "row {p}: {} is not a position within a kilometre of the origin",
                    v[c]
                ),
            ));
        }
        x.push(v);
    }
    let adapted = Adapted::from_metadata(|k| meta.get(k).cloned()).map_err(|(k, m)| bad(k, m))?;
    let built = drapelab_core::build::build_scene(scene);
    drapelab_core::build::check_start(scene, &built, &x).map_err(|d| bad(d.column, d.message))?;
    Ok(StartState {
        x,
        file: file.display().to_string(),
        adapted,
    })
}
