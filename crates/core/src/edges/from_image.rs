//! Edges from a photo: segment the fabric from the background (Otsu's threshold, imageproc), trace
//! the boundary column by column (or row by row for side edges) with sub-pixel positions from the
//! grey levels of the boundary pixels, convert to cm relative to the reference line through the two
//! fixed corners, and fit polynomials. Bad images are [`InputError`]s naming the file.

use super::segment::{EDGE_WINDOW, Segmented, is_marker, segment};
use super::{EdgeFit, View};
use crate::error::InputError;
use image::{Rgb, RgbImage};
use std::path::Path;

/// How pixels become centimetres.
#[derive(Debug, Clone, PartialEq)]
pub enum Calibration {
    /// A known scale and the pixel positions (u right, v down) of the left and right fixed corners.
    Given {
        /// Pixels per cm in the plane of the corners.
        px_per_cm: f64,
        /// Left and right corner positions, px.
        corners: [(f64, f64); 2],
    },
    /// Two red markers at the fixed corners, `side_cm` apart.
    Markers {
        /// Distance between the markers, cm.
        side_cm: f64,
    },
}

/// Options of [`fit_image`].
#[derive(Debug, Clone, PartialEq)]
pub struct FitImageOptions {
    /// Which hang the photo shows.
    pub view: View,
    /// Polynomial degree (4 in seed 000).
    pub degree: usize,
    /// Scale and corners.
    pub calibration: Calibration,
    /// The pinhole camera that took the photo, if known (its projection rides on every edge fit);
    /// None: orthographic.
    pub pinhole: Option<super::projection::Pinhole>,
}

/// The result of fitting a photo.
pub struct ImageFit {
    /// One fit per edge of the view.
    pub edges: Vec<EdgeFit>,
    /// The traced edge points each fit was made from, (x, y) in cm in the reference line's frame.
    pub points_cm: Vec<Vec<(f64, f64)>>,
    /// The photo with the reference line (blue) and the fitted curves (red).
    pub overlay: RgbImage,
    /// Corners used, px.
    pub corners: [(f64, f64); 2],
    /// Scale used, px per cm.
    pub px_per_cm: f64,
}

/// Reads an image file; an unreadable or undecodable file is an input error naming it.
pub fn read_gray(path: &Path) -> Result<RgbImage, InputError> {
    let bytes =
        std::fs::read(path).map_err(|e| InputError::new(path, "", format!("cannot read: {e}")))?;
    if bytes.is_empty() {
        return Err(InputError::new(path, "", "empty file: not an image"));
    }
    image::load_from_memory(&bytes)
        .map(|i| i.to_rgb8())
        .map_err(|e| InputError::new(path, "", format!("cannot decode image: {e}")))
}

/// Centroids of the two largest red blobs, sorted left to right, and their mean radius.
fn find_markers(img: &RgbImage) -> Option<([(f64, f64); 2], f64)> {
    let (w, h) = img.dimensions();
    let mut seen = vec![false; (w * h) as usize];
    let mut blobs: Vec<(usize, f64, f64)> = Vec::new();
    for v in 0..h {
        for u in 0..w {
            let k = (v * w + u) as usize;
            if seen[k] || !is_marker(img.get_pixel(u, v)) {
                continue;
            }
            let (mut n, mut su, mut sv) = (0usize, 0.0, 0.0);
            let mut stack = vec![(u, v)];
            seen[k] = true;
            while let Some((a, b)) = stack.pop() {
                n += 1;
                su += a as f64;
                sv += b as f64;
                for (da, db) in [(1i64, 0i64), (-1, 0), (0, 1), (0, -1)] {
                    let (na, nb) = (a as i64 + da, b as i64 + db);
                    if na < 0 || nb < 0 || na >= w as i64 || nb >= h as i64 {
                        continue;
                    }
                    let kk = (nb as u32 * w + na as u32) as usize;
                    if !seen[kk] && is_marker(img.get_pixel(na as u32, nb as u32)) {
                        seen[kk] = true;
                        stack.push((na as u32, nb as u32));
                    }
                }
            }
            blobs.push((n, su / n as f64, sv / n as f64));
        }
    }
    blobs.sort_by_key(|b| std::cmp::Reverse(b.0));
    if blobs.len() < 2 || blobs[1].0 < 5 {
        return None;
    }
    let mut c = [(blobs[0].1, blobs[0].2), (blobs[1].1, blobs[1].2)];
    if c[0].0 > c[1].0 {
        c.swap(0, 1);
    }
    let r = ((blobs[0].0 + blobs[1].0) as f64 / 2.0 / std::f64::consts::PI).sqrt();
    Some((c, r))
}

