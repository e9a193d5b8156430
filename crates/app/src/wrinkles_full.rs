//! `wrinkles-simulate`: seed 002's hung sheets as full continuum simulations (issue 36), each case
//! of a wrinkle config solved on two meshes ([`drapelab_core::wrinkles::full`]), its wrinkles
//! measured on the centre fibre by the seed's definitions, beside the seed's table and drapelab's
//! tension-field model. The lobe threshold of the count and the load constant c of Eq. 7 that the
//! simulations support are both chosen by leave-one-out over the cases, with held-out scores.
//! Outputs: `wrinkles_full.parquet` (one row per case), `fibres.parquet` (the centre fibres) and a
//! `.rrd` of the simulated sheets; the report and pictures are the reports crate's.

use crate::job::Job;
use crate::wrinkles_points::{
    FitSheet, MapAxes, PointRole, PointSpec, TensionFieldFit, fit_tension_field, point_specs,
};
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
    /// Grid points along the supports of the fabric reading's coarser mesh. Default 85: at 57
    /// (2.5 cm, longer than a fabric's bending length) six of the twelve sheets fold once where the
    /// finer meshes fold three times (issue 50's mesh study: n = 1, 3, 3, 3 on 29, 57, 85, 113
    /// points for I-h140). Must be below `fabric_fine_nx`.
    #[serde(default = "default_fabric_coarse_nx")]
    pub fabric_coarse_nx: usize,
    /// Grid points along the supports of the fabric reading's finer mesh, whose wrinkles are the
    /// result. Default 113.
    #[serde(default = "default_fine_nx")]
    pub fabric_fine_nx: usize,
    /// The cases of the map (issue 50): each solved read as fabric at every bending length ×
    /// shear rigidity below. Default empty (no map); the bundled pipeline names Table I's.
    #[serde(default)]
    pub map_cases: Vec<String>,
    /// The map's bending lengths, m. Default [0.007, 0.029]: the ends of the Cusick fabrics' range.
    #[serde(default = "default_map_lengths")]
    pub map_bending_lengths_m: Vec<f64>,
    /// The map's shear rigidities, N/m. Default [17, 170]: KES 0.3 and 3 gf/cm/deg.
    #[serde(default = "default_map_shears")]
    pub map_shear_N_per_m: Vec<f64>,
    /// Grid points along the supports of the map's and the photographs' coarser mesh. Default 57.
    #[serde(default = "default_coarse_nx")]
    pub points_coarse_nx: usize,
    /// ... and of their finer mesh, whose wrinkles are reported. Default 85.
    #[serde(default = "default_fabric_coarse_nx")]
    pub points_fine_nx: usize,
}

fn default_fabric_coarse_nx() -> usize {
    85
}
fn default_map_lengths() -> Vec<f64> {
    vec![0.007, 0.029]
}
fn default_map_shears() -> Vec<f64> {
    vec![17.0, 170.0]
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
            fabric_coarse_nx: default_fabric_coarse_nx(),
            fabric_fine_nx: default_fine_nx(),
            map_cases: Vec::new(),
            map_bending_lengths_m: default_map_lengths(),
            map_shear_N_per_m: default_map_shears(),
            points_coarse_nx: default_coarse_nx(),
            points_fine_nx: default_fabric_coarse_nx(),
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
    /// "converged", "converged in n only" (z_max apart by more than [`ZMAX_AGREEMENT_REL`]), "not
    /// converged in the mesh", or why a solve stopped.
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
        } else if self.coarse.wrinkles(threshold_rel).n == self.fine.wrinkles(threshold_rel).n {
            "converged in n only".into()
        } else {
            "not converged in the mesh".into()
        }
    }
}

/// A solved [`PointSpec`].
pub struct FabricPoint {
    /// What was solved.
    pub spec: PointSpec,
    /// The tension-field model with the config's Eq. 7.
    pub tension_field: WrinkleResult,
    /// Its solves on the points' two meshes.
    pub pair: MeshPair,
}

