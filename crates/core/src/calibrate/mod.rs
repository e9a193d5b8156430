//! Calibration of seed 000's mass-spring parameters against measured edges (issue 5, started): the
//! search space of Table 3 on the unit box, a cost that simulates a hang and scores its edges against
//! the measured ones (cached, non-convergence penalised and counted), and one ICA run per call.

mod gradient;
mod identifiability;
mod lattice;
mod sample;

pub use gradient::{LmReport, LmSettings, LmStop};
pub use identifiability::{Identifiability, Noise, identifiability, quadratic_half_widths};
use lattice::TANGENT_KEYS;
pub use lattice::{SharedLattice, WarmStart};
pub use sample::{
    EvaluatedCountry, OptimizerRun, SampleCalibration, SampleSettings, calibrate_sample,
};

use crate::edges::scene_view;
use crate::edges::{EdgeFit, EdgeSource, Projection, curve_distance_pct, simulated_edges};
use crate::material::Topology;
use crate::optim::{Ica, IcaReport, IcaSettings, Minimizer};
use crate::scene::Scene;
use crate::simulate::solve_scene;
use crate::solve::NoObserver;
use std::collections::HashMap;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Seed 000 Table 3's bounds, SI (elongation rate as a fraction).
#[derive(Debug, Clone, PartialEq)]
pub struct Bounds {
    /// Spring stiffness, N/m.
    pub stiffness_N_per_m: (f64, f64),
    /// Damping, N·s/m.
    pub damping_Ns_per_m: (f64, f64),
    /// Provot's elongation rate.
    pub elongation_rate: (f64, f64),
    /// Natural length, m.
    pub natural_length_m: (f64, f64),
}

impl Default for Bounds {
    fn default() -> Self {
        Self {
            stiffness_N_per_m: (500.0, 1200.0),
            damping_Ns_per_m: (10.0, 20.0),
            elongation_rate: (0.05, 0.20),
            natural_length_m: (0.04, 0.06),
        }
    }
}

/// A point of the search space.
#[derive(Debug, Clone, PartialEq)]
pub struct Params {
    /// Spring stiffness, N/m.
    pub stiffness_N_per_m: f64,
    /// Damping, N·s/m.
    pub damping_Ns_per_m: f64,
    /// Provot's elongation rate.
    pub elongation_rate: f64,
    /// Natural length, m.
    pub natural_length_m: f64,
    /// Spring families.
    pub topology: Topology,
}

impl Bounds {
    /// Maps u ∈ [0, 1]^5 to parameters; the fifth coordinate picks the topology by thirds.
    pub fn decode(&self, u: &[f64]) -> Params {
        let lerp = |(a, b): (f64, f64), t: f64| a + t.clamp(0.0, 1.0) * (b - a);
        Params {
            stiffness_N_per_m: lerp(self.stiffness_N_per_m, u[0]),
            damping_Ns_per_m: lerp(self.damping_Ns_per_m, u[1]),
            elongation_rate: lerp(self.elongation_rate, u[2]),
            natural_length_m: lerp(self.natural_length_m, u[3]),
            topology: match (u[4] * 3.0) as usize {
                0 => Topology::A,
                1 => Topology::B,
                _ => Topology::C,
            },
        }
    }
}

/// One simulated candidate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Evaluation {
    /// Cost: curve distance in % of the side, or the penalty.
    pub cost: f64,
    /// The solver's status.
    pub status: crate::solve::Status,
    /// Wall time of the simulation, s.
    pub simulation_time_s: f64,
}

/// The cost of a sample: simulate its hang with candidate parameters and score the edges.
pub struct Problem {
    /// The sample's scene (hang4 or hang2, with its density and grid).
    pub scene: Scene,
    /// Measured edges of the sample's photo.
    pub measured: Vec<EdgeFit>,
    /// Search bounds.
    pub bounds: Bounds,
    /// Side of the sample, cm.
    pub side_cm: f64,
    /// Cost given to a simulation that does not converge (counted in `failures`).
    pub penalty: f64,
    /// Reuse the evaluation of a parameter vector seen before (default true; off only to measure what
    /// the cache saves).
    pub caching: bool,
    /// Start every evaluation from the drape at the nearest node of a fixed lattice over
    /// (topology, specific stiffness, natural length), solved once per process ([`SharedLattice`]); off, from
    /// the sagged start. Either way the cost stays a pure function of the parameter vector.
    /// Default true.
    pub warm_start: bool,
    /// Start each warm-started evaluation from its lattice node's tangent prediction
    /// x(θ₀) + (dx/dθ)(θ − θ₀) rather than from the node's drape itself (where the node is an isolated
    /// minimum and the prediction's energy is the lower). Default true; off only to measure it.
    pub tangent_start: bool,
    /// Which curve of a simulated drape is compared with the photo's edges. Default the
    /// silhouette of its triangles, the curve a photo shows.
    pub edge_source: EdgeSource,
    /// How the photo's camera projected the drape (from the measured edges; orthographic if they
    /// say nothing): the simulated drape is projected the same way.
    pub projection: Projection,
    lattice: std::sync::Arc<std::sync::OnceLock<std::sync::Arc<SharedLattice>>>,
    cache: Mutex<HashMap<Vec<u64>, Evaluation>>,
    /// Simulations run (cache misses).
    pub simulations: AtomicUsize,
    /// Simulations that did not converge.
    pub failures: AtomicUsize,
}

