//! The tables of the Cusick stages (issue 16) besides `shadows.parquet`: `predictions.parquet` (one
//! row per fabric, the contract), the shadow outlines r(θ) of photos and of simulated drapes,
//! and the azimuthally averaged height profiles z(r), each row type its schema.

use drapelab_core::table::Table;
use serde::{Deserialize, Serialize};

/// One fabric: calibrated on one specimen, predicted against the others.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct PredictionRow {
    /// Fabric number.
    pub fabric: i32,
    /// The specimen calibrated on (the lowest-numbered).
    pub calibration_sample: i32,
    /// Bending length along the warp (the stiffer direction), c·ρ^(1/6), m (None if the calibration failed).
    pub bending_length_warp_m: Option<f64>,
    /// Bending length along the weft, c·ρ^(−1/6), m.
    pub bending_length_weft_m: Option<f64>,
    /// Calibrated bending length c of the geometric-mean rigidity √(B_warp B_weft), m.
    pub bending_length_mean_m: Option<f64>,
    /// Calibrated bending anisotropy ρ = B_warp / B_weft (1: isotropic).
    pub bending_ratio_warp_over_weft: Option<f64>,
    /// Calibrated curvature κ₀ beyond which the bending moment levels off, 1/m (None: linear bending).
    pub bending_saturation_curvature_per_m: Option<f64>,
    /// Every bending law tried whose drapes' mean node count lies within 1 of the calibration
    /// target, e.g. "ρ=1 ρ=2 ρ=1,κ₀c=2" (κ₀c: saturation curvature times c).
    pub laws_within_one_node: String,
    /// Whether the laws' node counts tell them apart (they span more than one node).
    pub law_identifiable: Option<bool>,
    /// Bending rigidity, N·m (None where the areal density is unknown: it needs the weight).
    pub bending_rigidity_N_m: Option<f64>,
    /// Lower end of the 2σ interval of the bending length, m: c · exp(−2σ/s), σ the uncertainty of
    /// the calibration's DC (its photos' SD/√n and the model's seed-to-seed SD), s = dDC/d ln c.
    pub bending_length_lo_m: Option<f64>,
    /// Upper end of that interval, m.
    pub bending_length_hi_m: Option<f64>,
    /// Sensitivity of the simulated DC to the bending length, dDC/d ln c, % (what pins c down).
    pub dc_sensitivity_pct: Option<f64>,
    /// Mean simulated DC over the perturbations, %.
    pub dc_predicted_pct: Option<f64>,
    /// SD of the simulated DC over the perturbations, %.
    pub dc_predicted_sd_pct: Option<f64>,
    /// Mean measured DC (photos) of the other specimens, %.
    pub dc_measured_mean_pct: f64,
    /// SD of the measured DC over the other specimens' captures, %.
    pub dc_measured_sd_pct: f64,
    /// DC of the calibration specimen (the target), %.
    pub dc_calibration_pct: f64,
    /// Mean simulated node count over the perturbation seeds.
    pub nodes_predicted: Option<f64>,
    /// Most frequent simulated node count over the seeds (the smaller on a tie).
    pub nodes_predicted_mode: Option<i32>,
    /// The simulated node counts' histogram, "nodes×seeds" ascending (e.g. "6×2 7×4").
    pub nodes_predicted_histogram: String,
    /// Sample SD of the simulated node count over the seeds.
    pub nodes_predicted_sd: Option<f64>,
    /// Perturbation seeds of the prediction per face (disjoint from the calibration's; as many again
    /// face down where a curl is fitted, on seeds of their own).
    pub prediction_seeds: i32,
    /// Median node count of the calibration specimen's photos (the calibration's target).
    pub nodes_calibration_median: f64,
    /// The node line's intercept (the other fabrics' least-squares line of their other specimens'
    /// mean residual, measured − model, on their calibration specimen's discrepancy, median − model
    /// mean), nodes (None: fewer than three other fabrics).
    pub nodes_line_intercept: Option<f64>,
    /// The node line's slope in [0, 1]: the share of the calibration specimen's discrepancy that is
    /// its fabric's.
    pub nodes_line_slope: Option<f64>,
    /// What is added to the model's node counts for the other specimens, nodes: the line at this
    /// fabric's discrepancy, or the whole discrepancy without a line.
    pub nodes_correction: Option<f64>,
    /// The node count predicted for the other specimens: `nodes_predicted` + `nodes_correction`.
    pub nodes_predicted_corrected: Option<f64>,
    /// Direction of the warp estimated from the calibration specimen's face-up photos: the maximum
    /// of their outlines' two-fold component, degrees from the photo's +x in [0, 180) (an
    /// orthotropic fabric reaches furthest along its stiffer direction). Not used by the prediction:
    /// the specimens lie on the tester at unknown orientations.
    pub warp_direction_deg: Option<f64>,
    /// Amplitude of that two-fold component, m.
    pub outline_two_fold_measured_m: Option<f64>,
    /// Amplitude of the two-fold component of the simulated drapes' outlines (warp along +x), m.
    pub outline_two_fold_predicted_m: Option<f64>,
    /// Median measured node count (photos) of the other specimens.
    pub nodes_measured_median: f64,
    /// Sample SD of the measured node count over the other specimens' captures.
    pub nodes_measured_sd: f64,
    /// The other specimens' captures' node counts as a histogram, "nodes×captures" ascending.
    pub nodes_measured_histogram: String,
    /// RMS over the rings of simulated minus measured mean height z(r), mm (None without registered meshes).
    pub profile_rms_mm: Option<f64>,
    /// The fabric's natural curl as fitted to the calibration specimen's face gap: the curvature
    /// a free strip rolls up to toward the fabric's face, 1/m (negative: toward its back; None: the
    /// fit is face-blind, see `status`).
    pub curl_per_m: Option<f64>,
    /// Lower end of the curl's 2σ interval (the face gap's standard error over its slope), 1/m.
    pub curl_lo_per_m: Option<f64>,
    /// Upper end of that interval, 1/m.
    pub curl_hi_per_m: Option<f64>,
    /// Whether the face gap pins the curl's side (its interval excludes zero).
    pub curl_identifiable: Option<bool>,
    /// Slope of the simulated face gap in the curl, d(DC_down − DC_up)/dκ, points per (1/m).
    pub face_gap_slope_pct_m: Option<f64>,
    /// The calibration specimen's face gap: mean DC face down less face up, points.
    pub calibration_face_gap_pct: Option<f64>,
    /// Predicted DC face up, %: the mean of both faces' drapes less half the predicted face gap.
    pub dc_predicted_face_up_pct: Option<f64>,
    /// Predicted DC face down, %: that mean plus half the predicted face gap.
    pub dc_predicted_face_down_pct: Option<f64>,
    /// The face gap expected of the other specimens, points: the calibration specimen's gap on
    /// the line fitted on the other fabrics (`gap_line_*`), or its own gap without a line.
    pub face_gap_predicted_pct: Option<f64>,
    /// The gap line's intercept (the other fabrics' least-squares line of their other specimens'
    /// gap on their calibration specimen's gap), points.
    pub gap_line_intercept_pct: Option<f64>,
    /// The gap line's slope in [0, 1]: the share of one specimen's gap that is its fabric's.
    pub gap_line_slope: Option<f64>,
    /// The curl of the prediction's drapes (face up; face down its negative): the fitted curl
    /// moved along its gap slope to the predicted gap, 1/m.
    pub curl_predicted_per_m: Option<f64>,
    /// The model's face gap at that curl, points (the predicted gap unless the curl hit its bound).
    pub face_gap_model_pct: Option<f64>,
    /// Mean DC of the face-up drapes (at the predicted curl), %.
    pub dc_drapes_face_up_pct: Option<f64>,
    /// Mean DC of the face-down drapes (the predicted curl negated), %.
    pub dc_drapes_face_down_pct: Option<f64>,
    /// "ok", or why there is no prediction.
    pub status: String,
    /// Drape solves made (the calibration's and the predictions').
    pub solves: i32,
    /// Mean wall time of one drape solve, s.
    pub solve_time_mean_s: f64,
    /// Wall time of the fabric's calibration and predictions, s.
    pub wall_time_s: f64,
}