impl FabricPoint {
    /// "CASE/fabric-c7_0mm-G17Npm": the sheet's name in recordings.
    pub fn label(&self) -> String {
        let (c_b, g) = (
            self.spec.reading.bending_length_m(&self.spec.inputs),
            self.spec.reading.rigidities(&self.spec.inputs).2,
        );
        let mm = format!("{:.1}", 1e3 * c_b).replace('.', "_");
        format!("{}/fabric-c{mm}mm-G{g:.0}Npm", self.spec.case)
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
    /// The map's and the photographs' fabric sheets (issue 50).
    pub points: Vec<FabricPoint>,
    /// Eq. 7 refitted to the fabric sheets (issue 50), where every case was read as fabric.
    pub fabric_fit: Option<TensionFieldFit>,
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
        for (coarse, fine, key) in [
            (self.fabric_coarse_nx, self.fabric_fine_nx, "fabric_fine_nx"),
            (self.points_coarse_nx, self.points_fine_nx, "points_fine_nx"),
        ] {
            if coarse < 5 || fine <= coarse {
                return bad(
                    key,
                    "must be larger than its coarser mesh's, which must be at least 5",
                );
            }
        }
        let bad_list = |v: &[f64]| v.is_empty() || v.iter().any(|x| !(x.is_finite() && *x > 0.0));
        if bad_list(&self.map_bending_lengths_m) {
            return bad(
                "map_bending_lengths_m",
                "must be positive lengths in m, at least one",
            );
        }
        if bad_list(&self.map_shear_N_per_m) {
            return bad(
                "map_shear_N_per_m",
                "must be positive rigidities in N/m, at least one",
            );
        }
        Ok(())
    }
}

/// Checks the parameters, and the cases they name against the config (names the bad key).
pub fn check(ctx: &Job<'_>, cfg: &WrinkleConfig, p: &WrinklesSimulateParams) -> Result<()> {
    p.check().map_err(|(k, m)| ctx.param_error(k, m))?;
    for (key, names) in [("cases", &p.cases), ("map_cases", &p.map_cases)] {
        if let Some(name) = names
            .iter()
            .find(|n| !cfg.cases.iter().any(|c| &c.case == *n))
        {
            return Err(ctx
                .param_error(key, format!("no case `{name}` in the config"))
                .into());
        }
    }
    Ok(())
}

/// Solves every case (or those named) on both meshes, and the map's and the photographs' fabric
/// sheets on theirs, in parallel, and makes the leave-one-out choices.
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
    let inputs: Vec<WrinkleInputs> = chosen.iter().map(|c| c.inputs(&cfg.defaults)).collect();
    let map = MapAxes {
        cases: &p.map_cases,
        bending_lengths_m: &p.map_bending_lengths_m,
        shear_N_per_m: &p.map_shear_N_per_m,
    };
    let specs = point_specs(cfg, &map, p.fabric.then(|| p.fabric_reading()));
    // Finer meshes first: the longest solves start first. Jobs (inputs, nx, setup): the plate's
    // finer mesh, every variant's coarser one, the fabric's finer and coarser meshes, then the
    // points' finer and coarser meshes.
    let variants = p.variants();
    let n = chosen.len();
    let fabric = HungSetup {
        reading: p.fabric_reading(),
        ..p.setup(variants[0])
    };
    let each = |nx: usize, setup: HungSetup| inputs.iter().map(move |i| (i, nx, setup));
    let mut jobs: Vec<(&WrinkleInputs, usize, HungSetup)> =
        each(p.fine_nx, p.setup(variants[0])).collect();
    for v in &variants {
        jobs.extend(each(p.coarse_nx, p.setup(*v)));
    }
    if p.fabric {
        jobs.extend(each(p.fabric_fine_nx, fabric));
        jobs.extend(each(p.fabric_coarse_nx, fabric));
    }
    for nx in [p.points_fine_nx, p.points_coarse_nx] {
        jobs.extend(specs.iter().map(|s| {
            let setup = HungSetup {
                reading: s.reading,
                ..fabric
            };
            (&s.inputs, nx, setup)
        }));
    }
    let mut solves = solve_all(ctx, &jobs)?
        .into_iter()
        .map(Some)
        .collect::<Vec<_>>();
    let mut take = |slot: usize| solves[slot].take().expect("each solve once");
    let fabric_at = (variants.len() + 1) * n;
    let mut cases = Vec::with_capacity(n);
    for (k, (c, inputs)) in chosen.iter().zip(inputs.iter()).enumerate() {
        cases.push(SimulatedCase {
            case: c.case.clone(),
            tension_field: drapelab_core::wrinkles::solve(inputs),
            inputs: inputs.clone(),
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
        });
    }
    let points_at = fabric_at + if p.fabric { 2 * n } else { 0 };
    let m = specs.len();
    let points = specs
        .into_iter()
        .enumerate()
        .map(|(k, spec)| FabricPoint {
            tension_field: drapelab_core::wrinkles::solve(&spec.inputs),
            spec,
            pair: MeshPair {
                fine: take(points_at + k),
                coarse: take(points_at + m + k),
            },
        })
        .collect();
    Ok(choose(cases, points, p))
}