impl Problem {
    /// A problem over `scene` against `measured` edges.
    pub fn new(scene: Scene, measured: Vec<EdgeFit>, side_cm: f64) -> Self {
        let projection = measured.first().map(|m| m.projection).unwrap_or_default();
        Self {
            scene,
            measured,
            bounds: Bounds::default(),
            side_cm,
            penalty: 100.0,
            caching: true,
            warm_start: true,
            tangent_start: true,
            edge_source: EdgeSource::default(),
            projection,
            lattice: Default::default(),
            cache: Mutex::new(HashMap::new()),
            simulations: AtomicUsize::new(0),
            failures: AtomicUsize::new(0),
        }
    }

    /// A problem over the same scene and measurement with an empty cache and counters, sharing this
    /// one's warm-start lattice (solved at most once for both): a baseline optimizer's own problem.
    pub fn fresh(&self) -> Self {
        let mut p = Self::new(self.scene.clone(), self.measured.clone(), self.side_cm);
        p.bounds = self.bounds.clone();
        p.penalty = self.penalty;
        p.caching = self.caching;
        p.warm_start = self.warm_start;
        p.edge_source = self.edge_source;
        p.projection = self.projection;
        p.lattice = self.lattice.clone();
        p
    }

    /// The scene with `p` applied.
    pub fn scene_for(&self, p: &Params) -> Scene {
        let mut s = self.scene.clone();
        let ms = s.material.mass_spring.get_or_insert_with(Default::default);
        ms.stiffness_N_per_m = p.stiffness_N_per_m;
        ms.damping_Ns_per_m = p.damping_Ns_per_m;
        ms.elongation_rate = p.elongation_rate;
        ms.natural_length_m = Some(p.natural_length_m);
        ms.topology = p.topology;
        s
    }

    /// The cache key of u: damping and elongation rate do not change a static drape and are left out.
    fn key(&self, u: &[f64]) -> Vec<u64> {
        let p = self.bounds.decode(u);
        vec![
            p.stiffness_N_per_m.to_bits(),
            p.natural_length_m.to_bits(),
            p.topology as u64,
        ]
    }

    /// The evaluation of u if it was simulated already.
    pub fn lookup(&self, u: &[f64]) -> Option<Evaluation> {
        self.cache.lock().expect("cache").get(&self.key(u)).copied()
    }

    /// Simulates u (once: results are cached) and scores it: the mean curve distance (% of the side)
    /// over the measured edges, or the penalty when the drape does not converge.
    pub fn evaluate(&self, u: &[f64]) -> Evaluation {
        let key = self.key(u);
        if self.caching
            && let Some(e) = self.cache.lock().expect("cache").get(&key)
        {
            return *e;
        }
        self.simulations.fetch_add(1, Ordering::Relaxed);
        let (sol, sim) = self.drape(u);
        let cost = match sim {
            Some(sim) => {
                let d: Vec<f64> = self
                    .measured
                    .iter()
                    .filter_map(|m| {
                        sim.iter().find(|s| s.edge == m.edge).map(|s| {
                            curve_distance_pct(m, s, m.x_max_cm.max(s.x_max_cm), self.side_cm)
                        })
                    })
                    .collect();
                if d.is_empty() {
                    self.penalty
                } else {
                    d.iter().sum::<f64>() / d.len() as f64
                }
            }
            None => {
                self.failures.fetch_add(1, Ordering::Relaxed);
                self.penalty
            }
        };
        let e = Evaluation {
            cost,
            status: sol.report.status,
            simulation_time_s: sol.report.wall_time_s,
        };
        self.cache.lock().expect("cache").insert(key, e);
        e
    }

