//! `wrinkles-simulate`: seed 002's hung sheets as full continuum simulations (issue 36), each case
//! of a wrinkle config solved on two meshes ([`drapelab_core::wrinkles::full`]), its wrinkles
//! measured on the centre fibre by the seed's definitions, beside the seed's table and drapelab's
//! tension-field model. The lobe threshold of the count and the load constant c of Eq. 7 that the
//! simulations support are both chosen by leave-one-out over the cases, with held-out scores.
//! Outputs: `wrinkles_full.parquet` (one row per case), `fibres.parquet` (the centre fibres) and a
//! `.rrd` of the simulated sheets; the report and pictures are the reports crate's.

use crate::job::Job;
use anyhow::Result;
use drapelab_core::cloth::Grid;
use drapelab_core::solve::{SolveReport, Status};
use drapelab_core::table::Table;
use drapelab_core::wrinkles::full::{
    self, FibreWrinkles, HungSetup, HungStart, LeaveOneOut, SheetReading, leave_one_out,
};
use drapelab_core::wrinkles::{WrinkleConfig, WrinkleInputs, WrinkleMesh, WrinkleResult};
use nalgebra::Vector3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Parameters of a `wrinkles-simulate` stage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WrinklesSimulateParams {
    /// Grid points along the supports on the coarser mesh; the rows follow h/L at the same
    /// spacing. Default 57 (2.5 cm on a 1.4 m sheet, half the bending length (D/w)^(1/3) of
    /// Table I's fabric).
    #[serde(default = "default_coarse_nx")]
    pub coarse_nx: usize,
    /// Grid points along the supports on the finer mesh, whose wrinkles are the result. Default 113.
    #[serde(default = "default_fine_nx")]
    pub fine_nx: usize,
    /// How the sheets start: "arc" (each row bent in plan to its length between the supports, free
    /// of membrane strain), "compressed" or "folded-K". Default "arc".
    #[serde(default = "default_start")]
    pub start: HungStart,
    /// Other starts solved on the coarser mesh, to show whether the count depends on the start.
    /// Default ["compressed", "folded-3"].
    #[serde(default = "default_other_starts")]
    pub other_starts: Vec<HungStart>,
    /// In-plane shear stiffnesses tried on the coarser mesh from the result's start, as fractions of
    /// the isotropic E·t/(2(1 + ν)) the results use (a woven fabric's shear stiffness is 10⁻² to 10⁻⁴
    /// of that). Default [1e-3, 1e-4].
    #[serde(default = "default_shear_ratios")]
    pub shear_ratios: Vec<f64>,
    /// Seed of the start's out-of-plane ripple. Default 1.
    #[serde(default = "default_seed")]
    pub seed: u64,
    /// Amplitude of the start's out-of-plane ripple, m. Default 0.005.
    #[serde(default = "default_ripple")]
    pub ripple_amplitude_m: f64,
    /// Lobe thresholds tried, as fractions of the fibre's z_max, in order of preference (smallest
    /// first); the count uses the one chosen by leave-one-out on mesh agreement. Default
    /// [0, 0.002, 0.005, 0.01, 0.02]: small enough not to hide centimetre folds under the
    /// upper boundary's decimetre excursion.
    #[serde(default = "default_thresholds")]
    pub thresholds_rel: Vec<f64>,
    /// Load constants c of Eq. 7 tried against the full simulations (dimensionless; only
    /// c/(1 − ν²) enters). Default 15 values from 10 to 1e5, log-spaced and rounded, and the
    /// seed's reading 135.
    #[serde(default = "default_constants")]
    pub buckling_constants: Vec<f64>,
    /// Only the cases of these names (empty: every case). Default empty.
    #[serde(default)]
    pub cases: Vec<String>,
    /// Solve every case read as a fabric too, on both meshes (issue 50). Default true.
    #[serde(default = "default_true")]
    pub fabric: bool,
    /// The fabric reading's bending length c, m: bending rigidity w c³ both ways (Peirce), no
    /// twist rigidity. Default 0.0143, the geometric middle of the 7–29 mm at which the bundled
    /// Cusick fabrics calibrate — chosen from fabrics, not from the seed's counts.
    #[serde(default = "default_fabric_bending_length")]
    pub fabric_bending_length_m: f64,
    /// The fabric reading's in-plane shear rigidity G, N/m. Default 53.3: 0.95 gf/cm/deg, the
    /// geometric middle of KES shear of apparel fabrics (0.3–3 gf/cm/deg).
    #[serde(default = "default_fabric_shear")]
    pub fabric_shear_N_per_m: f64,
}

