//! The tables of `wrinkles-simulate` (issues 36, 50): one row per sheet and reading
//! (`wrinkles_full.parquet`), the centre fibres (`fibres.parquet`), every start on the coarser mesh
//! (`starts.parquet`), and the recording of every sheet.

use crate::job::Job;
use crate::wrinkles::full::{FabricPoint, MeshPair, SheetSolve, SimulatedCase, WrinklesFull};
use crate::wrinkles::params::{Variant, WrinklesSimulateParams};
use crate::wrinkles::points::{SheetRole, SheetVerdict};
use anyhow::Result;
use drapelab_core::solve::Status;
use drapelab_core::table::Table;
use drapelab_core::wrinkles::full::{HungStart, ReadingKind, SheetReading};
use drapelab_core::wrinkles::{WrinkleInputs, WrinkleMesh, WrinkleResult};
use serde::{Deserialize, Serialize};

/// One case of seed 002: the seed's table, drapelab's tension-field model and the full
/// simulation side by side (the contract columns first).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct WrinkleFullRow {
    /// Case name, as in the report ("I-h90", …).
    pub case: String,
    /// The seed's number of wrinkles (none for a case the seed does not tabulate).
    pub n_seed: Option<i32>,
    /// drapelab's tension-field model's number of wrinkles (the config's ν and c).
    pub n_tension_field: i32,
    /// Wrinkles on the simulated sheet's centre fibre, finer mesh.
    pub n_full_simulation: i32,
    /// The same on the coarser mesh.
    pub n_full_simulation_coarse: i32,
    /// Largest out-of-plane displacement on the centre fibre, finer mesh, m.
    pub z_max_full_simulation_m: f64,
    /// Wall time of both solves, s.
    pub wall_time_s: f64,
    /// "converged", "converged in n only" (the meshes agree on n, not on z_max within 10 %), "not
    /// converged in the mesh" (they disagree on n), or "not converged" (a solve stopped early:
    /// `status_fine`, `status_coarse`).
    pub status: SheetVerdict,
    /// How the sheet's bending and shear were read from the case: "plate" (seed 002's E t³/12 and
    /// E t/2(1 + ν)) or "fabric" (a bending length and a shear rigidity of real fabrics).
    pub reading: ReadingKind,
    /// The sheet's bending length (B/w)^(1/3), m.
    pub bending_length_m: f64,
    /// The sheet's in-plane shear rigidity, N/m.
    pub shear_rigidity_N_per_m: f64,
    /// Why the sheet was solved: "table" (the case's result under its reading), "map" (a point of
    /// the map over bending length × shear rigidity) or "photograph" (the seed's Fig. 4).
    pub role: SheetRole,
    /// The same on the coarser mesh, m.
    pub z_max_full_simulation_coarse_m: f64,
    /// The seed's z_max, m.
    pub z_max_seed_m: Option<f64>,
    /// The tension-field model's z_max, m.
    pub z_max_tension_field_m: f64,
    /// The seed's Q.
    pub q_seed: Option<f64>,
    /// The tension-field model's Q.
    pub q_tension_field: f64,
    /// Q = (a₀/a_n)^(1/n) of the simulated sheet's line depths (finer mesh); none without wrinkles.
    pub q_full_simulation: Option<f64>,
    /// Depths of the simulated wrinkle lines below the supports, top first (finer mesh), m.
    pub line_depths_full_simulation_m: Vec<f64>,
    /// Lobe threshold of the counts, fraction of z_max (chosen by leave-one-out).
    pub threshold_rel: f64,
    /// The finer grid, "NXxNY".
    pub grid: String,
    /// The coarser grid, "NXxNY".
    pub grid_coarse: String,
    /// Newton iterations on the finer mesh.
    pub iterations: u32,
    /// Newton iterations on the coarser mesh.
    pub iterations_coarse: u32,
    /// Wall time of the finer mesh's solve, s.
    pub wall_time_fine_s: f64,
    /// Energy of the finer mesh's equilibrium, J.
    pub energy_J: f64,
    /// Edges of the finer sheet that pass through it (no self-contact term: 0 says none was needed).
    pub self_crossing_edges: u32,
    /// Status of the finer mesh's solve.
    pub status_fine: Status,
    /// Status of the coarser mesh's solve.
    pub status_coarse: Status,
}

impl Table for WrinkleFullRow {
    const FILE: &'static str = "wrinkles_full.parquet";
    const ROW: &'static str =
        "One hung sheet of seed 002: the seed, the tension-field model and the full simulation.";
}

/// One point of a simulated sheet's centre fibre.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct FibreRow {
    /// Case name.
    pub case: String,
    /// "plate" or "fabric".
    pub reading: ReadingKind,
    /// "fine" or "coarse".
    pub mesh: Mesh,
    /// Grid row from the top (0: the supports' row).
    pub row: i32,
    /// Depth below the supports, m.
    pub depth_m: f64,
    /// Out-of-plane displacement, m.
    pub out_of_plane_m: f64,
}

