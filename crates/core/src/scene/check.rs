//! The checks of a scene, section by section, each naming the file and the key; the physical
//! bounds drapelab computes in; [`ValidatedScene`], a scene that passed them.

use super::check_values::Check;
pub use super::check_values::MAGNITUDES;
use super::*;
use crate::error::InputError;
use serde::Serialize;
use std::path::Path;

impl Scene {
    /// Checks every value's range; the error names the key.
    pub fn validate(&self, path: &Path) -> Result<(), InputError> {
        let ck = Check { path };
        self.check_magnitudes(&ck)?;
        self.check_cloth(&ck)?;
        self.check_material(&ck)?;
        self.check_boundary(&ck)?;
        self.check_obstacles(&ck)?;
        self.check_solver(&ck)
    }

    /// Every physical number of the scene (its solver and recording options aside) is finite and
    /// zero or of a size drapelab computes in ([`MAGNITUDES`]); the error names the key as the other
    /// checks do and `--set` takes it (`loads.0.magnitude_N`, `obstacles.1.centre_m`).
    fn check_magnitudes(&self, ck: &Check<'_>) -> Result<(), InputError> {
        let Ok(toml::Value::Table(t)) = toml::Value::try_from(self) else {
            return Ok(());
        };
        t.iter()
            .filter(|(k, _)| !["solver", "record"].contains(&k.as_str()))
            .try_for_each(|(k, v)| super::check_values::magnitudes(ck, &|| k.clone(), v))
    }

    /// The cloth: sizes, density, grid, grading and refined lines.
    fn check_cloth(&self, ck: &Check<'_>) -> Result<(), InputError> {
        if self.cloth.is_mesh() {
            return self.check_mesh_cloth(ck);
        }
        self.check_grid_given(ck)?;
        let c = &self.cloth;
        ck.within("cloth.size_x_m", c.size_x_m, SHEET_SIDE_M)?;
        ck.within("cloth.size_y_m", c.size_y_m, SHEET_SIDE_M)?;
        ck.pos("cloth.areal_density_kg_per_m2", c.areal_density_kg_per_m2)?;
        if !c.initial_perturbation_m.is_finite() {
            return ck.err("cloth.initial_perturbation_m", "must be finite".into());
        }
        if let Some((key, message)) = self.grid_count_error() {
            return ck.err(key, message);
        }
        if !(0.0..1.0).contains(&c.grading) {
            return ck.err(
                "cloth.grading",
                format!("must be in [0, 1), got {}", c.grading),
            );
        }
        for (key, lines, origin, size, n) in [
            (
                "cloth.refine_x_m",
                &c.refine_x_m,
                c.origin_m[0],
                c.size_x_m,
                c.nx,
            ),
            (
                "cloth.refine_y_m",
                &c.refine_y_m,
                c.origin_m[1],
                c.size_y_m,
                c.ny,
            ),
        ] {
            if lines.is_empty() {
                continue;
            }
            if c.spacing != Spacing::Graded {
                return ck.err(key, "needs cloth.spacing = \"graded\"".into());
            }
            if let Some(v) = lines
                .iter()
                .find(|v| !(v.is_finite() && **v > origin && **v < origin + size))
            {
                return ck.err(
                    key,
                    format!(
                        "{v} m is not inside the sheet ({origin} m to {} m): give lines strictly between its edges",
                        origin + size
                    ),
                );
            }
            if lines.len() + 1 > n - 1 {
                return ck.err(
                    key,
                    format!(
                        "{} lines need at least {} particles along the side",
                        lines.len(),
                        lines.len() + 2
                    ),
                );
            }
        }
        Ok(())
    }

    /// The material: mass-spring or continuum, every constant in range.
    fn check_material(&self, ck: &Check<'_>) -> Result<(), InputError> {
        let c = &self.cloth;
        super::check_values::check_material_model(&self.material, ck, "material")?;
        if let Some(ms) = &self.material.mass_spring
            && ms.natural_length_m.is_some()
            && c.spacing != Spacing::Uniform
        {
            return ck.err(
                "material.mass_spring.natural_length_m",
                "needs cloth.spacing = \"uniform\"".into(),
            );
        }
        if let Some(cont) = &self.material.continuum {
            self.check_hinge_keys(ck, cont)?;
        }
        Ok(())
    }