/// The two fixed corners in the image (px), the scale (px per cm) and the guard band around the
/// corners (px).
type Calibrated = ([(f64, f64); 2], f64, f64);

/// The calibration the options give, checked against the image.
fn calibrate(
    img: &RgbImage,
    opts: &FitImageOptions,
    file: &Path,
) -> Result<Calibrated, InputError> {
    let (w, h) = img.dimensions();
    let (corners, s, guard) = match &opts.calibration {
        Calibration::Given { px_per_cm, corners } => {
            if !(px_per_cm.is_finite() && *px_per_cm > 0.0) {
                return Err(InputError::new(
                    file,
                    "--px-per-cm",
                    format!("must be a finite number > 0, got {px_per_cm}"),
                ));
            }
            for c in corners {
                if !(c.0.is_finite()
                    && c.1.is_finite()
                    && c.0 >= 0.0
                    && c.1 >= 0.0
                    && c.0 <= w as f64
                    && c.1 <= h as f64)
                {
                    return Err(InputError::new(
                        file,
                        "--corners",
                        format!("corner ({}, {}) lies outside the {w}×{h} image", c.0, c.1),
                    ));
                }
            }
            let mut c = *corners;
            if c[0].0 > c[1].0 {
                c.swap(0, 1);
            }
            (c, *px_per_cm, 4.0)
        }
        Calibration::Markers { side_cm } => {
            let Some((c, r)) = find_markers(img) else {
                return Err(InputError::new(
                    file,
                    "--markers",
                    "two red corner markers not found: give --px-per-cm and --corners instead",
                ));
            };
            let d = ((c[1].0 - c[0].0).powi(2) + (c[1].1 - c[0].1).powi(2)).sqrt();
            (c, d / side_cm, r + 3.0)
        }
    };
    if ((corners[1].0 - corners[0].0).powi(2) + (corners[1].1 - corners[0].1).powi(2)).sqrt() < 10.0
    {
        return Err(InputError::new(
            file,
            "--corners",
            "the two corners are less than 10 px apart",
        ));
    }
    Ok((corners, s, guard))
}

/// Fits the edges of a photo.
pub fn fit_image(
    img: &RgbImage,
    opts: &FitImageOptions,
    file: &Path,
) -> Result<ImageFit, InputError> {
    let (w, h) = img.dimensions();
    let (corners, s, guard) = calibrate(img, opts, file)?;
    let seg = segment(img, file)?;
    let mask = |u: i64, v: i64| {
        u >= 0 && v >= 0 && u < w as i64 && v < h as i64 && seg.fabric_at(u as u32, v as u32)
    };
    corners_touch_fabric(&corners, guard, &mask, file)?;
    let [c0, c1] = corners;
    let len = ((c1.0 - c0.0).powi(2) + (c1.1 - c0.1).powi(2)).sqrt();
    let tdir = ((c1.0 - c0.0) / len, (c1.1 - c0.1) / len);
    let up = (tdir.1, -tdir.0);
    let to_cm = |pu: f64, pv: f64| {
        let d = (pu - c0.0, pv - c0.1);
        (
            (d.0 * tdir.0 + d.1 * tdir.1) / s,
            (d.0 * up.0 + d.1 * up.1) / s,
        )
    };
    let span_cm = len / s;
    let (u_lo, u_hi) = ((c0.0 + guard).ceil() as i64, (c1.0 - guard).floor() as i64);
    let trace = |len: i64, px: &dyn Fn(i64) -> (i64, i64), last: bool| {
        trace_edge(&seg, (w, h), len, px, last)
    };
    let mut edges = Vec::new();
    let mut points_cm = Vec::new();
    for &name in opts.view.edges() {
        let mut pts: Vec<(f64, f64)> = Vec::new();
        match name {
            "bottom" | "top" => {
                for u in u_lo..=u_hi {
                    if let Some(ve) = trace(h as i64, &|v| (u, v), name == "bottom") {
                        pts.push(to_cm(u as f64, ve));
                    }
                }
            }
            _ => {
                // Side edges of a 2-corner hang: rows below the reference line.
                let v_lo = (c0.1.max(c1.1) + guard + 2.0).ceil() as i64;
                let offset = if name == "right" { span_cm } else { 0.0 };
                for v in v_lo..h as i64 {
                    if let Some(ue) = trace(w as i64, &|u| (u, v), name == "right") {
                        let (along, upc) = to_cm(ue, v as f64);
                        pts.push((-upc, along - offset));
                    }
                }
            }
        }
        let (fit, pts) = fit_edge(name, pts, &edges, span_cm, opts.degree, file)?;
        edges.push(fit);
        points_cm.push(pts);
    }
    let overlay = draw_overlay(img, &edges, corners, s);
    if let Some(p) = opts.pinhole {
        let projection = p.projection(corners, s, img.dimensions());
        for e in edges.iter_mut() {
            e.projection = projection;
        }
    }
    Ok(ImageFit {
        edges,
        points_cm,
        overlay,
        corners,
        px_per_cm: s,
    })
}