fn default_true() -> bool {
    true
}
fn default_fabric_bending_length() -> f64 {
    0.0143
}
fn default_fabric_shear() -> f64 {
    53.3
}
fn default_coarse_nx() -> usize {
    57
}
fn default_fine_nx() -> usize {
    113
}
fn default_start() -> HungStart {
    HungStart::Arc
}
fn default_other_starts() -> Vec<HungStart> {
    vec![HungStart::Compressed, HungStart::Folded(3)]
}
fn default_shear_ratios() -> Vec<f64> {
    vec![1e-3, 1e-4]
}
fn default_seed() -> u64 {
    1
}
fn default_ripple() -> f64 {
    0.005
}
fn default_thresholds() -> Vec<f64> {
    vec![0.0, 0.002, 0.005, 0.01, 0.02]
}
fn default_constants() -> Vec<f64> {
    let mut c: Vec<f64> = (0..15)
        .map(|k| 10f64.powf(1.0 + k as f64 * 4.0 / 14.0).round())
        .collect();
    c.push(135.0);
    c.sort_by(f64::total_cmp);
    c
}

impl Default for WrinklesSimulateParams {
    fn default() -> Self {
        Self {
            coarse_nx: default_coarse_nx(),
            fine_nx: default_fine_nx(),
            start: default_start(),
            other_starts: default_other_starts(),
            shear_ratios: default_shear_ratios(),
            seed: default_seed(),
            ripple_amplitude_m: default_ripple(),
            thresholds_rel: default_thresholds(),
            buckling_constants: default_constants(),
            cases: Vec::new(),
            fabric: true,
            fabric_bending_length_m: default_fabric_bending_length(),
            fabric_shear_N_per_m: default_fabric_shear(),
        }
    }
}

/// z_max of the two meshes must agree within this fraction for a case to count as converged in
/// the mesh (the 10 %).
pub const ZMAX_AGREEMENT_REL: f64 = 0.10;

/// One solved sheet.
pub struct SheetSolve {
    /// Its grid.
    pub grid: Grid,
    /// Final positions, m (x along the supports, y out of plane, z up; supports at z = 0).
    pub x: Vec<Vector3<f64>>,
    /// How the solve went.
    pub report: SolveReport,
}

impl SheetSolve {
    /// The centre fibre, top to bottom: (depth below the supports, out-of-plane displacement), m.
    pub fn fibre(&self) -> Vec<(f64, f64)> {
        let g = &self.grid;
        (0..g.ny)
            .rev()
            .map(|j| {
                let p = self.x[g.index(g.nx / 2, j)];
                (-p.z, p.y)
            })
            .collect()
    }
    /// Edges of the triangulated sheet that cross a triangle sharing no vertex with them (the
    /// sheet passing through itself; 0 for one that does not).
    pub fn self_crossings(&self) -> usize {
        use drapelab_core::contact::proximity::{MeshTopology, edge_triangle_crossings};
        let topo = MeshTopology::from_triangles(drapelab_core::cloth::cell_triangles(
            self.grid.nx,
            self.grid.ny,
        ));
        let mut edges: Vec<u32> = edge_triangle_crossings(&topo, &self.x[..self.grid.len()])
            .into_iter()
            .map(|c| c.0)
            .collect();
        edges.sort_unstable();
        edges.dedup();
        edges.len()
    }
    /// Wrinkles on the centre fibre with lobes from `threshold_rel` of z_max.
    pub fn wrinkles(&self, threshold_rel: f64) -> FibreWrinkles {
        full::sheet_wrinkles(&self.grid, &self.x, threshold_rel)
    }
    /// The sheet as a mesh (x, depth, out of plane), for recordings.
    pub fn mesh(&self) -> WrinkleMesh {
        WrinkleMesh {
            nx: self.grid.nx,
            ny: self.grid.ny,
            points: (0..self.grid.ny)
                .rev()
                .flat_map(|j| (0..self.grid.nx).map(move |i| (i, j)))
                .map(|(i, j)| {
                    let p = self.x[self.grid.index(i, j)];
                    [p.x, -p.z, p.y]
                })
                .collect(),
        }
    }
}

/// A start and a shear stiffness (fraction of the isotropic one).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Variant {
    /// The start.
    pub start: HungStart,
    /// In-plane shear stiffness as a fraction of E·t/(2(1 + ν)).
    pub shear_ratio: f64,
}

