//! Deterministic warm starts for a calibration: one lattice of static drapes for every sample,
//! where each sample had its own (a quarter of the main job's time).
//!
//! A slack net has several equilibria, so an evaluation cannot start from whatever solution came
//! before (its cost would depend on the order of evaluation and the thread count): it starts from
//! the nearest node of a fixed lattice, or that node's tangent prediction. The static drape of a mass-spring net under gravity depends on the spring stiffness k and the
//! areal density ρ only through the specific stiffness s = k/ρ: every term of its energy scales with
//! one of them (springs ∝ k, gravity and the self-contact barrier's κ ∝ ρ, the barrier's distances
//! unchanged), and so do the solver's residual tolerance (relative to a weight) and its damping
//! (relative to the Hessian's diagonal). So the drape of (k, ρ) is the drape of (k·ρ_ref/ρ, ρ_ref),
//! and one lattice at the reference density ρ_ref serves every sample whose scene differs only in
//! its density. Its stiffness nodes are a geometric ladder K_i = K_REF·R^i (i any integer), each
//! chain (topology, i) solved lazily, the first time an evaluation needs it, by continuation in the
//! natural length as before: a chain is a pure function of (scene without density, topology, i), so
//! an evaluation's start still depends on its own parameters only.

use super::{Params, Problem};
use crate::material::Topology;
use crate::scene::Scene;
use crate::solve::NoObserver;
use nalgebra::Vector3;
use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

/// One node's drape and, where it is an isolated minimum, its tangents: the sensitivities to the
/// stiffness and the natural length ([`crate::sensitivity`]), m per N/m and m per m.
pub(super) struct LatticeDrape {
    x: Vec<nalgebra::Vector3<f64>>,
    tangents: Option<[Vec<nalgebra::Vector3<f64>>; 2]>,
    /// Its self-contact candidate set: an evaluation nearby starts without a broad phase.
    candidates: Option<crate::physics::CandidateSet>,
    /// The factor of its exact Hessian: an evaluation nearby solves its Newton steps by conjugate
    /// gradients preconditioned with it, without a factorization of its own.
    factor: Option<std::sync::Arc<crate::solve::SparseSpd>>,
    /// What its solve adapted (κ growth): an evaluation nearby solves the model the node solved.
    adapted: crate::physics::Adapted,
}

/// Where an evaluation starts: the candidate starts (a lattice drape and its tangent prediction),
/// the node's self-contact candidate set and its factor.
#[derive(Default)]
pub struct WarmStart {
    /// Candidate start positions, m; the solve takes the one of lowest energy or, with `ordered`,
    /// the first of finite energy.
    pub starts: Vec<Vec<nalgebra::Vector3<f64>>>,
    /// Whether `starts` come in order of preference.
    pub ordered: bool,
    /// The node's self-contact candidate set.
    pub candidates: Option<crate::physics::CandidateSet>,
    /// The node's factor, the preconditioner of the evaluation's Newton steps.
    pub factor: Option<crate::solve::NeighbourFactor>,
    /// What the node's solve adapted (κ growth), taken up by the evaluation's model.
    pub adapted: Option<crate::physics::Adapted>,
}

/// The two keys of the lattice's tangents.
pub(super) const TANGENT_KEYS: [&str; 2] = [
    "material.mass_spring.stiffness_N_per_m",
    "material.mass_spring.natural_length_m",
];

