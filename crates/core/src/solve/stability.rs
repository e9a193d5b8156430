//! The stability of an explicit step: the highest natural frequency of the linearised sheet (power
//! iteration), the largest stable step of each explicit integrator, and the kinetic energy.

use super::kind::Integrator;
use crate::physics::{HessianBlocks, Model};
use nalgebra::Vector3;

/// The highest natural frequency ω_max (rad/s) at `x` and the effective mass (kg) of its mode, by
/// power iteration on M^{-1/2} K M^{-1/2} with the projected Hessian K (60 iterations from a fixed
/// start; a lower bound that converges to ω_max).
pub fn highest_mode(model: &Model, x: &[Vector3<f64>]) -> (f64, f64) {
    let mut h = HessianBlocks::default();
    model.hessian(x, &mut h, crate::physics::HessianMode::Projected);
    let n = model.len();
    let free: Vec<bool> = model
        .fixed
        .iter()
        .zip(&model.masses)
        .map(|(f, m)| !f && *m > 0.0)
        .collect();
    let inv_sqrt_m: Vec<f64> = model
        .masses
        .iter()
        .zip(&free)
        .map(|(m, f)| if *f { 1.0 / m.sqrt() } else { 0.0 })
        .collect();
    // A deterministic, non-symmetric start so that every mode is present.
    let mut v: Vec<Vector3<f64>> = (0..n)
        .map(|p| {
            let t = p as f64;
            Vector3::new(
                (1.3 * t).sin() + 0.1,
                (2.1 * t + 0.4).cos(),
                (0.7 * t + 1.1).sin(),
            ) * if free[p] { 1.0 } else { 0.0 }
        })
        .collect();
    let mut lambda = 0.0;
    let mut tmp = vec![Vector3::zeros(); n];
    let mut out = vec![Vector3::zeros(); n];
    for _ in 0..60 {
        let norm = v.iter().map(|a| a.norm_squared()).sum::<f64>().sqrt();
        if norm == 0.0 {
            return (0.0, 0.0);
        }
        for p in 0..n {
            v[p] /= norm;
            tmp[p] = v[p] * inv_sqrt_m[p];
        }
        out.iter_mut().for_each(|o| *o = Vector3::zeros());
        h.mul_add(&tmp, &mut out);
        for p in 0..n {
            out[p] *= inv_sqrt_m[p];
        }
        lambda = v.iter().zip(&out).map(|(a, b)| a.dot(b)).sum::<f64>();
        std::mem::swap(&mut v, &mut out);
    }
    let (mut num, mut den) = (0.0, 0.0);
    for p in 0..n {
        if free[p] {
            let w = v[p].norm_squared();
            num += w * model.masses[p];
            den += w;
        }
    }
    (
        lambda.max(0.0).sqrt(),
        if den > 0.0 { num / den } else { 0.0 },
    )
}

/// The largest stable time step of an explicit integrator at `x`, from the highest mode
/// ([`highest_mode`]): symplectic Euler needs Δt < (√(γ² + 4ω²) − γ)/ω² with γ = c/m (2/ω without
/// damping); forward Euler with damping c needs
/// |1 + Δt λ| < 1 for λ = −c/2m ± iω√(1 − ζ²), i.e. Δt < c/(m ω²) when underdamped and
/// Δt < 2/|λ_fast| when overdamped; without damping it is unstable at any Δt (0 is returned).
/// None for implicit Euler (unconditionally stable).
pub fn stability_limit_dt(
    model: &Model,
    x: &[Vector3<f64>],
    integrator: Integrator,
    damping_Ns_per_m: f64,
) -> Option<f64> {
    if matches!(
        integrator,
        Integrator::ImplicitEuler | Integrator::BaraffWitkin
    ) {
        return None;
    }
    let (w, m) = highest_mode(model, x);
    if w <= 0.0 || m <= 0.0 {
        return Some(f64::INFINITY);
    }
    let c = damping_Ns_per_m;
    Some(match integrator {
        // v' = v + Δt(−ω²x − γv), x' = x + Δt v' (γ = c/m) is stable for Δt²ω² + 2Δtγ < 4, i.e.
        // Δt < (√(γ² + 4ω²) − γ)/ω²: 2/ω undamped, 2/γ when damping dominates.
        Integrator::SymplecticEuler => {
            let g = c / m;
            ((g * g + 4.0 * w * w).sqrt() - g) / (w * w)
        }
        _ if c <= 0.0 => 0.0,
        _ if c < 2.0 * m * w => c / (m * w * w),
        _ => {
            let fast = c / (2.0 * m) * (1.0 + (1.0 - 4.0 * m * m * w * w / (c * c)).sqrt());
            2.0 / fast
        }
    })
}

/// Kinetic energy in J.
pub fn kinetic_energy(model: &Model, v: &[Vector3<f64>]) -> f64 {
    model
        .masses
        .iter()
        .zip(v)
        .map(|(m, vi)| 0.5 * m * vi.norm_squared())
        .sum()
}
