//! A photo split into fabric and background: a quadratic background model fitted to the border,
//! Otsu's threshold on what is left, the mean grey level of each side (seed 000 §2.2's image
//! processing before the edge fit).

use crate::error::InputError;
use image::{GrayImage, Rgb, RgbImage};
use std::path::Path;

/// Half-width of the window over which `subpixel_edge` (the edge fit) sums coverages, px: wide enough for a
/// blur of σ = 1.5 px (3σ on each side) beyond the boundary pixel.
pub(super) const EDGE_WINDOW: i64 = 5;

/// The photo in grey levels split into fabric and background (Otsu's threshold; the border is
/// mostly background), with the mean grey level of each.
pub(super) struct Segmented {
    pub(super) gray: GrayImage,
    /// The grey levels with the background model's variation taken out (what is thresholded).
    pub(super) flat: GrayImage,
    pub(super) threshold: f64,
    pub(super) fabric_dark: bool,
    pub(super) fabric: f64,
    /// The background's grey level as a quadratic in (u, v) (uneven light, vignetting), fitted by
    /// least squares to the background pixels at least `EDGE_WINDOW` + 4 px from any fabric.
    pub(super) background_model: [f64; 6],
}

/// The monomials of the background model at pixel (u, v), coordinates scaled to the image.
fn quadratic_terms(u: f64, v: f64, w: f64, h: f64) -> [f64; 6] {
    let (x, y) = (2.0 * u / w - 1.0, 2.0 * v / h - 1.0);
    [1.0, x, y, x * x, x * y, y * y]
}

/// The quadratic background `model` at pixel (u, v) of a `w` × `h` image.
fn model_at(model: &[f64; 6], u: i64, v: i64, w: u32, h: u32) -> f64 {
    quadratic_terms(u as f64, v as f64, w as f64, h as f64)
        .iter()
        .zip(model)
        .map(|(t, c)| t * c)
        .sum()
}

/// Least-squares quadratic of the background's grey level over the pixels `is_bg` admits.
fn fit_background(gray: &GrayImage, is_bg: &dyn Fn(u32, u32) -> bool, fallback: f64) -> [f64; 6] {
    let (w, h) = gray.dimensions();
    let mut ata = nalgebra::SMatrix::<f64, 6, 6>::zeros();
    let mut atb = nalgebra::SVector::<f64, 6>::zeros();
    let mut n = 0usize;
    for v in (0..h).step_by(2) {
        for u in (0..w).step_by(2) {
            if !is_bg(u, v) {
                continue;
            }
            let t = nalgebra::SVector::<f64, 6>::from(quadratic_terms(
                u as f64, v as f64, w as f64, h as f64,
            ));
            ata += t * t.transpose();
            atb += t * gray.get_pixel(u, v).0[0] as f64;
            n += 1;
        }
    }
    match (n >= 60).then(|| ata.cholesky()).flatten() {
        Some(c) => c.solve(&atb).into(),
        None => [fallback, 0.0, 0.0, 0.0, 0.0, 0.0],
    }
}

impl Segmented {
    /// The background model's grey level at pixel (u, v).
    pub(super) fn background_at(&self, u: i64, v: i64) -> f64 {
        let (w, h) = self.gray.dimensions();
        model_at(&self.background_model, u, v, w, h)
    }
    pub(super) fn at(&self, u: u32, v: u32) -> f64 {
        self.gray.get_pixel(u, v).0[0] as f64
    }
    /// Whether pixel (u, v) is fabric (thresholded on the flattened image).
    pub(super) fn fabric_at(&self, u: u32, v: u32) -> bool {
        let g = self.flat.get_pixel(u, v).0[0] as f64;
        if self.fabric_dark {
            g <= self.threshold
        } else {
            g > self.threshold
        }
    }
}

/// Segments a photo; an image with no fabric (or no contrast) is refused.
/// Rounds of thresholding and background fitting in [`segment`].
const SEGMENT_PASSES: usize = 2;

/// Otsu's threshold of `flat` and the fabric's polarity (the border is mostly background).
fn threshold(flat: &GrayImage) -> (f64, bool) {
    let (w, h) = flat.dimensions();
    let t = imageproc::contrast::otsu_level(flat) as f64;
    let mut border_above = 0usize;
    let mut border = 0usize;
    for u in 0..w {
        for v in [0, h - 1] {
            border += 1;
            border_above += (flat.get_pixel(u, v).0[0] as f64 > t) as usize;
        }
    }
    (t, border_above * 2 >= border)
}

