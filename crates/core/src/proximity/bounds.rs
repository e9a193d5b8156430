//! Per-vertex displacement bounds (Offset Geometric Contact: Chen, Hu, Kaufman, Yuksel et al.,
//! "Offset Geometric Contact", ACM TOG 44(4), 2025, §4.2): one proximity query at a state gives each
//! vertex a distance it may move, along any path, without any pair of primitives that share no
//! vertex coming within the thickness ξ. A step whose every vertex stays within its bound needs no
//! continuous collision detection.
//!
//! Why it holds: the points of a primitive are convex combinations of its vertices, so when every
//! vertex v moves by at most δ_v the distance of a pair (A, B) falls by at most max_A δ + max_B δ
//! (the bound self-contact's candidate lists use as well). With b_v = γ·min(r, d_P − ξ
//! over the pairs P that v belongs to and that lie within ξ + r), γ < ½, a pair within reach keeps
//! more than (1 − 2γ)(d_P − ξ) beyond ξ and a pair out of reach more than (1 − 2γ) r.

use super::{MeshTopology, Pair, V3, candidate_pairs, pair_distance};
use crate::proximity::Aabb;

/// Every pair of primitives sharing no vertex whose distance at `x` is below `within_m`, with the
/// distance, by checking every vertex against every triangle and every edge against every other
/// (O(n²)): the reference the broad phase and the bounds are tested against, and an independent
/// check of small meshes. Sorted by pair.
pub fn brute_force_pairs(topo: &MeshTopology, x: &[V3], within_m: f64) -> Vec<(Pair, f64)> {
    let mut out = Vec::new();
    let mut keep = |pair: Pair| {
        let idx = pair.vertices(topo);
        let d = pair_distance(pair.is_point_triangle(), &idx.map(|k| x[k])).0;
        if d < within_m {
            out.push((pair, d));
        }
    };
    for &v in &topo.vertices {
        for (t, tri) in topo.triangles.iter().enumerate() {
            if !tri.contains(&v) {
                keep(Pair::PointTriangle(v, t as u32));
            }
        }
    }
    for (a, ea) in topo.edges.iter().enumerate() {
        for (b, eb) in topo.edges.iter().enumerate().skip(a + 1) {
            if !ea.iter().any(|v| eb.contains(v)) {
                keep(Pair::EdgeEdge(a as u32, b as u32));
            }
        }
    }
    out.sort_unstable_by_key(|p| p.0);
    out
}

/// Every pair sharing no vertex within `within_m` at `x`, with its distance, by the spatial-hash
/// broad phase ([`candidate_pairs`]) and the exact distance: the same list as
/// [`brute_force_pairs`] at the cost of the pairs near each other.
pub fn pairs_within(topo: &MeshTopology, x: &[V3], within_m: f64) -> Vec<(Pair, f64)> {
    let boxes: Vec<Aabb> = x.iter().map(Aabb::point).collect();
    // Boxes grown by r on every side overlap wherever the primitives are within 2r.
    let candidates = candidate_pairs(topo, &boxes, 0.5 * within_m, |_| true);
    candidates
        .into_iter()
        .filter_map(|pair| {
            let idx = pair.vertices(topo);
            let d = pair_distance(pair.is_point_triangle(), &idx.map(|k| x[k])).0;
            (d < within_m).then_some((pair, d))
        })
        .collect()
}

/// OGC's share γ of a vertex's clearance it may use: below ½, so that the two primitives of a pair
/// together use less than its whole clearance.
pub const BOUND_SHARE: f64 = 0.45;