impl WrinklesSimulateParams {
    /// The result's variant, then the other starts, then the other shear stiffnesses.
    pub fn variants(&self) -> Vec<Variant> {
        let v = |start, shear_ratio| Variant { start, shear_ratio };
        std::iter::once(v(self.start, 1.0))
            .chain(self.other_starts.iter().map(|&s| v(s, 1.0)))
            .chain(self.shear_ratios.iter().map(|&r| v(self.start, r)))
            .collect()
    }
    fn setup(&self, v: Variant) -> HungSetup {
        HungSetup {
            start: v.start,
            ripple_amplitude_m: self.ripple_amplitude_m,
            seed: self.seed,
            reading: SheetReading::Plate {
                shear_ratio: v.shear_ratio,
            },
        }
    }
    /// The fabric reading of these parameters.
    pub fn fabric_reading(&self) -> SheetReading {
        SheetReading::Fabric {
            bending_length_m: self.fabric_bending_length_m,
            shear_N_per_m: self.fabric_shear_N_per_m,
        }
    }
}

/// One case: its inputs, the seed's result, the tension-field model's and the two simulations.
pub struct SimulatedCase {
    /// Case name.
    pub case: String,
    /// Its inputs.
    pub inputs: WrinkleInputs,
    /// The seed's published n, z_max (cm) and Q, where it gives them.
    pub seed: Option<drapelab_core::wrinkles::SeedResult>,
    /// drapelab's tension-field model with the config's ν and c.
    pub tension_field: WrinkleResult,
    /// The case read as seed 002's plate, from the result's start on both meshes.
    pub plate: MeshPair,
    /// The other variants' solves on the coarser mesh: the other starts (shear ratio 1), then the
    /// result's start with each of the other shear stiffnesses.
    pub others: Vec<(Variant, SheetSolve)>,
    /// The case read as a fabric, from the result's start on both meshes (issue 50), if asked.
    pub fabric: Option<MeshPair>,
}

/// One reading of a case solved on both meshes.
pub struct MeshPair {
    /// The coarser mesh's solve.
    pub coarse: SheetSolve,
    /// The finer mesh's solve, the result.
    pub fine: SheetSolve,
}

impl MeshPair {
    /// Both solves reached an equilibrium.
    pub fn solved(&self) -> bool {
        [&self.coarse, &self.fine]
            .iter()
            .all(|s| s.report.status == Status::Converged)
    }
    /// Both meshes give the same n and z_max within [`ZMAX_AGREEMENT_REL`] at `threshold_rel`.
    pub fn mesh_converged(&self, threshold_rel: f64) -> bool {
        let (c, f) = (
            self.coarse.wrinkles(threshold_rel),
            self.fine.wrinkles(threshold_rel),
        );
        self.solved()
            && c.n == f.n
            && (c.zmax_m - f.zmax_m).abs() <= ZMAX_AGREEMENT_REL * f.zmax_m.max(1e-12)
    }
    /// "converged", "not converged in the mesh", or why a solve stopped.
    pub fn status(&self, threshold_rel: f64) -> String {
        if let Some(s) = [&self.coarse, &self.fine]
            .into_iter()
            .find(|s| s.report.status != Status::Converged)
        {
            format!(
                "not converged: {} ({}x{})",
                s.report.status, s.grid.nx, s.grid.ny
            )
        } else if self.mesh_converged(threshold_rel) {
            "converged".into()
        } else {
            "not converged in the mesh".into()
        }
    }
}

/// Everything the stage found.
pub struct WrinklesFull {
    /// The cases, in the config's order.
    pub cases: Vec<SimulatedCase>,
    /// The lobe thresholds tried.
    pub thresholds_rel: Vec<f64>,
    /// The threshold chosen by leave-one-out on mesh agreement.
    pub threshold: LeaveOneOut,
    /// The load constants of Eq. 7 tried.
    pub buckling_constants: Vec<f64>,
    /// n of the tension-field model for each case and constant.
    pub tension_field_n: Vec<Vec<usize>>,
    /// The constant chosen by leave-one-out on agreement (±1) with the full simulation.
    pub constant: LeaveOneOut,
    /// The same against the sheets read as fabric (issue 50), where every case has them.
    pub constant_fabric: Option<LeaveOneOut>,
}

