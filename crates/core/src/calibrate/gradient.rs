//! Calibration by gradients: Levenberg–Marquardt over the parameters a static hang depends on (the
//! springs' stiffness and natural length, one topology at a time) on the edge-curve residuals, with
//! the Jacobian from the drape's sensitivities. At a converged drape x*(θ) the factor of its exact
//! Hessian gives dx*/dθ for both keys ([`crate::sensitivity`]: one factorization, two
//! back-substitutions, no solve), and the residuals' Jacobian is J = (∂r/∂x)(dx*/dθ), taken as the
//! central difference of the residuals along each tangent (the edges are fitted again, no solve).
//! Each step's drape starts from the tangent prediction x* + (dx*/dθ)Δθ. Solves are what it costs:
//! ICA spends thousands per sample.

use super::{Params, Problem, SharedLattice, TANGENT_KEYS};
use crate::edges::{EdgeFit, scene_view, simulated_edges};
use crate::material::Topology;
use crate::solve::NoObserver;
use nalgebra::{Matrix2, Vector2, Vector3};

/// Settings of the Levenberg–Marquardt calibration.
#[derive(Debug, Clone, PartialEq)]
pub struct LmSettings {
    /// Equilibrium solves allowed per topology. Default 25.
    pub max_solves: usize,
    /// Initial damping λ (relative to JᵀJ's diagonal). Default 1e-3.
    pub lambda_initial: f64,
    /// Converged when an accepted step lowers the residuals' sum of squares by less than this
    /// fraction, or moves the unit-box parameters by less than its square root. Default 1e-8.
    pub tol_rel: f64,
}

impl Default for LmSettings {
    fn default() -> Self {
        Self {
            max_solves: 25,
            lambda_initial: 1e-3,
            tol_rel: 1e-8,
        }
    }
}

/// The outcome of a Levenberg–Marquardt calibration of one sample.
#[derive(Debug, Clone, PartialEq)]
pub struct LmReport {
    /// The best parameters (damping and elongation rate at their lower bounds: a static drape does
    /// not see them).
    pub best: Params,
    /// Its mean curve distance over the measured edges, % of the side (the cost of ICA's runs).
    pub best_cost_pct: f64,
    /// Equilibrium solves, over every topology tried.
    pub solves: usize,
    /// Accepted steps, over every topology.
    pub iterations: usize,
    /// JᵀJ at the best point in (N/m, m) coordinates, residuals in % of the side: the Gauss–Newton
    /// curvature of half the residuals' sum of squares, for intervals.
    pub jtj: [[f64; 2]; 2],
    /// 2σ half-widths of the stiffness (N/m) and natural length (m) from JᵀJ ([`two_sigma`]); None
    /// where JᵀJ is singular.
    pub half_width_2sigma: [Option<f64>; 2],
    /// Why the best topology's run stopped.
    pub stop: LmStop,
}

/// Why a Levenberg–Marquardt run stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LmStop {
    /// The relative step fell below √tol.
    ConvergedStep,
    /// The relative fall of the cost fell below tol.
    ConvergedCost,
    /// The solve budget was spent (the solves made).
    Solves(usize),
    /// The damped normal equations were singular.
    SingularNormalEquations,
    /// No damping found a step that lowers the residuals.
    NoDescent,
    /// The warm-start lattice has no node of this topology.
    NoLatticeNode,
    /// The drape at the start did not converge.
    StartNotConverged,
    /// No topology gave a converged drape with every edge.
    NoTopology,
}

impl std::fmt::Display for LmStop {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LmStop::ConvergedStep => f.write_str("converged (step)"),
            LmStop::ConvergedCost => f.write_str("converged (cost)"),
            LmStop::Solves(n) => write!(f, "{n} solves"),
            LmStop::SingularNormalEquations => f.write_str("singular normal equations"),
            LmStop::NoDescent => f.write_str("no step lowers the residuals"),
            LmStop::NoLatticeNode => f.write_str("no lattice node"),
            LmStop::StartNotConverged => f.write_str("the start did not converge"),
            LmStop::NoTopology => f.write_str("no topology gave a converged drape with every edge"),
        }
    }
}