impl Table for PredictionRow {
    const FILE: &'static str = "predictions.parquet";
    const ROW: &'static str = "One Cusick fabric: bending length calibrated on its lowest-numbered specimen, its other specimens predicted.";
}

/// One point of a shadow outline r(θ) (smoothed over ±5°) about the pedestal centre.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct OutlineRow {
    /// Fabric number.
    pub fabric: i32,
    /// Specimen of a photographed outline (None for a simulated one).
    pub sample: Option<i32>,
    /// Capture of a photographed outline.
    pub capture: Option<i32>,
    /// Perturbation seed of a simulated outline (None for a photographed one).
    pub seed: Option<i32>,
    /// Polar angle from +x, rad.
    pub theta_rad: f64,
    /// Radius of the outline, m.
    pub radius_m: f64,
}

impl Table for OutlineRow {
    const FILE: &'static str = "outlines.parquet";
    const ROW: &'static str =
        "One point of a Cusick shadow outline r(θ): a capture's photo or a simulated drape.";
}

/// One ring of a fabric's azimuthally averaged height profile z(r), measured and predicted.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ProfileRow {
    /// Fabric number.
    pub fabric: i32,
    /// Rest (material) radius of the ring's centre, m.
    pub radius_m: f64,
    /// Mean height over the registered meshes of the predicted specimens, m (pedestal top z = 0).
    pub z_measured_m: Option<f64>,
    /// SD of that height over the meshes, m.
    pub z_measured_sd_m: Option<f64>,
    /// Mean height over the simulated drapes, m.
    pub z_predicted_m: Option<f64>,
    /// SD of that height over the perturbations, m.
    pub z_predicted_sd_m: Option<f64>,
}

impl Table for ProfileRow {
    const FILE: &'static str = "profiles.parquet";
    const ROW: &'static str = "One ring of a Cusick fabric's azimuthally averaged height z(r): the registered meshes against the simulated drapes.";
}
