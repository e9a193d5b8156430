//! How well the drape pins each calibrated parameter near the optimum: the cost's rise along each
//! axis at a noise level, and the half-widths of a quadratic fit to the cost (seed 000 §4's
//! identifiability of the mass-spring parameters).

use super::Problem;
use crate::edges::EdgeFit;

/// What the drape tells of one parameter near the optimum.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Identifiability {
    /// Parameter name with its unit (`stiffness_N_per_m`, ...; `topology` has none).
    pub name: &'static str,
    /// Half-width of the interval around the optimum over which the cost rises by less than the
    /// measurement noise, in the parameter's unit; infinite when the cost does not rise at all.
    pub uncertainty: f64,
    /// Whether that half-width is below the required fraction of the value (for `topology`: whether
    /// every other topology costs more than the optimum plus the noise).
    pub identifiable: bool,
}

/// What "a cost indistinguishable from the optimum" means in [`identifiability`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Noise {
    /// A given measurement error of the photos, in the cost's unit (% of the side): a worst-case
    /// bound, since all of it may lie along the model's directions.
    Given(f64),
    /// Nonlinear least squares: σ̂² from the residual at the optimum over the degrees of freedom left
    /// (5 coefficients per measured edge, minus the 2 fitted parameters), and a 2σ (about 95 %) interval.
    FromResidual,
    /// The residual's σ̂ and a systematic σ of the photos (% of the side: the edges' RMS
    /// [`crate::edges::systematic_pct`]) in quadrature: the setup's errors move whole curves and
    /// leave no residual, so they widen the interval by 2σ_sys.
    ResidualPlusSystematic(f64),
}

impl Noise {
    /// δ: the rise of the squared cost that this noise explains at the optimum `best_u` (the
    /// residual's share per degree of freedom of the fit, or the given noise's square).
    fn cost_rise(self, problem: &Problem, best_u: &[f64]) -> f64 {
        let c0 = problem.cost(best_u);
        let dof = (5 * problem.measured.len()).saturating_sub(2).max(1) as f64;
        match self {
            Noise::Given(n) => n * n,
            Noise::FromResidual => 4.0 * c0 * c0 / dof,
            Noise::ResidualPlusSystematic(s) => 4.0 * c0 * c0 / dof + 4.0 * s * s,
        }
    }

    /// The noise model for `measured` edges: a `given` bound if any; else the residual, with the
    /// edges' systematic part (their RMS) when `systematic` and every edge carries one.
    pub fn for_edges(given: Option<f64>, measured: &[EdgeFit], systematic: bool) -> Noise {
        let sys: Option<Vec<f64>> = measured.iter().map(|e| e.systematic_pct).collect();
        match (given, sys) {
            (Some(n), _) => Noise::Given(n),
            (None, Some(s)) if systematic && !s.is_empty() => Noise::ResidualPlusSystematic(
                (s.iter().map(|x| x * x).sum::<f64>() / s.len() as f64).sqrt(),
            ),
            _ => Noise::FromResidual,
        }
    }
}