impl LatticeDrape {
    /// The node's drape with its tangents at that drape, when it has them. `reach` is how far
    /// (stiffness N/m, natural length m) an evaluation's parameters may lie from the node's: the
    /// node's self-contact candidate set covers every tangent prediction within it, so that an
    /// evaluation starts without a broad phase (a quarter of the evaluations ran one, 7 % of the
    /// main job's calibrate stage, when the set covered the node's drape alone).
    fn of(scene: &Scene, sol: crate::simulate::Solution, reach: [f64; 2]) -> Option<Self> {
        if !sol.report.is_converged() {
            return None;
        }
        let mut factor = None;
        let tangents = scene.clone().validated().ok().and_then(|v| {
            let mut eq = crate::sensitivity::Equilibrium::new(
                &v,
                &sol.model,
                &sol.x,
                &sol.report,
                "lattice",
            )
            .ok()?;
            factor = Some(std::sync::Arc::new(eq.factor().factor().copy()));
            let [a, b] = TANGENT_KEYS.map(|k| eq.sensitivity(k).ok().map(|s| s.dx));
            Some([a?, b?])
        });
        let candidates = match &tangents {
            Some([dk, dl]) => {
                let spread: Vec<f64> = dk
                    .iter()
                    .zip(dl)
                    .map(|(u, w)| u.norm() * reach[0] + w.norm() * reach[1])
                    .collect();
                sol.model.candidates_covering(&sol.x, &spread)
            }
            None => sol.model.candidates_covering(&sol.x, &[]),
        };
        Some(Self {
            factor,
            adapted: crate::physics::Adapted::of(&sol.model),
            candidates,
            x: sol.x,
            tangents,
        })
    }
}

/// Natural-length nodes of a chain, 0.5 mm apart over Table 3's 40–60 mm.
const LENGTHS: usize = 41;
/// The reference areal density of every shared lattice, kg/m².
const RHO_REF: f64 = 0.05;
/// The first rung of the stiffness ladder at the reference density, N/m.
const K_REF: f64 = 1000.0;
/// The ratio of two rungs: ±10 % at most from an evaluation's specific stiffness to its node's, as
/// the per-sample lattice of five stiffnesses over 500–1200 N/m had.
const R: f64 = 1.2;

type Chain = Arc<OnceLock<Vec<Option<LatticeDrape>>>>;

/// The lattice shared by every problem whose scene differs only in density (and stiffness).
pub struct SharedLattice {
    /// The scene at the reference density (stiffness and natural length set per node).
    reference: Scene,
    /// The natural-length nodes, m.
    lengths: Vec<f64>,
    chains: Mutex<HashMap<(Topology, i32), Chain>>,
}

/// Every shared lattice of the process, by the hash of its reference scene.
static LATTICES: Mutex<Vec<(u64, Arc<SharedLattice>)>> = Mutex::new(Vec::new());

impl SharedLattice {
    /// The lattice for `problem`'s scene, made on first use.
    pub fn for_problem(problem: &Problem) -> Arc<SharedLattice> {
        let b = &problem.bounds;
        let mut reference = problem.scene_for(&Params {
            stiffness_N_per_m: K_REF,
            damping_Ns_per_m: b.damping_Ns_per_m.0,
            elongation_rate: b.elongation_rate.0,
            natural_length_m: b.natural_length_m.0,
            topology: Topology::A,
        });
        reference.cloth.areal_density_kg_per_m2 = RHO_REF;
        let lengths: Vec<f64> = (0..LENGTHS)
            .map(|k| {
                let (lo, hi) = b.natural_length_m;
                lo + (hi - lo) * k as f64 / (LENGTHS - 1) as f64
            })
            .collect();
        let key = {
            let text = serde_json::to_string(&(&reference, &lengths)).unwrap_or_default();
            u64::from_le_bytes(
                blake3::hash(text.as_bytes()).as_bytes()[..8]
                    .try_into()
                    .unwrap_or([0; 8]),
            )
        };
        let mut all = LATTICES.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((_, l)) = all.iter().find(|(k, _)| *k == key) {
            return l.clone();
        }
        let l = Arc::new(SharedLattice {
            reference,
            lengths,
            chains: Mutex::new(HashMap::new()),
        });
        all.push((key, l.clone()));
        l
    }

    /// The reference scene at stiffness `k`, natural length `l`, topology `t`.
    fn scene(&self, k: f64, l: f64, t: Topology) -> Scene {
        let mut s = self.reference.clone();
        let ms = s.material.mass_spring.get_or_insert_with(Default::default);
        ms.stiffness_N_per_m = k;
        ms.natural_length_m = Some(l);
        ms.topology = t;
        s
    }