    /// The cost of u (see [`Self::evaluate`]).
    pub fn cost(&self, u: &[f64]) -> f64 {
        self.evaluate(u).cost
    }

    /// The static drape at u, with its fitted edges when the solve converged.
    pub fn drape(&self, u: &[f64]) -> (crate::simulate::Solution, Option<Vec<EdgeFit>>) {
        let params = self.bounds.decode(u);
        let scene = self.scene_for(&params);
        let warm = match self.warm_start {
            true => self.lattice().starts(
                &params,
                self.scene.cloth.areal_density_kg_per_m2,
                self.tangent_start,
            ),
            false => WarmStart::default(),
        };
        let starts: Vec<&[nalgebra::Vector3<f64>]> =
            warm.starts.iter().map(Vec::as_slice).collect();
        let sol = match starts.is_empty() {
            // Warm-started next to an equilibrium, a curved step's two extra gradients buy nothing:
            // straight steps there took the knitted calibration from 377 s to 264 s with the same
            // calibrated parameters (issue 34, one run each on one machine); reusing the factorization
            // (chord steps) took it from 280 s to 247 s (reports/newton_iterations.md).
            false => {
                let opts = crate::solve::StaticOptions {
                    direction: crate::solve::Direction::Straight,
                    factor_reuse: crate::solve::FactorReuse::Chord,
                    // The cost reads the status only, and the start is a stable lattice drape (or
                    // its tangent prediction): the minimum check was a third of an evaluation's
                    // factorizations.
                    check_minimum: false,
                    residual_tol_rel: scene
                        .solver
                        .static_
                        .residual_tol_rel
                        .max(EVALUATION_TOL_REL),
                    ..scene.solver.static_.clone()
                };
                // Its Newton steps by CG with the node's factor: no factorization while that
                // converges (the slack population's median went from 1 factorization and 7
                // iterations to 0 and 4, its slowest solve from 0.3 s to 27 ms).
                let neighbour = crate::solve::WarmData {
                    factor: warm.factor.as_ref(),
                    candidates: warm.candidates.as_ref(),
                    adapted: warm.adapted,
                };
                let solve = match warm.ordered {
                    true => crate::simulate::solve_scene_from_first,
                    false => crate::simulate::solve_scene_from_lowest,
                };
                solve(&scene, Some(&opts), &starts, neighbour, &mut NoObserver)
            }
            true => solve_scene(&scene, &mut NoObserver),
        };
        let edges = match (sol.report.is_converged(), scene_view(&scene)) {
            (true, Ok((view, corners))) => Some(
                simulated_edges(
                    &sol.grid,
                    &sol.x,
                    view,
                    corners,
                    self.edge_source,
                    self.projection,
                )
                .into_iter()
                .filter_map(|(n, pts)| EdgeFit::from_points(&n, &pts, 4))
                .collect(),
            ),
            _ => None,
        };
        (sol, edges)
    }

    /// One ICA run over the five-dimensional box.
    pub fn run_ica(&self, settings: &IcaSettings) -> (Params, IcaReport) {
        let report = Ica {
            settings: settings.clone(),
            dim: 5,
        }
        .run(&|u: &[f64]| self.cost(u), |_| {});
        (self.bounds.decode(&report.best_x), report)
    }
}

/// The loosest residual tolerance (of the lightest particle's weight) of a warm-started evaluation:
/// the scene's own when that is looser. On seed 000's 14 × 14 net the drapes solved to 1e-4 lie
/// within 1.5e-9 m of the same drapes solved on to hang4's 1e-9 (largest particle distance over 200
/// Latin-hypercube points of Table 3's box; `crates/core/examples/slack_population.rs` prints it),
/// some 10⁵ times below what a photo's edge resolves. Against 1e-6 it takes the slack population's
/// median from 4 Newton iterations and 1.6 ms to 3 and 1.2 ms, and the main job's calibrate stage
/// from 80 s to 65 s with every calibrated stiffness within 1 N/m and natural length within 1 µm
/// (issue 47). The lattice's own drapes, which seed every start and carry the tangents, keep the
/// scene's tolerance.
pub const EVALUATION_TOL_REL: f64 = 1e-4;

/// The cost restricted to the parameters a static drape depends on (stiffness and natural length, unit
/// box), the others held at a base point: what the Nelder–Mead polish minimises.
struct StaticSubspace {
    base: Vec<f64>,
}