/// Identifiability of each parameter at the optimum `best_u` (seed 000's five: stiffness, damping,
/// elongation rate, natural length, topology). The squared cost, quadratic in the parameters near a
/// minimum (cost² ≈ c² + ½ δᵀHδ), is fitted by least squares to costs sampled around the optimum:
/// jointly on a `steps` × `steps` grid for stiffness and natural length, which trade off against each
/// other (each axis scaled to where the cost rises by a few noise levels), and along a line over
/// ±`window` of the range (unit box) for damping and the elongation rate. A parameter's uncertainty is
/// the half-width, projected on its axis, of the region where cost² exceeds its minimum by less than
/// Δ: √(2Δ (H⁻¹)ᵢᵢ), so a correlated pair shows its whole valley. Δ is `noise`² for a given noise,
/// or 4c²/(N − 2) from the residual c with N = 5 × edges (a 2σ interval). A parameter is identifiable when its
/// uncertainty is below `rel_tol` × its value; a static drape cannot see damping or the elongation
/// rate, so their cost is flat and their uncertainty infinite. The topology is identifiable when
/// every other topology raises cost² by more than Δ.
pub fn identifiability(
    problem: &Problem,
    best_u: &[f64],
    window: f64,
    steps: usize,
    noise: Noise,
    rel_tol: f64,
) -> Vec<Identifiability> {
    const NAMES: [&str; 4] = [
        "stiffness_N_per_m",
        "damping_Ns_per_m",
        "elongation_rate",
        "natural_length_m",
    ];
    let b = &problem.bounds;
    let ranges = [
        b.stiffness_N_per_m,
        b.damping_Ns_per_m,
        b.elongation_rate,
        b.natural_length_m,
    ];
    let best = b.decode(best_u);
    let values = [
        best.stiffness_N_per_m,
        best.damping_Ns_per_m,
        best.elongation_rate,
        best.natural_length_m,
    ];
    let steps = steps.max(3);
    let offsets: Vec<f64> = (0..steps)
        .map(|k| -window + 2.0 * window * k as f64 / (steps - 1) as f64)
        .collect();
    let sample = |dims: &[usize], grid: Vec<Vec<f64>>| sample_costs(problem, best_u, dims, grid);
    let mut half_widths = [f64::INFINITY; 4];
    let joint = [0usize, 3];
    // Per axis, a step over which the cost rises by a few times the noise: the quadratic model holds
    // there, and the fit sees curvature rather than round-off.
    let delta = noise.cost_rise(problem, best_u);
    let noise_pct = 0.5 * delta.sqrt();
    let reach: Vec<f64> = joint
        .iter()
        .map(|&d| quadratic_reach(problem, best_u, d, window, noise_pct))
        .collect();
    let grid2: Vec<Vec<f64>> = offsets
        .iter()
        .flat_map(|&a| {
            let reach = &reach;
            offsets
                .iter()
                .map(move |&c| vec![a * reach[0], c * reach[1]])
        })
        .collect();
    let w = quadratic_half_widths(&sample(&joint, grid2), delta);
    for (k, &d) in joint.iter().enumerate() {
        half_widths[d] = w[k];
    }
    for d in [1usize, 2] {
        let line = offsets.iter().map(|&t| vec![t]).collect();
        half_widths[d] = quadratic_half_widths(&sample(&[d], line), delta)[0];
    }
    let mut out: Vec<Identifiability> = (0..4)
        .map(|d| {
            let uncertainty = half_widths[d] * (ranges[d].1 - ranges[d].0);
            Identifiability {
                name: NAMES[d],
                uncertainty,
                identifiable: uncertainty < rel_tol * values[d].abs(),
            }
        })
        .collect();
    out.push(topology_identifiability(problem, best_u, delta));
    out
}

/// Squared costs at `best_u` moved by each `t` of `grid` along `dims` (clamped to the box), with the
/// moves; failed drapes left out.
fn sample_costs(
    problem: &Problem,
    best_u: &[f64],
    dims: &[usize],
    grid: Vec<Vec<f64>>,
) -> Vec<(Vec<f64>, f64)> {
    grid.into_iter()
        .filter_map(|t| {
            let mut u = best_u.to_vec();
            let mut moved = Vec::with_capacity(dims.len());
            for (&d, &td) in dims.iter().zip(&t) {
                u[d] = (best_u[d] + td).clamp(0.0, 1.0);
                moved.push(u[d] - best_u[d]);
            }
            let c = problem.cost(&u);
            (c < problem.penalty).then_some((moved, c * c))
        })
        .collect()
}

