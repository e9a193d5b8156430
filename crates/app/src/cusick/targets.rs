//! The measured side of a Cusick fabric (its calibration specimen's targets and the other
//! specimens' DC and node statistics) and the prediction row that carries it, filled in from a
//! calibration's fit, its node distribution and its per-face predictions.

use crate::cusick::captures::FacePredictions;
use crate::cusick::measure::ShadowRow;
use crate::cusick::tables::PredictionRow;
use drapelab_core::cusick::*;
use drapelab_core::measure::{mean_sd, median};
use drapelab_record::cusick::CaptureKey;

/// The measured side of a fabric: the calibration specimen (its DC, that DC's standard error and
/// its median node count) and the other specimens' DC mean, SD and median node count.
pub struct Targets {
    pub(crate) calib: i32,
    pub(crate) specimen: SpecimenTargets,
    pub(crate) others: Vec<CaptureKey>,
    pub(crate) dc_mean_pct: f64,
    pub(crate) dc_sd_pct: f64,
    pub(crate) nodes_median: f64,
    pub(crate) nodes_sd: f64,
    pub(crate) nodes_histogram: String,
}

/// A fabric's targets from its captures: the calibration (lowest-numbered) specimen's DC, nodes
/// and face gap, and the other specimens' statistics the predictions are scored against.
pub fn targets(rows: &[&ShadowRow]) -> Targets {
    let calib = rows.iter().map(|r| r.sample).min().unwrap_or(0);
    let own: Vec<&&ShadowRow> = rows.iter().filter(|r| r.sample == calib).collect();
    let (dc_pct, sd) = mean_sd(&own.iter().map(|r| r.dc_photo_pct).collect::<Vec<_>>());
    let others: Vec<&&ShadowRow> = rows.iter().filter(|r| r.sample != calib).collect();
    let (dc_mean_pct, dc_sd_pct) =
        mean_sd(&others.iter().map(|r| r.dc_photo_pct).collect::<Vec<_>>());
    Targets {
        calib,
        specimen: SpecimenTargets {
            dc_pct,
            dc_se_pct: sd / (own.len().max(1) as f64).sqrt(),
            nodes: median(&own.iter().map(|r| r.nodes_photo as f64).collect::<Vec<_>>()),
            face_gap: face_gap(own.iter().map(|r| (r.face, r.dc_photo_pct))),
            predicted_face_gap_pct: None,
        },
        others: others
            .iter()
            .map(|r| (r.fabric, r.sample, r.capture))
            .collect(),
        dc_mean_pct,
        dc_sd_pct,
        nodes_median: median(
            &others
                .iter()
                .map(|r| r.nodes_photo as f64)
                .collect::<Vec<_>>(),
        ),
        nodes_sd: mean_sd(
            &others
                .iter()
                .map(|r| r.nodes_photo as f64)
                .collect::<Vec<_>>(),
        )
        .1,
        nodes_histogram: histogram_label(&histogram(others.iter().map(|r| r.nodes_photo as usize))),
    }
}

/// A prediction row with the fabric's targets and no prediction yet (filled in by the caller).
pub fn empty_row(fabric: i32, tg: &Targets, line: Option<GapLine>) -> PredictionRow {
    PredictionRow {
        fabric,
        calibration_sample: tg.calib,
        bending_length_warp_m: None,
        bending_length_weft_m: None,
        bending_length_mean_m: None,
        bending_ratio_warp_over_weft: None,
        bending_saturation_curvature_per_m: None,
        laws_within_one_node: String::new(),
        law_identifiable: None,
        bending_length_lo_m: None,
        bending_length_hi_m: None,
        dc_sensitivity_pct: None,
        bending_rigidity_N_m: None,
        dc_predicted_pct: None,
        dc_predicted_sd_pct: None,
        dc_measured_mean_pct: tg.dc_mean_pct,
        dc_measured_sd_pct: tg.dc_sd_pct,
        dc_calibration_pct: tg.specimen.dc_pct,
        nodes_predicted: None,
        nodes_predicted_mode: None,
        nodes_predicted_histogram: String::new(),
        prediction_seeds: 0,
        nodes_calibration_median: tg.specimen.nodes,
        nodes_line_intercept: None,
        nodes_line_slope: None,
        nodes_correction: None,
        nodes_predicted_corrected: None,
        nodes_measured_median: tg.nodes_median,
        nodes_measured_sd: tg.nodes_sd,
        nodes_measured_histogram: tg.nodes_histogram.clone(),
        nodes_predicted_sd: None,
        warp_direction_deg: None,
        outline_two_fold_measured_m: None,
        outline_two_fold_predicted_m: None,
        profile_rms_mm: None,
        curl_per_m: None,
        curl_lo_per_m: None,
        curl_hi_per_m: None,
        curl_identifiable: None,
        face_gap_slope_pct_m: None,
        calibration_face_gap_pct: tg.specimen.face_gap.map(|g| g.gap_pct),
        dc_predicted_face_up_pct: None,
        dc_predicted_face_down_pct: None,
        face_gap_predicted_pct: tg.specimen.predicted_face_gap_pct,
        gap_line_intercept_pct: line.map(|l| l.intercept_pct),
        gap_line_slope: line.map(|l| l.slope),
        curl_predicted_per_m: None,
        face_gap_model_pct: None,
        dc_drapes_face_up_pct: None,
        dc_drapes_face_down_pct: None,
        status: String::new(),
        solves: 0,
        solve_time_mean_s: 0.0,
        wall_time_s: 0.0,
    }
}

