//! The exact large-deflection elastica of a heavy cantilever (seed 003 §10.3.4, Table 10.1's "exact
//! solution"): an inextensible strip of bending rigidity D per unit width, clamped horizontally at
//! s = 0 and free at s = L, under its own weight q per unit area. With θ the angle below the horizontal,
//! D θ'' = −q (L − s) cos θ, θ(0) = 0, θ'(L) = 0 (no moment at the free end); x' = cos θ, z' = −sin θ.
//! Solved by shooting on θ'(0) (bisection, θ'(L) grows with θ'(0)) with classical Runge–Kutta.

use crate::cloth::Edge;
use crate::scene::Scene;
use crate::simulate::Solution;

/// Runge–Kutta steps along the strip.
const STEPS: usize = 20_000;

/// The elastica sampled at `STEPS + 1` equally spaced arc lengths.
#[derive(Debug, Clone)]
pub struct HeavyElastica {
    /// Length of the strip in m.
    pub length_m: f64,
    /// Curvature at the clamp θ'(0) in 1/m.
    pub clamp_curvature_per_m: f64,
    /// (x, z) of the centre line at each sample, m, from the clamp (z down negative).
    points_m: Vec<(f64, f64)>,
}

impl HeavyElastica {
    /// Solves the elastica for bending rigidity `bending_N_m` (N·m, i.e. N·m²/m of width), load
    /// `load_N_per_m2` (weight per area) and length `length_m`.
    pub fn solve(bending_N_m: f64, load_N_per_m2: f64, length_m: f64) -> Self {
        let (d, q, l) = (bending_N_m, load_N_per_m2, length_m);
        let h = l / STEPS as f64;
        let shoot = |k0: f64, keep: bool| -> (f64, Vec<(f64, f64)>) {
            let f = |s: f64, y: [f64; 4]| -> [f64; 4] {
                [y[1], -q * (l - s) * y[0].cos() / d, y[0].cos(), -y[0].sin()]
            };
            let mut y = [0.0, k0, 0.0, 0.0];
            let mut pts = Vec::with_capacity(if keep { STEPS + 1 } else { 0 });
            if keep {
                pts.push((0.0, 0.0));
            }
            for k in 0..STEPS {
                let s = k as f64 * h;
                let k1 = f(s, y);
                let y2: [f64; 4] = std::array::from_fn(|i| y[i] + 0.5 * h * k1[i]);
                let k2 = f(s + 0.5 * h, y2);
                let y3: [f64; 4] = std::array::from_fn(|i| y[i] + 0.5 * h * k2[i]);
                let k3 = f(s + 0.5 * h, y3);
                let y4: [f64; 4] = std::array::from_fn(|i| y[i] + h * k3[i]);
                let k4 = f(s + h, y4);
                y = std::array::from_fn(|i| {
                    y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
                });
                if keep {
                    pts.push((y[2], y[3]));
                }
            }
            (y[1], pts)
        };
        // θ'(0) = qL²/(2D) is the small-deflection clamp curvature, an upper bound (cos θ ≤ 1).
        let (mut lo, mut hi) = (0.0, q * l * l / d);
        for _ in 0..80 {
            let mid = 0.5 * (lo + hi);
            if shoot(mid, false).0 > 0.0 {
                hi = mid
            } else {
                lo = mid
            }
        }
        let k0 = 0.5 * (lo + hi);
        Self {
            length_m: l,
            clamp_curvature_per_m: k0,
            points_m: shoot(k0, true).1,
        }
    }

    /// The elastica of a scene that is a strip clamped along its x-min edge with a continuum
    /// material (bending rigidity along x); None for any other scene.
    pub fn of_cantilever(scene: &Scene) -> Option<Self> {
        if scene.boundary.clamp_edges != [Edge::Xmin] || !scene.obstacles.is_empty() {
            return None;
        }
        let r = scene.material.continuum.as_ref()?.rigidities().ok()?;
        let q = scene.cloth.areal_density_kg_per_m2 * scene.gravity.g_m_per_s2;
        Some(Self::solve(r.bending_warp_N_m, q, scene.cloth.size_x_m))
    }

    /// (x, z) at arc length `s_m` from the clamp (linear between samples; clamped to [0, L]).
    pub fn at(&self, s_m: f64) -> (f64, f64) {
        let u = (s_m / self.length_m).clamp(0.0, 1.0) * STEPS as f64;
        let k = (u.floor() as usize).min(STEPS - 1);
        let t = u - k as f64;
        let (a, b) = (self.points_m[k], self.points_m[k + 1]);
        (a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1))
    }

    /// The free end (x, z).
    pub fn tip(&self) -> (f64, f64) {
        self.points_m[STEPS]
    }

    /// Largest distance in the x–z plane between a solved strip's particles and the elastica at
    /// their arc length (the particle's rest distance from the clamp line), in m; NaN when the
    /// solve did not converge.
    pub fn distance(&self, sol: &Solution) -> f64 {
        if !sol.report.is_converged() {
            return f64::NAN;
        }
        let g = &sol.grid;
        let (x0, z0) = (sol.at(0, 0).x, sol.at(0, 0).z);
        let mut err: f64 = 0.0;
        for j in 0..g.ny {
            for i in 0..g.nx {
                let (xe, ze) = self.at(g.xs[i] - g.xs[0]);
                let p = sol.at(i, j);
                err = err.max(((p.x - x0 - xe).powi(2) + (p.z - z0 - ze).powi(2)).sqrt());
            }
        }
        err
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_light_load_gives_the_small_deflection_tip_ql4_over_8d() {
        // Linear beam theory: w = qL⁴/(8D) when the deflection is small.
        let (d, q, l) = (1.0, 1e-3, 1.0);
        let e = HeavyElastica::solve(d, q, l);
        let w = -e.tip().1;
        assert!((w - q * l.powi(4) / (8.0 * d)).abs() < 1e-3 * w, "{w}");
        assert!(
            (e.clamp_curvature_per_m - q * l * l / (2.0 * d)).abs()
                < 1e-3 * e.clamp_curvature_per_m
        );
    }

    #[test]
    fn the_strip_keeps_its_length() {
        let e = HeavyElastica::solve(8.1e-6, 1.86, 0.05);
        let mut len = 0.0;
        let mut prev = (0.0, 0.0);
        for k in 1..=200 {
            let p = e.at(0.05 * k as f64 / 200.0);
            len += ((p.0 - prev.0).powi(2) + (p.1 - prev.1).powi(2)).sqrt();
            prev = p;
        }
        assert!((len - 0.05).abs() < 1e-6, "{len}");
    }
}
