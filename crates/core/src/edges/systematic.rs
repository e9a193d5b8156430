//! The systematic part of a photo's edge measurement (issue 17): noise shows in a fit's residual,
//! but an error of the setup moves the whole curve and leaves no residual. The photo is refitted under
//! the errors a real setup makes — the corners half a pixel off, the scale 0.5 % off, a defocus blur
//! of 1 px, a gradient of light of 20 grey levels from top to bottom — and each edge's curve distance
//! from the nominal fit (% of the side) is that error's share; their RMS is the edge's systematic
//! uncertainty, which the calibration's intervals add to the residual's.

use super::{Calibration, EdgeFit, FitImageOptions, ImageFit, curve_distance_pct, fit_image};
use crate::error::InputError;
use image::RgbImage;
use std::path::Path;

/// The setup errors a photo is refitted under, by name.
pub const PERTURBATIONS: [&str; 4] = [
    "corners 0.5 px low",
    "scale +0.5 %",
    "blur 1 px",
    "light gradient 20 levels",
];

/// Per perturbation (in [`PERTURBATIONS`]' order), per edge of `nominal`, the curve distance (% of
/// `side_cm`) between the nominal fit and the fit of the perturbed photo.
pub fn edge_perturbations(
    img: &RgbImage,
    opts: &FitImageOptions,
    nominal: &ImageFit,
    side_cm: f64,
    file: &Path,
) -> Result<Vec<Vec<f64>>, InputError> {
    let [c0, c1] = nominal.corners;
    let given = |corners: [(f64, f64); 2], px_per_cm: f64| FitImageOptions {
        calibration: Calibration::Given { px_per_cm, corners },
        ..opts.clone()
    };
    let s = nominal.px_per_cm;
    let low = [(c0.0, c0.1 + 0.5), (c1.0, c1.1 + 0.5)];
    let blurred = imageproc::filter::gaussian_blur_f32(img, 1.0);
    let h = img.height().max(1) as f64;
    let mut lit = img.clone();
    for (_, v, p) in lit.enumerate_pixels_mut() {
        let d = 20.0 * (v as f64 / h - 0.5);
        for ch in p.0.iter_mut() {
            *ch = (*ch as f64 + d).round().clamp(0.0, 255.0) as u8;
        }
    }
    let span_cm = (c1.0 - c0.0).hypot(c1.1 - c0.1) / s;
    let cases: [(&RgbImage, FitImageOptions); 4] = [
        (img, given(low, s)),
        (img, given(nominal.corners, 1.005 * s)),
        (&blurred, given(nominal.corners, s)),
        (&lit, given(nominal.corners, s)),
    ];
    cases
        .iter()
        .map(|(im, o)| {
            let fit = fit_image(im, o, file)?;
            Ok(nominal
                .edges
                .iter()
                .map(|e| {
                    fit.edges
                        .iter()
                        .find(|f| f.edge == e.edge)
                        .map_or(f64::NAN, |f| distance(e, f, span_cm, side_cm))
                })
                .collect())
        })
        .collect()
}

/// Curve distance over the edge's own domain (the sides' x is depth, not the span).
fn distance(a: &EdgeFit, b: &EdgeFit, span_cm: f64, side_cm: f64) -> f64 {
    match a.edge.as_str() {
        "left" | "right" => curve_distance_pct(a, b, a.x_max_cm, side_cm),
        _ => curve_distance_pct(a, b, span_cm, side_cm),
    }
}

/// Each edge's systematic uncertainty (% of the side): the RMS over the perturbations of
/// [`edge_perturbations`].
pub fn systematic_pct(per: &[Vec<f64>]) -> Vec<f64> {
    let edges = per.first().map_or(0, Vec::len);
    (0..edges)
        .map(|e| (per.iter().map(|p| p[e] * p[e]).sum::<f64>() / per.len() as f64).sqrt())
        .collect()
}

/// `fit` with each edge's systematic uncertainty set ([`edge_perturbations`] with the corners' span
/// as the side).
pub fn with_systematics(
    img: &RgbImage,
    opts: &FitImageOptions,
    mut fit: ImageFit,
    file: &Path,
) -> Result<ImageFit, InputError> {
    let [c0, c1] = fit.corners;
    let side_cm = (c1.0 - c0.0).hypot(c1.1 - c0.1) / fit.px_per_cm;
    let sys = systematic_pct(&edge_perturbations(img, opts, &fit, side_cm, file)?);
    for (e, s) in fit.edges.iter_mut().zip(sys) {
        e.systematic_pct = Some(s);
    }
    Ok(fit)
}
