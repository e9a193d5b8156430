//! Tension-field wrinkles of a vertically hung fabric (seed 002): a sheet of horizontal length L and
//! height h hangs from two supports moved inward by d each (l = L − 2d apart). Wrinkle lines are
//! cosines through the supports, y_i = a_i cos(πx/l) (Eq. 1/6, y down from the supports), with
//! amplitudes in geometric progression a_{i−1}/a_i = Q (Eq. 5) from the upper boundary a_n to the lower
//! boundary a₀; out of plane, line i sits at z = ±z_max cos(πx/l), alternating from line to line (Eq. 4).
//!
//! The seed's text is garbled in its equations; drapelab reads them as follows (docs/src/science/wrinkles.md):
//! - Eq. 7, enforced with equality: w h (Q − 1)/(t (Q + 1)) = σ_c = c E t² / (l² (1 − ν²)), so the
//!   critical ratio is Q_c = (1 + s)/(1 − s) with s = c E t³ / (w h l² (1 − ν²)); s ≥ 1 means the
//!   sheet is stiff enough not to wrinkle (n = 0). The load constant c is not given by the seed.
//! - Eq. 7 for a fabric (issue 50): E t³/(1 − ν²) = 12 D with the fabric's bending rigidity
//!   w c_b³ (c_b its bending length) in place of the plate's D, where the case gives c_b.
//! - Eq. 8: the upper boundary (x, a_n cos(πx/l), z_max cos(πx/l)) has the sheet's length L:
//!   L = ∫_{−l/2}^{l/2} √(1 + (π/l)² (a_n² + z_max²) sin²(πx/l)) dx (Simpson).
//! - Eq. 9: the vertical fibre at x = 0 keeps its length h across the n strips:
//!   h = Σ_{i=1}^{n} √((a_{i−1} − a_i)² + (2 z_max)²), with a₀ = h, the centre of the lower boundary.
//! - Eq. 10: n = Int[ln(a₀/a_n) / ln Q_c] (nearest integer, at least 1).
//!
//! The iteration starts from a_n = 0.01 h and a tentative z_max, as the seed does: n from Eq. 10,
//! Q = (a₀/a_n)^{1/n} (Eq. 5), z_max from Eq. 9, a_n from Eq. 8 (both updates under-relaxed by ½),
//! until the length L' of Eq. 8 computed with the current a_n and z_max is within the tolerance of L
//! and n no longer changes (when Eq. 10 alternates between two values, n is held at the larger).

mod config;
pub mod full;
mod mesh;

pub use config::{Defaults, SeedResult, Sweep, WrinkleCase, WrinkleConfig, load_config};
pub use mesh::{WrinkleMesh, count_folds, wrinkle_mesh};

use serde::Serialize;

/// The inputs of one case, SI.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WrinkleInputs {
    /// Horizontal length of the sheet L, m.
    pub length_m: f64,
    /// Height of the sheet h, m.
    pub height_m: f64,
    /// Thickness t, m.
    pub thickness_m: f64,
    /// Young's modulus E, Pa.
    pub youngs_modulus_Pa: f64,
    /// Poisson's ratio ν, in [0, 0.5).
    pub poisson_ratio: f64,
    /// Weight per area w, N/m².
    pub weight_N_per_m2: f64,
    /// Inward displacement d of each support, m (l = L − 2d).
    pub support_displacement_m: f64,
    /// Load constant c of Eq. 7 (dimensionless).
    pub buckling_constant: f64,
    /// Relative tolerance on L' against L (the seed uses 0.05).
    pub tolerance_rel: f64,
    /// Iterations allowed.
    pub max_iterations: usize,
    /// Tentative z_max to start from, m (the seed suggests 0.014).
    pub initial_zmax_m: f64,
    /// Intervals of the Simpson rule (even).
    pub simpson_intervals: usize,
    /// Eq. 7 read for a fabric: its bending length c_b, m, so that E t³/(1 − ν²) becomes 12 w c_b³
    /// (the fabric's bending rigidity w c_b³ in place of the plate's); None: the seed's plate.
    pub bending_length_m: Option<f64>,
}

