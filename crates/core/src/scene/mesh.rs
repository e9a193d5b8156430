//! A flat pattern as a scene's sheet (`cloth.mesh`, issue 49): read with the scene, placed by
//! `rotation_deg` and `origin_m`, and the checks a mesh sheet adds — the grid's keys refused, pins by
//! the file's groups, the continuum material required.

use super::check_values::Check;
use super::{ClothSpec, Scene, SheetShape};
use crate::cloth::Spacing;
use crate::error::InputError;
use crate::pattern::Pattern;
use nalgebra::{Rotation3, Vector3};
use std::path::Path;

/// The mesh files a scene file names (`cloth.mesh` and every `obstacles.N.mesh`, relative to the
/// scene file's folder), read from its TOML without loading the scene: a pipeline hashes them with
/// the scene, so that a changed OBJ makes the stages that read the scene stale. Empty for a grid
/// scene without mesh obstacles or a file that is not a scene.
pub fn mesh_files_of(scene_path: &Path) -> Vec<std::path::PathBuf> {
    let Some(table) = crate::textfile::read_text(scene_path, crate::textfile::NonUtf8::Refuse)
        .ok()
        .and_then(|t| t.parse::<toml::Table>().ok())
    else {
        return Vec::new();
    };
    let cloth_table = table.get("cloth");
    let cloth = ["mesh", "pattern"]
        .into_iter()
        .filter_map(|k| cloth_table.and_then(|c| c.get(k)));
    let obstacles = table.get("obstacles").and_then(|o| o.as_array());
    let bodies = obstacles
        .into_iter()
        .flatten()
        .filter_map(|o| o.get("mesh"));
    cloth
        .into_iter()
        .chain(bodies)
        .filter_map(|m| m.as_str())
        .map(|mesh| {
            let file = Path::new(mesh);
            match scene_path.parent() {
                Some(dir) if file.is_relative() => dir.join(file),
                _ => file.to_path_buf(),
            }
        })
        .collect()
}

/// The units an OBJ file's coordinates may have, m: a micrometre to a kilometre.
const MESH_UNIT_M: (f64, f64) = (1e-6, 1e3);

/// Why `unit_m` is no unit of an OBJ file's coordinates (`mesh_unit_m`), or None.
pub(super) fn mesh_unit_error(unit_m: f64) -> Option<String> {
    let (lo, hi) = MESH_UNIT_M;
    (!(unit_m.is_finite() && (lo..=hi).contains(&unit_m))).then(|| {
        format!(
            "must be a unit in m from {lo:e} to {hi:e} (1 for metres, 0.01 for centimetres, 0.001 for millimetres), got {unit_m:e}"
        )
    })
}

/// The most uniform refinements a scene may ask of its mesh (`cloth.mesh_refine`): 4⁴ = 256 times
/// the file's triangles.
const MAX_MESH_REFINE: usize = 4;

impl ClothSpec {
    /// Whether the sheet is a mesh (`cloth.mesh`) rather than the grid.
    pub fn is_mesh(&self) -> bool {
        self.mesh.is_some() || self.sewing_pattern.is_some()
    }

    /// Reads `cloth.mesh` (a relative path from the folder of `scene_path`) into `pattern`; the
    /// error names the mesh file and its defect, or the scene file and `cloth.mesh` when it is missing.
    pub(super) fn read_mesh(&mut self, scene_path: &Path) -> Result<(), InputError> {
        let Some(file) = &self.mesh else {
            self.pattern = None;
            return Ok(());
        };
        if let Some(m) = mesh_unit_error(self.mesh_unit_m) {
            return Err(InputError::new(scene_path, "cloth.mesh_unit_m", m));
        }
        if self.mesh_refine > MAX_MESH_REFINE {
            return Err(InputError::new(
                scene_path,
                "cloth.mesh_refine",
                format!(
                    "must be at most {MAX_MESH_REFINE} (each level multiplies the particles by about 4), got {}",
                    self.mesh_refine
                ),
            ));
        }
        let path = super::files::named_file(scene_path, file, "cloth.mesh")?;
        let mut pattern = crate::pattern::read_obj(&path, self.mesh_unit_m)?;
        // Each level splits every triangle in four: about four times the vertices.
        let refined = pattern.vertex_count() as f64 * 4f64.powi(self.mesh_refine as i32);
        if let Some(m) = crate::memory::too_large(refined) {
            let m = format!(
                "{} refinements of {}: {m}",
                self.mesh_refine,
                path.display()
            );
            return Err(InputError::new(scene_path, "cloth.mesh_refine", m));
        }
        for _ in 0..self.mesh_refine {
            pattern = pattern.refined();
        }
        self.pattern = Some(std::sync::Arc::new(pattern));
        Ok(())
    }
}