/// A converged drape with its residuals and their Jacobian in the unit box's (stiffness, natural
/// length) coordinates.
struct Point {
    u: Vector2<f64>,
    x: Vec<Vector3<f64>>,
    r: Vec<f64>,
    /// dx*/du for each coordinate (the tangents times the box's widths).
    tangents: [Vec<Vector3<f64>>; 2],
    jac: Vec<[f64; 2]>,
}

impl Point {
    fn sum_sq(&self) -> f64 {
        self.r.iter().map(|v| v * v).sum()
    }
}

impl Problem {
    /// The residuals of a drape `x` of `scene`: per measured edge with a simulated counterpart, the
    /// difference of the two curves at 201 points over their span, in % of the side and scaled by
    /// 1/√201, so that each edge's part has the norm of its curve distance. None when an edge is
    /// missing or the view cannot be set.
    fn edge_residuals(
        &self,
        scene: &crate::scene::Scene,
        grid: &crate::cloth::Grid,
        x: &[Vector3<f64>],
    ) -> Option<Vec<f64>> {
        let (view, corners) = scene_view(scene).ok()?;
        let sim: Vec<EdgeFit> =
            simulated_edges(grid, x, view, corners, self.edge_source, self.projection)
                .into_iter()
                .filter_map(|(n, pts)| EdgeFit::from_points(&n, &pts, 4))
                .collect();
        const N: usize = 201;
        let scale = 100.0 / (self.side_cm * (N as f64).sqrt());
        let mut r = Vec::with_capacity(self.measured.len() * N);
        for m in &self.measured {
            let s = sim.iter().find(|s| s.edge == m.edge)?;
            let span = m.x_max_cm.max(s.x_max_cm);
            r.extend((0..N).map(|k| {
                let xk = span * k as f64 / (N - 1) as f64;
                scale * (m.eval(xk) - s.eval(xk))
            }));
        }
        (!r.is_empty()).then_some(r)
    }

    /// The mean curve distance (% of the side) of residuals from [`Self::edge_residuals`].
    fn mean_distance(&self, r: &[f64]) -> f64 {
        let n = self.measured.len().max(1);
        r.chunks(r.len() / n)
            .map(|e| e.iter().map(|v| v * v).sum::<f64>().sqrt())
            .sum::<f64>()
            / n as f64
    }

    /// The parameters at unit-box coordinates `u` (stiffness, natural length) of `topology`.
    fn lm_params(&self, u: &Vector2<f64>, topology: Topology) -> Params {
        let b = &self.bounds;
        let lerp = |(a, c): (f64, f64), t: f64| a + t.clamp(0.0, 1.0) * (c - a);
        Params {
            stiffness_N_per_m: lerp(b.stiffness_N_per_m, u[0]),
            damping_Ns_per_m: b.damping_Ns_per_m.0,
            elongation_rate: b.elongation_rate.0,
            natural_length_m: lerp(b.natural_length_m, u[1]),
            topology,
        }
    }

    /// The drape at `u` from the lowest of `starts`, with residuals, tangents and Jacobian; None
    /// when it does not converge, is no isolated minimum or loses an edge.
    fn lm_point(
        &self,
        u: Vector2<f64>,
        topology: Topology,
        starts: &[&[Vector3<f64>]],
    ) -> Option<Point> {
        let scene = self.scene_for(&self.lm_params(&u, topology));
        let opts = crate::solve::StaticOptions {
            direction: crate::solve::Direction::Straight,
            factor_reuse: crate::solve::FactorReuse::Chord,
            ..scene.solver.static_.clone()
        };
        let cold = crate::solve::WarmData::default();
        let sol = crate::simulate::solve_scene_from_lowest(
            &scene,
            Some(&opts),
            starts,
            cold,
            &mut NoObserver,
        );
        if !sol.report.is_converged() {
            return None;
        }
        let r = self.edge_residuals(&scene, &sol.grid, &sol.x)?;
        let valid = scene.clone().validated().ok()?;
        let mut eq = crate::sensitivity::Equilibrium::new(
            &valid,
            &sol.model,
            &sol.x,
            &sol.report,
            "levenberg-marquardt",
        )
        .ok()?;
        let b = &self.bounds;
        let widths = [
            b.stiffness_N_per_m.1 - b.stiffness_N_per_m.0,
            b.natural_length_m.1 - b.natural_length_m.0,
        ];
        let mut tangents: [Vec<Vector3<f64>>; 2] = [Vec::new(), Vec::new()];
        for i in 0..2 {
            let dx = eq.sensitivity(TANGENT_KEYS[i]).ok()?.dx;
            tangents[i] = dx.iter().map(|v| v * widths[i]).collect();
        }
        let jac = self.jacobian(&scene, &sol, &tangents, r.len())?;
        drop(eq);
        Some(Point {
            u,
            x: sol.x,
            r,
            tangents,
            jac,
        })
    }