/// The boundary along one line of pixels `px(k)`, k in 0..len, of a `(w, h)` photo segmented as
/// `seg`: the last (or first) fabric pixel that has a fabric neighbour on the line, refined to
/// sub-pixel ([`subpixel_edge`]).
fn trace_edge(
    seg: &Segmented,
    (w, h): (u32, u32),
    len: i64,
    px: &dyn Fn(i64) -> (i64, i64),
    last: bool,
) -> Option<f64> {
    let inside = |u: i64, v: i64| u >= 0 && v >= 0 && u < w as i64 && v < h as i64;
    let fab = |k: i64| {
        let (u, v) = px(k);
        inside(u, v) && seg.fabric_at(u as u32, v as u32)
    };
    let mut hits = (0..len).filter(|&k| fab(k) && (fab(k + 1) || fab(k - 1)));
    let kb = if last { hits.next_back() } else { hits.next() }?;
    let line = |k: i64| {
        let (u, v) = px(k);
        inside(u, v).then(|| (seg.at(u as u32, v as u32), seg.background_at(u, v)))
    };
    Some(subpixel_edge(
        &line,
        &fab,
        kb,
        if last { 1 } else { -1 },
        seg.fabric,
    ))
}

/// Refuses a calibration whose corners the fabric does not touch (within the guard and 3 px).
fn corners_touch_fabric(
    corners: &[(f64, f64); 2],
    guard: f64,
    mask: &dyn Fn(i64, i64) -> bool,
    file: &Path,
) -> Result<(), InputError> {
    for c in corners {
        let r = guard as i64 + 3;
        let (cu, cv) = (c.0 as i64, c.1 as i64);
        let touches = (-r..=r).any(|dv| (-r..=r).any(|du| mask(cu + du, cv + dv)));
        if !touches {
            return Err(InputError::new(
                file,
                "--corners",
                format!(
                    "the fabric touches no corner at ({:.1}, {:.1}): check the corner positions or markers",
                    c.0, c.1
                ),
            ));
        }
    }
    Ok(())
}

/// The polynomial of edge `name` through its traced points `pts` (cm), trimmed where a side edge
/// runs past the bottom edge's depth at its side (seed 000 Fig. 3); the fit and the points kept.
fn fit_edge(
    name: &str,
    pts: Vec<(f64, f64)>,
    edges: &[EdgeFit],
    span_cm: f64,
    degree: usize,
    file: &Path,
) -> Result<(EdgeFit, Vec<(f64, f64)>), InputError> {
    let bottom_depth = |x: f64| {
        edges
            .iter()
            .find(|e| e.edge == "bottom")
            .map(|e| -e.eval(x))
            .unwrap_or(f64::INFINITY)
    };
    let side_depth = if name == "right" {
        bottom_depth(span_cm)
    } else {
        bottom_depth(0.0)
    };
    let pts = super::trim_edge(name, pts, span_cm, side_depth);
    let Some(fit) = EdgeFit::from_points(name, &pts, degree) else {
        return Err(InputError::new(
            file,
            "",
            format!(
                "too few points on the {name} edge ({}) to fit degree {degree}",
                pts.len()
            ),
        ));
    };
    Ok((fit, pts))
}