impl WrinklesFull {
    /// The lobe threshold the counts use.
    pub fn threshold_rel(&self) -> f64 {
        self.thresholds_rel[self.threshold.chosen]
    }
    /// Cases where the tension-field model with constant number `k` is within ±1 of the
    /// simulation.
    pub fn agreement(&self, k: usize) -> usize {
        self.agreement_rows().iter().filter(|row| row[k]).count()
    }
    fn agreement_rows(&self) -> Vec<Vec<bool>> {
        let t = self.threshold_rel();
        let n: Vec<usize> = self
            .cases
            .iter()
            .map(|c| c.plate.fine.wrinkles(t).n)
            .collect();
        self.agreement_with(&n)
    }
    /// The fabric reading's counts (finer mesh), one per case, if every case has them.
    pub fn fabric_counts(&self) -> Option<Vec<usize>> {
        let t = self.threshold_rel();
        self.cases
            .iter()
            .map(|c| c.fabric.as_ref().map(|f| f.fine.wrinkles(t).n))
            .collect()
    }
    /// For each case and constant: is the tension field within ±1 of `n[case]`?
    pub fn agreement_with(&self, n: &[usize]) -> Vec<Vec<bool>> {
        self.tension_field_n
            .iter()
            .zip(n)
            .map(|(ns, &n)| ns.iter().map(|&m| m.abs_diff(n) <= 1).collect())
            .collect()
    }
    /// The counts of the sheets with in-plane shear stiffness `ratio` of the isotropic one
    /// (coarser mesh), one per case, if every case has that variant.
    pub fn shear_counts(&self, ratio: f64) -> Option<Vec<usize>> {
        let t = self.threshold_rel();
        self.cases
            .iter()
            .map(|c| {
                c.others
                    .iter()
                    .find(|(v, _)| v.shear_ratio == ratio)
                    .map(|(_, s)| s.wrinkles(t).n)
            })
            .collect()
    }
}

/// The grid of a case with `nx` points along the supports and rows at the same spacing.
pub fn case_grid(inp: &WrinkleInputs, nx: usize) -> (usize, usize) {
    let ny = ((nx - 1) as f64 * inp.height_m / inp.length_m).round() as usize + 1;
    (nx, ny.max(3))
}

impl WrinklesSimulateParams {
    /// Checks the parameters by themselves: the bad key and why.
    pub fn check(&self) -> std::result::Result<(), (&'static str, String)> {
        let bad = |key, m: &str| Err((key, m.to_string()));
        if self.coarse_nx < 5 {
            return bad("coarse_nx", "must be at least 5");
        }
        if self.fine_nx <= self.coarse_nx {
            return bad("fine_nx", "must be larger than coarse_nx");
        }
        if !(self.ripple_amplitude_m.is_finite() && self.ripple_amplitude_m > 0.0) {
            return bad("ripple_amplitude_m", "must be a positive length in m");
        }
        if self.thresholds_rel.is_empty()
            || self.thresholds_rel.iter().any(|t| !(0.0..1.0).contains(t))
        {
            return bad(
                "thresholds_rel",
                "must be fractions in [0, 1), at least one",
            );
        }
        if self.buckling_constants.is_empty()
            || self
                .buckling_constants
                .iter()
                .any(|c| !(c.is_finite() && *c > 0.0))
        {
            return bad(
                "buckling_constants",
                "must be positive numbers, at least one",
            );
        }
        if self
            .shear_ratios
            .iter()
            .any(|r| !(r.is_finite() && *r > 0.0))
        {
            return bad("shear_ratios", "must be positive fractions");
        }
        if !(self.fabric_bending_length_m.is_finite() && self.fabric_bending_length_m > 0.0) {
            return bad("fabric_bending_length_m", "must be a positive length in m");
        }
        if !(self.fabric_shear_N_per_m.is_finite() && self.fabric_shear_N_per_m > 0.0) {
            return bad("fabric_shear_N_per_m", "must be a positive rigidity in N/m");
        }
        Ok(())
    }
}

/// Checks the parameters, and the cases they name against the config (names the bad key).
pub fn check(ctx: &Job<'_>, cfg: &WrinkleConfig, p: &WrinklesSimulateParams) -> Result<()> {
    p.check().map_err(|(k, m)| ctx.param_error(k, m))?;
    if let Some(name) = p
        .cases
        .iter()
        .find(|n| !cfg.cases.iter().any(|c| &c.case == *n))
    {
        return Err(ctx
            .param_error("cases", format!("no case `{name}` in the config"))
            .into());
    }
    Ok(())
}

