//! Calibration of seed 000's mass-spring parameters against measured edges (issue 5, started): the
//! search space of Table 3 on the unit box, a cost that simulates a hang and scores its edges against
//! the measured ones (cached, non-convergence penalised and counted), and one ICA run per call.

use crate::cli::edges::scene_view;
use crate::edges::{EdgeFit, curve_distance_pct, edges_from_particles};
use crate::material::Topology;
use crate::optim::{Ica, IcaReport, IcaSettings};
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
    pub status: &'static str,
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
    cache: Mutex<HashMap<Vec<u64>, Evaluation>>,
    /// Simulations run (cache misses).
    pub simulations: AtomicUsize,
    /// Simulations that did not converge.
    pub failures: AtomicUsize,
}

impl Problem {
    /// A problem over `scene` against `measured` edges.
    pub fn new(scene: Scene, measured: Vec<EdgeFit>, side_cm: f64) -> Self {
        Self {
            scene,
            measured,
            bounds: Bounds::default(),
            side_cm,
            penalty: 100.0,
            cache: Mutex::new(HashMap::new()),
            simulations: AtomicUsize::new(0),
            failures: AtomicUsize::new(0),
        }
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
        if let Some(e) = self.cache.lock().expect("cache").get(&key) {
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
            status: sol.report.status.as_str(),
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
        let scene = self.scene_for(&self.bounds.decode(u));
        let sol = solve_scene(&scene, &mut NoObserver);
        let edges = match (sol.report.is_converged(), scene_view(&scene)) {
            (true, Ok((view, corners))) => Some(
                edges_from_particles(&sol.grid, &sol.x, view, corners)
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

/// Areal density (kg/m²) of each sample of seed 000 Table 2, read from `knitted_samples.csv`
/// (`sample` and `weight_g_per_m2` columns; `#` lines are comments).
pub fn read_sample_densities(path: &std::path::Path) -> anyhow::Result<HashMap<u32, f64>> {
    let text = std::fs::read_to_string(path)?;
    let mut lines = text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty());
    let header: Vec<&str> = lines.next().unwrap_or_default().split(',').collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .ok_or_else(|| anyhow::anyhow!("{}: no column {name}", path.display()))
    };
    let (cs, cw) = (col("sample")?, col("weight_g_per_m2")?);
    let mut out = HashMap::new();
    for l in lines {
        let f: Vec<&str> = l.split(',').collect();
        out.insert(f[cs].trim().parse()?, f[cw].trim().parse::<f64>()? / 1000.0);
    }
    Ok(out)
}

/// The sample number in a path such as `datasets/knitted/sample_08/hang4`.
pub fn sample_number(path: &str) -> Option<u32> {
    path.split('/')
        .find_map(|p| p.strip_prefix("sample_"))
        .and_then(|n| n.parse().ok())
}

/// How much the cost changes when one parameter sweeps its range with the others at the optimum:
/// (name, min cost, max cost) for stiffness, damping, elongation rate, natural length, topology.
/// A parameter whose sweep changes the cost by less than `tol` is not identifiable from the drape.
pub fn sensitivity(
    problem: &Problem,
    best_u: &[f64],
    steps: usize,
) -> Vec<(&'static str, f64, f64)> {
    const NAMES: [&str; 5] = [
        "stiffness_N_per_m",
        "damping_Ns_per_m",
        "elongation_rate",
        "natural_length_m",
        "topology",
    ];
    (0..5)
        .map(|d| {
            let n = if d == 4 { 3 } else { steps.max(2) };
            let costs: Vec<f64> = (0..n)
                .map(|k| {
                    let mut u = best_u.to_vec();
                    u[d] = if d == 4 {
                        (k as f64 + 0.5) / 3.0
                    } else {
                        k as f64 / (n - 1) as f64
                    };
                    problem.cost(&u)
                })
                .collect();
            (
                NAMES[d],
                costs.iter().copied().fold(f64::INFINITY, f64::min),
                costs.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            )
        })
        .collect()
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
    .map(|s| crate::scene::parse_override(s))
    .collect::<Result<Vec<_>, _>>()?;
    Ok(Scene::load(scene_file, &sets)?.scene)
}
