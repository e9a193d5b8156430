//! Scenes as TOML: the cloth, its material, the boundary, gravity, the solver and what to record.
//!
//! A scene file is read once into a [`Scene`] (unknown keys refused), `--set KEY=VALUE` overrides
//! are applied by dotted path before that, and [`Scene::validate`] checks every value's range.
//! Every error is an [`InputError`] naming the file and the key.

use crate::cloth::{Corner, Edge, Spacing};
use crate::config::{from_table, read_toml_table, set_dotted};
use crate::error::InputError;
use crate::error::KeyError;
use crate::material::Material;
use crate::solve::{DynamicOptions, StaticOptions};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

mod mesh;
pub use mesh::mesh_file_of;

/// The sheet: size, resolution, spacing and areal density.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClothSpec {
    /// Side along x in m, 1e-4 to 100 ([`SHEET_SIDE_M`]); a grid sheet's (leave out with `mesh`).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub size_x_m: f64,
    /// Side along y in m, 1e-4 to 100; a grid sheet's.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub size_y_m: f64,
    /// Particles along x (≥ 2); a grid sheet's.
    #[serde(default, skip_serializing_if = "is_zero_count")]
    pub nx: usize,
    /// Particles along y (≥ 2); a grid sheet's.
    #[serde(default, skip_serializing_if = "is_zero_count")]
    pub ny: usize,
    /// A flat pattern piece as the sheet instead of the grid: a Wavefront OBJ file of triangles or
    /// polygons at z = 0 in its own frame (relative paths from the scene file's folder), checked once
    /// ([`crate::pattern`]); its `g`/`o` groups name vertex sets for `boundary.pin_groups`. Needs
    /// `[material.continuum]`. Default none (the grid).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mesh: Option<PathBuf>,
    /// The mesh file's length unit in m: 1 for metres (default), 0.01 for centimetres, 0.001 for
    /// millimetres.
    #[serde(default = "default_unit", skip_serializing_if = "is_one")]
    pub mesh_unit_m: f64,
    /// The warp's direction in the mesh's plane, degrees from its +x towards +y (default 0: warp
    /// along x, as on the grid). Change it for a panel cut on the bias (45) or across the roll (90).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub warp_angle_deg: f64,
    /// The mesh's placement: rotations about x, then y, then z (degrees, right-handed) of the
    /// pattern's plane, before `origin_m` is added. Default [0, 0, 0] (flat, horizontal). [90, 0, 0]
    /// stands a pattern in the x–z plane (a curtain hung from its top).
    #[serde(default, skip_serializing_if = "is_zero3")]
    pub rotation_deg: [f64; 3],
    /// The pattern read from `mesh` (set when the scene is loaded).
    #[serde(skip)]
    pub pattern: Option<std::sync::Arc<crate::pattern::Pattern>>,
    /// "uniform" (default) or "graded" (finer towards the edges).
    #[serde(default)]
    pub spacing: Spacing,
    /// For graded spacing: 0 = uniform .. <1 = strongly graded. Default 0.5.
    #[serde(default = "default_grading")]
    pub grading: f64,
    /// For graded spacing: x coordinates in m (the scene's frame, like obstacles) of interior lines
    /// x = const that become grid lines and towards which the grid is refined, e.g. a table's
    /// edges (seed 003 Fig. 10.3). Default none: refined towards the sheet's edges only.
    #[serde(default)]
    pub refine_x_m: Vec<f64>,
    /// For graded spacing: y coordinates in m of interior lines y = const, as `refine_x_m`.
    #[serde(default)]
    pub refine_y_m: Vec<f64>,
    /// Areal density (mass per area) in kg/m² (45 g/m² = 0.045).
    pub areal_density_kg_per_m2: f64,
    /// "square" (default) or "disc": the circle inscribed in the sheet, the grid particles outside it
    /// left out (a drape-tester specimen).
    #[serde(default)]
    pub shape: SheetShape,
    /// Position of particle (0, 0) in m: the flat sheet spans origin + [0, size_x] × [0, size_y] at
    /// z = origin z. Default [0, 0, 0].
    #[serde(default)]
    pub origin_m: [f64; 3],
    /// Amplitude of an out-of-plane initial perturbation z = a·sin(πx/Lx)·sin(πy/Ly)·(y/Ly) in m,
    /// used to break the mirror symmetry of a hang. Default 0.
    #[serde(default)]
    pub initial_perturbation_m: f64,
}

fn default_grading() -> f64 {
    0.5
}

fn default_unit() -> f64 {
    1.0
}

