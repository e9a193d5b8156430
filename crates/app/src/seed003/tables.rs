//! The tables of a `seed003-solve` stage: seed 003's scenes solved at two grids, their drapes, and the
//! studies its report sets beside the seed's Tables 10.1, 10.2 and 10.4 and §10.3.3's loading.

use drapelab_core::scene::ContactMethod;
use drapelab_core::solve::Status;
use drapelab_core::table::Table;
use serde::{Deserialize, Serialize};

/// One scene solved at its grid and at twice its resolution (2n − 1 lines per side).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Seed003SceneRow {
    /// Scene name.
    pub scene: String,
    /// Grid lines along x.
    pub nx: u32,
    /// Grid lines along y.
    pub ny: u32,
    /// Contact treatment (None: the scene has no obstacle).
    pub contact: Option<ContactMethod>,
    /// Status of the solve at the scene's grid.
    pub status: Status,
    /// Its Newton iterations (or steps).
    pub iterations: u64,
    /// Its wall time, s.
    pub wall_time_s: f64,
    /// Status of the solve at twice the resolution.
    pub fine_status: Status,
    /// Its wall time, s.
    pub fine_wall_time_s: f64,
    /// Largest distance between a particle and the same material point of the finer drape, m (None
    /// unless both converged).
    pub grid_gap_m: Option<f64>,
    /// Drape coefficient of the vertical projection, % (None unless converged, or not on a support).
    pub drape_coefficient_pct: Option<f64>,
    /// Nodes of the projection's outline (None likewise, and for a quarter model).
    pub folds: Option<u32>,
    /// Deepest penetration into an obstacle, m (None unless converged).
    pub max_penetration_m: Option<f64>,
    /// Whether pictures show it also from above (a drape on a table or pedestal).
    pub from_above: bool,
}

impl Table for Seed003SceneRow {
    const FILE: &'static str = "scenes.parquet";
    const ROW: &'static str = "One seed 003 scene solved at its grid and at twice its resolution (a seed003-solve stage).";
}

/// One particle of a scene's drape at its own grid.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct DrapeParticleRow {
    /// Scene name.
    pub scene: String,
    /// Grid column.
    pub i: u32,
    /// Grid row.
    pub j: u32,
    /// Material coordinate along x (the grid line's), m.
    pub u_m: f64,
    /// Material coordinate along y, m.
    pub v_m: f64,
    /// Position x, m.
    pub x_m: f64,
    /// Position y, m.
    pub y_m: f64,
    /// Position z (up), m.
    pub z_m: f64,
    /// Whether the particle belongs to the sheet (a disc's corners do not).
    pub present: bool,
}

impl Table for DrapeParticleRow {
    const FILE: &'static str = "drapes.parquet";
    const ROW: &'static str = "One particle of a seed 003 drape at the scene's grid, in grid order (a seed003-solve stage).";
}

/// One of Table 10.2's edge points of the quarter table drape, as drapelab puts it.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct TableEdgeRow {
    /// The point's name in Table 10.2.
    pub point: String,
    /// Its material point along x, m.
    pub u_m: f64,
    /// Its material point along y, m.
    pub v_m: f64,
    /// Where drapelab puts it: x, m.
    pub x_m: f64,
    /// y, m.
    pub y_m: f64,
    /// Drop below the table's top (down positive), m.
    pub drop_m: f64,
}

impl Table for TableEdgeRow {
    const FILE: &'static str = "table_edges.parquet";
    const ROW: &'static str = "One of seed 003 Table 10.2's edge points of the quarter table drape, as drapelab drapes it.";
}

/// A material of the rod study (seed 003 Table 10.4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RodMaterial {
    /// Table 10.3 as the seed takes it (no twist rigidity).
    Table103,
    /// Table 10.3 with an isotropic plate's twist rigidity √(D_warp D_weft), which the KES data do
    /// not give.
    Table103Twist,
    /// Deng's (1994) finite-element material: isotropic, the warp bending rigidity in every
    /// direction.
    DengFe,
}

impl RodMaterial {
    /// Its name in the report.
    pub fn label(self) -> &'static str {
        match self {
            RodMaterial::Table103 => "Table 10.3",
            RodMaterial::Table103Twist => "Table 10.3, twist √(D_warp D_weft)",
            RodMaterial::DengFe => "Deng's FE material (isotropic D_warp)",
        }
    }
}