    /// ∂r/∂u: the central difference of the residuals along each tangent, a step that moves no
    /// particle by more than 10⁻⁶ m.
    fn jacobian(
        &self,
        scene: &crate::scene::Scene,
        sol: &crate::simulate::Solution,
        tangents: &[Vec<Vector3<f64>>; 2],
        n: usize,
    ) -> Option<Vec<[f64; 2]>> {
        let mut jac = vec![[0.0; 2]; n];
        for (i, t) in tangents.iter().enumerate() {
            let big = t.iter().map(|v| v.norm()).fold(0.0, f64::max);
            if big == 0.0 {
                continue;
            }
            let h = 1e-6 / big;
            let moved = |s: f64| -> Vec<Vector3<f64>> {
                sol.x.iter().zip(t).map(|(x, d)| x + d * s).collect()
            };
            let rp = self.edge_residuals(scene, &sol.grid, &moved(h))?;
            let rm = self.edge_residuals(scene, &sol.grid, &moved(-h))?;
            if rp.len() != n || rm.len() != n {
                return None;
            }
            for k in 0..n {
                jac[k][i] = (rp[k] - rm[k]) / (2.0 * h);
            }
        }
        Some(jac)
    }
}

/// 2σ half-widths of the two parameters from the Gauss–Newton covariance σ̂² (JᵀJ)⁻¹ (`jtj` in the
/// parameters' units), σ̂² = Σr²/(m − 2) over the `m` residuals taken as independent. They are
/// samples along the same few curves, so these intervals come out narrower than the
/// curvature-based ones, which count 5 degrees of freedom per edge. None where JᵀJ is singular.
pub fn two_sigma(jtj: &[[f64; 2]; 2], sum_sq: f64, m: usize) -> [Option<f64>; 2] {
    let a = Matrix2::new(jtj[0][0], jtj[0][1], jtj[1][0], jtj[1][1]);
    match (a.try_inverse(), m > 2) {
        (Some(inv), true) => {
            let s2 = sum_sq / (m - 2) as f64;
            [0, 1].map(|i| {
                let v = s2 * inv[(i, i)];
                (v.is_finite() && v >= 0.0).then(|| 2.0 * v.sqrt())
            })
        }
        _ => [None; 2],
    }
}

/// JᵀJ and Jᵀr of a point.
fn normal_equations(p: &Point) -> (Matrix2<f64>, Vector2<f64>) {
    let mut a = Matrix2::zeros();
    let mut g = Vector2::zeros();
    for (j, r) in p.jac.iter().zip(&p.r) {
        let j = Vector2::new(j[0], j[1]);
        a += j * j.transpose();
        g += j * *r;
    }
    (a, g)
}