fn is_one(v: &f64) -> bool {
    *v == 1.0
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

fn is_zero_count(v: &usize) -> bool {
    *v == 0
}

fn is_zero3(v: &[f64; 3]) -> bool {
    v.iter().all(|c| *c == 0.0)
}

/// Boundary conditions.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoundarySpec {
    /// Corners pinned where they lie: "xmin_ymin", "xmax_ymin", "xmin_ymax", "xmax_ymax".
    #[serde(default)]
    pub pin_corners: Vec<Corner>,
    /// Particles pinned where they lie, by grid indices [i, j].
    #[serde(default)]
    pub pin_particles: Vec<[usize; 2]>,
    /// Edges clamped (position and slope fixed): "xmin", "xmax", "ymin", "ymax".
    #[serde(default)]
    pub clamp_edges: Vec<Edge>,
    /// Edges on a symmetry plane (a quarter or half model): their particles keep the coordinate normal
    /// to the edge and the bending across it is mirrored. Continuum model and static solver only.
    #[serde(default)]
    pub symmetry_edges: Vec<Edge>,
    /// Every vertex of these groups of the mesh (`cloth.mesh`, its `g`/`o` names) pinned where it
    /// lies. Default none.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub pin_groups: Vec<String>,
    /// `[[boundary.holds]]`: some coordinates of some particles held where they start (a sheet
    /// supported vertically round its edge, a corner restrained in the plane: seed 003 §10.5). Static
    /// solver only. Default none.
    #[serde(default)]
    pub holds: Vec<Hold>,
}

/// Coordinates of particles held at their initial values.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Hold {
    /// Particles by grid indices [i, j]. Default none.
    #[serde(default)]
    pub particles: Vec<[usize; 2]>,
    /// Every particle of these edges: "xmin", "xmax", "ymin", "ymax". Default none.
    #[serde(default)]
    pub edges: Vec<Edge>,
    /// The coordinates held: any of "x", "y", "z".
    pub components: Vec<Axis>,
}

/// A coordinate axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Axis {
    /// x.
    X,
    /// y.
    Y,
    /// z (up).
    Z,
}

impl Axis {
    /// 0, 1 or 2.
    pub fn index(self) -> usize {
        match self {
            Axis::X => 0,
            Axis::Y => 1,
            Axis::Z => 2,
        }
    }
}

/// A concentrated force on one particle (seed 003's perturbation forces Q_p, §10.5–10.6, and the
/// diagonal pull of §10.5), raised with the load factor like gravity. 1 gf = 9.80665e-3 N.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointLoad {
    /// The particle by grid indices [i, j]; or give `at_m`.
    #[serde(default)]
    pub particle: Option<[usize; 2]>,
    /// The initial (x, y) in m of the loaded point (origin included); the nearest present particle
    /// takes the force.
    #[serde(default)]
    pub at_m: Option<[f64; 2]>,
    /// Direction of the force (normalised on use).
    pub direction: [f64; 3],
    /// Magnitude in N (0 is allowed: a sweep's unperturbed point).
    pub magnitude_N: f64,
}

/// Gravity.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GravitySpec {
    /// Gravitational acceleration in m/s², acting along −z, 0 to 1000 ([`GRAVITY_M_PER_S2`]).
    /// Default 9.80665.
    #[serde(default = "default_g")]
    pub g_m_per_s2: f64,
}

fn default_g() -> f64 {
    crate::STANDARD_GRAVITY_M_PER_S2
}

impl Default for GravitySpec {
    fn default() -> Self {
        Self {
            g_m_per_s2: default_g(),
        }
    }
}

pub use crate::solve::SolverKind;

impl SelfContactMode {
    /// Whether a scene solved by `kind` gets the sheet's self-contact term under this mode
    /// ([`ContactSpec::self_contact`]): not off, and a solver that handles it.
    pub fn applies_to(self, kind: SolverKind) -> bool {
        self != SelfContactMode::Off && kind.supports_self_contact()
    }
}

/// The solver and its tolerances.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SolverSpec {
    /// "static" (default), "explicit-euler", "symplectic-euler", "implicit-euler" (the incremental
    /// potential minimised per step) or "baraff-witkin" (implicit Euler linearised once per step).
    #[serde(default)]
    pub kind: SolverKind,
    /// Options of the static solver.
    #[serde(default, rename = "static")]
    pub static_: StaticOptions,
    /// Options of the dynamic solvers.
    #[serde(default)]
    pub dynamic: DynamicOptions,
}