/// The outcome of [`solve`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WrinkleResult {
    /// Number of wrinkles (strips between consecutive wrinkle lines).
    pub n: usize,
    /// Ratio of consecutive amplitudes, (a₀/a_n)^{1/n} (Eq. 5).
    pub q: f64,
    /// Critical ratio from Eq. 7.
    pub q_critical: f64,
    /// Largest out-of-plane displacement, m.
    pub zmax_m: f64,
    /// Amplitudes a₀ (lower boundary) … a_n (upper boundary), m.
    pub amplitudes_m: Vec<f64>,
    /// Iterations made.
    pub iterations: usize,
    /// Whether |L' − L| ≤ tolerance · L with n settled.
    pub converged: bool,
    /// |L' − L| / L at the last iteration: the tolerance actually reached.
    pub length_error_rel: f64,
    /// Why the iteration ended.
    pub message: String,
}

/// Composite Simpson rule for ∫_a^b f with `intervals` (rounded up to even) sub-intervals.
pub fn simpson(f: impl Fn(f64) -> f64, a: f64, b: f64, intervals: usize) -> f64 {
    let n = (intervals.max(2) + 1) & !1;
    let h = (b - a) / n as f64;
    let inner: f64 = (1..n)
        .map(|k| f(a + k as f64 * h) * if k % 2 == 1 { 4.0 } else { 2.0 })
        .sum();
    h / 3.0 * (f(a) + inner + f(b))
}

/// Distance between the supports l = L − 2d, m.
pub fn support_span_m(inp: &WrinkleInputs) -> f64 {
    inp.length_m - 2.0 * inp.support_displacement_m
}

/// Eq. 7's bending term E t³/(1 − ν²) = 12 D, N·m: the plate's, or 12 w c_b³ for a fabric of
/// bending length c_b.
pub fn bending_term_N_m(inp: &WrinkleInputs) -> f64 {
    match inp.bending_length_m {
        Some(c) => 12.0 * inp.weight_N_per_m2 * c.powi(3),
        None => inp.youngs_modulus_Pa * inp.thickness_m.powi(3) / (1.0 - inp.poisson_ratio.powi(2)),
    }
}

/// Eq. 7 with equality: the critical ratio Q_c, or None when s ≥ 1 (no wrinkles).
pub fn critical_ratio(inp: &WrinkleInputs) -> Option<f64> {
    let l = support_span_m(inp);
    let s = inp.buckling_constant * bending_term_N_m(inp)
        / (inp.weight_N_per_m2 * inp.height_m * l * l);
    (s < 1.0).then(|| (1.0 + s) / (1.0 - s))
}

/// Eq. 8: the length of a cosine boundary of in-plane amplitude `a` and out-of-plane amplitude `z`
/// between supports `l` apart.
pub fn boundary_length_m(a: f64, z: f64, l: f64, intervals: usize) -> f64 {
    let k = (std::f64::consts::PI / l).powi(2) * (a * a + z * z);
    simpson(
        |x| (1.0 + k * (std::f64::consts::PI * x / l).sin().powi(2)).sqrt(),
        -0.5 * l,
        0.5 * l,
        intervals,
    )
}

