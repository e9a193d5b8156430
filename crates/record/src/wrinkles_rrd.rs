//! `wrinkles.rrd`: each case's deformed grid (seed 002) as a static rerun mesh, Z up (the sheet's
//! height along z).

use crate::Staged;
use crate::rerun;
use anyhow::Result;
use drapelab_core::wrinkles::WrinkleMesh;
use std::path::Path;

/// Writes one mesh per case under `cases/<case>/mesh`, atomically.
pub fn write_wrinkle_meshes(out: &Path, meshes: &[(String, WrinkleMesh)]) -> Result<()> {
    let staged = Staged::new(out)?;
    let rec = rerun::RecordingStreamBuilder::new("drapelab_wrinkles").save(staged.path())?;
    rec.log_static("/", &rerun::ViewCoordinates::RIGHT_HAND_Z_UP())?;
    for (case, m) in meshes {
        let path = format!("cases/{}/mesh", case.replace(['/', '='], "_"));
        rec.log_static(
            path,
            &rerun::Mesh3D::new(
                m.points
                    .iter()
                    .map(|q| [q[0] as f32, q[2] as f32, -q[1] as f32]),
            )
            .with_triangle_indices(m.triangles()),
        )?;
    }
    rec.flush_blocking()?;
    drop(rec);
    staged.commit()?;
    Ok(())
}
