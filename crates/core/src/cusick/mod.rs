//! The Cusick drape tester (BS 5058 / ISO 9073-9): a circular specimen on a smaller pedestal,
//! measured by its shadow from above. The drape coefficient DC = (S − S_pedestal)/(S_specimen −
//! S_pedestal) and the node count come from the shadow's area and its outline r(θ); the same
//! measures are taken of a photo's silhouette, of a mesh's vertical projection and of a hem polygon,
//! so that each can be checked against the others (data: Gong, Mao & Wang, CVPR 2024).

mod branch;
mod calibrate;
mod drape;
mod fabric;
mod face;
mod params;
mod priors;

pub use branch::{
    Continuation, DrapeBranch, MAX_CONTINUATION_LN, bending_length_tangent, continue_drape,
};
pub use calibrate::{
    BendingCalibration, DC_SLOPE_PRIOR_PCT, SecantSearch, calibrate_bending_length,
    secant_bending_length,
};
pub use drape::{
    DiscMesh, DrapeParams, DrapeStart, drape_dc, drape_model, drape_start, polar_disc, solve_drape,
    solve_drape_from, solve_drape_observed, subdivide_disc,
};
pub use fabric::{
    BendingLaw, FabricFit, FabricOutcome, FabricSettings, LawCandidate, NodeDistribution,
    SeededDrape, SpecimenTargets, calibrate_and_predict, calibrate_fabric, histogram,
    histogram_label, prediction_curl, seeded_drapes,
};
pub use face::{CurlFit, Face, FaceGap, GAP_TOL_PCT, MAX_CURL_PER_M, fit_curl};
pub use params::{SPECIMEN_KEYS, SpecimenParameters};
pub use priors::{
    DcCapture, DcPrediction, GapLine, Interval, IntervalSource, MIN_FABRICS, MIN_POOL, NodeLine,
    face_gap, gap_lines, node_lines, prediction_intervals, shrinkage_line,
};

use crate::measure::{Projection, count_rises, outline_radii, smooth_circular};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// The tester's geometry.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Tester {
    /// Radius of the flat specimen, m. Default 0.15 (a 30 cm specimen).
    pub specimen_radius_m: f64,
    /// Radius of the pedestal, m. Default 0.09 (18 cm).
    pub pedestal_radius_m: f64,
}

impl Default for Tester {
    fn default() -> Self {
        Tester {
            specimen_radius_m: 0.15,
            pedestal_radius_m: 0.09,
        }
    }
}

impl Tester {
    /// DC in % of a shadow of area `s_m2` (BS 5058): 100 flat, 0 hanging straight down.
    pub fn dc_pct(&self, s_m2: f64) -> f64 {
        let pi = std::f64::consts::PI;
        let (sp, ss) = (
            pi * self.pedestal_radius_m.powi(2),
            pi * self.specimen_radius_m.powi(2),
        );
        100.0 * (s_m2 - sp) / (ss - sp)
    }
}

/// How a top-view silhouette photo maps to the tester's frame: u = cu + s·x, v = cv − s·y (u column,
/// v row, pixel centres at integers; image right = +x, up = +y).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SilhouetteScale {
    /// Pixels per metre s. Default 723.2 (the BDP dataset's 256² silhouettes).
    pub px_per_m: f64,
    /// Pixel (cu, cv) of the pedestal centre. Default (126.95, 127.44).
    pub centre_px: [f64; 2],
    /// Grey level below which a pixel is shadow. Default 128.
    pub threshold: u8,
}

impl Default for SilhouetteScale {
    fn default() -> Self {
        SilhouetteScale {
            px_per_m: 723.2,
            centre_px: [126.95, 127.44],
            threshold: 128,
        }
    }
}

/// The shadow of a silhouette photo (dark on light) as a projection in the tester's frame.
pub fn silhouette_projection(img: &image::GrayImage, scale: &SilhouetteScale) -> Projection {
    let (w, h) = (img.width() as usize, img.height() as usize);
    let pixel = 1.0 / scale.px_per_m;
    let [cu, cv] = scale.centre_px;
    // Column col ↔ u = col; row r ↔ v = h − 1 − r (rows run up, image rows down).
    let origin = [(-cu - 0.5) * pixel, (cv - h as f64 + 0.5) * pixel];
    let mut p = Projection::empty(w, h, pixel, origin);
    for (u, v, px) in img.enumerate_pixels() {
        if px.0[0] < scale.threshold {
            p.covered[(h - 1 - v as usize) * w + u as usize] = true;
        }
    }
    p
}

