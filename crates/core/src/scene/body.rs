//! Mesh obstacles read with the scene (`[[obstacles]] kind = "mesh"`, issue 77): each OBJ file,
//! relative to the scene file's folder, read into its [`TriangleBody`]; a defect is an error naming
//! the mesh file and its line (or the scene file and the key, for a file that is not there).

use crate::error::InputError;
use crate::obstacle::{BodyDefect, Obstacle, TriangleBody};
use nalgebra::Vector3;
use std::path::Path;
use std::sync::Arc;

/// Reads every mesh obstacle's file into its body (`scene_path` names the scene in errors and
/// gives the folder relative paths are read from).
pub(super) fn read_bodies(obstacles: &mut [Obstacle], scene_path: &Path) -> Result<(), InputError> {
    for (k, o) in obstacles.iter_mut().enumerate() {
        if let Obstacle::Mesh {
            mesh,
            mesh_unit_m,
            body,
            ..
        } = o
        {
            let key = |name: &str| format!("obstacles.{k}.{name}");
            if let Some(m) = super::mesh::mesh_unit_error(*mesh_unit_m) {
                return Err(InputError::new(scene_path, key("mesh_unit_m"), m));
            }
            let path = super::files::named_file(scene_path, mesh, &key("mesh"))?;
            *body = Some(Arc::new(read_body(&path, *mesh_unit_m)?));
        }
    }
    Ok(())
}

/// A body mesh from the OBJ file at `path` in units of `unit_m` metres.
pub fn read_body(path: &Path, unit_m: f64) -> Result<TriangleBody, InputError> {
    let text = crate::textfile::read_text(path, crate::textfile::NonUtf8::Replace)
        .map_err(|e| InputError::new(path, "file", e))?;
    let (v, faces) = crate::pattern::parse_obj_triangles(&text)
        .map_err(|d| InputError::new(path, d.key, d.message))?;
    let vertices: Vec<Vector3<f64>> = v
        .iter()
        .map(|p| Vector3::new(p[0], p[1], p[2]) * unit_m)
        .collect();
    let triangles: Vec<[u32; 3]> = faces.iter().map(|(t, _)| t.map(|i| i as u32)).collect();
    TriangleBody::new(vertices, triangles).map_err(|d| {
        let line = |t: usize| format!("line {}", faces[t].1);
        match d {
            BodyDefect::NoTriangles => InputError::new(
                path,
                "f",
                "the file has no faces (`f` lines): a body needs triangles",
            ),
            BodyDefect::Degenerate(t) => InputError::new(
                path,
                line(t),
                "a face without area (its corners on a line or two of them the same)",
            ),
            BodyDefect::NotFinite(i) => InputError::new(
                path,
                format!("vertex {}", i + 1),
                "a coordinate that is not finite",
            ),
            BodyDefect::MissingVertex(t) => InputError::new(
                path,
                line(t),
                "a face names a vertex the file does not have",
            ),
            d @ (BodyDefect::Open(..)
            | BodyDefect::NonManifold(..)
            | BodyDefect::Inconsistent(..)
            | BodyDefect::InsideOut
            | BodyDefect::SelfIntersecting(..)) => InputError::new(path, "f", d.to_string()),
        }
    })
}

/// Takes each mesh obstacle's body over from `from` where it names the same file and unit (a
/// scene rebuilt from its table, where bodies are not serialized).
pub fn carry_bodies(obstacles: &mut [Obstacle], from: &[Obstacle]) {
    for (o, f) in obstacles.iter_mut().zip(from) {
        if let (
            Obstacle::Mesh {
                mesh,
                mesh_unit_m,
                body,
                ..
            },
            Obstacle::Mesh {
                mesh: m2,
                mesh_unit_m: u2,
                body: b2,
                ..
            },
        ) = (o, f)
            && mesh == m2
            && mesh_unit_m == u2
        {
            body.clone_from(b2);
        }
    }
}

impl super::Scene {
    /// `contact.body_edges` needs a mesh body and the barrier method.
    pub(super) fn check_body_edges(
        &self,
        ck: &super::check_values::Check<'_>,
    ) -> Result<(), InputError> {
        let meshed = self
            .obstacles
            .iter()
            .any(|o| matches!(o, crate::obstacle::Obstacle::Mesh { .. }));
        if self.contact.body_edges
            && !(meshed && self.contact.method == super::ContactMethod::Barrier)
        {
            return ck.err(
                "contact.body_edges",
                "keeps the sheet's edges off a mesh body's edges: it needs an obstacle of kind \"mesh\" and contact.method = \"barrier\"".into(),
            );
        }
        Ok(())
    }
}
