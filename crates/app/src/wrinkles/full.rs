//! `wrinkles-simulate`: seed 002's hung sheets as full continuum simulations (issues 36, 50), each
//! case of a wrinkle config solved on two meshes ([`drapelab_core::wrinkles::full`]) read as a plate
//! and as a fabric, and the map's and photographs' fabric sheets; their wrinkles measured on the
//! centre fibre by the seed's definitions. The lobe threshold of the count and Eq. 7's reading that
//! the simulations support are chosen by leave-one-out over the cases, with held-out scores. The
//! parameters are [`crate::wrinkles::params`]'s, the tables [`crate::wrinkles::tables`]'s, the report
//! and pictures the reports crate's.

use crate::job::Job;
use crate::wrinkles::params::{Variant, WrinklesSimulateParams};
use crate::wrinkles::points::{
    FitSheet, MapAxes, PointSpec, SheetRole, SheetVerdict, TensionFieldFit, fit_tension_field,
    point_specs,
};
use anyhow::Result;
use drapelab_core::cloth::Grid;
use drapelab_core::solve::{SolveReport, Status};
use drapelab_core::wrinkles::full::{self, FibreWrinkles, HungSetup, LeaveOneOut, leave_one_out};
use drapelab_core::wrinkles::{WrinkleConfig, WrinkleInputs, WrinkleMesh, WrinkleResult};
use nalgebra::Vector3;
use rayon::prelude::*;

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
        use drapelab_core::proximity::{MeshTopology, edge_triangle_crossings};
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
    /// Converged, converged in n only (z_max apart by more than [`ZMAX_AGREEMENT_REL`]), not
    /// converged in the mesh, or not converged (a solve stopped early).
    pub fn status(&self, threshold_rel: f64) -> SheetVerdict {
        if [&self.coarse, &self.fine]
            .into_iter()
            .any(|s| s.report.status != Status::Converged)
        {
            SheetVerdict::NotConverged
        } else if self.mesh_converged(threshold_rel) {
            SheetVerdict::Converged
        } else if self.coarse.wrinkles(threshold_rel).n == self.fine.wrinkles(threshold_rel).n {
            SheetVerdict::ConvergedInNOnly
        } else {
            SheetVerdict::NotConvergedInMesh
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

/// Checks the parameters, and the cases they name against the config (names the bad key).
pub fn check(ctx: &Job<'_>, cfg: &WrinkleConfig, p: &WrinklesSimulateParams) -> Result<()> {
    p.check().map_err(|e| ctx.param_error(&e.key, e.message))?;
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
    let variants = p.variants();
    let n = chosen.len();
    let jobs = solve_jobs(p, &inputs, &specs);
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

/// The solves, finer meshes first (the longest start first), as (inputs, nx, setup): the plate's
/// finer mesh, every variant's coarser one, the fabric's finer and coarser meshes, then the points'
/// finer and coarser meshes.
fn solve_jobs<'a>(
    p: &WrinklesSimulateParams,
    inputs: &'a [WrinkleInputs],
    specs: &'a [PointSpec],
) -> Vec<(&'a WrinkleInputs, usize, HungSetup)> {
    let variants = p.variants();
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
    jobs
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
            role: SheetRole::Table,
            inputs: &c.inputs,
            reading,
            n: c.fabric.as_ref()?.fine.wrinkles(t).n,
        });
    }
    for pt in found
        .points
        .iter()
        .filter(|q| q.spec.role == SheetRole::Map)
    {
        let group = found.cases.iter().position(|c| c.case == pt.spec.case);
        sheets.push(FitSheet {
            group: group.unwrap_or(found.cases.len() + sheets.len()),
            case: &pt.spec.case,
            role: SheetRole::Map,
            inputs: &pt.spec.inputs,
            reading: pt.spec.reading,
            n: pt.pair.fine.wrinkles(t).n,
        });
    }
    fit_tension_field(&p.buckling_constants, &sheets)
}