/// Raster pixel of mesh and hem projections, m (0.5 mm).
pub const RASTER_PIXEL_M: f64 = 0.0005;
/// Half-width of the raster window about the pedestal centre, m.
pub const RASTER_HALF_M: f64 = 0.16;

fn window() -> Projection {
    let n = (2.0 * RASTER_HALF_M / RASTER_PIXEL_M).round() as usize;
    Projection::empty(n, n, RASTER_PIXEL_M, [-RASTER_HALF_M, -RASTER_HALF_M])
}

/// The vertical projection of a triangle mesh (every triangle onto z = 0) on a 0.5 mm raster over
/// ±0.16 m.
pub fn mesh_projection(x: &[Vector3<f64>], triangles: &[[usize; 3]]) -> Projection {
    let mut p = window();
    p.fill_triangles(x, triangles.iter().copied());
    p
}

/// The vertical projection of the region a closed hem polyline bounds (even–odd rule), on the
/// raster of [`mesh_projection`].
pub fn hem_projection(hem: &[Vector3<f64>]) -> Projection {
    let mut p = window();
    let n = hem.len();
    for row in 0..p.ny {
        let y = p.centre(0, row)[1];
        // Crossings of the row's line with the hem's edges, then fill between pairs.
        let mut xs: Vec<f64> = (0..n)
            .filter_map(|k| {
                let (a, b) = (hem[k], hem[(k + 1) % n]);
                ((a.y <= y) != (b.y <= y)).then(|| a.x + (y - a.y) / (b.y - a.y) * (b.x - a.x))
            })
            .collect();
        xs.sort_by(f64::total_cmp);
        // Pixel centres x = x₀ + (col + ½)·pixel inside [a, b): col from ⌈(a − x₀)/pixel − ½⌉.
        let col_of = |x: f64| {
            ((x - p.origin_m[0]) / p.pixel_m - 0.5)
                .ceil()
                .clamp(0.0, p.nx as f64) as usize
        };
        for pair in xs.chunks_exact(2) {
            for col in col_of(pair[0])..col_of(pair[1]) {
                p.covered[row * p.nx + col] = true;
            }
        }
    }
    p
}

/// What a shadow shows.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ShadowMeasures {
    /// Shadow area S, m².
    pub area_m2: f64,
    /// Drape coefficient, %.
    pub dc_pct: f64,
    /// Nodes: maxima of the smoothed outline more prominent than 4 mm.
    pub nodes: usize,
    /// The smoothed outline radius r(θ) in 1° sectors from θ = 0 (+x), m.
    pub outline_m: Vec<f64>,
}

/// The polar angle (rad, from +x) of the centre of sector `k` of `sectors` equal sectors of an
/// outline r(θ) (sector k holds the angles [k, k + 1) · 2π / sectors).
pub fn sector_angle_rad(k: usize, sectors: usize) -> f64 {
    (k as f64 + 0.5) * std::f64::consts::TAU / sectors as f64
}

/// Sectors of the outline r(θ).
pub const OUTLINE_SECTORS: usize = 360;
/// Smoothing of the outline: sectors on each side (±5°).
pub const OUTLINE_SMOOTH: usize = 5;
/// Prominence a maximum of the outline needs to count as a node, m.
pub const NODE_PROMINENCE_M: f64 = 0.004;

/// DC, nodes and outline of a shadow about the pedestal centre (0, 0).
pub fn shadow_measures(p: &Projection, tester: &Tester) -> ShadowMeasures {
    let area = p.area_m2();
    let outline = smooth_circular(
        &outline_radii(p, [0.0, 0.0], OUTLINE_SECTORS),
        OUTLINE_SMOOTH,
    );
    ShadowMeasures {
        area_m2: area,
        dc_pct: tester.dc_pct(area),
        nodes: count_rises(&outline, NODE_PROMINENCE_M),
        outline_m: outline,
    }
}

/// The two-fold component of outlines r(θ) (sectors from θ = 0, see [`sector_angle_rad`]), averaged
/// as complex amplitudes over `outlines` (drapes of one fabric in one orientation): its amplitude
/// a₂ (m) and the direction θ₂ ∈ [0, π) (rad) of its maximum, r(θ) ≈ r̄ + a₂ cos 2(θ − θ₂). An
/// orthotropic fabric reaches furthest along its stiffer direction, so θ₂ estimates the warp.
pub fn two_fold(outlines: &[Vec<f64>]) -> (f64, f64) {
    let (mut re, mut im) = (0.0, 0.0);
    for o in outlines {
        let n = o.len();
        for (k, r) in o.iter().enumerate() {
            let t = 2.0 * sector_angle_rad(k, n);
            re += 2.0 * r * t.cos() / (n * outlines.len()) as f64;
            im += 2.0 * r * t.sin() / (n * outlines.len()) as f64;
        }
    }
    let theta = 0.5 * im.atan2(re);
    (re.hypot(im), theta.rem_euclid(std::f64::consts::PI))
}

