//! A deterministic sagged start for static solves from a flat sheet. A flat net has no transverse
//! stiffness, and Newton from it wastes its first tens of iterations finding how deep the sheet
//! hangs (a slack net of seed 000 even has to buckle out of its plane). Instead: the shape of a
//! membrane under uniform tension and the sheet's weight — the graph Laplacian of the model's
//! couplings (weights 1/ℓ², ℓ the flat distance), zero on the fixed particles, loaded by the masses —
//! gives the sag's shape φ (max 1), and a one-dimensional minimisation of the true potential energy
//! along x₀ − s φ ẑ gives its depth s. Newton then starts where springs already carry the weight.
//!
//! A sheet pinned along one line (two corners of an edge, two diagonal corners) cannot sag into
//! place: it has to swing down about that line, a rigid rotation that Newton in Cartesian
//! coordinates follows in short steps (hang2 11²: 80 of its 113 iterations). [`folded_start`] folds
//! each side of the line down by the angle that minimises the true potential energy instead (a
//! one-dimensional search, as for the sag's depth): the rotation costs no strain, so the angle is the
//! one gravity and bending settle on.

use super::linear::{DofMap, SparseSpd};
use crate::physics::{CandidateSet, HessianBlocks, Model};
use nalgebra::{Matrix3, Vector3};
use std::f64::consts::FRAC_PI_2;