/// What to record besides `particles.parquet` and `run.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RecordSpec {
    /// Write `timeline.mcap` (Foxglove SceneUpdate in JSON). Default false.
    #[serde(default)]
    pub timeline: bool,
    /// Write `drape.rrd` (rerun). Default false.
    #[serde(default)]
    pub rerun: bool,
    /// Record every k-th Newton iteration or time step (the final state is always recorded). Default 1.
    #[serde(default = "default_every")]
    pub every: usize,
    /// Dynamics: record frames at this rate of simulated time, Hz, instead of every k-th step (the
    /// implicit integrator lands a step on each frame time; the explicit ones record the first step
    /// at or past it). Default none.
    #[serde(default)]
    pub frame_rate_hz: Option<f64>,
}

fn default_every() -> usize {
    1
}

impl Default for RecordSpec {
    fn default() -> Self {
        Self {
            timeline: false,
            rerun: false,
            every: 1,
            frame_rate_hz: None,
        }
    }
}

/// A complete scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// A short name.
    pub name: String,
    /// What the scene is, in words.
    #[serde(default)]
    pub description: String,
    /// The sheet.
    pub cloth: ClothSpec,
    /// The fabric model.
    pub material: Material,
    /// Pins and clamps.
    #[serde(default)]
    pub boundary: BoundarySpec,
    /// Gravity.
    #[serde(default)]
    pub gravity: GravitySpec,
    /// Solver.
    #[serde(default)]
    pub solver: SolverSpec,
    /// Recording.
    #[serde(default)]
    pub record: RecordSpec,
    /// Rigid obstacles (seed 003): `[[obstacles]]` with `kind` = plane, box, cylinder, sphere, pedestal
    /// or revolution. Default none.
    #[serde(default)]
    pub obstacles: Vec<crate::contact::Obstacle>,
    /// How contact with the obstacles is treated.
    #[serde(default)]
    pub contact: ContactSpec,
    /// `[[loads]]`: concentrated forces on particles. Default none.
    #[serde(default)]
    pub loads: Vec<PointLoad>,
}

/// The outline of the sheet.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SheetShape {
    /// The whole rectangle.
    #[default]
    Square,
    /// The circle inscribed in the rectangle.
    Disc,
}

/// How contact with obstacles is treated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ContactMethod {
    /// A smooth barrier energy: no particle can enter an obstacle in any direction (default).
    #[default]
    Barrier,
    /// Seed 003 §10.7.1: a node that went below an obstacle's upper surface is pulled back vertically
    /// onto it and held there while the obstacle pushes on it (active set).
    VerticalGap,
}

/// Contact options.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    /// "barrier" (default) or "vertical-gap".
    #[serde(default)]
    pub method: ContactMethod,
    /// Barrier activation distance d̂ in m: the gap at which contact forces start. Default 1e-3.
    #[serde(default = "default_contact_distance")]
    pub distance_m: f64,
    /// Fix the particles that start above the top face of a box table or a pedestal, as seed 003 does
    /// for the part of a sheet lying on a table (§10.5, §10.6). Default false (they slide freely).
    #[serde(default)]
    pub fix_supported: bool,
    /// Coulomb friction coefficient μ of the barrier contact (lagged, refreshed over 20 load
    /// increments). Default 0 (frictionless).
    #[serde(default)]
    pub friction_coefficient: f64,
    /// Self-contact of the sheet (written `self`): "auto" (default: on for the static solve and
    /// implicit Euler, off for the explicit and linearised integrators, which a barrier would make
    /// unstable), "on" (an input error with those integrators) or "off".
    #[serde(default, rename = "self")]
    pub self_contact: SelfContactMode,
    /// Thickness ξ of the sheet for self-contact, m: two layers' mid-surfaces stay more than ξ apart
    /// and repel from 2ξ (the activation distance). Default: the continuum material's `thickness_m`,
    /// else 1 mm, at most a fifth of the grid's shortest spacing.
    #[serde(default)]
    pub self_thickness_m: Option<f64>,
}

/// Whether the sheet's self-contact is modelled ([`ContactSpec::self_contact`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SelfContactMode {
    /// On wherever the solver supports it (the static solve, implicit Euler).
    #[default]
    Auto,
    /// On; an input error with a solver that does not support it.
    On,
    /// Off: the sheet may pass through itself.
    Off,
}

fn default_contact_distance() -> f64 {
    1e-3
}

impl Default for ContactSpec {
    fn default() -> Self {
        Self {
            method: ContactMethod::default(),
            distance_m: default_contact_distance(),
            fix_supported: false,
            friction_coefficient: 0.0,
            self_contact: SelfContactMode::Auto,
            self_thickness_m: None,
        }
    }
}