/// Solves every case (or those named) on both meshes, in parallel, and makes the two
/// leave-one-out choices.
pub fn simulate(
    ctx: &Job<'_>,
    cfg: &WrinkleConfig,
    p: &WrinklesSimulateParams,
) -> Result<WrinklesFull> {
    check(ctx, cfg, p)?;
    let chosen: Vec<_> = cfg
        .cases
        .iter()
        .filter(|c| p.cases.is_empty() || p.cases.contains(&c.case))
        .collect();
    // Finer meshes first: the longest solves start first. Job (case, nx, setup): the plate's
    // finer mesh, every variant's coarser one, then the fabric's finer and coarser meshes.
    let variants = p.variants();
    let n = chosen.len();
    let fabric = HungSetup {
        reading: p.fabric_reading(),
        ..p.setup(variants[0])
    };
    let mut jobs: Vec<(usize, usize, HungSetup)> = (0..n)
        .map(|k| (k, p.fine_nx, p.setup(variants[0])))
        .collect();
    for v in &variants {
        jobs.extend((0..n).map(|k| (k, p.coarse_nx, p.setup(*v))));
    }
    if p.fabric {
        jobs.extend((0..n).map(|k| (k, p.fine_nx, fabric)));
        jobs.extend((0..n).map(|k| (k, p.coarse_nx, fabric)));
    }
    ctx.started(jobs.len());
    let mut solves: Vec<Option<SheetSolve>> = jobs
        .par_iter()
        .map(|&(k, nx, setup)| {
            let inp = chosen[k].inputs(&cfg.defaults);
            let s = full::solve_hung(&inp, case_grid(&inp, nx), &setup);
            ctx.item_done();
            s.map(|s| SheetSolve {
                grid: s.grid,
                x: s.x,
                report: s.report,
            })
            .map(Some)
        })
        .collect::<std::result::Result<_, _>>()?;
    let fabric_at = (variants.len() + 1) * n;
    let cases: Vec<SimulatedCase> = chosen
        .iter()
        .enumerate()
        .map(|(k, c)| {
            let inputs = c.inputs(&cfg.defaults);
            let mut take = |slot: usize| solves[slot].take().expect("each solve once");
            SimulatedCase {
                case: c.case.clone(),
                tension_field: drapelab_core::wrinkles::solve(&inputs),
                inputs,
                seed: c.seed.clone(),
                plate: MeshPair {
                    fine: take(k),
                    coarse: take(n + k),
                },
                others: variants[1..]
                    .iter()
                    .enumerate()
                    .map(|(o, v)| (*v, take((o + 2) * n + k)))
                    .collect(),
                fabric: p.fabric.then(|| MeshPair {
                    fine: take(fabric_at + k),
                    coarse: take(fabric_at + n + k),
                }),
            }
        })
        .collect();
    Ok(choose(cases, p))
}

/// The leave-one-out choices over the solved cases.
fn choose(cases: Vec<SimulatedCase>, p: &WrinklesSimulateParams) -> WrinklesFull {
    let ok: Vec<Vec<bool>> = cases
        .iter()
        .map(|c| {
            p.thresholds_rel
                .iter()
                .map(|&t| c.plate.mesh_converged(t))
                .collect()
        })
        .collect();
    let threshold = leave_one_out(&ok);
    let tension_field_n: Vec<Vec<usize>> = cases
        .iter()
        .map(|c| {
            p.buckling_constants
                .iter()
                .map(|&b| {
                    let inp = WrinkleInputs {
                        buckling_constant: b,
                        ..c.inputs.clone()
                    };
                    drapelab_core::wrinkles::solve(&inp).n
                })
                .collect()
        })
        .collect();
    let mut out = WrinklesFull {
        cases,
        thresholds_rel: p.thresholds_rel.clone(),
        threshold,
        buckling_constants: p.buckling_constants.clone(),
        tension_field_n,
        constant: LeaveOneOut {
            chosen: 0,
            held_out: Vec::new(),
        },
        constant_fabric: None,
    };
    out.constant = leave_one_out(&out.agreement_rows());
    out.constant_fabric = out
        .fabric_counts()
        .map(|n| leave_one_out(&out.agreement_with(&n)));
    out
}

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
    /// "converged", "not converged in the mesh" (the meshes disagree on n or on z_max by more than
    /// 10 %), or "not converged: STATUS (GRID)" for a solve that stopped early.
    pub status: String,
    /// How the sheet's bending and shear were read from the case: "plate" (seed 002's E t³/12 and
    /// E t/2(1 + ν)) or "fabric" (a bending length and a shear rigidity of real fabrics).
    pub reading: String,
    /// The sheet's bending length (B/w)^(1/3), m.
    pub bending_length_m: f64,
    /// The sheet's in-plane shear rigidity, N/m.
    pub shear_rigidity_N_per_m: f64,
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
    pub reading: String,
    /// "fine" or "coarse".
    pub mesh: String,
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
    pub status: String,
    /// Edges of the sheet that pass through it.
    pub self_crossing_edges: u32,
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
                status: s.report.status.to_string(),
                self_crossing_edges: s.self_crossings() as u32,
            });
        }
    }
    out
}

