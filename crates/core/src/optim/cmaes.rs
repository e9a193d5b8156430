//! CMA-ES, the baseline of ICA (Hansen's (μ/μ_w, λ) strategy with cumulative step-size adaptation and
//! rank-one plus rank-μ covariance updates), on the unit box: candidates are evaluated at their
//! projection onto the box plus a quadratic penalty on the distance outside it. Random draws are serial,
//! costs of a generation parallel: a seed gives the same result on any thread count.

use nalgebra::{DMatrix, DVector, SymmetricEigen};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

/// The result of a CMA-ES run.
#[derive(Debug, Clone, PartialEq)]
pub struct CmaesReport {
    /// Best position found (in the box).
    pub best_x: Vec<f64>,
    /// Its cost.
    pub best_cost: f64,
    /// Cost evaluations used.
    pub evaluations: usize,
    /// Best cost after each generation.
    pub history: Vec<f64>,
}

fn normal(rng: &mut ChaCha8Rng) -> f64 {
    let (u1, u2): (f64, f64) = (rng.random::<f64>().max(1e-300), rng.random());
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

/// Minimises `cost` over [0, 1]^dim within `budget` evaluations, from the box centre with step 0.3.
pub fn cmaes(
    cost: &(dyn Fn(&[f64]) -> f64 + Sync),
    dim: usize,
    budget: usize,
    seed: u64,
) -> CmaesReport {
    let n = dim as f64;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let st = Strategy::new(dim);
    let (lambda, mu, mu_eff, w) = (st.lambda, st.mu, st.mu_eff, &st.w);
    let mut m = DVector::from_element(dim, 0.5);
    let mut sigma = 0.3;
    let mut c = DMatrix::<f64>::identity(dim, dim);
    let (mut p_sigma, mut p_c) = (DVector::zeros(dim), DVector::zeros(dim));
    let (mut best_x, mut best_cost) = (vec![0.5; dim], f64::INFINITY);
    let mut evaluations = 0;
    let mut history = Vec::new();
    let mut g = 0usize;
    while evaluations + lambda <= budget.max(lambda) {
        let eig = SymmetricEigen::new(c.clone());
        let d = eig.eigenvalues.map(|v| v.max(1e-20).sqrt());
        let b = eig.eigenvectors;
        let ys: Vec<DVector<f64>> = (0..lambda)
            .map(|_| &b * DVector::from_fn(dim, |i, _| d[i] * normal(&mut rng)))
            .collect();
        let xs: Vec<DVector<f64>> = ys.iter().map(|y| &m + y * sigma).collect();
        let costs: Vec<f64> = xs.par_iter().map(|x| penalised(cost, x)).collect();
        evaluations += lambda;
        let mut order: Vec<usize> = (0..lambda).collect();
        order.sort_by(|&a, &b| costs[a].total_cmp(&costs[b]));
        if costs[order[0]] < best_cost {
            best_cost = costs[order[0]];
            best_x = xs[order[0]].iter().map(|v| v.clamp(0.0, 1.0)).collect();
        }
        history.push(best_cost);
        let y_w: DVector<f64> = order
            .iter()
            .take(mu)
            .zip(w)
            .map(|(&k, wi)| &ys[k] * *wi)
            .fold(DVector::zeros(dim), |a, b| a + b);
        m += &y_w * sigma;
        let inv_sqrt_c = &b * DMatrix::from_diagonal(&d.map(|v| 1.0 / v)) * b.transpose();
        p_sigma = &p_sigma * (1.0 - st.c_sigma)
            + &inv_sqrt_c * &y_w * (st.c_sigma * (2.0 - st.c_sigma) * mu_eff).sqrt();
        g += 1;
        let h_sigma = p_sigma.norm() / (1.0 - (1.0 - st.c_sigma).powi(2 * g as i32)).sqrt()
            < (1.4 + 2.0 / (n + 1.0)) * st.chi_n;
        let hs = if h_sigma { 1.0 } else { 0.0 };
        p_c = &p_c * (1.0 - st.c_c) + &y_w * (hs * (st.c_c * (2.0 - st.c_c) * mu_eff).sqrt());
        let rank_mu = order
            .iter()
            .take(mu)
            .zip(w)
            .fold(DMatrix::zeros(dim, dim), |acc, (&k, wi)| {
                acc + &ys[k] * ys[k].transpose() * *wi
            });
        c = &c * (1.0 - st.c_1 - st.c_mu)
            + (&p_c * p_c.transpose() + &c * ((1.0 - hs) * st.c_c * (2.0 - st.c_c))) * st.c_1
            + rank_mu * st.c_mu;
        sigma *= ((st.c_sigma / st.d_sigma) * (p_sigma.norm() / st.chi_n - 1.0)).exp();
        if !sigma.is_finite() || sigma < 1e-14 {
            break;
        }
    }
    CmaesReport {
        best_x,
        best_cost,
        evaluations,
        history,
    }
}

/// The cost at `x` clamped to the unit box, plus 10³ times the squared distance clamped away (a
/// NaN cost is infinite).
fn penalised(cost: &(dyn Fn(&[f64]) -> f64 + Sync), x: &DVector<f64>) -> f64 {
    let clamped: Vec<f64> = x.iter().map(|v| v.clamp(0.0, 1.0)).collect();
    let out: f64 = x.iter().zip(&clamped).map(|(a, b)| (a - b).powi(2)).sum();
    let v = cost(&clamped);
    if v.is_nan() {
        f64::INFINITY
    } else {
        v + 1e3 * out
    }
}

/// Hansen's default strategy parameters for dimension n ("The CMA Evolution Strategy: A
/// Tutorial", 2016, Table 1): population λ, parents μ with weights w, the learning rates.
struct Strategy {
    lambda: usize,
    mu: usize,
    w: Vec<f64>,
    mu_eff: f64,
    c_sigma: f64,
    d_sigma: f64,
    c_c: f64,
    c_1: f64,
    c_mu: f64,
    /// E‖N(0, I)‖.
    chi_n: f64,
}

impl Strategy {
    fn new(dim: usize) -> Self {
        let n = dim as f64;
        let lambda = 4 + (3.0 * n.ln()).floor() as usize;
        let mu = lambda / 2;
        let raw: Vec<f64> = (0..mu)
            .map(|i| (mu as f64 + 0.5).ln() - ((i + 1) as f64).ln())
            .collect();
        let sum: f64 = raw.iter().sum();
        let w: Vec<f64> = raw.iter().map(|v| v / sum).collect();
        let mu_eff = 1.0 / w.iter().map(|v| v * v).sum::<f64>();
        let c_sigma = (mu_eff + 2.0) / (n + mu_eff + 5.0);
        let c_1 = 2.0 / ((n + 1.3).powi(2) + mu_eff);
        Self {
            lambda,
            mu,
            w,
            mu_eff,
            c_sigma,
            d_sigma: 1.0 + 2.0 * (((mu_eff - 1.0) / (n + 1.0)).sqrt() - 1.0).max(0.0) + c_sigma,
            c_c: (4.0 + mu_eff / n) / (n + 4.0 + 2.0 * mu_eff / n),
            c_1,
            c_mu: (1.0 - c_1)
                .min(2.0 * (mu_eff - 2.0 + 1.0 / mu_eff) / ((n + 2.0).powi(2) + mu_eff)),
            chi_n: n.sqrt() * (1.0 - 1.0 / (4.0 * n) + 1.0 / (21.0 * n * n)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shifted(x: &[f64]) -> f64 {
        x.iter()
            .enumerate()
            .map(|(k, v)| (k as f64 + 1.0) * (v - 0.2 - 0.15 * k as f64).powi(2))
            .sum()
    }

    #[test]
    fn converges_on_an_ill_scaled_quadratic_within_its_budget() {
        let r = cmaes(&shifted, 5, 1500, 3);
        assert!(r.best_cost < 1e-8, "{r:?}");
        assert!(r.evaluations <= 1500);
    }

    #[test]
    fn same_seed_same_result_on_one_and_two_threads() {
        let run = |t: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(t)
                .build()
                .unwrap()
                .install(|| cmaes(&shifted, 4, 400, 9))
        };
        assert_eq!(run(1), run(2));
    }

    #[test]
    fn a_minimum_on_the_boundary_is_found_inside_the_box() {
        let r = cmaes(
            &|x: &[f64]| x.iter().map(|v| (v + 0.5).powi(2)).sum(),
            3,
            600,
            1,
        );
        assert!(r.best_x.iter().all(|v| (0.0..=1e-3).contains(v)), "{r:?}");
    }
}