/// The topology is identified when every other topology (the best point otherwise) costs more than
/// the best by the noise `delta` (in squared cost).
fn topology_identifiability(problem: &Problem, best_u: &[f64], delta: f64) -> Identifiability {
    let b = &problem.bounds;
    let best = b.decode(best_u);
    let c0 = problem.cost(best_u);
    let others_cost_more = (0..3).all(|k| {
        let mut u = best_u.to_vec();
        u[4] = (k as f64 + 0.5) / 3.0;
        b.decode(&u).topology == best.topology || problem.cost(&u).powi(2) > c0 * c0 + delta
    });
    Identifiability {
        name: "topology",
        uncertainty: if others_cost_more { 0.0 } else { f64::INFINITY },
        identifiable: others_cost_more,
    }
}

/// Along axis `d` of the unit box, a step (as a fraction of `window`) over which the cost rises
/// by 3–30 times the noise `noise_pct` from `best_u`: the quadratic model holds there, and a fit sees
/// curvature rather than round-off.
fn quadratic_reach(
    problem: &Problem,
    best_u: &[f64],
    d: usize,
    window: f64,
    noise_pct: f64,
) -> f64 {
    let c0 = problem.cost(best_u);
    let rise = |h: f64| {
        [-h, h]
            .iter()
            .map(|&t| {
                let mut u = best_u.to_vec();
                u[d] = (best_u[d] + t).clamp(0.0, 1.0);
                problem.cost(&u) - c0
            })
            .fold(f64::NEG_INFINITY, f64::max)
    };
    let mut h = window / 8.0;
    for _ in 0..12 {
        let r = rise(h);
        if r < 3.0 * noise_pct && h < window {
            h = (2.0 * h).min(window);
        } else if r > 30.0 * noise_pct {
            h *= 0.5;
        } else {
            break;
        }
    }
    h / window
}

/// Fits y ≈ a + gᵀt + ½ tᵀHt to `pts` (t ∈ ℝⁿ, squared cost y) and returns, per coordinate, the
/// half-width of the region y ≤ y_min + `delta` projected on that axis: √(2Δ (H⁻¹)ᵢᵢ). Infinite where
/// H is not positive definite (a flat or one-sided cost) or there are too few points.
pub fn quadratic_half_widths(pts: &[(Vec<f64>, f64)], delta: f64) -> Vec<f64> {
    let n = pts.first().map_or(0, |p| p.0.len());
    let pairs: Vec<(usize, usize)> = (0..n).flat_map(|i| (i..n).map(move |j| (i, j))).collect();
    let cols = 1 + n + pairs.len();
    let flat = vec![f64::INFINITY; n];
    if n == 0 || pts.len() < cols {
        return flat;
    }
    let m = nalgebra::DMatrix::from_fn(pts.len(), cols, |r, k| {
        let t = &pts[r].0;
        match k {
            0 => 1.0,
            k if k <= n => t[k - 1],
            k => {
                let (i, j) = pairs[k - 1 - n];
                t[i] * t[j]
            }
        }
    });
    let y = nalgebra::DVector::from_iterator(pts.len(), pts.iter().map(|p| p.1));
    let Ok(coef) = m.svd(true, true).solve(&y, 1e-14) else {
        return flat;
    };
    let mut h = nalgebra::DMatrix::zeros(n, n);
    for (k, &(i, j)) in pairs.iter().enumerate() {
        let c = coef[1 + n + k];
        if i == j {
            h[(i, i)] = 2.0 * c;
        } else {
            h[(i, j)] = c;
            h[(j, i)] = c;
        }
    }
    let scale = y.iter().fold(0.0f64, |s, v| s.max(v.abs())).max(1e-300);
    let eig = h.clone().symmetric_eigen();
    if eig.eigenvalues.iter().any(|&e| e <= 1e-9 * scale) {
        return flat;
    }
    let Some(h_inv) = h.try_inverse() else {
        return flat;
    };
    (0..n)
        .map(|i| (2.0 * delta * h_inv[(i, i)]).sqrt())
        .collect()
}