impl Table for FibreRow {
    const FILE: &'static str = "fibres.parquet";
    const ROW: &'static str =
        "One point of a simulated hung sheet's centre fibre (seed 002 Fig. 3).";
}

/// One case solved from one start with one shear stiffness on the coarser mesh: whether the count
/// depends on the start, and what a fabric's low shear stiffness does.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct StartRow {
    /// Case name.
    pub case: String,
    /// The start ("arc", "compressed", "folded-K").
    pub start: String,
    /// In-plane shear stiffness as a fraction of the isotropic E·t/(2(1 + ν)).
    pub shear_ratio: f64,
    /// In-plane shear stiffness G·t, N/m.
    pub shear_stiffness_N_per_m: f64,
    /// Whether this is the result's start and shear stiffness (its coarser mesh).
    pub result_start: bool,
    /// The grid, "NXxNY".
    pub grid: String,
    /// Wrinkles on the centre fibre.
    pub n: i32,
    /// Largest out-of-plane displacement on the centre fibre, m.
    pub z_max_m: f64,
    /// Energy of the equilibrium reached, J (lower: a more stable state).
    pub energy_J: f64,
    /// Newton iterations.
    pub iterations: u32,
    /// The solve's status.
    pub status: Status,
    /// Edges of the sheet that pass through it.
    pub self_crossing_edges: u32,
}

/// Which of a sheet's two meshes (the `mesh` column).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Mesh {
    /// The finer.
    Fine,
    /// The coarser.
    Coarse,
}

impl Table for StartRow {
    const FILE: &'static str = "starts.parquet";
    const ROW: &'static str = "One hung sheet of seed 002 solved from one start with one shear stiffness on the coarser mesh.";
}

/// Every case from every variant on the coarser mesh, the result's first.
pub fn start_rows(found: &WrinklesFull, result_start: HungStart) -> Vec<StartRow> {
    let t = found.threshold_rel();
    let mut out = Vec::new();
    let result = Variant {
        start: result_start,
        shear_ratio: 1.0,
    };
    for c in &found.cases {
        let iso = c.inputs.youngs_modulus_Pa * c.inputs.thickness_m
            / (2.0 * (1.0 + c.inputs.poisson_ratio));
        for (v, s) in
            std::iter::once((result, &c.plate.coarse)).chain(c.others.iter().map(|(v, s)| (*v, s)))
        {
            let w = s.wrinkles(t);
            out.push(StartRow {
                case: c.case.clone(),
                start: v.start.to_string(),
                shear_ratio: v.shear_ratio,
                shear_stiffness_N_per_m: v.shear_ratio * iso,
                result_start: v == result,
                grid: format!("{}x{}", s.grid.nx, s.grid.ny),
                n: w.n as i32,
                z_max_m: w.zmax_m,
                energy_J: s.report.energy_J,
                iterations: s.report.iterations as u32,
                status: s.report.status,
                self_crossing_edges: s.self_crossings() as u32,
            });
        }
    }
    out
}

/// The result table: every case read as a plate, every case read as a fabric, then the map's and
/// the photographs' fabric sheets.
pub fn rows(found: &WrinklesFull, p: &WrinklesSimulateParams) -> Vec<WrinkleFullRow> {
    let plate = SheetReading::Plate { shear_ratio: 1.0 };
    let fabric = p.fabric_reading();
    let plates = found
        .cases
        .iter()
        .map(|c| row(found, &c.source(), &plate, &c.plate));
    let fabrics = found
        .cases
        .iter()
        .filter_map(|c| Some(row(found, &c.source(), &fabric, c.fabric.as_ref()?)));
    let points = found
        .points
        .iter()
        .map(|q| row(found, &q.source(), &q.spec.reading, &q.pair));
    plates.chain(fabrics).chain(points).collect()
}

/// What a row says of a sheet besides its solves.
pub struct RowSource<'a> {
    /// Case name.
    pub case: &'a str,
    /// A case's result, a map point or a photograph.
    pub role: crate::wrinkles::points::SheetRole,
    /// The case's inputs.
    pub inputs: &'a WrinkleInputs,
    /// The seed's result, where it gives one.
    pub seed: Option<&'a drapelab_core::wrinkles::SeedResult>,
    /// The tension-field model's.
    pub tension_field: &'a WrinkleResult,
}

impl SimulatedCase {
    /// The case as a row's source.
    pub fn source(&self) -> RowSource<'_> {
        RowSource {
            case: &self.case,
            role: crate::wrinkles::points::SheetRole::Table,
            inputs: &self.inputs,
            seed: self.seed.as_ref(),
            tension_field: &self.tension_field,
        }
    }
}