/// Segments a photo; an image with no fabric (or no contrast) is refused. Twice: Otsu's threshold on
/// the grey levels, the background's quadratic fitted to what it calls background, then Otsu again
/// on the image flattened by that background, and so on for [`SEGMENT_PASSES`] rounds (uneven light or vignetting otherwise pushes dim
/// background corners over the threshold).
pub(super) fn segment(img: &RgbImage, file: &Path) -> Result<Segmented, InputError> {
    let (w, h) = img.dimensions();
    // Grey levels; marker pixels count as background.
    let mut gray = GrayImage::new(w, h);
    for (u, v, p) in img.enumerate_pixels() {
        let [r, g, b] = p.0;
        let l = if is_marker(p) {
            255.0
        } else {
            0.299 * r as f64 + 0.587 * g as f64 + 0.114 * b as f64
        };
        gray.put_pixel(u, v, image::Luma([l.round() as u8]));
    }
    let mut flat = gray.clone();
    let mut pass = 0;
    loop {
        let (t, fabric_dark) = threshold(&flat);
        let is_fabric = |g: f64| if fabric_dark { g <= t } else { g > t };
        let fab = |u: u32, v: u32| is_fabric(flat.get_pixel(u, v).0[0] as f64);
        let levels = mean_levels(&gray, &fab);
        let (fabric, background) = levels.ok_or_else(|| {
            InputError::new(
                file,
                "",
                "no fabric found: the image is all background (or has no contrast)",
            )
        })?;
        let background_model = fit_background(&gray, &|u, v| clear_of(img, &fab, u, v), background);
        pass += 1;
        if pass == SEGMENT_PASSES {
            return Ok(Segmented {
                gray,
                flat,
                threshold: t,
                fabric_dark,
                fabric,
                background_model,
            });
        }
        flat = GrayImage::from_fn(w, h, |u, v| {
            let g = gray.get_pixel(u, v).0[0] as f64
                - model_at(&background_model, u as i64, v as i64, w, h)
                + background;
            image::Luma([g.round().clamp(0.0, 255.0) as u8])
        });
    }
}

/// The mean grey levels of fabric and background by `fab`; None when there is too little fabric or
/// too little contrast to trace an edge.
fn mean_levels(gray: &GrayImage, fab: &dyn Fn(u32, u32) -> bool) -> Option<(f64, f64)> {
    let (w, h) = gray.dimensions();
    let (mut nf, mut sf, mut nb, mut sb) = (0usize, 0.0, 0usize, 0.0);
    for (u, v, p) in gray.enumerate_pixels() {
        let g = p.0[0] as f64;
        if fab(u, v) {
            nf += 1;
            sf += g;
        } else {
            nb += 1;
            sb += g;
        }
    }
    let (fabric, background) = (
        if nf > 0 { sf / nf as f64 } else { 0.0 },
        if nb > 0 { sb / nb as f64 } else { 0.0 },
    );
    (nf >= (w * h) as usize / 200 && nb > 0 && (fabric - background).abs() >= 15.0)
        .then_some((fabric, background))
}

pub(super) fn is_marker(p: &Rgb<u8>) -> bool {
    let [r, g, b] = p.0;
    r > 150 && g < 100 && b < 100
}

/// Whether pixel (u, v) is background far from the fabric (and from the markers): a coarse distance
/// test on the fabric mask, checked along the axes and diagonals.
pub(super) fn clear_of(img: &RgbImage, fab: &dyn Fn(u32, u32) -> bool, u: u32, v: u32) -> bool {
    let (w, h) = img.dimensions();
    let r = EDGE_WINDOW + 4;
    let ok = |du: i64, dv: i64| {
        let (a, b) = (u as i64 + du, v as i64 + dv);
        if a < 0 || b < 0 || a >= w as i64 || b >= h as i64 {
            return true;
        }
        let (a, b) = (a as u32, b as u32);
        !fab(a, b) && !is_marker(img.get_pixel(a, b))
    };
    [
        (0, 0),
        (r, 0),
        (-r, 0),
        (0, r),
        (0, -r),
        (r, r),
        (-r, -r),
        (r, -r),
        (-r, r),
    ]
    .iter()
    .all(|&(du, dv)| ok(du, dv))
}
