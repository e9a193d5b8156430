//! Drape measured as edge curves (seed 000, Figs 3, 11, 12): points on the edges of the hanging sheet,
//! relative to the reference line through the two fixed corners, fitted by a polynomial (degree 4).
//!
//! Coordinates of an edge, in cm: for the `top` and `bottom` edges, x runs along the reference line from
//! the left corner and y is perpendicular to it, up positive (a sag is negative); for the `left` and
//! `right` edges of a 2-corner hang, x is the depth below the line and y the offset along the line from
//! the vertical through that edge's corner (positive towards the right corner).

mod from_image;
mod from_particles;
mod poly;
mod render;
mod table;

pub use from_image::{Calibration, FitImageOptions, ImageFit, fit_image, read_gray};
pub use from_particles::{ReferenceLine, edges_from_particles};
pub use poly::{Polynomial, fit_polynomial};
pub use render::{Camera, RenderOptions, RenderedPhoto, render_drape};
pub use table::{read_edges, write_edges};

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

/// Seed 000 Eq. 5 on two fitted curves: 100 × the RMS of the differences of their coefficients, with
/// coordinates normalised by the sample's side L (x̂ = x/L, ŷ = y/L, so the coefficient of x^p becomes
/// a_p·L^(p−1)); dimensionless and comparable with the seed's percentages.
pub fn eq5_objective_pct(a: &EdgeFit, b: &EdgeFit, side_cm: f64) -> f64 {
    let n = a.coefficients.len().max(b.coefficients.len());
    let get = |c: &[f64], p: usize| c.get(p).copied().unwrap_or(0.0);
    let ss: f64 = (0..n)
        .map(|p| {
            let d =
                (get(&a.coefficients, p) - get(&b.coefficients, p)) * side_cm.powi(p as i32 - 1);
            d * d
        })
        .sum();
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