    /// Chain (t, i), solved on first use: continuation in the natural length from the sagged start.
    fn chain(&self, t: Topology, i: i32) -> Chain {
        let chain = {
            let mut chains = self.chains.lock().unwrap_or_else(|e| e.into_inner());
            chains.entry((t, i)).or_default().clone()
        };
        chain.get_or_init(|| {
            let k = K_REF * R.powi(i);
            // An evaluation's node is its nearest rung (within a factor √R) and length node.
            let reach = [
                k * (R.sqrt() - 1.0),
                0.5 * (self.lengths[1] - self.lengths[0]),
            ];
            let mut prev: Option<(Vec<Vector3<f64>>, crate::physics::Adapted)> = None;
            self.lengths
                .iter()
                .map(|&l| {
                    let scene = self.scene(k, l, t);
                    let sol = match &prev {
                        Some((x0, adapted)) => {
                            let warm = crate::solve::WarmData {
                                adapted: Some(*adapted),
                                ..Default::default()
                            };
                            let from = crate::simulate::solve_scene_from_lowest;
                            from(&scene, None, &[x0], warm, &mut NoObserver)
                        }
                        None => crate::simulate::solve_scene(&scene, &mut NoObserver),
                    };
                    let node = LatticeDrape::of(&scene, sol, reach);
                    if let Some(n) = &node {
                        prev = Some((n.x.clone(), n.adapted));
                    }
                    node
                })
                .collect()
        });
        chain
    }

    /// The rung nearest to reference stiffness `k`.
    fn rung(k: f64) -> i32 {
        ((k / K_REF).ln() / R.ln()).round() as i32
    }

    /// The rungs a problem's stiffness bounds reach at its density.
    fn rungs(problem: &Problem) -> std::ops::RangeInclusive<i32> {
        let scale = RHO_REF / problem.scene.cloth.areal_density_kg_per_m2;
        let (lo, hi) = problem.bounds.stiffness_N_per_m;
        Self::rung(lo * scale)..=Self::rung(hi * scale)
    }

    /// Solves every chain `problem`'s box reaches, in parallel (those solved already are kept).
    pub fn prepare(&self, problem: &Problem) {
        use rayon::prelude::*;
        let chains: Vec<(Topology, i32)> = [Topology::A, Topology::B, Topology::C]
            .into_iter()
            .flat_map(|t| Self::rungs(problem).map(move |i| (t, i)))
            .collect();
        chains.par_iter().for_each(|&(t, i)| {
            self.chain(t, i);
        });
    }

    /// Every converged node of `topology` within `problem`'s box, as (stiffness at the problem's
    /// density N/m, natural length m, drape).
    pub fn nodes(
        &self,
        problem: &Problem,
        topology: Topology,
    ) -> Vec<(f64, f64, Vec<Vector3<f64>>)> {
        let scale = problem.scene.cloth.areal_density_kg_per_m2 / RHO_REF;
        let (lo, hi) = problem.bounds.stiffness_N_per_m;
        let mut out = Vec::new();
        for i in Self::rungs(problem) {
            let k = K_REF * R.powi(i) * scale;
            if !(lo..=hi).contains(&k) {
                continue;
            }
            let chain = self.chain(topology, i);
            for (node, &l) in chain.get().into_iter().flatten().zip(&self.lengths) {
                if let Some(n) = node {
                    out.push((k, l, n.x.clone()));
                }
            }
        }
        out
    }

    /// The starts of an evaluation at `p` on a sheet of density `rho`: its nearest node's drape
    /// and, with `tangent`, the node's tangent prediction at the equivalent reference stiffness
    /// k·ρ_ref/ρ and the Hermite prediction between the two length nodes around it.
    pub fn starts(&self, p: &Params, rho: f64, tangent: bool) -> WarmStart {
        let Some((chain, j, dk)) = self.locate(p, rho) else {
            return WarmStart::default();
        };
        let Some(Some(node)) = chain.get().and_then(|c| c.get(j)) else {
            return WarmStart::default();
        };
        let mut v = vec![node.x.clone()];
        let mut ordered = false;
        if tangent {
            // The Hermite start first, the node's drape behind it in case the Hermite start is not
            // admissible (infinite energy: a pair within the thickness); else the lower-energy of the
            // node's drape and its tangent prediction.
            let hermite = chain
                .get()
                .and_then(|c| self.hermite(c, p.natural_length_m, dk));
            match hermite {
                Some(h) => {
                    v.insert(0, h);
                    ordered = true;
                }
                None => v.extend(self.tangent_prediction(p, rho)),
            }
        }
        // The evaluation's energy is ρ/ρ_ref times the node's at the same specific stiffness: the
        // node's factor preconditions its steps as it is.
        let factor = node.factor.clone().map(crate::solve::NeighbourFactor);
        WarmStart {
            starts: v,
            ordered,
            candidates: node.candidates.clone(),
            factor,
            adapted: Some(node.adapted),
        }
    }