/// The sub-pixel position of a boundary along a line of pixels (pixel k spans [k − ½, k + ½): pixel
/// centres at integers, as in OpenCV and imageproc). `kb` is the boundary pixel (the last fabric
/// pixel going in direction `dir`, +1 or −1); `line(k)` the grey level and the background model's
/// level there (None outside the image), `fab(k)` whether pixel k is fabric. A pixel's grey level is
/// the area-weighted mix of the fabric's and the background's, so the fabric covers
/// Σ (g − b)/(f − b) pixels of a window that starts inside the fabric. The background b comes from
/// the image's background model (a gradient of light or vignetting leaves no bias); the fabric's f
/// is read just inside the window, which starts as deep as the blur reaches beyond the boundary
/// (shading varies across the sheet, so f is taken where the edge's shading still holds);
/// `fabric` is the fallback where the line offers no fabric pixel.
pub fn subpixel_edge(
    line: &dyn Fn(i64) -> Option<(f64, f64)>,
    fab: &dyn Fn(i64) -> bool,
    kb: i64,
    dir: i64,
    fabric: f64,
) -> f64 {
    let m = EDGE_WINDOW;
    let b_edge = line(kb).map_or(fabric, |p| p.1);
    let contrast = (fabric - b_edge).abs();
    // How far the blur reaches: the pixels beyond the boundary still 10 % of the contrast off the
    // background. The window starts one pixel deeper than that into the fabric (at least one).
    let reach = (1..=m)
        .take_while(|&j| line(kb + dir * j).is_some_and(|(g, b)| (g - b).abs() > 0.1 * contrast))
        .count() as i64;
    let depth = (1..=(reach + 1).min(m - 1))
        .take_while(|&j| fab(kb - dir * j))
        .last()
        .unwrap_or(0);
    // Without blur the nearest fabric pixel holds the edge's shading; with blur, one past the window
    // start, beyond the blur's reach.
    let at_depth = depth.max(1) + i64::from(reach > 0);
    let inside: Vec<f64> = (at_depth..=at_depth)
        .map(|j| kb - dir * j)
        .filter(|&k| fab(k))
        .filter_map(|k| line(k).map(|p| p.0))
        .collect();
    let f = if inside.is_empty() {
        fabric
    } else {
        inside.iter().sum::<f64>() / inside.len() as f64
    };
    let start = kb - dir * depth;
    let end = kb + dir * m;
    let covered: f64 = (0..=(end - start) * dir)
        .map(|j| start + dir * j)
        .map(|k| line(k).map_or(0.0, |(g, b)| ((g - b) / (f - b)).clamp(0.0, 1.0)))
        .sum();
    // The fabric starts at the outer face of `start` and covers `covered` pixels in direction dir.
    start as f64 - 0.5 * dir as f64 + dir as f64 * covered
}

/// The photo with the reference line in blue and the fitted curves in red.
fn draw_overlay(img: &RgbImage, edges: &[EdgeFit], corners: [(f64, f64); 2], s: f64) -> RgbImage {
    let [c0, c1] = corners;
    let len = ((c1.0 - c0.0).powi(2) + (c1.1 - c0.1).powi(2)).sqrt();
    let tdir = ((c1.0 - c0.0) / len, (c1.1 - c0.1) / len);
    let up = (tdir.1, -tdir.0);
    let span_cm = len / s;
    // Overlay: reference line in blue, fitted curves in red.
    let mut overlay = img.clone();
    let to_px = |along: f64, upc: f64| {
        (
            c0.0 + (along * tdir.0 + upc * up.0) * s,
            c0.1 + (along * tdir.1 + upc * up.1) * s,
        )
    };
    imageproc::drawing::draw_line_segment_mut(
        &mut overlay,
        (c0.0 as f32, c0.1 as f32),
        (c1.0 as f32, c1.1 as f32),
        Rgb([30, 60, 230]),
    );
    for e in edges {
        let n = 200;
        let mut prev: Option<(f64, f64)> = None;
        for k in 0..=n {
            let x = e.x_min_cm + (e.x_max_cm - e.x_min_cm) * k as f64 / n as f64;
            let y = e.eval(x);
            let p = match e.edge.as_str() {
                "left" => to_px(y, -x),
                "right" => to_px(y + span_cm, -x),
                _ => to_px(x, y),
            };
            if let Some(q) = prev {
                imageproc::drawing::draw_line_segment_mut(
                    &mut overlay,
                    (q.0 as f32, q.1 as f32),
                    (p.0 as f32, p.1 as f32),
                    Rgb([230, 20, 20]),
                );
            }
            prev = Some(p);
        }
    }
    overlay
}
