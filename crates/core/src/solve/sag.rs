//! A deterministic sagged start for static solves from a flat sheet. A flat net has no transverse
//! stiffness, and Newton from it wastes its first tens of iterations finding how deep the sheet
//! hangs (a slack net of seed 000 even has to buckle out of its plane). Instead: the shape of a
//! membrane under uniform tension and the sheet's weight — the graph Laplacian of the model's
//! couplings (weights 1/ℓ², ℓ the flat distance), zero on the fixed particles, loaded by the masses —
//! gives the sag's shape φ (max 1), and a one-dimensional minimisation of the true potential energy
//! along x₀ − s φ ẑ gives its depth s. Newton then starts where springs already carry the weight.

use super::linear::{DofMap, SparseSpd};
use crate::physics::{HessianBlocks, Model};
use nalgebra::{Matrix3, Vector3};

/// The membrane's sag shape: L φ = m over the free particles, φ = 0 on fixed ones, scaled to max 1.
/// None when nothing is free or the sheet is not tied to any fixed particle.
fn sag_shape(model: &Model, x0: &[Vector3<f64>]) -> Option<Vec<f64>> {
    let mut h = HessianBlocks::default();
    model.hessian(x0, &mut h, true);
    let mut edges: Vec<(u32, u32)> = h.pairs.iter().copied().filter(|(p, q)| p != q).collect();
    edges.sort_unstable();
    edges.dedup();
    let mut lap = HessianBlocks::default();
    for p in 0..model.len() {
        lap.push(p, p, Matrix3::zeros());
    }
    for &(p, q) in &edges {
        let (p, q) = (p as usize, q as usize);
        let l2 = (x0[p] - x0[q]).norm_squared();
        if l2 <= 0.0 {
            continue;
        }
        let w = Matrix3::identity() / l2;
        lap.push(p, p, w);
        lap.push(q, q, w);
        lap.push(p, q, -w);
    }
    let dofs = DofMap::new(&model.fixed);
    if dofs.n == 0 {
        return None;
    }
    let mut spd = SparseSpd::new();
    let scale = edges
        .iter()
        .map(|&(p, q)| 1.0 / (x0[p as usize] - x0[q as usize]).norm_squared())
        .fold(0.0, f64::max);
    if !spd.factorize(&dofs, &lap, &vec![1e-12 * scale; dofs.n]) {
        return None;
    }
    let mut rhs = vec![0.0; dofs.n];
    for p in 0..model.len() {
        if let Some(d) = dofs.dof(p) {
            rhs[d + 2] = model.masses[p];
        }
    }
    spd.solve_in_place(&mut rhs);
    let phi: Vec<f64> = (0..model.len())
        .map(|p| dofs.dof(p).map_or(0.0, |d| rhs[d + 2]))
        .collect();
    let top = phi.iter().copied().fold(0.0, f64::max);
    (top > 0.0 && top.is_finite()).then(|| phi.into_iter().map(|v| v / top).collect())
}

/// Moves the free particles of `x` (a flat sheet, or one with a small perturbation) down to the
/// sagged start (see the module) and returns its depth in m; None (x untouched) when there is no
/// gravity, the sheet hangs from nothing, or sagging does not lower the energy.
pub fn sagged_start(model: &Model, x: &mut [Vector3<f64>]) -> Option<f64> {
    if model.gravity_m_per_s2 <= 0.0 || model.fixed.iter().all(|&f| f) {
        return None;
    }
    let phi = sag_shape(model, x)?;
    let x0 = x.to_vec();
    let mut trial = x0.clone();
    let mut energy = |s: f64| {
        for p in 0..x0.len() {
            trial[p] = x0[p] - Vector3::new(0.0, 0.0, s * phi[p]);
        }
        model.energy(&trial, 1.0)
    };
    // Bracket the minimum by doubling from a thousandth of the sheet's extent, then golden section.
    let extent = x0
        .iter()
        .map(|p| (p - x0[0]).norm())
        .fold(0.0, f64::max)
        .max(1e-6);
    let e0 = energy(0.0);
    let mut s = 1e-3 * extent;
    let mut es = energy(s);
    if es.partial_cmp(&e0) != Some(std::cmp::Ordering::Less) {
        return None;
    }
    loop {
        let t = 2.0 * s;
        let et = energy(t);
        if et.partial_cmp(&es) != Some(std::cmp::Ordering::Less) || t > 4.0 * extent {
            break;
        }
        (s, es) = (t, et);
    }
    let (mut a, mut b) = (0.5 * s, 2.0 * s);
    let r = 0.5 * (5f64.sqrt() - 1.0);
    let (mut c, mut d) = (b - r * (b - a), a + r * (b - a));
    let (mut ec, mut ed) = (energy(c), energy(d));
    for _ in 0..40 {
        if ec < ed {
            (b, d, ed) = (d, c, ec);
            c = b - r * (b - a);
            ec = energy(c);
        } else {
            (a, c, ec) = (c, d, ed);
            d = a + r * (b - a);
            ed = energy(d);
        }
    }
    let s = 0.5 * (a + b);
    if energy(s).partial_cmp(&e0) != Some(std::cmp::Ordering::Less) {
        return None;
    }
    for p in 0..x.len() {
        x[p] = x0[p] - Vector3::new(0.0, 0.0, s * phi[p]);
    }
    Some(s)
}