/// A bending law in a few characters: "ρ=2", "ρ=1,κ₀c=2".
pub fn law_label(law: &BendingLaw) -> String {
    match law.bending_saturation {
        Some(s) => format!("ρ={},κ₀c={s}", law.bending_ratio),
        None => format!("ρ={}", law.bending_ratio),
    }
}

/// The fitted parameters into a row: c and the law, warp and weft bending lengths (B ∝ c³, so
/// c_warp = c ρ^(1/6)), the rigidity where the density is known.
pub fn fill_fit(row: &mut PredictionRow, fit: &FabricFit, weight_N_per_m2: Option<f64>) {
    let (c, rho) = (fit.bending_length_m, fit.law.bending_ratio);
    row.bending_length_mean_m = Some(c);
    row.bending_length_warp_m = Some(c * rho.powf(1.0 / 6.0));
    row.bending_length_weft_m = Some(c * rho.powf(-1.0 / 6.0));
    row.bending_ratio_warp_over_weft = Some(rho);
    row.bending_saturation_curvature_per_m = fit.law.bending_saturation.map(|s| s / c);
    row.laws_within_one_node = fit
        .laws_within_one_node
        .iter()
        .map(law_label)
        .collect::<Vec<_>>()
        .join(" ");
    row.law_identifiable = Some(fit.law_identifiable);
    row.bending_rigidity_N_m = weight_N_per_m2.map(|w| w * c.powi(3));
    row.dc_sensitivity_pct = fit.dc_sensitivity_pct;
    if let Some([lo, hi]) = fit.bending_length_interval_m {
        row.bending_length_lo_m = Some(lo);
        row.bending_length_hi_m = Some(hi);
    }
}

/// The predicted distribution into a row.
pub fn fill_distribution(row: &mut PredictionRow, d: &NodeDistribution) {
    row.dc_predicted_pct = Some(d.dc_mean_pct);
    row.dc_predicted_sd_pct = Some(d.dc_sd_pct);
    row.nodes_predicted = Some(d.nodes_mean);
    row.nodes_predicted_mode = Some(d.nodes_mode as i32);
    row.nodes_predicted_sd = Some(d.nodes_sd);
    row.nodes_predicted_histogram = histogram_label(&d.histogram);
    row.status = if d.converged == d.tried {
        "ok".into()
    } else {
        format!(
            "{} of {} perturbed drapes did not converge",
            d.tried - d.converged,
            d.tried
        )
    };
}

/// The fitted curl and each face's prediction into `row`; the faces' predictions (none when no
/// drape converged).
pub(crate) fn fill_faces(
    row: &mut PredictionRow,
    outcome: &FabricOutcome,
) -> Option<FacePredictions> {
    let average = outcome.distribution.clone()?;
    let (mut up, mut down) = (None, None);
    match &outcome.curl {
        Ok(c) => {
            row.curl_per_m = Some(c.curl_per_m);
            row.curl_lo_per_m = Some(c.interval_per_m[0]);
            row.curl_hi_per_m = Some(c.interval_per_m[1]);
            row.curl_identifiable = Some(c.identifiable);
            row.face_gap_slope_pct_m = Some(c.gap_slope_pct_m);
            if c.at_bound {
                row.status = format!(
                    "{}; the curl stopped at its bound ({} /m): the drape's DC moves {:.3} points per 1/m, too little to reach the face gap",
                    row.status, c.curl_per_m, c.gap_slope_pct_m
                );
            }
            let of = |d: Vec<_>| NodeDistribution::of(&d, d.len());
            up = of(outcome.face(false));
            down = of(outcome.face(true));
            row.dc_drapes_face_up_pct = up.as_ref().map(|f| f.dc_mean_pct);
            row.dc_drapes_face_down_pct = down.as_ref().map(|f| f.dc_mean_pct);
            row.curl_predicted_per_m = outcome.prediction_curl_per_m;
            row.face_gap_model_pct = outcome.prediction_gap_pct;
        }
        Err(why) => row.status = format!("{}; face-blind: {why}", row.status),
    }
    let gap_pct = outcome
        .prediction_gap_pct
        .filter(|_| up.is_some() && down.is_some());
    let faces = FacePredictions {
        up,
        down,
        average,
        gap_pct,
    };
    if gap_pct.is_some() {
        row.dc_predicted_face_up_pct = Some(faces.dc_pct(Face::Up));
        row.dc_predicted_face_down_pct = Some(faces.dc_pct(Face::Down));
    }
    Some(faces)
}