/// The rod drape's corners under one contact treatment and material (seed 003 Table 10.4).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct RodCornerRow {
    /// The material.
    pub material: RodMaterial,
    /// Contact treatment.
    pub contact: ContactMethod,
    /// Friction coefficient of the barrier (lagged; 0: frictionless).
    pub friction_coefficient: f64,
    /// Status of the solve.
    pub status: Status,
    /// Corner A: x, m.
    pub corner_a_x_m: f64,
    /// Corner A: y, m.
    pub corner_a_y_m: f64,
    /// Corner A: drop (down positive), m.
    pub corner_a_drop_m: f64,
    /// Corner B turned by 180° about the vertical: x, m.
    pub corner_b_x_m: f64,
    /// Corner B turned: y, m.
    pub corner_b_y_m: f64,
    /// Corner B: drop, m.
    pub corner_b_drop_m: f64,
}

impl Table for RodCornerRow {
    const FILE: &'static str = "rod.parquet";
    const ROW: &'static str = "The rod drape's corners A and B under one contact treatment and material (seed 003 Table 10.4).";
}

/// Corner A of the rod drape on one grid (the grid study of Table 10.4).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct RodGridRow {
    /// The material.
    pub material: RodMaterial,
    /// Contact treatment.
    pub contact: ContactMethod,
    /// Friction coefficient of the barrier (0 under the vertical gap).
    pub friction_coefficient: f64,
    /// Grid lines per side.
    pub grid: u32,
    /// Status of the solve.
    pub status: Status,
    /// Newton iterations.
    pub iterations: u64,
    /// Wall time, s.
    pub wall_time_s: f64,
    /// Corner A: x, m.
    pub corner_a_x_m: f64,
    /// Corner A: y, m.
    pub corner_a_y_m: f64,
    /// Corner A: drop (down positive), m.
    pub corner_a_drop_m: f64,
}

impl Table for RodGridRow {
    const FILE: &'static str = "rod_grid.parquet";
    const ROW: &'static str = "Corner A of the rod drape on one grid, per material and contact treatment (seed 003 Table 10.4's grid study).";
}

/// The cantilever's free end on one grid (seed 003 Table 10.1).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct CantileverGridRow {
    /// The cantilever scene.
    pub scene: String,
    /// The grid as Table 10.1 labels it ("uniform 20x1", "non-uniform 56x1").
    pub grid: String,
    /// The scene's grading of a non-uniform grid.
    pub grading: f64,
    /// Status of the solve.
    pub status: Status,
    /// Horizontal displacement −u of the free end, m.
    pub minus_u_m: f64,
    /// Vertical displacement w of the free end (down positive), m.
    pub w_m: f64,
    /// The exact elastica's −u, m.
    pub exact_minus_u_m: f64,
    /// The exact elastica's w, m.
    pub exact_w_m: f64,
}

impl Table for CantileverGridRow {
    const FILE: &'static str = "cantilever_grid.parquet";
    const ROW: &'static str =
        "The cantilever's free end on one grid beside the exact elastica (seed 003 Table 10.1).";
}

/// How a load–displacement curve is loaded (§10.3.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Loading {
    /// The load in equal increments, each solve starting from the last.
    Increments,
    /// The whole load at once.
    SingleStep,
}

/// One load step of the cantilever's load–displacement curve (seed 003 §10.3.3).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct LoadStepRow {
    /// The cantilever scene.
    pub scene: String,
    /// Increments or a single step.
    pub loading: Loading,
    /// Load factor reached (1: the whole weight).
    pub load_factor: f64,
    /// The free end's deflection (down positive), m.
    pub tip_deflection_m: f64,
    /// Status of this step's solve.
    pub status: Status,
    /// Newton iterations so far in this loading.
    pub iterations: u64,
    /// Wall time so far in this loading, s.
    pub wall_time_s: f64,
}

impl Table for LoadStepRow {
    const FILE: &'static str = "load_displacement.parquet";
    const ROW: &'static str =
        "One load step of the cantilever by increments or in a single step (seed 003 §10.3.3).";
}