    /// Pins, holds, point loads, clamps: inside the grid and enough to hold the sheet.
    fn check_boundary(&self, ck: &Check<'_>) -> Result<(), InputError> {
        if self.cloth.is_mesh() {
            self.check_mesh_boundary(ck)?;
        }
        let c = &self.cloth;
        for (n, p) in self.boundary.pin_particles.iter().enumerate() {
            if p[0] >= c.nx || p[1] >= c.ny {
                return ck.err(
                    &format!("boundary.pin_particles.{n}"),
                    format!(
                        "[{}, {}] lies outside the {}×{} grid (i < nx, j < ny)",
                        p[0], p[1], c.nx, c.ny
                    ),
                );
            }
        }
        if !self.boundary.symmetry_edges.is_empty()
            && (self.material.continuum.is_none() || self.solver.kind != SolverKind::Static)
        {
            return ck.err(
                "boundary.symmetry_edges",
                "symmetry planes need [material.continuum] and solver.kind = \"static\"".into(),
            );
        }
        if !self.boundary.holds.is_empty() && self.solver.kind != SolverKind::Static {
            return ck.err(
                "boundary.holds",
                "held coordinates need solver.kind = \"static\"".into(),
            );
        }
        for (h, hold) in self.boundary.holds.iter().enumerate() {
            if hold.components.is_empty() {
                return ck.err(
                    &format!("boundary.holds.{h}.components"),
                    "name at least one of \"x\", \"y\", \"z\"".into(),
                );
            }
            if let Some(p) = hold.particles.iter().find(|p| p[0] >= c.nx || p[1] >= c.ny) {
                return ck.err(
                    &format!("boundary.holds.{h}.particles"),
                    format!(
                        "[{}, {}] lies outside the {}×{} grid",
                        p[0], p[1], c.nx, c.ny
                    ),
                );
            }
        }
        self.check_loads(ck)?;
        if !self.boundary.clamp_edges.is_empty() && (c.nx < 3 || c.ny < 3) {
            return ck.err(
                "boundary.clamp_edges",
                "a clamp needs at least 3 particles along each side".into(),
            );
        }
        if self.boundary.pin_corners.is_empty()
            && self.boundary.pin_particles.is_empty()
            && self.boundary.clamp_edges.is_empty()
            && self.boundary.holds.is_empty()
            && self.boundary.pin_groups.is_empty()
            && (!self.contact.fix_supported || self.obstacles.is_empty())
            // A sewn garment closes round its body: the body alone holds it.
            && (!c.is_sewn() || self.obstacles.is_empty())
        {
            return ck.err(
                "boundary",
                "nothing is pinned or clamped: the sheet would fall freely".into(),
            );
        }
        if c.origin_m.iter().any(|v| !v.is_finite()) {
            return ck.err("cloth.origin_m", "must be finite".into());
        }
        self.check_contact(ck)
    }

    /// Each `[[loads]]` entry: one particle on the grid or a finite position, a magnitude ≥ 0 N and
    /// a finite non-zero direction.
    fn check_loads(&self, ck: &Check<'_>) -> Result<(), InputError> {
        let c = &self.cloth;
        for (k, l) in self.loads.iter().enumerate() {
            let key = |f: &str| format!("loads.{k}.{f}");
            match (l.particle, l.at_m) {
                (Some(p), None) if p[0] >= c.nx || p[1] >= c.ny => {
                    return ck.err(
                        &key("particle"),
                        format!(
                            "[{}, {}] lies outside the {}×{} grid",
                            p[0], p[1], c.nx, c.ny
                        ),
                    );
                }
                (None, Some(a)) if a.iter().any(|v| !v.is_finite()) => {
                    return ck.err(&key("at_m"), "must be finite".into());
                }
                (Some(_), Some(_)) | (None, None) => {
                    return ck.err(
                        &key("particle"),
                        "give exactly one of `particle` or `at_m`".into(),
                    );
                }
                _ => {}
            }
            ck.nonneg(&key("magnitude_N"), l.magnitude_N)?;
            let d = l.direction;
            if d.iter().any(|v| !v.is_finite()) || d.iter().all(|v| *v == 0.0) {
                return ck.err(&key("direction"), "must be finite and not zero".into());
            }
        }
        Ok(())
    }