    /// The chain of an evaluation at `p` on a sheet of density `rho`, its nearest length node and
    /// the evaluation's reference stiffness less the chain's, N/m.
    fn locate(&self, p: &Params, rho: f64) -> Option<(Chain, usize, f64)> {
        let k = p.stiffness_N_per_m * RHO_REF / rho;
        let i = Self::rung(k);
        let (lo, hi) = (self.lengths[0], self.lengths[self.lengths.len() - 1]);
        let t = ((p.natural_length_m - lo) / (hi - lo)).clamp(0.0, 1.0);
        let j = (t * (self.lengths.len() - 1) as f64).round() as usize;
        Some((self.chain(p.topology, i), j, k - K_REF * R.powi(i)))
    }

    /// The nearest node's tangent prediction x(θ₀) + (∂x/∂k)(k − k₀) + (∂x/∂L₀)(L₀ − L₀,₀) of the
    /// drape at `p` on a sheet of density `rho` (k at the reference density); None where that node
    /// has no tangents.
    pub fn tangent_prediction(&self, p: &Params, rho: f64) -> Option<Vec<Vector3<f64>>> {
        let (chain, j, a) = self.locate(p, rho)?;
        let node = chain.get()?.get(j)?.as_ref()?;
        let [dk, dl] = node.tangents.as_ref()?;
        let b = p.natural_length_m - self.lengths[j];
        Some(
            node.x
                .iter()
                .zip(dk.iter().zip(dl))
                .map(|(x, (u, w))| x + u * a + w * b)
                .collect(),
        )
    }

    /// The cubic Hermite prediction at natural length `l` from the two nodes of `chain` around it
    /// (their drapes and length tangents), plus their stiffness tangents interpolated linearly times
    /// `dk`: within O(h⁴) of the drape in the length (h the nodes' spacing) where the tangent
    /// prediction is within O(h²) — the slack population's evaluations took a median of 3 Newton
    /// iterations from the tangent prediction and 2 from this (`examples/slack_population.rs`).
    /// None where either node lacks its tangents (a fold between them, say).
    fn hermite(
        &self,
        chain: &[Option<LatticeDrape>],
        l: f64,
        dk: f64,
    ) -> Option<Vec<Vector3<f64>>> {
        let h = self.lengths[1] - self.lengths[0];
        let j0 =
            (((l - self.lengths[0]) / h).floor().max(0.0) as usize).min(self.lengths.len() - 2);
        let t = ((l - self.lengths[j0]) / h).clamp(0.0, 1.0);
        let (a, b) = (chain.get(j0)?.as_ref()?, chain.get(j0 + 1)?.as_ref()?);
        let ([ka, la], [kb, lb]) = (a.tangents.as_ref()?, b.tangents.as_ref()?);
        let (t2, t3) = (t * t, t * t * t);
        let (h00, h10) = (2.0 * t3 - 3.0 * t2 + 1.0, (t3 - 2.0 * t2 + t) * h);
        let (h01, h11) = (3.0 * t2 - 2.0 * t3, (t3 - t2) * h);
        Some(
            (0..a.x.len())
                .map(|q| {
                    a.x[q] * h00
                        + la[q] * h10
                        + b.x[q] * h01
                        + lb[q] * h11
                        + (ka[q] * (1.0 - t) + kb[q] * t) * dk
                })
                .collect(),
        )
    }
}