/// Solves every job (inputs, grid points along the supports, setup) in parallel, with progress.
fn solve_all(
    ctx: &Job<'_>,
    jobs: &[(&WrinkleInputs, usize, HungSetup)],
) -> Result<Vec<SheetSolve>> {
    ctx.started(jobs.len());
    let solves = jobs
        .par_iter()
        .map(|&(inp, nx, setup)| {
            let s = full::solve_hung(inp, case_grid(inp, nx), &setup);
            ctx.item_done();
            s.map(|s| SheetSolve {
                grid: s.grid,
                x: s.x,
                report: s.report,
            })
        })
        .collect::<std::result::Result<_, _>>()?;
    Ok(solves)
}

/// The leave-one-out choices over the solved cases.
fn choose(
    cases: Vec<SimulatedCase>,
    points: Vec<FabricPoint>,
    p: &WrinklesSimulateParams,
) -> WrinklesFull {
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
                        bending_length_m: None,
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
        points,
        fabric_fit: None,
    };
    out.constant = leave_one_out(&out.agreement_rows());
    out.fabric_fit = fit_fabric(&out, p);
    out
}

/// Eq. 7 refitted to the fabric sheets: the cases' results, then the map's points (each in its
/// case's group); none unless every case was read as fabric.
fn fit_fabric(found: &WrinklesFull, p: &WrinklesSimulateParams) -> Option<TensionFieldFit> {
    let t = found.threshold_rel();
    let reading = p.fabric_reading();
    let mut sheets: Vec<FitSheet<'_>> = Vec::new();
    for (k, c) in found.cases.iter().enumerate() {
        sheets.push(FitSheet {
            group: k,
            case: &c.case,
            role: "table",
            inputs: &c.inputs,
            reading,
            n: c.fabric.as_ref()?.fine.wrinkles(t).n,
        });
    }
    for pt in found
        .points
        .iter()
        .filter(|q| q.spec.role == PointRole::Map)
    {
        let group = found.cases.iter().position(|c| c.case == pt.spec.case);
        sheets.push(FitSheet {
            group: group.unwrap_or(found.cases.len() + sheets.len()),
            case: &pt.spec.case,
            role: "map",
            inputs: &pt.spec.inputs,
            reading: pt.spec.reading,
            n: pt.pair.fine.wrinkles(t).n,
        });
    }
    fit_tension_field(&p.buckling_constants, &sheets)
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
    /// "converged", "converged in n only" (the meshes agree on n, not on z_max within 10 %), "not
    /// converged in the mesh" (they disagree on n), or "not converged: STATUS (GRID)" for a solve
    /// that stopped early.
    pub status: String,
    /// How the sheet's bending and shear were read from the case: "plate" (seed 002's E t³/12 and
    /// E t/2(1 + ν)) or "fabric" (a bending length and a shear rigidity of real fabrics).
    pub reading: String,
    /// The sheet's bending length (B/w)^(1/3), m.
    pub bending_length_m: f64,
    /// The sheet's in-plane shear rigidity, N/m.
    pub shear_rigidity_N_per_m: f64,
    /// Why the sheet was solved: "table" (the case's result under its reading), "map" (a point of
    /// the map over bending length × shear rigidity) or "photograph" (the seed's Fig. 4).
    pub role: String,
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
    /// "table", "map" or "photograph".
    pub role: &'static str,
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
            role: "table",
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
            role: self.spec.role.name(),
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
        reading: reading.name().into(),
        bending_length_m: reading.bending_length_m(c.inputs),
        shear_rigidity_N_per_m: reading.rigidities(c.inputs).2,
        role: c.role.into(),
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
        let cases = found.cases.iter().flat_map(|c| {
            readings(c).map(move |(reading, pair)| (format!("{}/{reading}", c.case), pair))
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

/// Loads the config (input `config`), simulates and writes the tables and recording.
pub fn run(ctx: &Job<'_>, p: &WrinklesSimulateParams) -> Result<WrinklesFull> {
    let cfg = drapelab_core::wrinkles::load_config(ctx.input("config")?)?;
    let found = simulate(ctx, &cfg, p)?;
    write_outputs(ctx, &found, p)?;
    Ok(found)
}
