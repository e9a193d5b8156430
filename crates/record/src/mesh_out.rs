//! The drape as a mesh: `triangles.parquet` (the sheet's triangles as row indices into
//! `particles.parquet`) and, when asked, `drape.obj` (Wavefront OBJ, metres) for any mesh tool.

use crate::table::{Table, read_table, write_table};
use anyhow::Result;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// One triangle of the sheet.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct TriangleRow {
    /// First corner: a row index (from 0) into particles.parquet.
    pub a: i32,
    /// Second corner, counter-clockwise seen from +z on the flat sheet.
    pub b: i32,
    /// Third corner.
    pub c: i32,
}

impl Table for TriangleRow {
    const FILE: &'static str = "triangles.parquet";
    const ROW: &'static str = "One triangle of the sheet: three row indices (from 0) into particles.parquet (and last_state.parquet), over present particles only; two per grid cell.";
}

/// Writes the triangles `tris` (particle indices, which are particles.parquet's rows).
pub fn write_triangles(path: &Path, tris: &[[u32; 3]]) -> Result<()> {
    let rows: Vec<TriangleRow> = tris
        .iter()
        .map(|t| TriangleRow {
            a: t[0] as i32,
            b: t[1] as i32,
            c: t[2] as i32,
        })
        .collect();
    write_table(path, &rows)
}

/// Reads triangles.parquet back.
pub fn read_triangles(path: &Path) -> Result<Vec<TriangleRow>> {
    read_table::<TriangleRow>(path)
}

/// The drape `x` (m) as Wavefront OBJ text: every particle a vertex in particles.parquet's order
/// (so a face's indices are its rows plus one), then the triangles.
pub fn obj_text(name: &str, x: &[Vector3<f64>], tris: &[[u32; 3]]) -> String {
    use std::fmt::Write;
    let mut s = format!(
        "# drapelab {} drape: {name} (metres)\no {name}\n",
        drapelab_core::VERSION
    );
    for p in x {
        let _ = writeln!(s, "v {} {} {}", p.x, p.y, p.z);
    }
    for t in tris {
        let _ = writeln!(s, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    s
}

/// A sewn garment's bodies as one OBJ in the particles' frame (each mesh body moved by its
/// offset), to show the garment on what holds it.
pub(crate) fn write_body_obj(
    scene: &drapelab_core::scene::Scene,
    path: &std::path::Path,
) -> anyhow::Result<()> {
    let (mut x, mut tris) = (Vec::new(), Vec::new());
    for o in &scene.obstacles {
        if let drapelab_core::obstacle::Obstacle::Mesh {
            offset_m,
            body: Some(b),
            ..
        } = o
        {
            let base = x.len() as u32;
            let off = nalgebra::Vector3::from(*offset_m);
            x.extend(b.vertices().iter().map(|v| v + off));
            tris.extend(b.triangles().iter().map(|t| t.map(|k| k + base)));
        }
    }
    let text = crate::obj_text("body", &x, &tris);
    drapelab_core::atomic::write_text(path, &text)?;
    Ok(())
}