    /// The `[contact]` table: distances, friction and self-contact settings.
    fn check_contact(&self, ck: &Check<'_>) -> Result<(), InputError> {
        ck.pos("contact.distance_m", self.contact.distance_m)?;
        ck.nonneg(
            "contact.friction_coefficient",
            self.contact.friction_coefficient,
        )?;
        if let Some(t) = self.contact.self_thickness_m {
            ck.pos("contact.self_thickness_m", t)?;
            let h = self.sheet_spacing_m();
            if t > 0.2 * h {
                return ck.err(
                    "contact.self_thickness_m",
                    format!(
                        "{t} m is over a fifth of the grid's shortest spacing ({h:.4} m): the flat sheet \
would already touch itself; use a coarser grid or a thinner sheet"
                    ),
                );
            }
        }
        self.check_body_edges(ck)?;
        if self.contact.self_contact == SelfContactMode::On
            && !self.solver.kind.supports_self_contact()
        {
            return ck.err(
                "contact.self",
                format!(
                    "\"on\" needs the static solver or implicit-euler, not {}; use \"auto\" or \"off\"",
                    self.solver.kind.name()
                ),
            );
        }
        Ok(())
    }

    /// Every obstacle valid and clear of the flat sheet.
    fn check_obstacles(&self, ck: &Check<'_>) -> Result<(), InputError> {
        if self.obstacles.is_empty() {
            return Ok(());
        }
        let flat = self.initial_positions();
        let edges = self.sheet_edges();
        for (k, o) in self.obstacles.iter().enumerate() {
            o.check().map_err(|e| {
                InputError::new(ck.path, format!("obstacles.{k}.{}", e.key), e.message)
            })?;
            let d: Vec<f64> = flat.iter().map(|x| o.signed_distance(x).0).collect();
            if let Some((p, d)) = d
                .iter()
                .copied()
                .enumerate()
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .filter(|(_, d)| *d <= 0.0)
            {
                return ck.err(
                    &format!("obstacles.{k}"),
                    format!(
                        "the sheet starts inside this obstacle{} (particle {} is {:.3e} m deep): \
                         move the obstacle down or the sheet up (cloth.origin_m)",
                        mesh_named(o),
                        self.particle_name(p),
                        -d
                    ),
                );
            }
            // Both ends outside, the edge through the obstacle: a wall thinner than the sheet's
            // spacing. An edge longer than the distance of neither end can reach it.
            if let Some(&[a, b]) = edges.iter().find(|[a, b]| {
                let l = (flat[*a] - flat[*b]).norm();
                (d[*a] <= l || d[*b] <= l) && o.segment_enters(&flat[*a], &flat[*b])
            }) {
                return ck.err(
                    &format!("obstacles.{k}"),
                    format!(
                        "the sheet starts through this obstacle{}: the edge from particle {} to {} \
passes through it (a part thinner than the sheet's spacing): move the obstacle or the sheet \
(cloth.origin_m) so that the sheet starts clear of it",
                        mesh_named(o),
                        self.particle_name(a),
                        self.particle_name(b)
                    ),
                );
            }
        }
        Ok(())
    }

