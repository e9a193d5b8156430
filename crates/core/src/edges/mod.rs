//! Drape measured as edge curves (seed 000, Figs 3, 11, 12): points on the edges of the hanging sheet,
//! relative to the reference line through the two fixed corners, fitted by a polynomial (degree 4).
//!
//! Coordinates of an edge, in cm: for the `top` and `bottom` edges, x runs along the reference line from
//! the left corner and y is perpendicular to it, up positive (a sag is negative); for the `left` and
//! `right` edges of a 2-corner hang, x is the depth below the line and y the offset along the line from
//! the vertical through that edge's corner (positive towards the right corner).

mod from_image;
mod from_particles;
mod photo;
mod poly;
mod projection;
mod render;
mod segment;
mod systematic;

pub use from_image::{Calibration, FitImageOptions, ImageFit, fit_image, read_gray};
pub use from_particles::{
    EdgeSource, ReferenceLine, edges_from_particles, edges_from_silhouette, simulated_edges,
};
pub use photo::{CameraFile, ScoreRow, read_camera, render_options, scene_view, score_edges};
pub use poly::{Polynomial, fit_polynomial};
pub use projection::{Pinhole, Projection};
pub use render::{Camera, RenderOptions, RenderedPhoto, render_drape, render_view};
pub use systematic::{PERTURBATIONS, edge_perturbations, systematic_pct, with_systematics};

use serde::{Deserialize, Serialize};

/// Which hang a photo shows, and so which edges it has.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum View {
    /// Four corners pinned; the camera faces one edge; one curve, the lower boundary (`bottom`).
    Hang4,
    /// Two corners of one edge pinned; the camera faces the sheet; four curves.
    Hang2,
}

impl View {
    /// The edges of this view.
    pub fn edges(self) -> &'static [&'static str] {
        match self {
            View::Hang4 => &["bottom"],
            View::Hang2 => &["top", "bottom", "left", "right"],
        }
    }
}

/// A fitted edge curve.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EdgeFit {
    /// `top`, `bottom`, `left` or `right`.
    pub edge: String,
    /// Polynomial coefficients of x^0 .. x^degree (x and y in cm).
    pub coefficients: Vec<f64>,
    /// RMS residual of the fit in cm.
    pub rms_residual_cm: f64,
    /// Number of points fitted.
    pub n_points: usize,
    /// Range of x covered by the points, in cm.
    pub x_min_cm: f64,
    /// Range of x covered by the points, in cm.
    pub x_max_cm: f64,
    /// Systematic uncertainty of a photographed edge, % of the side ([`systematic_pct`]; None for a
    /// simulated edge or when not estimated).
    #[serde(default)]
    pub systematic_pct: Option<f64>,
    /// How the camera projected the drape onto the corners' plane (photographed edges; a simulated
    /// edge is projected by its problem's camera). Default orthographic.
    #[serde(default)]
    pub projection: Projection,
}

impl EdgeFit {
    /// Fits `points` (x, y in cm) with a polynomial of `degree`.
    pub fn from_points(edge: &str, points: &[(f64, f64)], degree: usize) -> Option<Self> {
        let (p, rms) = fit_polynomial(points, degree)?;
        let (lo, hi) = points
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &(x, _)| {
                (a.min(x), b.max(x))
            });
        Some(Self {
            edge: edge.into(),
            coefficients: p.coefficients,
            rms_residual_cm: rms,
            n_points: points.len(),
            x_min_cm: lo,
            x_max_cm: hi,
            systematic_pct: None,
            projection: Projection::Orthographic,
        })
    }
    /// The curve at x (cm).
    pub fn eval(&self, x: f64) -> f64 {
        Polynomial {
            coefficients: self.coefficients.clone(),
        }
        .eval(x)
    }
}

/// Fraction of the corner-to-corner span left out at both ends of every edge, in photos and in
/// simulations alike: near the fixed corners the boundary turns sharply (and markers or clamps hide it),
/// and a quartic fitted over the same domain is what makes two measurements comparable.
pub const EDGE_TRIM: f64 = 0.04;

/// Keeps the points of an edge inside the common fitting domain: for `top`/`bottom`, x within
/// [t, span − t]; for `left`/`right`, depth within [t, bottom_depth − t], with t = EDGE_TRIM × span.
pub fn trim_edge(
    edge: &str,
    points: Vec<(f64, f64)>,
    span_cm: f64,
    bottom_depth_cm: f64,
) -> Vec<(f64, f64)> {
    let t = EDGE_TRIM * span_cm;
    let (lo, hi) = match edge {
        "left" | "right" => (t, bottom_depth_cm - t),
        _ => (t, span_cm - t),
    };
    points
        .into_iter()
        .filter(|p| p.0 >= lo && p.0 <= hi)
        .collect()
}