/// The coordinates of the unit box that a static drape can see: stiffness and natural length.
const STATIC_DIMS: [usize; 2] = [0, 3];

impl StaticSubspace {
    fn full(&self, v: &[f64]) -> Vec<f64> {
        let mut u = self.base.clone();
        for (&d, &x) in STATIC_DIMS.iter().zip(v) {
            u[d] = x.clamp(0.0, 1.0);
        }
        u
    }
}

impl Problem {
    /// The warm-start lattice of this problem's scene (shared with every problem whose scene differs
    /// only in density), its chains over this problem's box solved on first use, in parallel.
    fn lattice(&self) -> &SharedLattice {
        self.lattice.get_or_init(|| {
            let l = SharedLattice::for_problem(self);
            l.prepare(self);
            l
        })
    }

    /// Polishes an optimum: Nelder–Mead (argmin) over stiffness and natural length from `u` (topology,
    /// damping and elongation rate held), with at most `max_iters` iterations (a few evaluations each).
    /// ICA finds the valley of the cost; the valley is long and narrow (stiffness and natural length
    /// trade off), and a local simplex walks along it far more cheaply than more decades would.
    /// Returns the better of `u` and the polished point, with its cost.
    pub fn polish(&self, u: &[f64], max_iters: u64) -> (Vec<f64>, f64) {
        let sub = StaticSubspace { base: u.to_vec() };
        let v0: Vec<f64> = STATIC_DIMS.iter().map(|&d| u[d]).collect();
        let nm = crate::optim::NelderMead {
            max_iters,
            step: 0.02,
            sd_tolerance: 1e-7,
        };
        let r = nm.minimize(&|v: &[f64]| self.cost(&sub.full(v)), Some(&v0));
        if r.best_x == v0 {
            (u.to_vec(), r.best_cost)
        } else {
            (sub.full(&r.best_x), r.best_cost)
        }
    }
}

/// Areal density (kg/m²) of each sample of seed 000 Table 2, read from `knitted_samples.csv`
/// (`sample` and `weight_g_per_m2` columns; `#` lines are comments).
pub fn read_sample_densities(path: &std::path::Path) -> anyhow::Result<HashMap<u32, f64>> {
    use crate::error::InputError;
    let text = std::fs::read_to_string(path)
        .map_err(|e| InputError::new(path, "", format!("cannot read: {e}")))?;
    let mut lines = text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty());
    let header: Vec<&str> = lines.next().unwrap_or_default().split(',').collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .ok_or_else(|| InputError::new(path, name, "no such column in the header line"))
    };
    let (cs, cw) = (col("sample")?, col("weight_g_per_m2")?);
    let mut out = HashMap::new();
    for (k, l) in lines.enumerate() {
        let f: Vec<&str> = l.split(',').map(str::trim).collect();
        let bad = || {
            InputError::new(
                path,
                format!("row {}", k + 1),
                format!("`{l}`: needs an integer `sample` and a number `weight_g_per_m2`"),
            )
        };
        let sample = f.get(cs).and_then(|v| v.parse().ok()).ok_or_else(bad)?;
        let grams = f
            .get(cw)
            .and_then(|v| v.parse::<f64>().ok())
            .ok_or_else(bad)?;
        out.insert(sample, grams / 1000.0);
    }
    Ok(out)
}

/// The sample number in a path such as `datasets/knitted/sample_08/hang4`.
pub fn sample_number(path: &str) -> Option<u32> {
    path.split('/')
        .find_map(|p| p.strip_prefix("sample_"))
        .and_then(|n| n.parse().ok())
}

/// The scene of a knitted sample: `scene_file` on a `grid` × `grid` net with the sample's Table 2
/// density (`sample` is a path holding `sample_NN`).
pub fn sample_scene(
    scene_file: &std::path::Path,
    densities: &HashMap<u32, f64>,
    sample: &str,
    grid: usize,
) -> anyhow::Result<Scene> {
    use anyhow::Context;
    let n =
        sample_number(sample).with_context(|| format!("`{sample}`: no sample_NN in the path"))?;
    let rho = *densities
        .get(&n)
        .with_context(|| format!("sample {n} is not in knitted_samples.csv"))?;
    let sets = [
        format!("cloth.nx={grid}"),
        format!("cloth.ny={grid}"),
        format!("cloth.areal_density_kg_per_m2={rho}"),
    ]
    .iter()
    .map(|s| crate::config::parse_override(s))
    .collect::<Result<Vec<_>, _>>()?;
    Ok(Scene::load(scene_file, &sets)?.scene.into_inner())
}