/// A scene with the file it came from.
#[derive(Debug, Clone)]
pub struct LoadedScene {
    /// The validated scene.
    pub scene: ValidatedScene,
    /// The file it was read from.
    pub path: PathBuf,
}

impl Scene {
    /// The grid of the scene (uniform or graded, refined towards `cloth.refine_x_m`/`refine_y_m`);
    /// of a mesh sheet, its vertices as one row ([`Grid::vertex_row`](crate::cloth::Grid::vertex_row)).
    pub fn grid(&self) -> crate::cloth::Grid {
        if let Some(p) = self.pattern() {
            return crate::cloth::Grid::vertex_row(p.vertex_count());
        }
        let c = &self.cloth;
        let local =
            |lines: &[f64], origin: f64| lines.iter().map(|v| v - origin).collect::<Vec<_>>();
        let (rx, ry) = (
            local(&c.refine_x_m, c.origin_m[0]),
            local(&c.refine_y_m, c.origin_m[1]),
        );
        crate::cloth::Grid::new(
            c.nx,
            c.ny,
            c.size_x_m,
            c.size_y_m,
            c.spacing,
            if c.spacing == Spacing::Graded {
                c.grading
            } else {
                0.0
            },
            [&rx, &ry],
        )
    }

    /// Initial positions of the grid particles: the flat sheet at `cloth.origin_m`, with the optional
    /// perturbation z += a·sin(πu)·sin(πw)·w (u, w the fractions along x and y); of a mesh sheet, its
    /// placed vertices.
    pub fn initial_positions(&self) -> Vec<nalgebra::Vector3<f64>> {
        if let Some(p) = self.pattern() {
            return self.mesh_positions(p);
        }
        let c = &self.cloth;
        let o = nalgebra::Vector3::new(c.origin_m[0], c.origin_m[1], c.origin_m[2]);
        self.grid()
            .flat_positions()
            .into_iter()
            .map(|p| {
                let (u, w) = (p.x / c.size_x_m, p.y / c.size_y_m);
                let dz = c.initial_perturbation_m
                    * (std::f64::consts::PI * u).sin()
                    * (std::f64::consts::PI * w).sin()
                    * w;
                p + o + nalgebra::Vector3::new(0.0, 0.0, dz)
            })
            .collect()
    }

    /// The scene on an `nx × ny` grid: every particle named by grid indices (pins, holds, point loads)
    /// moves to the same material point, index i → round(i (nx − 1)/(nx₀ − 1)) (exact when the new
    /// grid's lines fall on the old one's, as in 2n − 1 refinement).
    pub fn regridded(&self, nx: usize, ny: usize) -> Scene {
        let mut s = self.clone();
        let (nx0, ny0) = (self.cloth.nx, self.cloth.ny);
        let map = |p: [usize; 2]| {
            let f = |i: usize, n0: usize, n: usize| {
                if n0 > 1 {
                    ((i * (n - 1)) as f64 / (n0 - 1) as f64).round() as usize
                } else {
                    i.min(n - 1)
                }
            };
            [f(p[0], nx0, nx), f(p[1], ny0, ny)]
        };
        s.cloth.nx = nx;
        s.cloth.ny = ny;
        for p in &mut s.boundary.pin_particles {
            *p = map(*p);
        }
        for h in &mut s.boundary.holds {
            for p in &mut h.particles {
                *p = map(*p);
            }
        }
        for l in &mut s.loads {
            if let Some(p) = &mut l.particle {
                *p = map(*p);
            }
        }
        s
    }

    /// Reads, overrides and validates a scene file.
    ///
    /// A grid override (`cloth.nx`, `cloth.ny`) moves the particles the file names by grid index
    /// (pins, holds, point loads) to the same material points on the new grid, as [`Scene::regridded`]
    /// does; index lists given among the overrides themselves are taken as indices of the new grid.
    pub fn load(
        path: &Path,
        overrides: &[(String, toml::Value)],
    ) -> Result<LoadedScene, InputError> {
        Self::load_table(path, read_toml_table(path)?, overrides)
    }