/// The membrane's sag shape: L φ = m over the free particles, φ = 0 on fixed ones, scaled to max 1.
/// None when nothing is free or the sheet is not tied to any fixed particle.
fn sag_shape(model: &Model, x0: &[Vector3<f64>]) -> Option<Vec<f64>> {
    let mut h = HessianBlocks::default();
    model.hessian(x0, &mut h, crate::physics::HessianMode::Projected);
    let mut edges: Vec<(u32, u32)> = h.all().map(|(&e, _)| e).filter(|(p, q)| p != q).collect();
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
    let mut candidates = CandidateSet::default();
    let mut energy = |s: f64| {
        for p in 0..x0.len() {
            trial[p] = x0[p] - Vector3::new(0.0, 0.0, s * phi[p]);
        }
        model.energy_with(&trial, &mut candidates, 1.0)
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
    let s = golden_section(&mut energy, (0.5 * s, 2.0 * s));
    if energy(s).partial_cmp(&e0) != Some(std::cmp::Ordering::Less) {
        return None;
    }
    for p in 0..x.len() {
        x[p] = x0[p] - Vector3::new(0.0, 0.0, s * phi[p]);
    }
    Some(s)
}

/// The minimiser of `f` on the bracket (a, b) by 40 steps of golden-section search (the bracket
/// shrinks to 0.618⁴⁰ ≈ 4e-9 of its width): the bracket's midpoint.
fn golden_section(f: &mut impl FnMut(f64) -> f64, (mut a, mut b): (f64, f64)) -> f64 {
    let r = 0.5 * (5f64.sqrt() - 1.0);
    let (mut c, mut d) = (b - r * (b - a), a + r * (b - a));
    let (mut ec, mut ed) = (f(c), f(d));
    for _ in 0..40 {
        if ec < ed {
            (b, d, ed) = (d, c, ec);
            c = b - r * (b - a);
            ec = f(c);
        } else {
            (a, c, ec) = (c, d, ed);
            d = a + r * (b - a);
            ed = f(d);
        }
    }
    0.5 * (a + b)
}

/// The line through the fixed particles when they all lie on one (within 1e-9 of the sheet's
/// extent): (a point of it, its unit direction). None with fewer than two distinct fixed particles,
/// off the line, or a vertical line.
fn pin_line(model: &Model, x: &[Vector3<f64>]) -> Option<(Vector3<f64>, Vector3<f64>)> {
    let pins: Vec<Vector3<f64>> = (0..model.len())
        .filter(|&p| model.fixed[p])
        .map(|p| x[p])
        .collect();
    let a = *pins.first()?;
    let b = *pins
        .iter()
        .max_by(|p, q| (*p - a).norm().total_cmp(&(*q - a).norm()))?;
    let extent = x.iter().map(|p| (p - a).norm()).fold(0.0, f64::max);
    let u = (b - a).try_normalize(1e-9 * extent.max(1e-300))?;
    let off = |p: &Vector3<f64>| {
        let r = p - a;
        (r - u * r.dot(&u)).norm()
    };
    (pins.iter().all(|p| off(p) <= 1e-9 * extent) && u.z.abs() < 0.99).then_some((a, u))
}

/// Moves the free particles of `x` to the sheet folded down about the line of its fixed particles
/// (see the module): each particle's offset from the line turned by the angle θ about it, on each
/// side downwards, θ in [0, π/2] minimising the energy (sampled every 5°, then golden section).
/// Returns θ in rad; None (x untouched) when the fixed particles are not on one line, a component
/// is held, there is no gravity, or folding does not lower the energy.
pub fn folded_start(model: &Model, x: &mut [Vector3<f64>]) -> Option<f64> {
    if model.gravity_m_per_s2 <= 0.0 || model.held_components.iter().any(|h| h.contains(&true)) {
        return None;
    }
    let (a, u) = pin_line(model, x)?;
    let x0 = x.to_vec();
    // Per particle: the offset from the line and the unit vector it turns towards (downwards).
    let arms: Vec<(Vector3<f64>, Vector3<f64>)> = x0
        .iter()
        .map(|p| {
            let r = p - a;
            let perp = r - u * r.dot(&u);
            let turn = u.cross(&perp);
            (perp, if turn.z > 0.0 { -turn } else { turn })
        })
        .collect();
    let mut trial = x0.clone();
    let mut candidates = CandidateSet::default();
    let mut energy = |t: f64| {
        let (c, s) = (t.cos(), t.sin());
        for p in 0..x0.len() {
            if !model.fixed[p] {
                let (perp, turn) = arms[p];
                trial[p] = x0[p] - perp + perp * c + turn * s;
            }
        }
        model.energy_with(&trial, &mut candidates, 1.0)
    };
    let step = 5f64.to_radians();
    let samples: Vec<f64> = (0..=18).map(|k| energy(k as f64 * step)).collect();
    let k = (0..samples.len()).min_by(|&i, &j| samples[i].total_cmp(&samples[j]))?;
    if k == 0 {
        return None;
    }
    let bracket = (
        (k as f64 - 1.0) * step,
        ((k + 1) as f64 * step).min(FRAC_PI_2),
    );
    let t = golden_section(&mut energy, bracket);
    let e = energy(t);
    if e.partial_cmp(&samples[0]) != Some(std::cmp::Ordering::Less) {
        return None;
    }
    x.copy_from_slice(&trial);
    Some(t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::{Gravity, SpringFamily, Springs};

    /// An n × n net of springs (k N/m, spacing h) in the plane z = 0, the given particles fixed.
    fn net(n: usize, fixed: &[usize], k: f64) -> (Model, Vec<Vector3<f64>>) {
        let h = 0.05;
        let x: Vec<Vector3<f64>> = (0..n * n)
            .map(|p| Vector3::new((p % n) as f64 * h, (p / n) as f64 * h, 0.0))
            .collect();
        let mut pairs = Vec::new();
        for j in 0..n {
            for i in 0..n {
                if i + 1 < n {
                    pairs.push((j * n + i, j * n + i + 1));
                }
                if j + 1 < n {
                    pairs.push((j * n + i, (j + 1) * n + i));
                }
            }
        }
        let rest = vec![h; pairs.len()];
        let ks = vec![k; pairs.len()];
        let masses = vec![1e-3; n * n];
        let mut is_fixed = vec![false; n * n];
        fixed.iter().for_each(|&p| is_fixed[p] = true);
        let model = Model {
            terms: vec![
                Box::new(Springs::new(SpringFamily::Tensile, pairs, rest, ks)),
                Box::new(Gravity::new(masses.clone(), 9.81)),
            ],
            masses,
            fixed: is_fixed,
            held_components: vec![],
            n_grid: n * n,
            gravity_m_per_s2: 9.81,
            damping_Ns_per_m: 0.0,
            elongation_rate: None,
            constant_hessian: Default::default(),
        };
        (model, x)
    }

    #[test]
    fn a_net_pinned_along_one_edge_folds_straight_down_without_strain() {
        // Pinned at the two ends of its top edge, a net without bending hangs straight down: the
        // fold turns it by 90°, and every spring keeps its length (a rigid rotation).
        let n = 7;
        let (model, mut x) = net(n, &[n * (n - 1), n * n - 1], 100.0);
        let x0 = x.clone();
        let e0 = model.energy(&x, 1.0);
        let t = folded_start(&model, &mut x).expect("pins on one line");
        assert!((t - FRAC_PI_2).abs() < 1e-6, "θ = {t}");
        assert!(model.energy(&x, 1.0) < e0);
        for p in 0..n * n {
            let (i, j) = (p % n, p / n);
            if i + 1 < n {
                let (a, b) = ((x[p] - x[p + 1]).norm(), (x0[p] - x0[p + 1]).norm());
                assert!((a - b).abs() < 1e-12);
            }
            // The row j hangs (n − 1 − j) spacings below the pinned edge.
            assert!(
                (x[p].z + (n - 1 - j) as f64 * 0.05).abs() < 1e-12,
                "{p}: {}",
                x[p].z
            );
        }
    }

    #[test]
    fn pins_off_one_line_or_a_held_component_leave_the_start_alone() {
        let n = 5;
        // Three corners: not on one line.
        let (model, mut x) = net(n, &[0, n - 1, n * n - 1], 100.0);
        let x0 = x.clone();
        assert!(folded_start(&model, &mut x).is_none());
        assert_eq!(x, x0);
        // One pin: no line.
        let (model, mut x) = net(n, &[0], 100.0);
        assert!(folded_start(&model, &mut x).is_none());
        // A held component (a symmetry plane).
        let (mut model, mut x) = net(n, &[0, n - 1], 100.0);
        model.held_components = vec![[false, true, false]; n * n];
        assert!(folded_start(&model, &mut x).is_none());
    }
}
