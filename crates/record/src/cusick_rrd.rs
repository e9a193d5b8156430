//! `drapes.rrd` of the Cusick stages: per fabric, the registered meshes of its specimens and the
//! simulated drapes overlaid (each on its own entity, so either can be hidden), the fabrics laid out
//! on a grid 0.4 m apart, Z up.

use crate::Staged;
use crate::rerun;
use anyhow::Result;
use nalgebra::Vector3;
use std::path::Path;

/// A mesh to log: its entity name under the fabric, vertices (m, pedestal top centre at the
/// origin) and triangles.
pub struct NamedMesh<'a> {
    /// Entity name, e.g. `measured/s2_c1` or `simulated/seed_0`.
    pub name: String,
    /// Vertices, m.
    pub vertices: &'a [Vector3<f64>],
    /// Triangles.
    pub triangles: &'a [[usize; 3]],
}

/// Spacing of the fabrics' grid in the recording, m.
pub const FABRIC_SPACING_M: f64 = 0.4;

/// Writes every fabric's meshes under `fabric_<nn>/…`, fabric k placed at column (k − 1) mod 5 and
/// row (k − 1) / 5 of a grid [`FABRIC_SPACING_M`] apart; the pedestal as a point ring. Atomic.
pub fn write_cusick_drapes(
    out: &Path,
    pedestal_radius_m: f64,
    fabrics: &[(i32, Vec<NamedMesh<'_>>)],
) -> Result<()> {
    let staged = Staged::new(out)?;
    let rec = rerun::RecordingStreamBuilder::new("drapelab_cusick").save(staged.path())?;
    rec.log_static("/", &rerun::ViewCoordinates::RIGHT_HAND_Z_UP())?;
    for (fabric, meshes) in fabrics {
        let k = (fabric - 1).max(0) as f64;
        let off = Vector3::new(
            FABRIC_SPACING_M * (k % 5.0),
            -FABRIC_SPACING_M * (k / 5.0).floor(),
            0.0,
        );
        let base = format!("fabric_{fabric:02}");
        let ring = (0..90).map(|i| {
            let t = i as f64 / 90.0 * std::f64::consts::TAU;
            let p = off + pedestal_radius_m * Vector3::new(t.cos(), t.sin(), 0.0);
            [p.x as f32, p.y as f32, p.z as f32]
        });
        rec.log_static(
            format!("{base}/pedestal"),
            &rerun::Points3D::new(ring).with_radii([0.002f32]),
        )?;
        for m in meshes {
            let v = m.vertices.iter().map(|p| {
                let q = p + off;
                [q.x as f32, q.y as f32, q.z as f32]
            });
            let tris = m.triangles.iter().map(|t| t.map(|i| i as u32));
            rec.log_static(
                format!("{base}/{}", m.name),
                &rerun::Mesh3D::new(v).with_triangle_indices(tris),
            )?;
        }
    }
    rec.flush_blocking()?;
    drop(rec);
    staged.commit()?;
    Ok(())
}