    /// The sheet's edges as its flat start has them: a mesh's triangles' edges, the grid's lines.
    fn sheet_edges(&self) -> Vec<[usize; 2]> {
        let mut edges: Vec<[usize; 2]> = match self.pattern() {
            Some(p) => p
                .triangles
                .iter()
                .flat_map(|t| {
                    (0..3).map(move |k| [t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3])])
                })
                .collect(),
            None => {
                let (nx, ny) = (self.cloth.nx, self.cloth.ny);
                let right =
                    (0..ny).flat_map(|j| (1..nx).map(move |i| [j * nx + i - 1, j * nx + i]));
                let up = (1..ny).flat_map(|j| (0..nx).map(move |i| [(j - 1) * nx + i, j * nx + i]));
                right.chain(up).collect()
            }
        };
        edges.sort_unstable();
        edges.dedup();
        edges
    }

    /// Gravity, the solvers' tolerances and budgets, and the recording.
    fn check_solver(&self, ck: &Check<'_>) -> Result<(), InputError> {
        ck.nonneg("gravity.g_m_per_s2", self.gravity.g_m_per_s2)?;
        ck.within(
            "gravity.g_m_per_s2",
            self.gravity.g_m_per_s2,
            GRAVITY_M_PER_S2,
        )?;
        let in_file = |e: crate::error::KeyError, section: &str| {
            let e = if e.key.is_empty() {
                crate::error::KeyError::new(section, e.message)
            } else {
                e.under(section)
            };
            InputError::new(ck.path, e.key, e.message)
        };
        self.solver
            .static_
            .check()
            .map_err(|e| in_file(e, "solver.static"))?;
        // Adaptive implicit steps grow from dt_s to max_dt_s: their count is bounded by the larger.
        let adaptive =
            self.solver.kind == SolverKind::ImplicitEuler && self.solver.dynamic.adaptive_dt;
        self.solver
            .dynamic
            .check(adaptive)
            .map_err(|e| in_file(e, "solver.dynamic"))?;
        if let Some(f) = self.record.frame_rate_hz
            && !(f.is_finite() && f > 0.0)
        {
            return ck.err(
                "record.frame_rate_hz",
                format!("must be a number > 0, got {f}"),
            );
        }
        if self.record.every == 0 {
            return ck.err("record.every", "must be ≥ 1".into());
        }
        Ok(())
    }
}

/// A scene whose every value has been range-checked ([`Scene::validate`]): what the model builder
/// ([`crate::build::build_scene`]) and the solvers take. Read it as a [`Scene`] (`Deref`); change it
/// with [`ValidatedScene::modify`], which checks the result again.
#[derive(Debug, Clone, PartialEq)]
pub struct ValidatedScene(pub(super) Scene);

impl std::ops::Deref for ValidatedScene {
    type Target = Scene;
    fn deref(&self) -> &Scene {
        &self.0
    }
}

impl Serialize for ValidatedScene {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.0.serialize(s)
    }
}

impl Scene {
    /// Checks the scene (errors name the scene, not a file: it was built or changed in code).
    pub fn validated(self) -> Result<ValidatedScene, InputError> {
        self.validate(Path::new(&format!("scene `{}`", self.name)))?;
        Ok(ValidatedScene(self))
    }
}

impl ValidatedScene {
    /// The scene, no longer known to be valid.
    pub fn into_inner(self) -> Scene {
        self.0
    }
    /// A changed copy, checked again.
    pub fn modify(&self, change: impl FnOnce(&mut Scene)) -> Result<ValidatedScene, InputError> {
        let mut s = self.0.clone();
        change(&mut s);
        s.validated()
    }
}

/// The sides a sheet may have, m: from 0.1 mm (a yarn's width) to 100 m.
pub const SHEET_SIDE_M: (f64, f64) = (1e-4, 100.0);

/// The gravitational accelerations a scene may have, m/s²: none (0, loads alone) to 1000 (a
/// centrifuge's 100 g).
pub const GRAVITY_M_PER_S2: (f64, f64) = (0.0, 1000.0);

/// A mesh obstacle's file, as an error names it (` (mesh FILE)`); empty for an analytic shape.
fn mesh_named(o: &crate::obstacle::Obstacle) -> String {
    match o {
        crate::obstacle::Obstacle::Mesh { mesh, .. } => format!(" (mesh {})", mesh.display()),
        _ => String::new(),
    }
}