/// The result table: every case read as a plate, then every case read as a fabric.
pub fn rows(found: &WrinklesFull, p: &WrinklesSimulateParams) -> Vec<WrinkleFullRow> {
    let plate = SheetReading::Plate { shear_ratio: 1.0 };
    let fabric = p.fabric_reading();
    let plates = found.cases.iter().map(|c| row(found, c, &plate, &c.plate));
    let fabrics = found
        .cases
        .iter()
        .filter_map(|c| Some(row(found, c, &fabric, c.fabric.as_ref()?)));
    plates.chain(fabrics).collect()
}

/// One case under one reading.
fn row(
    found: &WrinklesFull,
    c: &SimulatedCase,
    reading: &SheetReading,
    pair: &MeshPair,
) -> WrinkleFullRow {
    let t = found.threshold_rel();
    let (wf, wc) = (pair.fine.wrinkles(t), pair.coarse.wrinkles(t));
    let grid = |s: &SheetSolve| format!("{}x{}", s.grid.nx, s.grid.ny);
    WrinkleFullRow {
        case: c.case.clone(),
        n_seed: c.seed.as_ref().map(|r| r.n as i32),
        n_tension_field: c.tension_field.n as i32,
        n_full_simulation: wf.n as i32,
        n_full_simulation_coarse: wc.n as i32,
        z_max_full_simulation_m: wf.zmax_m,
        wall_time_s: pair.fine.report.wall_time_s + pair.coarse.report.wall_time_s,
        status: pair.status(t),
        reading: reading.name().into(),
        bending_length_m: reading.bending_length_m(&c.inputs),
        shear_rigidity_N_per_m: reading.rigidities(&c.inputs).2,
        z_max_full_simulation_coarse_m: wc.zmax_m,
        z_max_seed_m: c.seed.as_ref().map(|r| r.zmax_cm / 100.0),
        z_max_tension_field_m: c.tension_field.zmax_m,
        q_seed: c.seed.as_ref().map(|r| r.q),
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
    }
}

/// Each case's readings: ("plate", its solves), then ("fabric", its solves) where solved.
fn readings(c: &SimulatedCase) -> impl Iterator<Item = (&'static str, &MeshPair)> {
    std::iter::once(("plate", &c.plate)).chain(c.fabric.as_ref().map(|f| ("fabric", f)))
}

/// The centre fibres of both meshes.
pub fn fibre_rows(found: &WrinklesFull) -> Vec<FibreRow> {
    let mut out = Vec::new();
    for c in &found.cases {
        for (reading, pair) in readings(c) {
            for (mesh, s) in [("fine", &pair.fine), ("coarse", &pair.coarse)] {
                out.extend(
                    s.fibre()
                        .into_iter()
                        .enumerate()
                        .map(|(k, (d, y))| FibreRow {
                            case: c.case.clone(),
                            reading: reading.into(),
                            mesh: mesh.into(),
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
        let meshes: Vec<(String, WrinkleMesh)> = found
            .cases
            .iter()
            .flat_map(|c| {
                readings(c).flat_map(move |(reading, pair)| {
                    [
                        (format!("{}/{reading}/fine", c.case), pair.fine.mesh()),
                        (format!("{}/{reading}/coarse", c.case), pair.coarse.mesh()),
                    ]
                })
            })
            .collect();
        drapelab_record::write_wrinkle_meshes(out, &meshes)?;
    }
    Ok(())
}

/// Loads the config (input `config`), simulates and writes the tables and recording.
pub fn run(ctx: &Job<'_>, p: &WrinklesSimulateParams) -> Result<WrinklesFull> {
    let cfg = drapelab_core::wrinkles::load_config(ctx.input("config")?)?;
    let found = simulate(ctx, &cfg, p)?;
    write_outputs(ctx, &found, p)?;
    Ok(found)
}