/// Each vertex's displacement bound at `x`, m: γ·min(`reach_m`, the clearance d − ξ of every pair
/// within ξ + `reach_m` that it belongs to), γ = [`BOUND_SHARE`]; 0 for a vertex of a pair already
/// within `thickness_m`; infinite for a particle in no triangle. Every path on which each vertex
/// stays within its bound of `x` keeps every pair farther apart than ξ (see the module's
/// comment), and every pair that comes within ξ + (1 − 2γ)`reach_m` on it is one of the pairs this
/// query measured.
pub fn vertex_bounds(topo: &MeshTopology, x: &[V3], thickness_m: f64, reach_m: f64) -> Vec<f64> {
    let mut clearance = vec![f64::INFINITY; x.len()];
    for &v in &topo.vertices {
        clearance[v as usize] = reach_m;
    }
    for (pair, d) in pairs_within(topo, x, thickness_m + reach_m) {
        let gap = (d - thickness_m).max(0.0);
        for v in pair.vertices(topo) {
            clearance[v] = clearance[v].min(gap);
        }
    }
    clearance.into_iter().map(|c| BOUND_SHARE * c).collect()
}

/// The largest fraction in [0, ∞] of the step `dx` that keeps every vertex within its `bounds`
/// ([`vertex_bounds`]): min over moving vertices of b_v / |dx_v| (infinite when none moves).
pub fn bounded_fraction(bounds: &[f64], dx: &[V3]) -> f64 {
    bounds
        .iter()
        .zip(dx)
        .filter(|(_, d)| d.norm_squared() > 0.0)
        .map(|(b, d)| b / d.norm())
        .fold(f64::INFINITY, f64::min)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// A sheet of `n` × `n` vertices (spacing 1 cm) folded over itself along x = 0 with the upper
    /// layer `gap` (m) above the lower one, crumpled by noise of `noise` (m): layers facing
    /// each other at millimetres, the kind of state where folds press.
    fn folded(n: u32, gap: f64, noise: f64, rng: &mut ChaCha8Rng) -> (Vec<V3>, Vec<[u32; 3]>) {
        let h = 0.01;
        let mut x = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let s = (i as f64 - 0.5 * (n - 1) as f64) * h;
                let (px, pz) = if s < 0.0 {
                    (s, 0.0)
                } else {
                    // The right half turned over onto the left: a half-circle fold of diameter gap.
                    let a = (s / (0.5 * gap)).min(std::f64::consts::PI);
                    let beyond = (s - 0.5 * gap * std::f64::consts::PI).max(0.0);
                    (0.5 * gap * a.sin() - beyond, 0.5 * gap * (1.0 - a.cos()))
                };
                let jitter = V3::from_fn(|_, _| rng.random_range(-noise..=noise));
                x.push(V3::new(px, j as f64 * h, pz) + jitter);
            }
        }
        let mut tris = Vec::new();
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                let p = j * n + i;
                tris.push([p, p + 1, p + n + 1]);
                tris.push([p, p + n + 1, p + n]);
            }
        }
        (x, tris)
    }

    #[test]
    fn the_broad_phase_with_exact_distances_finds_the_brute_force_pairs() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        for (gap, noise) in [(3e-3, 5e-4), (1.5e-3, 2e-4), (8e-3, 2e-3)] {
            let (x, tris) = folded(9, gap, noise, &mut rng);
            let topo = MeshTopology::from_triangles(tris);
            for within in [1e-3, 4e-3, 1.2e-2] {
                let brute = brute_force_pairs(&topo, &x, within);
                assert_eq!(
                    pairs_within(&topo, &x, within),
                    brute,
                    "gap {gap}, within {within}"
                );
                assert!(!brute.is_empty() || within < gap - 2.0 * noise);
            }
        }
    }

    /// The smallest distance of any pair sharing no vertex (brute force), m.
    fn closest(topo: &MeshTopology, x: &[V3]) -> f64 {
        let all = brute_force_pairs(topo, x, f64::INFINITY);
        all.iter().map(|p| p.1).fold(f64::INFINITY, f64::min)
    }

    /// The smallest pair distance at eight points of the straight path from `x` to `y`.
    fn least_on_path(topo: &MeshTopology, x: &[V3], y: &[V3]) -> f64 {
        let at = |t: f64| -> Vec<V3> { x.iter().zip(y).map(|(p, q)| p + (q - p) * t).collect() };
        (1..=8)
            .map(|k| closest(topo, &at(k as f64 / 8.0)))
            .fold(f64::INFINITY, f64::min)
    }

    /// Moves each vertex by at most `scale` times its bound: random directions, and the vertices
    /// of the closest pairs straight at each other (the adversarial move).
    fn moved(x: &[V3], b: &[f64], scale: f64, toward: &[V3], rng: &mut ChaCha8Rng) -> Vec<V3> {
        (0..x.len())
            .map(|v| {
                let r = V3::from_fn(|_, _| rng.random_range(-1.0..=1.0));
                let dir = (toward[v] + 0.3 * r).try_normalize(0.0).unwrap_or(V3::z());
                x[v] + dir * (scale * b[v] * rng.random_range(0.8..=1.0))
            })
            .collect()
    }

    /// Each vertex's direction toward the other primitive of its closest pair (zero when none).
    fn toward_closest(topo: &MeshTopology, x: &[V3], within: f64) -> Vec<V3> {
        let mut best = vec![(f64::INFINITY, V3::zeros()); x.len()];
        for (pair, d) in brute_force_pairs(topo, x, within) {
            let idx = pair.vertices(topo);
            let (_, c) = pair_distance(pair.is_point_triangle(), &idx.map(|k| x[k]));
            let r: V3 = (0..4).map(|k| x[idx[k]] * c[k]).sum();
            let split = if pair.is_point_triangle() { 1 } else { 2 };
            for (k, &v) in idx.iter().enumerate() {
                let sign = if k < split { -1.0 } else { 1.0 };
                if d < best[v].0 {
                    best[v] = (d, r * sign);
                }
            }
        }
        best.into_iter().map(|b| b.1).collect()
    }

    /// Property: random moves within the bounds never bring a pair within the thickness, at any
    /// point of the straight path; the same moves at three times the bounds do (the test can fail).
    #[test]
    fn a_move_within_the_vertex_bounds_never_brings_a_pair_within_the_thickness() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let (xi, reach) = (5e-4, 4e-3);
        let mut crossed_beyond = 0;
        for case in 0..24 {
            let gap = rng.random_range(1.2e-3..6e-3);
            let (x, tris) = folded(7, gap, 3e-4, &mut rng);
            let topo = MeshTopology::from_triangles(tris);
            assert!(closest(&topo, &x) > xi, "case {case} starts apart");
            let b = vertex_bounds(&topo, &x, xi, reach);
            let toward = toward_closest(&topo, &x, xi + reach);
            let y = moved(&x, &b, 1.0, &toward, &mut rng);
            let d = least_on_path(&topo, &x, &y);
            assert!(d > xi, "case {case}: {d} on the path, within ξ = {xi}");
            let dx: Vec<V3> = y.iter().zip(&x).map(|(q, p)| q - p).collect();
            assert!(bounded_fraction(&b, &dx) >= 1.0 - 1e-12);
            let far = moved(&x, &b, 3.0, &toward, &mut rng);
            crossed_beyond += usize::from(least_on_path(&topo, &x, &far) <= xi);
        }
        assert!(
            crossed_beyond >= 12,
            "{crossed_beyond} of 24 moves at 3× reached ξ"
        );
    }

    #[test]
    fn every_pair_that_comes_into_the_band_was_measured_by_the_query() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let (xi, reach) = (5e-4, 4e-3);
        for _ in 0..8 {
            let (x, tris) = folded(7, rng.random_range(3e-3..8e-3), 3e-4, &mut rng);
            let topo = MeshTopology::from_triangles(tris);
            let measured: Vec<Pair> = pairs_within(&topo, &x, xi + reach)
                .into_iter()
                .map(|p| p.0)
                .collect();
            let b = vertex_bounds(&topo, &x, xi, reach);
            let toward = toward_closest(&topo, &x, f64::INFINITY);
            let y = moved(&x, &b, 1.0, &toward, &mut rng);
            let band = xi + (1.0 - 2.0 * BOUND_SHARE) * reach;
            for (pair, _) in brute_force_pairs(&topo, &y, band) {
                assert!(
                    measured.contains(&pair),
                    "{pair:?} came into the band unmeasured"
                );
            }
        }
    }
}