impl FabricPoint {
    /// The point as a row's source.
    pub fn source(&self) -> RowSource<'_> {
        RowSource {
            case: &self.spec.case,
            role: self.spec.role,
            inputs: &self.spec.inputs,
            seed: self.spec.seed.as_ref(),
            tension_field: &self.tension_field,
        }
    }
}

/// One sheet under one reading.
fn row(
    found: &WrinklesFull,
    c: &RowSource<'_>,
    reading: &SheetReading,
    pair: &MeshPair,
) -> WrinkleFullRow {
    let t = found.threshold_rel();
    let (wf, wc) = (pair.fine.wrinkles(t), pair.coarse.wrinkles(t));
    let grid = |s: &SheetSolve| format!("{}x{}", s.grid.nx, s.grid.ny);
    WrinkleFullRow {
        case: c.case.to_string(),
        n_seed: c.seed.map(|r| r.n as i32),
        n_tension_field: c.tension_field.n as i32,
        n_full_simulation: wf.n as i32,
        n_full_simulation_coarse: wc.n as i32,
        z_max_full_simulation_m: wf.zmax_m,
        wall_time_s: pair.fine.report.wall_time_s + pair.coarse.report.wall_time_s,
        status: pair.status(t),
        reading: reading.kind(),
        bending_length_m: reading.bending_length_m(c.inputs),
        shear_rigidity_N_per_m: reading.rigidities(c.inputs).2,
        role: c.role,
        z_max_full_simulation_coarse_m: wc.zmax_m,
        z_max_seed_m: c.seed.and_then(|r| r.zmax_cm).map(|z| z / 100.0),
        z_max_tension_field_m: c.tension_field.zmax_m,
        q_seed: c.seed.and_then(|r| r.q),
        q_tension_field: c.tension_field.q,
        q_full_simulation: wf.q,
        line_depths_full_simulation_m: wf.line_depths_m,
        threshold_rel: t,
        grid: grid(&pair.fine),
        grid_coarse: grid(&pair.coarse),
        iterations: pair.fine.report.iterations as u32,
        iterations_coarse: pair.coarse.report.iterations as u32,
        wall_time_fine_s: pair.fine.report.wall_time_s,
        energy_J: pair.fine.report.energy_J,
        self_crossing_edges: pair.fine.self_crossings() as u32,
        status_fine: pair.fine.report.status,
        status_coarse: pair.coarse.report.status,
    }
}

/// Each case's readings: (plate, its solves), then (fabric, its solves) where solved.
fn readings(c: &SimulatedCase) -> impl Iterator<Item = (ReadingKind, &MeshPair)> {
    std::iter::once((ReadingKind::Plate, &c.plate))
        .chain(c.fabric.as_ref().map(|f| (ReadingKind::Fabric, f)))
}

/// The centre fibres of both meshes.
pub fn fibre_rows(found: &WrinklesFull) -> Vec<FibreRow> {
    let mut out = Vec::new();
    for c in &found.cases {
        for (reading, pair) in readings(c) {
            for (mesh, s) in [(Mesh::Fine, &pair.fine), (Mesh::Coarse, &pair.coarse)] {
                out.extend(
                    s.fibre()
                        .into_iter()
                        .enumerate()
                        .map(|(k, (d, y))| FibreRow {
                            case: c.case.clone(),
                            reading,
                            mesh,
                            row: k as i32,
                            depth_m: d,
                            out_of_plane_m: y,
                        }),
                );
            }
        }
    }
    out
}

/// Writes the tables and the recording the job asks for (`table`, `fibres`, `starts`,
/// `recording`).
pub fn write_outputs(
    ctx: &Job<'_>,
    found: &WrinklesFull,
    p: &WrinklesSimulateParams,
) -> Result<()> {
    if let Some(out) = ctx.optional_output("starts") {
        drapelab_record::write_table(out, &start_rows(found, p.start))?;
    }
    if let Some(out) = ctx.optional_output("table") {
        drapelab_record::write_table(out, &rows(found, p))?;
    }
    if let Some(out) = ctx.optional_output("fibres") {
        drapelab_record::write_table(out, &fibre_rows(found))?;
    }
    if let Some(out) = ctx.optional_output("recording") {
        let cases = found.cases.iter().flat_map(|c| {
            readings(c).map(move |(reading, pair)| (format!("{}/{}", c.case, reading.name()), pair))
        });
        let points = found.points.iter().map(|q| (q.label(), &q.pair));
        let meshes: Vec<(String, WrinkleMesh)> = cases
            .chain(points)
            .flat_map(|(label, pair)| {
                [
                    (format!("{label}/fine"), pair.fine.mesh()),
                    (format!("{label}/coarse"), pair.coarse.mesh()),
                ]
            })
            .collect();
        drapelab_record::write_wrinkle_meshes(out, &meshes)?;
    }
    Ok(())
}
