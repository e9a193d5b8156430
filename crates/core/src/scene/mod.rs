//! Scenes as TOML: the cloth, its material, the boundary, gravity, the solver and what to record.
//!
//! A scene file is read once into a [`Scene`] (unknown keys refused), `--set KEY=VALUE` overrides
//! are applied by dotted path before that, and [`Scene::validate`] checks every value's range.
//! Every error is an [`InputError`] naming the file and the key.

use crate::cloth::{Corner, Edge, Spacing};
use crate::material::Material;
use crate::solve::{DynamicOptions, StaticOptions};
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

mod body;
mod check;
mod check_values;
mod fabric;
mod files;
mod grid;
mod load;
mod mesh;
mod sew;

pub use body::{carry_bodies, read_body};
pub use check::{GRAVITY_M_PER_S2, MAGNITUDES, SHEET_SIDE_M, ValidatedScene};
pub use fabric::{Fabric, FabricFile};
pub use files::absolute_file_keys;
pub use mesh::mesh_files_of;

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
    /// Uniform refinements of the mesh: each splits every triangle into four at its edges'
    /// midpoints (particles about ×4, seams and groups kept; [`crate::pattern::Pattern::refined`]).
    /// Default 0 (the file as it is); at most 4. Raise it to run a bundled pattern finer, lower it
    /// with `--set` for a quick look.
    #[serde(default, skip_serializing_if = "is_zero_count")]
    pub mesh_refine: usize,
    /// The warp's direction in the mesh's plane, degrees from its +x towards +y (default 0: warp
    /// along x, as on the grid). Change it for a panel cut on the bias (45) or across the roll (90).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub warp_angle_deg: f64,
    /// The mesh's placement: rotations about x, then y, then z (degrees, right-handed) of the
    /// pattern's plane, before `origin_m` is added. Default [0, 0, 0] (flat, horizontal). [90, 0, 0]
    /// stands a pattern in the x–z plane (a curtain hung from its top).
    #[serde(default, skip_serializing_if = "is_zero3")]
    pub rotation_deg: [f64; 3],
    /// The pattern read from `mesh`, or sewn from the sewing pattern (set when the scene is loaded).
    #[serde(skip)]
    pub pattern: Option<std::sync::Arc<crate::pattern::Pattern>>,
    /// A garment from a sewing pattern instead of `mesh`: GarmentCode's JSON (`*_specification.json`,
    /// [`crate::sewing`]), relative to the scene file's folder. Its panels are triangulated at
    /// `resolution_m`, placed where the pattern places them (clear of the body), sewn without
    /// crossing on the scene's bodies in the scene's fabric, and welded into one sheet, which the
    /// scene then drapes. Needs `[material.continuum]` (or a fabric file). Default none.
    #[serde(default, rename = "pattern", skip_serializing_if = "Option::is_none")]
    pub sewing_pattern: Option<PathBuf>,
    /// A sewing pattern's mesh resolution, m: the length of its boundary segments and triangles'
    /// sides. Default 0.01 (1 cm); 0.02 for a quick look, finer for small folds.
    #[serde(
        default = "default_resolution",
        skip_serializing_if = "is_default_resolution"
    )]
    pub resolution_m: f64,
    /// How the sewing pattern was sewn (set when the scene is loaded).
    #[serde(skip)]
    pub sewing: Option<std::sync::Arc<crate::sewing::sew::SewReport>>,
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
    /// Areal density (mass per area) in kg/m² (45 g/m² = 0.045). Required unless the scene's
    /// fabric file (`material.fabric`) gives it.
    #[serde(default)]
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

fn default_resolution() -> f64 {
    0.01
}

fn is_default_resolution(r: &f64) -> bool {
    *r == 0.01
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
    pub obstacles: Vec<crate::obstacle::Obstacle>,
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
    /// Keep the sheet's edges off a mesh body's feature edges too, not only its vertices off the
    /// body ([`crate::physics::BodyEdgeBarrier`]). Default false: enough for bodies smoother than
    /// the sheet (a dress form); turn it on for sharp ones (a table's rim) whose edges a coarse
    /// sheet's edges would cut.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub body_edges: bool,
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
            body_edges: false,
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::set_dotted;
    use crate::error::InputError;
    use std::path::Path;

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