/// The damped Gauss–Newton step from `p` with the box's bounds: a coordinate at its bound whose
/// step would leave the box is held there and the other one solved alone (projected
/// Levenberg–Marquardt; the natural length of the stiffest samples sits at Table 3's lower bound).
fn bounded_step(p: &Point, lambda: f64) -> Option<Vector2<f64>> {
    let (a, g) = normal_equations(p);
    let damped = a + Matrix2::from_diagonal(&a.diagonal()) * lambda;
    let step = damped.lu().solve(&(-g))?;
    let leaves = |i: usize| (p.u[i] <= 0.0 && step[i] < 0.0) || (p.u[i] >= 1.0 && step[i] > 0.0);
    match (leaves(0), leaves(1)) {
        (false, false) => Some(step),
        (true, true) => Some(Vector2::zeros()),
        (held0, _) => {
            let free = usize::from(held0);
            let mut s = Vector2::zeros();
            if damped[(free, free)] > 0.0 {
                s[free] = -g[free] / damped[(free, free)];
            }
            Some(s)
        }
    }
}

/// One topology's run: (best point, accepted steps, solves, why it stopped).
type Run = (Option<Point>, usize, usize, LmStop);

impl Problem {
    /// Solves the warm-start lattice now (it is otherwise solved at the first evaluation that needs
    /// it), so that its cost can be timed apart.
    pub fn warm_start_lattice(&self) {
        self.lattice();
    }

    /// Levenberg–Marquardt calibration of the stiffness and natural length, for each topology from
    /// its best node of the warm-start lattice (the drapes every optimizer of the problem shares);
    /// the best topology's result.
    pub fn run_lm(&self, settings: &LmSettings) -> LmReport {
        let lattice = self.lattice();
        let mut best: Option<(Topology, Point, LmStop)> = None;
        let (mut solves, mut iterations) = (0, 0);
        for topology in [Topology::A, Topology::B, Topology::C] {
            let (point, its, n, stop) = self.lm_topology(lattice, topology, settings);
            solves += n;
            iterations += its;
            if let Some(p) = point
                && best
                    .as_ref()
                    .is_none_or(|(_, b, _)| p.sum_sq() < b.sum_sq())
            {
                best = Some((topology, p, stop));
            }
        }
        let b = &self.bounds;
        let widths = [
            b.stiffness_N_per_m.1 - b.stiffness_N_per_m.0,
            b.natural_length_m.1 - b.natural_length_m.0,
        ];
        match best {
            Some((topology, p, stop)) => {
                let (a, _) = normal_equations(&p);
                let jtj = [
                    [
                        a[(0, 0)] / (widths[0] * widths[0]),
                        a[(0, 1)] / (widths[0] * widths[1]),
                    ],
                    [
                        a[(1, 0)] / (widths[0] * widths[1]),
                        a[(1, 1)] / (widths[1] * widths[1]),
                    ],
                ];
                LmReport {
                    best: self.lm_params(&p.u, topology),
                    best_cost_pct: self.mean_distance(&p.r),
                    solves,
                    iterations,
                    half_width_2sigma: two_sigma(&jtj, p.sum_sq(), p.r.len()),
                    jtj,
                    stop,
                }
            }
            None => LmReport {
                best: self.lm_params(&Vector2::new(0.5, 0.5), Topology::A),
                best_cost_pct: self.penalty,
                solves,
                iterations,
                jtj: [[0.0; 2]; 2],
                half_width_2sigma: [None; 2],
                stop: LmStop::NoTopology,
            },
        }
    }

    /// The lattice node of `topology` whose drape is closest to the measured edges, in unit-box
    /// coordinates, with its drape.
    fn best_node(
        &self,
        lattice: &SharedLattice,
        topology: Topology,
    ) -> Option<(Vector2<f64>, Vec<Vector3<f64>>)> {
        let b = &self.bounds;
        let unit = |(lo, hi): (f64, f64), v: f64| (v - lo) / (hi - lo);
        let mut best: Option<(f64, Vector2<f64>, Vec<Vector3<f64>>)> = None;
        for (k, l, x) in lattice.nodes(self, topology) {
            let u = Vector2::new(unit(b.stiffness_N_per_m, k), unit(b.natural_length_m, l));
            let scene = self.scene_for(&self.lm_params(&u, topology));
            let grid = scene.grid();
            let Some(r) = self.edge_residuals(&scene, &grid, &x) else {
                continue;
            };
            let ss: f64 = r.iter().map(|v| v * v).sum();
            if best.as_ref().is_none_or(|(s, _, _)| ss < *s) {
                best = Some((ss, u, x));
            }
        }
        best.map(|(_, u, x)| (u, x))
    }