/// Seed 000 Eq. 5 on two fitted curves: 100 × the RMS of the differences of their five coefficients.
/// The seed does not say in which coordinates the coefficients are taken; drapelab takes them in
/// coordinates centred on the fitting domain and scaled to it, x̂ = (x − c)/h ∈ [−1, 1] (c and h the
/// centre and half-width of the union of both curves' x ranges), with ŷ = y/L (L the side). In these
/// coordinates the monomials are well conditioned, so Eq. 5 follows the distance between the curves;
/// with x/L from the corner instead, photo noise of 0.03 % of the side moves Eq. 5 by 0.2–3 %
/// ([`eq5_uncentred_pct`]).
pub fn eq5_objective_pct(a: &EdgeFit, b: &EdgeFit, side_cm: f64) -> f64 {
    let lo = a.x_min_cm.min(b.x_min_cm);
    let hi = a.x_max_cm.max(b.x_max_cm);
    let (c, h) = (0.5 * (lo + hi), (0.5 * (hi - lo)).max(1e-12));
    let ca = centred_coefficients(&a.coefficients, c, h, side_cm);
    let cb = centred_coefficients(&b.coefficients, c, h, side_cm);
    rms_difference_pct(&ca, &cb)
}

/// Eq. 5 with coefficients in x̂ = x/L, ŷ = y/L measured from the left corner (the coefficient of x^p
/// becomes a_p·L^(p−1)): the reading that is ill-conditioned; kept for comparison.
pub fn eq5_uncentred_pct(a: &EdgeFit, b: &EdgeFit, side_cm: f64) -> f64 {
    let scale = |c: &[f64]| -> Vec<f64> {
        c.iter()
            .enumerate()
            .map(|(p, v)| v * side_cm.powi(p as i32 - 1))
            .collect()
    };
    rms_difference_pct(&scale(&a.coefficients), &scale(&b.coefficients))
}

/// Coefficients of q(x̂) = p(c + h x̂)/L, by the binomial expansion of (c + h x̂)^p.
fn centred_coefficients(p: &[f64], c: f64, h: f64, side_cm: f64) -> Vec<f64> {
    let mut q = vec![0.0; p.len()];
    for (n, &a) in p.iter().enumerate() {
        let mut binom = 1.0;
        for (k, qk) in q.iter_mut().enumerate().take(n + 1) {
            *qk += a * binom * c.powi((n - k) as i32) * h.powi(k as i32) / side_cm;
            binom *= (n - k) as f64 / (k + 1) as f64;
        }
    }
    q
}

/// 100 × the RMS of the differences of two coefficient vectors (the shorter padded with zeros).
fn rms_difference_pct(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().max(b.len());
    let get = |c: &[f64], p: usize| c.get(p).copied().unwrap_or(0.0);
    let ss: f64 = (0..n).map(|p| (get(a, p) - get(b, p)).powi(2)).sum();
    100.0 * (ss / n as f64).sqrt()
}

/// RMS vertical distance between two curves over x ∈ [0, span_cm] (201 samples), in % of the side.
pub fn curve_distance_pct(a: &EdgeFit, b: &EdgeFit, span_cm: f64, side_cm: f64) -> f64 {
    let n = 201;
    let ss: f64 = (0..n)
        .map(|k| {
            let x = span_cm * k as f64 / (n - 1) as f64;
            (a.eval(x) - b.eval(x)).powi(2)
        })
        .sum();
    100.0 * (ss / n as f64).sqrt() / side_cm
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centred_coefficients_describe_the_same_curve() {
        let p = [0.3, -1.2, 0.05, -0.002, 1.5e-5];
        let (c, h, l) = (24.0, 23.0, 50.0);
        let q = centred_coefficients(&p, c, h, l);
        for t in [-1.0, -0.3, 0.0, 0.7, 1.0] {
            let x: f64 = c + h * t;
            let px: f64 = p
                .iter()
                .enumerate()
                .map(|(k, a)| a * x.powi(k as i32))
                .sum();
            let qt: f64 = q
                .iter()
                .enumerate()
                .map(|(k, a)| a * t.powi(k as i32))
                .sum();
            assert!((px / l - qt).abs() < 1e-12, "{px} {qt}");
        }
    }
}