impl ClothSpec {
    /// Takes `from`'s pattern over to this copy of its cloth (a scene rebuilt from its table, where
    /// the pattern is not serialized): the same file and refinement, rescaled when `mesh_unit_m`
    /// changed.
    pub fn carry_pattern(&mut self, from: &ClothSpec) {
        if self.mesh != from.mesh || self.mesh_refine != from.mesh_refine {
            return;
        }
        self.pattern = from.pattern.as_ref().map(|p| {
            let s = self.mesh_unit_m / from.mesh_unit_m;
            if s == 1.0 {
                return p.clone();
            }
            std::sync::Arc::new(p.scaled(s))
        });
    }
}

impl Scene {
    /// The pattern of a mesh sheet (read when the scene was loaded); none for a grid sheet.
    pub fn pattern(&self) -> Option<&Pattern> {
        self.cloth.pattern.as_deref()
    }

    /// Start positions of the mesh's vertices: the file's (a flat pattern with the optional
    /// perturbation along its normal, `initial_perturbation_m`, the grid's formula over the
    /// pattern's bounding box; a garment's pieces as placed), rotated about x, y, then z by
    /// `rotation_deg` and moved by `origin_m`.
    pub(super) fn mesh_positions(&self, p: &Pattern) -> Vec<Vector3<f64>> {
        let c = &self.cloth;
        let [rx, ry, rz] = c.rotation_deg.map(f64::to_radians);
        let rotation = Rotation3::from_euler_angles(rx, ry, rz);
        let origin = Vector3::from(c.origin_m);
        let (lo, hi) = p.bounds_m();
        let pi = std::f64::consts::PI;
        let flat = p.is_flat();
        p.start_m
            .iter()
            .map(|q| {
                let u = (q[0] - lo[0]) / (hi[0] - lo[0]).max(f64::MIN_POSITIVE);
                let w = (q[1] - lo[1]) / (hi[1] - lo[1]).max(f64::MIN_POSITIVE);
                // A flat pattern lies in its own plane z = 0 (whatever constant z the file has).
                let z = match flat {
                    true => c.initial_perturbation_m * (pi * u).sin() * (pi * w).sin() * w,
                    false => q[2],
                };
                origin + rotation * Vector3::new(q[0], q[1], z)
            })
            .collect()
    }

    /// The sheet's shortest spacing, m: the grid's closest lines, or a mesh's shortest edge.
    pub fn sheet_spacing_m(&self) -> f64 {
        match self.pattern() {
            Some(p) => p.shortest_edge_m(),
            None => self.grid().min_spacing_m(),
        }
    }

    /// How errors name particle `p`: `[i, j]` on the grid, `vertex N` (the file's 1-based numbering)
    /// on a mesh.
    pub fn particle_name(&self, p: usize) -> String {
        if self.cloth.is_mesh() {
            format!("vertex {}", p + 1)
        } else {
            format!("[{}, {}]", p % self.cloth.nx, p / self.cloth.nx)
        }
    }

    /// A mesh sheet's cloth keys: the pattern read, none of the grid's keys, a finite placement and
    /// warp, a pattern of a size drapelab computes in.
    pub(super) fn check_mesh_cloth(&self, ck: &Check<'_>) -> Result<(), InputError> {
        let c = &self.cloth;
        let Some(p) = self.pattern() else {
            return ck.err(
                "cloth.mesh",
                "was not read: load the scene from its file (Scene::load) so that the mesh is read"
                    .into(),
            );
        };
        let grid_keys = [
            ("cloth.size_x_m", c.size_x_m != 0.0),
            ("cloth.size_y_m", c.size_y_m != 0.0),
            ("cloth.nx", c.nx != 0),
            ("cloth.ny", c.ny != 0),
            ("cloth.spacing", c.spacing != Spacing::Uniform),
            ("cloth.refine_x_m", !c.refine_x_m.is_empty()),
            ("cloth.refine_y_m", !c.refine_y_m.is_empty()),
            ("cloth.shape", c.shape != SheetShape::Square),
        ];
        if let Some((key, _)) = grid_keys.iter().find(|(_, given)| *given) {
            return ck.err(
                key,
                "is a grid sheet's key; a mesh sheet (cloth.mesh) takes its outline and resolution \
from the file: leave it out"
                    .into(),
            );
        }
        ck.pos("cloth.areal_density_kg_per_m2", c.areal_density_kg_per_m2)?;
        for (key, v) in [
            ("cloth.warp_angle_deg", c.warp_angle_deg),
            ("cloth.initial_perturbation_m", c.initial_perturbation_m),
        ]
        .into_iter()
        .chain(c.rotation_deg.map(|r| ("cloth.rotation_deg", r)))
        {
            if !v.is_finite() {
                return ck.err(key, format!("must be finite, got {v}"));
            }
        }
        if !p.is_flat() && c.initial_perturbation_m != 0.0 {
            return ck.err(
                "cloth.initial_perturbation_m",
                "perturbs a flat pattern along its normal; a garment (pieces placed in 3D) starts as the file places it: leave it out".into(),
            );
        }
        let (lo, hi) = p.bounds_m();
        let side = (hi[0] - lo[0]).max(hi[1] - lo[1]);
        ck.within("cloth.mesh", side, super::SHEET_SIDE_M)
    }