    /// Levenberg–Marquardt for one topology from its best lattice node.
    fn lm_topology(&self, lattice: &SharedLattice, topology: Topology, s: &LmSettings) -> Run {
        let Some((u0, x0)) = self.best_node(lattice, topology) else {
            return (None, 0, 0, LmStop::NoLatticeNode);
        };
        let mut solves = 1;
        let Some(mut p) = self.lm_point(u0, topology, &[&x0]) else {
            return (None, 0, solves, LmStop::StartNotConverged);
        };
        let (mut lambda, mut accepted) = (s.lambda_initial, 0);
        let stop = loop {
            if solves >= s.max_solves {
                break LmStop::Solves(solves);
            }
            let Some(step) = bounded_step(&p, lambda) else {
                break LmStop::SingularNormalEquations;
            };
            let u = (p.u + step).map(|v| v.clamp(0.0, 1.0));
            let du = u - p.u;
            if du.norm() < s.tol_rel.sqrt() {
                break LmStop::ConvergedStep;
            }
            let predicted: Vec<Vector3<f64>> =
                p.x.iter()
                    .zip(p.tangents[0].iter().zip(&p.tangents[1]))
                    .map(|(x, (a, b))| x + a * du[0] + b * du[1])
                    .collect();
            solves += 1;
            match self.lm_point(u, topology, &[&predicted, &p.x]) {
                Some(q) if q.sum_sq() < p.sum_sq() => {
                    let gain = (p.sum_sq() - q.sum_sq()) / p.sum_sq().max(1e-300);
                    p = q;
                    accepted += 1;
                    lambda = (lambda / 3.0).max(1e-9);
                    if gain < s.tol_rel {
                        break LmStop::ConvergedCost;
                    }
                }
                _ => {
                    lambda *= 4.0;
                    if lambda > 1e8 {
                        break LmStop::NoDescent;
                    }
                }
            }
        };
        (Some(p), accepted, solves, stop)
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_jtj_intervals_of_a_straight_line_are_those_of_least_squares() {
        // y = 2 + 3x + noise at 8 points: the Gauss–Newton covariance of (intercept, slope) at the
        // least-squares optimum is the textbook one, se(slope)² = s²/Σ(x − x̄)².
        let x: Vec<f64> = (0..8).map(|i| i as f64 * 0.5).collect();
        let noise = [0.1, -0.2, 0.05, 0.15, -0.1, 0.0, -0.05, 0.12];
        let y: Vec<f64> = x
            .iter()
            .zip(noise)
            .map(|(x, e)| 2.0 + 3.0 * x + e)
            .collect();
        let n = x.len() as f64;
        let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
        let sxx: f64 = x.iter().map(|x| (x - mx).powi(2)).sum();
        let slope: f64 = x
            .iter()
            .zip(&y)
            .map(|(x, y)| (x - mx) * (y - my))
            .sum::<f64>()
            / sxx;
        let intercept = my - slope * mx;
        let sum_sq: f64 = x
            .iter()
            .zip(&y)
            .map(|(x, y)| (intercept + slope * x - y).powi(2))
            .sum();
        let jtj = [
            [n, x.iter().sum::<f64>()],
            [x.iter().sum::<f64>(), x.iter().map(|x| x * x).sum::<f64>()],
        ];
        let [a, b] = super::two_sigma(&jtj, sum_sq, x.len());
        let s2 = sum_sq / (n - 2.0);
        let se_slope = (s2 / sxx).sqrt();
        let se_intercept = (s2 * (1.0 / n + mx * mx / sxx)).sqrt();
        assert!((b.unwrap() - 2.0 * se_slope).abs() < 1e-12 * se_slope);
        assert!((a.unwrap() - 2.0 * se_intercept).abs() < 1e-12 * se_intercept);
        // A singular JᵀJ (the parameters not separable) has no interval.
        assert_eq!(
            super::two_sigma(&[[1.0, 1.0], [1.0, 1.0]], 1.0, 8),
            [None, None]
        );
    }
}