/// The azimuthally averaged height profile z(r) of a drape: the mean z of the material points whose
/// rest radius falls in each of `bins` rings between the pedestal and the specimen's edge (NaN for
/// an empty ring). Independent of where the folds fall.
pub fn height_profile(
    rest_xy: &[[f64; 2]],
    x: &[Vector3<f64>],
    tester: &Tester,
    bins: usize,
) -> Vec<f64> {
    let (r0, r1) = (tester.pedestal_radius_m, tester.specimen_radius_m);
    let (mut sum, mut count) = (vec![0.0; bins], vec![0usize; bins]);
    for (q, p) in rest_xy.iter().zip(x) {
        let r = q[0].hypot(q[1]);
        if r < r0 || r > r1 + 1e-9 {
            continue;
        }
        let k = (((r - r0) / (r1 - r0) * bins as f64) as usize).min(bins - 1);
        sum[k] += p.z;
        count[k] += 1;
    }
    sum.iter()
        .zip(&count)
        .map(|(s, &c)| if c == 0 { f64::NAN } else { s / c as f64 })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn flower(k: usize, amp: f64) -> Vec<Vector3<f64>> {
        (0..720)
            .map(|i| {
                let t = i as f64 / 720.0 * std::f64::consts::TAU;
                let r = 0.12 + amp * (k as f64 * t).cos();
                Vector3::new(r * t.cos(), r * t.sin(), -0.05)
            })
            .collect()
    }

    #[test]
    fn a_flat_specimen_has_dc_100_and_one_hanging_straight_down_0() {
        let t = Tester::default();
        let pi = std::f64::consts::PI;
        assert!((t.dc_pct(pi * 0.15f64.powi(2)) - 100.0).abs() < 1e-12);
        assert!(t.dc_pct(pi * 0.09f64.powi(2)).abs() < 1e-12);
        let flat = shadow_measures(&hem_projection(&flower(6, 0.0)), &t);
        let exact = t.dc_pct(pi * 0.12f64.powi(2));
        assert!(
            (flat.dc_pct - exact).abs() < 0.3,
            "{} vs {exact}",
            flat.dc_pct
        );
        assert_eq!(flat.nodes, 0);
    }

    #[test]
    fn the_two_fold_component_of_an_elliptic_outline_gives_its_amplitude_and_direction() {
        let o = |dir: f64| -> Vec<f64> {
            (0..360)
                .map(|k| 0.12 + 0.01 * (2.0 * (sector_angle_rad(k, 360) - dir)).cos())
                .collect()
        };
        for deg in [0.0f64, 30.0, 100.0, 170.0] {
            let (a, t) = two_fold(&[o(deg.to_radians()), o(deg.to_radians())]);
            assert!((a - 0.01).abs() < 1e-9, "{a}");
            assert!(
                (t.to_degrees() - deg).abs() < 1e-6,
                "{} vs {deg}",
                t.to_degrees()
            );
        }
    }

    #[test]
    fn a_hem_with_k_lobes_has_k_nodes() {
        for k in 5..=12 {
            let m = shadow_measures(&hem_projection(&flower(k, 0.012)), &Tester::default());
            assert_eq!(m.nodes, k, "k = {k}");
        }
    }

    #[test]
    fn a_silhouette_maps_to_the_tester_frame() {
        // A disc of radius 0.1 m centred 2 cm to the right of the pedestal centre.
        let s = SilhouetteScale::default();
        let img = image::GrayImage::from_fn(256, 256, |u, v| {
            let x = (u as f64 - s.centre_px[0]) / s.px_per_m;
            let y = (s.centre_px[1] - v as f64) / s.px_per_m;
            image::Luma([if (x - 0.02).hypot(y) < 0.1 { 0 } else { 255 }])
        });
        let p = silhouette_projection(&img, &s);
        let pi = std::f64::consts::PI;
        assert!((p.area_m2() / (pi * 0.01) - 1.0).abs() < 0.01);
        let r = outline_radii(&p, [0.0, 0.0], 360);
        // Furthest along +x (θ = 0), nearest along −x.
        assert!((r[0] - 0.12).abs() < 0.002, "{}", r[0]);
        assert!((r[180] - 0.08).abs() < 0.002, "{}", r[180]);
    }
}