    /// A grid sheet: the grid's keys given, the mesh's keys not.
    pub(super) fn check_grid_given(&self, ck: &Check<'_>) -> Result<(), InputError> {
        let c = &self.cloth;
        if c.nx == 0 && c.ny == 0 && c.size_x_m == 0.0 && c.size_y_m == 0.0 {
            return ck.err(
                "cloth",
                "give the grid (size_x_m, size_y_m, nx, ny) or a mesh (mesh = \"FILE.obj\")".into(),
            );
        }
        let mesh_keys = [
            ("cloth.mesh_unit_m", c.mesh_unit_m != 1.0),
            ("cloth.mesh_refine", c.mesh_refine != 0),
            ("cloth.warp_angle_deg", c.warp_angle_deg != 0.0),
            (
                "cloth.rotation_deg",
                c.rotation_deg.iter().any(|r| *r != 0.0),
            ),
            ("boundary.pin_groups", !self.boundary.pin_groups.is_empty()),
        ];
        if let Some((key, _)) = mesh_keys.iter().find(|(_, given)| *given) {
            return ck.err(
                key,
                "is a mesh sheet's key (with cloth.mesh); the grid's warp runs along x".into(),
            );
        }
        Ok(())
    }

    /// The keys only hinges bend by (saturation, curl): finite, the saturation > 0, and a mesh
    /// sheet to bend (a grid's bending is linear along its lines).
    pub(super) fn check_hinge_keys(
        &self,
        ck: &Check<'_>,
        cont: &crate::material::Continuum,
    ) -> Result<(), InputError> {
        let keys = [
            ("bending_saturation_per_m", cont.bending_saturation_per_m),
            ("curl_per_m", cont.curl_per_m),
        ];
        for (k, v) in keys.iter().filter_map(|(k, v)| v.map(|v| (*k, v))) {
            let key = format!("material.continuum.{k}");
            if !self.cloth.is_mesh() {
                return ck.err(
                    &key,
                    "bends a mesh sheet's hinges (cloth.mesh); a grid sheet's bending is linear along its lines: drape a pattern, or leave it out".into(),
                );
            }
            match k {
                "curl_per_m" if !v.is_finite() => {
                    ck.err(&key, format!("must be finite, got {v}"))?
                }
                "bending_saturation_per_m" => ck.pos(&key, v)?,
                _ => {}
            }
        }
        Ok(())
    }

    /// A mesh sheet's material and boundary: the continuum material; pins by group only (the grid's
    /// indices, corners, edges and holds have no meaning on a mesh); every group named in the file.
    pub(super) fn check_mesh_boundary(&self, ck: &Check<'_>) -> Result<(), InputError> {
        if self.material.continuum.is_none() {
            return ck.err(
                "material",
                "a mesh sheet (cloth.mesh) needs [material.continuum] (the membrane and bending on \
its triangles)"
                    .into(),
            );
        }
        let b = &self.boundary;
        let grid_keys = [
            ("boundary.pin_corners", !b.pin_corners.is_empty()),
            ("boundary.pin_particles", !b.pin_particles.is_empty()),
            ("boundary.clamp_edges", !b.clamp_edges.is_empty()),
            ("boundary.symmetry_edges", !b.symmetry_edges.is_empty()),
            ("boundary.holds", !b.holds.is_empty()),
        ];
        if let Some((key, _)) = grid_keys.iter().find(|(_, given)| *given) {
            return ck.err(
                key,
                "addresses the grid; on a mesh sheet pin the file's groups (boundary.pin_groups)"
                    .into(),
            );
        }
        if let Some(k) = self.loads.iter().position(|l| l.particle.is_some()) {
            return ck.err(
                &format!("loads.{k}.particle"),
                "is a grid index; on a mesh sheet give the load's position (at_m)".into(),
            );
        }
        let groups = &self.pattern().expect("checked before").groups;
        if let Some((k, g)) = b
            .pin_groups
            .iter()
            .enumerate()
            .find(|(_, g)| !groups.contains_key(*g))
        {
            let known: Vec<&str> = groups.keys().map(String::as_str).collect();
            return ck.err(
                &format!("boundary.pin_groups.{k}"),
                format!(
                    "the mesh has no group `{g}` (its groups: {})",
                    if known.is_empty() {
                        "none; name vertex sets with `g` lines".to_string()
                    } else {
                        known.join(", ")
                    }
                ),
            );
        }
        Ok(())
    }

    /// The vertices of the mesh's pinned groups (`boundary.pin_groups`).
    pub fn pinned_group_vertices(&self) -> Vec<usize> {
        let Some(p) = self.pattern() else {
            return Vec::new();
        };
        let mut v: Vec<usize> = self
            .boundary
            .pin_groups
            .iter()
            .filter_map(|g| p.groups.get(g))
            .flatten()
            .copied()
            .collect();
        v.sort_unstable();
        v.dedup();
        v
    }
}