/// The combined amplitude A = √(a² + z²) whose boundary has length `length` (Eq. 8 inverted by
/// bisection; the length grows with A).
fn amplitude_for_length(length: f64, l: f64, intervals: usize) -> f64 {
    let (mut lo, mut hi) = (0.0, l);
    while boundary_length_m(hi, 0.0, l, intervals) < length {
        hi *= 2.0;
    }
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if boundary_length_m(mid, 0.0, l, intervals) < length {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Eq. 9's fibre length at x = 0 for n strips between a₀ and a_n = a₀/Qⁿ with z_max = z.
fn fibre_length_m(a0: f64, q: f64, n: usize, z: f64) -> f64 {
    (1..=n)
        .map(|i| {
            let d = a0 * q.powi(-(i as i32 - 1)) * (1.0 - 1.0 / q);
            (d * d + 4.0 * z * z).sqrt()
        })
        .sum()
}

/// Eq. 9 solved for z_max (bisection; the fibre length grows with z). Zero when the strips are
/// already at least h long without folding out of plane.
fn zmax_for_height(h: f64, a0: f64, q: f64, n: usize) -> f64 {
    if fibre_length_m(a0, q, n, 0.0) >= h {
        return 0.0;
    }
    let (mut lo, mut hi) = (0.0, h);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if fibre_length_m(a0, q, n, mid) < h {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Solves one case by the seed's iteration (module docs). Inputs must be valid ([`WrinkleCase`]
/// checks them); a case that does not settle within `max_iterations` is returned with
/// `converged = false`, never as an error.
pub fn solve(inp: &WrinkleInputs) -> WrinkleResult {
    let h = inp.height_m;
    let l = support_span_m(inp);
    let ni = inp.simpson_intervals;
    let Some(qc) = critical_ratio(inp) else {
        return WrinkleResult {
            n: 0,
            q: f64::INFINITY,
            q_critical: f64::INFINITY,
            zmax_m: 0.0,
            amplitudes_m: vec![],
            iterations: 0,
            converged: true,
            length_error_rel: 0.0,
            message: "Eq. 7: the critical stress exceeds the load (s ≥ 1): no wrinkles".into(),
        };
    };
    // The upper boundary takes up the excess length L − l in and out of plane: a_n² + z² = A².
    let big_a = amplitude_for_length(inp.length_m, l, ni);
    let a0 = h;
    let mut an = 0.01 * h;
    let mut z = inp.initial_zmax_m;
    let mut n_prev = 0;
    let mut err = f64::INFINITY;
    let mut q = qc;
    let mut held: Option<usize> = None;
    let mut history: Vec<usize> = Vec::new();
    for it in 1..=inp.max_iterations {
        let n_eq10 = ((a0 / an).ln() / qc.ln()).round().max(1.0) as usize;
        // Eq. 10 at a rounding boundary can alternate between two values; hold the larger once it does.
        if held.is_none()
            && history.len() >= 2
            && history[history.len() - 2] == n_eq10
            && n_prev != n_eq10
        {
            held = Some(n_eq10.max(n_prev));
        }
        history.push(n_eq10);
        let n = held.unwrap_or(n_eq10);
        q = (a0 / an).powf(1.0 / n as f64);
        let length = boundary_length_m(an, z, l, ni);
        err = (length - inp.length_m).abs() / inp.length_m;
        let done = err <= inp.tolerance_rel && n == n_prev;
        if done {
            return WrinkleResult {
                n,
                q,
                q_critical: qc,
                zmax_m: z,
                amplitudes_m: (0..=n).map(|i| a0 * q.powi(-(i as i32))).collect(),
                iterations: it,
                converged: true,
                length_error_rel: err,
                message: format!("L' within {:.3} % of L, n settled", 100.0 * err),
            };
        }
        n_prev = n;
        // Under-relaxed updates: the plain fixed point of (z_max, a_n) can cycle when n is small.
        let z_new = zmax_for_height(h, a0, q, n).min(big_a);
        z = if it == 1 { z_new } else { 0.5 * (z + z_new) };
        let an_new = (big_a * big_a - z * z).max(0.0).sqrt();
        an = (0.5 * (an + an_new)).clamp(1e-6 * h, a0 * (1.0 - 1e-9));
    }
    let n = n_prev.max(1);
    WrinkleResult {
        n,
        q,
        q_critical: qc,
        zmax_m: z,
        amplitudes_m: (0..=n).map(|i| a0 * q.powi(-(i as i32))).collect(),
        iterations: inp.max_iterations,
        converged: false,
        length_error_rel: err,
        message: format!(
            "not converged after {} iterations: L' off by {:.3} % or n still changing",
            inp.max_iterations,
            100.0 * err
        ),
    }
}