    /// [`Scene::load`] of a scene already parsed into a TOML table (the Python package's dict
    /// scenes); `path` names it in errors and resolves nothing.
    pub fn load_table(
        path: &Path,
        file: toml::Table,
        overrides: &[(String, toml::Value)],
    ) -> Result<LoadedScene, InputError> {
        let is_grid = |k: &str| k == "cloth.nx" || k == "cloth.ny";
        let with = |keep: &dyn Fn(&str) -> bool| -> Result<Scene, InputError> {
            let mut table = file.clone();
            for (k, v) in overrides.iter().filter(|(k, _)| keep(k)) {
                set_dotted(&mut table, k, v.clone()).map_err(|m| InputError::new(path, k, m))?;
            }
            read_renamed_keys(&mut table).map_err(|e| InputError::new(path, e.key, e.message))?;
            let mut scene: Scene = from_table(path, "", table)?;
            scene.cloth.read_mesh(path)?;
            Ok(scene)
        };
        let mut scene = with(&|_| true)?;
        if overrides.iter().any(|(k, _)| is_grid(k)) {
            let on_file_grid = with(&|k| !is_grid(k))?;
            on_file_grid.validate(path)?;
            let given = |prefix: &str| {
                overrides
                    .iter()
                    .any(|(k, _)| k == prefix || k.starts_with(&format!("{prefix}.")))
            };
            let mut moved = on_file_grid.regridded(scene.cloth.nx, scene.cloth.ny);
            if given("boundary.pin_particles") || given("boundary") {
                moved.boundary.pin_particles = scene.boundary.pin_particles.clone();
            }
            if given("boundary.holds") || given("boundary") {
                moved.boundary.holds = scene.boundary.holds.clone();
            }
            let load_particle_given = overrides.iter().any(|(k, _)| {
                k == "loads" || (k.starts_with("loads.") && k.ends_with(".particle"))
            });
            if load_particle_given {
                moved.loads = scene.loads.clone();
            }
            scene = moved;
        }
        scene.validate(path)?;
        Ok(LoadedScene {
            scene: ValidatedScene(scene),
            path: path.to_path_buf(),
        })
    }

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
    /// checks do (`loads[0].magnitude_N`, `obstacles[1].centre_m`).
    fn check_magnitudes(&self, ck: &Check<'_>) -> Result<(), InputError> {
        // The key is spelled only for an error: a scene is checked once per solve, and a
        // calibration solves tens of thousands.
        fn walk(
            ck: &Check<'_>,
            key: &dyn Fn() -> String,
            v: &toml::Value,
        ) -> Result<(), InputError> {
            match v {
                toml::Value::Float(f) if !f.is_finite() => {
                    ck.err(&key(), format!("must be a finite number, got {f}"))
                }
                toml::Value::Float(f)
                    if *f != 0.0 && !(MAGNITUDES.0..=MAGNITUDES.1).contains(&f.abs()) =>
                {
                    ck.err(
                        &key(),
                        format!(
                            "{f} is outside the sizes drapelab computes in: zero, or {:e} to {:e} \
in the key's unit (SI)",
                            MAGNITUDES.0, MAGNITUDES.1
                        ),
                    )
                }
                toml::Value::Table(t) => t
                    .iter()
                    .try_for_each(|(k, v)| walk(ck, &|| format!("{}.{k}", key()), v)),
                // A list of tables names its entry as the other checks do (`loads[0].magnitude_N`);
                // a list of numbers (a point, a profile) is named as a whole.
                toml::Value::Array(a) => a.iter().enumerate().try_for_each(|(i, v)| match v {
                    toml::Value::Table(_) => walk(ck, &|| format!("{}[{i}]", key()), v),
                    _ => walk(ck, key, v),
                }),
                _ => Ok(()),
            }
        }
        let Ok(toml::Value::Table(t)) = toml::Value::try_from(self) else {
            return Ok(());
        };
        t.iter()
            .filter(|(k, _)| !["solver", "record"].contains(&k.as_str()))
            .try_for_each(|(k, v)| walk(ck, &|| k.clone(), v))
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
        if c.nx < 2 || c.nx > 2049 {
            return ck.err("cloth.nx", format!("must be in 2..=2049, got {}", c.nx));
        }
        if c.ny < 2 || c.ny > 2049 {
            return ck.err("cloth.ny", format!("must be in 2..=2049, got {}", c.ny));
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
        match (&self.material.mass_spring, &self.material.continuum) {
            (Some(_), Some(_)) => {
                return ck.err(
                    "material",
                    "give either [material.mass_spring] or [material.continuum], not both".into(),
                );
            }
            (None, None) => {
                return ck.err(
                    "material",
                    "missing: add [material.mass_spring] or [material.continuum]".into(),
                );
            }
            (Some(ms), None) => {
                ck.pos(
                    "material.mass_spring.stiffness_N_per_m",
                    ms.stiffness_N_per_m,
                )?;
                for (k, v) in [
                    (
                        "structural_stiffness_N_per_m",
                        ms.structural_stiffness_N_per_m,
                    ),
                    ("shear_stiffness_N_per_m", ms.shear_stiffness_N_per_m),
                    ("bend_stiffness_N_per_m", ms.bend_stiffness_N_per_m),
                    ("natural_length_m", ms.natural_length_m),
                ] {
                    if let Some(v) = v {
                        ck.pos(&format!("material.mass_spring.{k}"), v)?;
                    }
                }
                ck.nonneg("material.mass_spring.damping_Ns_per_m", ms.damping_Ns_per_m)?;
                ck.pos("material.mass_spring.elongation_rate", ms.elongation_rate)?;
                if ms.natural_length_m.is_some() && c.spacing != Spacing::Uniform {
                    return ck.err(
                        "material.mass_spring.natural_length_m",
                        "needs cloth.spacing = \"uniform\"".into(),
                    );
                }
            }
            (None, Some(cont)) => {
                let r = cont.rigidities().map_err(|e| {
                    InputError::new(ck.path, format!("material.continuum.{}", e.key), e.message)
                })?;
                for (k, v) in [
                    ("tensile_warp", r.tensile_warp_N_per_m),
                    ("tensile_weft", r.tensile_weft_N_per_m),
                    ("bending_warp", r.bending_warp_N_m),
                    ("bending_weft", r.bending_weft_N_m),
                ] {
                    ck.pos(&format!("material.continuum.{k}"), v)?;
                }
                ck.nonneg("material.continuum.shear", r.shear_N_per_m)?;
                ck.nonneg("material.continuum.bending_twist", r.bending_twist_N_m)?;
            }
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
                    &format!("boundary.pin_particles[{n}]"),
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
                    &format!("boundary.holds[{h}].components"),
                    "name at least one of \"x\", \"y\", \"z\"".into(),
                );
            }
            if let Some(p) = hold.particles.iter().find(|p| p[0] >= c.nx || p[1] >= c.ny) {
                return ck.err(
                    &format!("boundary.holds[{h}].particles"),
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
            let key = |f: &str| format!("loads[{k}].{f}");
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
        for (k, o) in self.obstacles.iter().enumerate() {
            o.check().map_err(|e| {
                InputError::new(ck.path, format!("obstacles[{k}].{}", e.key), e.message)
            })?;
            if let Some((p, d)) = flat
                .iter()
                .enumerate()
                .map(|(p, x)| (p, o.signed_distance(x).0))
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .filter(|(_, d)| *d <= 0.0)
            {
                return ck.err(
                    &format!("obstacles[{k}]"),
                    format!(
                        "the sheet starts inside this obstacle (particle {} is {:.3e} m deep): \
                         move the obstacle down or the sheet up (cloth.origin_m)",
                        self.particle_name(p),
                        -d
                    ),
                );
            }
        }
        Ok(())
    }

    /// Gravity, the solvers' tolerances and budgets, and the recording.
    fn check_solver(&self, ck: &Check<'_>) -> Result<(), InputError> {
        ck.nonneg("gravity.g_m_per_s2", self.gravity.g_m_per_s2)?;
        ck.within(
            "gravity.g_m_per_s2",
            self.gravity.g_m_per_s2,
            GRAVITY_M_PER_S2,
        )?;
        let s = &self.solver.static_;
        ck.pos("solver.static.residual_tol_rel", s.residual_tol_rel)?;
        ck.pos("solver.static.lm_damping_initial", s.lm_damping_initial)?;
        ck.pos("solver.static.strain_bound", s.strain_bound)?;
        if s.max_iterations == 0 || s.load_steps == 0 {
            return ck.err(
                "solver.static",
                "max_iterations and load_steps must be ≥ 1".into(),
            );
        }
        let d = &self.solver.dynamic;
        ck.pos("solver.dynamic.dt_s", d.dt_s)?;
        ck.pos("solver.dynamic.max_time_s", d.max_time_s)?;
        if let Some(w) = d.max_wall_time_s {
            ck.pos("solver.dynamic.max_wall_time_s", w)?;
        }
        ck.pos("solver.dynamic.residual_tol_rel", d.residual_tol_rel)?;
        ck.pos("solver.dynamic.speed_tol_m_per_s", d.speed_tol_m_per_s)?;
        ck.pos("solver.dynamic.strain_bound", d.strain_bound)?;
        ck.pos("solver.dynamic.cg_tol_rel", d.cg_tol_rel)?;
        if !(0.0..=100.0).contains(&d.auto_dt_fraction) {
            return ck.err(
                "solver.dynamic.auto_dt_fraction",
                format!(
                    "must be in [0, 100] (above 1 is beyond the estimated limit), got {}",
                    d.auto_dt_fraction
                ),
            );
        }
        // Adaptive implicit steps grow from dt_s to max_dt_s: their count is bounded by the larger.
        let adaptive = self.solver.kind == SolverKind::ImplicitEuler && d.adaptive_dt;
        let step = if adaptive {
            d.max_dt_s.max(d.dt_s)
        } else {
            d.dt_s
        };
        if d.max_time_s / step > 1e9 {
            return ck.err(
                "solver.dynamic.max_time_s",
                "more than 1e9 steps: raise dt_s or lower max_time_s".into(),
            );
        }
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
pub struct ValidatedScene(Scene);

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

/// The range checks of [`Scene::validate`], naming the file and the key.
struct Check<'a> {
    path: &'a Path,
}

impl Check<'_> {
    fn err(&self, key: &str, message: String) -> Result<(), InputError> {
        Err(InputError::new(self.path, key, message))
    }
    fn pos(&self, key: &str, v: f64) -> Result<(), InputError> {
        if !v.is_finite() || v <= 0.0 {
            return self.err(key, format!("must be a finite number > 0, got {v}"));
        }
        Ok(())
    }
    fn nonneg(&self, key: &str, v: f64) -> Result<(), InputError> {
        if !v.is_finite() || v < 0.0 {
            return self.err(key, format!("must be a finite number ≥ 0, got {v}"));
        }
        Ok(())
    }
    /// `v` within the physical bounds `(lo, hi)` of the key (in its unit).
    fn within(&self, key: &str, v: f64, (lo, hi): (f64, f64)) -> Result<(), InputError> {
        if !(v.is_finite() && (lo..=hi).contains(&v)) {
            return self.err(key, format!("must be in {lo} to {hi}, got {v}"));
        }
        Ok(())
    }
}

/// The sizes drapelab computes in: every physical number of a scene is zero or between these in
/// size, in SI units (10⁻¹² to 10¹²): beyond them sums of forces and energies lose their digits or
/// overflow, and a solve would end in NaN as if the physics had failed.
pub const MAGNITUDES: (f64, f64) = (1e-12, 1e12);

/// The sides a sheet may have, m: from 0.1 mm (a yarn's width) to 100 m.
pub const SHEET_SIDE_M: (f64, f64) = (1e-4, 100.0);

/// The gravitational accelerations a scene may have, m/s²: none (0, loads alone) to 1000 (a
/// centrifuge's 100 g).
pub const GRAVITY_M_PER_S2: (f64, f64) = (0.0, 1000.0);

/// The solver keys issue 46 turned from booleans into strategies, read as their successors: (table,
/// old boolean, new key, its value for true, for false).
const RENAMED_KEYS: [(&str, &str, &str, &str, &str); 4] = [
    ("static", "curvilinear", "direction", "curved", "straight"),
    (
        "static",
        "carried_damping",
        "regularization",
        "carried-damping",
        "shift-ladder",
    ),
    (
        "static",
        "reuse_factorization",
        "factor_reuse",
        "chord",
        "fresh",
    ),
    (
        "dynamic",
        "reuse_factorization",
        "factor_reuse",
        "chord",
        "fresh",
    ),
];

/// Rewrites the old boolean solver keys of a scene table (`solver.static.curvilinear`,
/// `carried_damping`, `reuse_factorization`, `coarse_start` and `sag_start`,
/// `solver.dynamic.reuse_factorization`) into the strategy keys that replaced them, so that scene
/// files written before keep their meaning. Err (key, message) for a non-boolean value or an old
/// key given together with its successor.
fn read_renamed_keys(table: &mut toml::Table) -> Result<(), KeyError> {
    let Some(toml::Value::Table(solver)) = table.get_mut("solver") else {
        return Ok(());
    };
    let flag = |t: &mut toml::Table, sub: &str, old: &str| -> Result<Option<bool>, _> {
        let key = format!("solver.{sub}.{old}");
        match t.remove(old) {
            None => Ok(None),
            Some(toml::Value::Boolean(b)) => Ok(Some(b)),
            Some(v) => Err(KeyError::new(
                key,
                format!("expected a boolean, got the {} {v}", v.type_str()),
            )),
        }
    };
    for (sub, old, new, yes, no) in RENAMED_KEYS {
        let Some(toml::Value::Table(t)) = solver.get_mut(sub) else {
            continue;
        };
        if let Some(b) = flag(t, sub, old)? {
            rename_into(t, (sub, old, new), if b { yes } else { no })?;
        }
    }
    if let Some(toml::Value::Table(t)) = solver.get_mut("static") {
        let (nested, shaped) = (
            flag(t, "static", "coarse_start")?,
            flag(t, "static", "sag_start")?,
        );
        if nested.is_some() || shaped.is_some() {
            let start =
                crate::solve::Start::from_flags(nested.unwrap_or(true), shaped.unwrap_or(true));
            let name = serde_json::to_value(start)
                .map_err(|e| KeyError::new("solver.static.start", e.to_string()))?;
            let old = if nested.is_some() {
                "coarse_start"
            } else {
                "sag_start"
            };
            rename_into(
                t,
                ("static", old, "start"),
                name.as_str().unwrap_or_default(),
            )?;
        }
    }
    Ok(())
}

/// Sets `new` to `value` in the solver table `t` unless the file gives `new` itself.
fn rename_into(
    t: &mut toml::Table,
    (sub, old, new): (&str, &str, &str),
    value: &str,
) -> Result<(), KeyError> {
    if t.contains_key(new) {
        return Err(KeyError::new(
            format!("solver.{sub}.{old}"),
            format!("replaced by solver.{sub}.{new}, which is given too: keep only `{new}`"),
        ));
    }
    t.insert(new.into(), toml::Value::String(value.into()));
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn set_dotted_reaches_tables_and_array_elements() {
        let mut t: toml::Table = "[cloth]\nnx = 3\n[[loads]]\nmagnitude_N = 1.0\n"
            .parse()
            .unwrap();
        set_dotted(&mut t, "cloth.ny", toml::Value::Integer(5)).unwrap();
        set_dotted(&mut t, "loads.0.magnitude_N", toml::Value::Float(2.0)).unwrap();
        set_dotted(
            &mut t,
            "solver.static.max_iterations",
            toml::Value::Integer(9),
        )
        .unwrap();
        assert_eq!(t["cloth"]["ny"].as_integer(), Some(5));
        assert_eq!(t["loads"][0]["magnitude_N"].as_float(), Some(2.0));
        assert_eq!(
            t["solver"]["static"]["max_iterations"].as_integer(),
            Some(9)
        );
        let e = set_dotted(&mut t, "loads.3.magnitude_N", toml::Value::Float(1.0)).unwrap_err();
        assert!(e.contains("beyond"), "{e}");
        assert!(set_dotted(&mut t, "loads.x.magnitude_N", toml::Value::Float(1.0)).is_err());
        // A failed set leaves the table as it was.
        assert_eq!(t["cloth"]["nx"].as_integer(), Some(3));
    }

    #[test]
    fn the_old_solver_booleans_are_read_as_the_strategies_that_replaced_them() {
        use crate::solve::{Direction, FactorReuse, Regularization, Start};
        let hang4 = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../datasets/scenes/hang4.toml");
        let read = |sets: &[&str]| -> Result<Scene, InputError> {
            let sets: Vec<_> = sets
                .iter()
                .map(|s| crate::config::parse_override(s).unwrap())
                .collect();
            Scene::load(&hang4, &sets).map(|l| (*l.scene).clone())
        };
        let s = read(&[
            "solver.static.curvilinear=false",
            "solver.static.carried_damping=true",
            "solver.static.reuse_factorization=true",
            "solver.static.coarse_start=false",
            "solver.dynamic.reuse_factorization=false",
        ])
        .unwrap();
        let o = &s.solver.static_;
        assert_eq!(o.direction, Direction::Straight);
        assert_eq!(o.regularization, Regularization::CarriedDamping);
        assert_eq!(o.factor_reuse, FactorReuse::Chord);
        assert_eq!(o.start, Start::Shaped);
        assert_eq!(s.solver.dynamic.factor_reuse, FactorReuse::Fresh);
        let s = read(&["solver.static.sag_start=false"]).unwrap();
        assert_eq!(s.solver.static_.start, Start::NestedFlat);
        // Defaults untouched without the old keys.
        let s = read(&[]).unwrap();
        assert_eq!(s.solver.static_.start, Start::Nested);
        assert_eq!(s.solver.static_.direction, Direction::Curved);
        // An old key beside its successor, and a non-boolean, name the old key.
        let e = read(&[
            "solver.static.curvilinear=true",
            "solver.static.direction=straight",
        ])
        .unwrap_err();
        assert_eq!(e.key, "solver.static.curvilinear");
        let e = read(&["solver.static.sag_start=1"]).unwrap_err();
        assert_eq!(e.key, "solver.static.sag_start");
    }
}
