//! `predictions_by_capture.parquet` (issue 51): one row per capture of every specimen but the
//! calibration one — the model's DC and node count for the capture's face (face up at the fitted
//! curl, face down at its negative; the face average where the face is unknown or the fit is
//! face-blind), a 90 % prediction interval, and the baselines a textile lab would use beside it.
//!
//! The interval holds the specimen-to-specimen variation the model cannot know: it is the
//! prediction plus the 5 % and 95 % quantiles of the residuals (measured − predicted) of every
//! *other* fabric's captures of the same kind (known face, or face average) — leave one fabric
//! out, never this fabric's own data — widened to hold the prediction itself where those residuals
//! lie all on one side (issue 78: a point is never outside its own interval). With fewer than
//! [`drapelab_core::cusick::MIN_POOL`] such residuals (a dataset of
//! one or two fabrics) it falls back to ±1.645 of the model's own spread (its seeds' DC SD and the
//! calibration specimen's), and says so.

use crate::cusick::measure::ShadowRow;
use drapelab_core::cusick::{DcPrediction, Face, Interval, NodeDistribution};
use drapelab_core::measure::mean;
use drapelab_core::table::Table;
use serde::{Deserialize, Serialize};

/// One capture of a predicted specimen.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CaptureRow {
    /// Fabric number.
    pub fabric: i32,
    /// Specimen number.
    pub sample: i32,
    /// Capture number (1–2 face up, 3–4 face down in the bundled dataset).
    pub capture: i32,
    /// "up", "down" or "unknown".
    pub face: Face,
    /// Predicted DC for this face, %: the mean over both faces' perturbation seeds shifted by half
    /// the model's face gap at the fabric's predicted curl ([`FacePredictions::dc_pct`]).
    pub dc_predicted_pct: f64,
    /// Lower end of the 90 % prediction interval, %.
    pub dc_low_pct: f64,
    /// Upper end of the 90 % prediction interval, %.
    pub dc_high_pct: f64,
    /// Predicted node count for this face: the mean over its seeds plus the fabric's node
    /// correction ([`drapelab_core::cusick::node_lines`]).
    pub nodes_predicted: f64,
    /// The predicted node count as a whole number: `nodes_predicted` rounded (the likeliest count;
    /// six seeds' mean estimates it better than their mode).
    pub nodes_predicted_mode: i32,
    /// The model's own node count for this face: the mean over its seeds, uncorrected.
    pub nodes_model_mean: f64,
    /// The most frequent node count of this face's seeds (the smaller on a tie), uncorrected.
    pub nodes_model_mode: i32,
    /// How the interval was made: "leave-one-fabric-out" or "model spread".
    pub interval: String,
    /// The capture's measured DC (its photo), %.
    pub dc_measured_pct: f64,
    /// The capture's measured node count (its photo).
    pub nodes_measured: i32,
    /// The face-average prediction (both faces' seeds), %.
    pub dc_face_average_pct: f64,
    /// The mean DC of this face's own drapes, % (the face-blind drapes' where there is no curl).
    pub dc_face_drapes_pct: f64,
    /// Baseline: the calibration specimen's mean DC over both faces, carried over, %.
    pub dc_carry_over_pct: f64,
    /// Baseline: the calibration specimen's mean DC on this face, carried over, % (None: it has no
    /// capture on this face, or the face is unknown).
    pub dc_carry_over_face_pct: Option<f64>,
    /// Baseline: the mean DC of the fabric's other predicted specimens (not this one), %.
    pub dc_other_specimens_pct: Option<f64>,
    /// Baseline: the same on this face only, %.
    pub dc_other_specimens_face_pct: Option<f64>,
}

impl Table for CaptureRow {
    const FILE: &'static str = "predictions_by_capture.parquet";
    const ROW: &'static str = "One capture of a predicted Cusick specimen: its face's predicted DC with a 90 % interval (leave one fabric out), nodes, and baselines.";
}

/// A fabric's predictions per face: the node and DC distributions of its face-up and face-down
/// seeds (both none for a face-blind fit) and of all of them, the face average.
#[derive(Debug, Clone, PartialEq)]
pub struct FacePredictions {
    /// Face up (curl as fitted).
    pub up: Option<NodeDistribution>,
    /// Face down (curl negated).
    pub down: Option<NodeDistribution>,
    /// Every seed of both faces (or of the face-blind prediction).
    pub average: NodeDistribution,
    /// The face gap the model gives at the prediction's curl, points (none: face-blind).
    pub gap_pct: Option<f64>,
}

impl FacePredictions {
    fn of(&self, face: Face) -> &NodeDistribution {
        let own = match face {
            Face::Up => self.up.as_ref(),
            Face::Down => self.down.as_ref(),
            Face::Unknown => None,
        };
        own.unwrap_or(&self.average)
    }

    /// The predicted DC of a capture on `face`: the mean of every drape (both faces: their mean is
    /// the curl-free DC to second order in the curl) shifted by half the model's face gap, down
    /// up and up down. The difference of the two faces' seed means would carry the seeds' spread
    /// (SD 1–5 points over six seeds) into the gap; the gap of one perturbation turned over does not.
    pub fn dc_pct(&self, face: Face) -> f64 {
        self.average.dc_mean_pct + 0.5 * self.gap_pct.unwrap_or(0.0) * face.gap_sign()
    }
}

/// The captures of a fabric's specimens but its calibration specimen `calib`, in order.
fn predicted<'a>(rows: &'a [&'a ShadowRow], calib: i32) -> impl Iterator<Item = &'a ShadowRow> {
    rows.iter().copied().filter(move |r| r.sample != calib)
}

/// What the prediction intervals need of one fabric's predicted captures (`rows`: all its
/// captures; `calib`: the calibration specimen), in the order of [`capture_rows`].
pub fn dc_predictions(
    rows: &[&ShadowRow],
    calib: i32,
    pred: &FacePredictions,
) -> Vec<DcPrediction> {
    predicted(rows, calib)
        .map(|r| DcPrediction {
            fabric: r.fabric,
            face: r.face,
            measured_pct: r.dc_photo_pct,
            predicted_pct: pred.dc_pct(r.face),
            face_average_pct: pred.average.dc_mean_pct,
        })
        .collect()
}

/// The mean residual (measured − the model's mean for the capture's face) of a fabric's predicted
/// captures' node counts, where the model has one: what the node line is fitted on.
pub fn node_residual(rows: &[&ShadowRow], calib: i32, pred: &FacePredictions) -> Option<f64> {
    let residuals: Vec<f64> = predicted(rows, calib)
        .map(|r| (r.nodes_photo as f64, pred.of(r.face).nodes_mean))
        .filter(|(_, model)| model.is_finite())
        .map(|(measured, model)| measured - model)
        .collect();
    mean(&residuals)
}

/// The rows of one fabric's predicted captures (`rows`: all its captures; `calib`: the calibration
/// specimen), each with the fabric's node `correction` (nodes) and its interval (`intervals`, in
/// the order of [`dc_predictions`]).
pub fn capture_rows(
    rows: &[&ShadowRow],
    calib: i32,
    pred: &FacePredictions,
    correction: f64,
    intervals: &[Interval],
) -> Vec<CaptureRow> {
    let dc_where = |keep: &dyn Fn(&ShadowRow) -> bool| {
        mean(
            &rows
                .iter()
                .filter(|r| keep(r))
                .map(|r| r.dc_photo_pct)
                .collect::<Vec<_>>(),
        )
    };
    let carry = dc_where(&|r| r.sample == calib).unwrap_or(f64::NAN);
    predicted(rows, calib)
        .zip(intervals)
        .map(|(r, iv)| {
            let face = r.face;
            let p = pred.of(face);
            let known = face != Face::Unknown;
            let same_face = |o: &ShadowRow| known && o.face == face;
            let nodes_predicted = p.nodes_mean + correction;
            CaptureRow {
                fabric: r.fabric,
                sample: r.sample,
                capture: r.capture,
                face,
                dc_predicted_pct: pred.dc_pct(face),
                dc_low_pct: iv.low_pct,
                dc_high_pct: iv.high_pct,
                nodes_predicted,
                nodes_predicted_mode: nodes_predicted.round() as i32,
                nodes_model_mean: p.nodes_mean,
                nodes_model_mode: p.nodes_mode as i32,
                interval: iv.source.label().into(),
                dc_measured_pct: r.dc_photo_pct,
                nodes_measured: r.nodes_photo as i32,
                dc_face_average_pct: pred.average.dc_mean_pct,
                dc_face_drapes_pct: p.dc_mean_pct,
                dc_carry_over_pct: carry,
                dc_carry_over_face_pct: dc_where(&|o| o.sample == calib && same_face(o)),
                dc_other_specimens_pct: dc_where(&|o| o.sample != calib && o.sample != r.sample),
                dc_other_specimens_face_pct: dc_where(&|o| {
                    o.sample != calib && o.sample != r.sample && same_face(o)
                }),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use drapelab_core::cusick::IntervalSource;

    fn distribution(dc: f64, nodes: usize) -> NodeDistribution {
        NodeDistribution {
            converged: 1,
            tried: 1,
            nodes_mean: nodes as f64,
            nodes_mode: nodes,
            nodes_sd: 0.0,
            histogram: vec![(nodes, 1)],
            dc_mean_pct: dc,
            dc_sd_pct: 0.0,
        }
    }

    #[test]
    fn a_capture_gets_the_faces_mean_shifted_by_half_the_gap_and_its_faces_nodes() {
        // Face-up drapes at 60 % and 7 nodes, face-down at 66 % and 9, all of them at 62 % and 8;
        // the model's gap 3 points: up 60.5, down 63.5, unknown 62, nodes each face's own.
        let pred = FacePredictions {
            up: Some(distribution(60.0, 7)),
            down: Some(distribution(66.0, 9)),
            average: distribution(62.0, 8),
            gap_pct: Some(3.0),
        };
        let shadow = |sample: i32, face: Face, dc: f64| ShadowRow::photo(4, sample, 1, face, dc);
        let rows = [
            shadow(1, Face::Up, 58.0),
            shadow(2, Face::Up, 61.0),
            shadow(2, Face::Down, 64.0),
            shadow(3, Face::Unknown, 62.5),
        ];
        let refs: Vec<&ShadowRow> = rows.iter().collect();
        let iv = Interval {
            low_pct: 1.0,
            high_pct: 2.0,
            source: IntervalSource::ModelSpread,
        };
        let dc = dc_predictions(&refs, 1, &pred);
        assert_eq!(dc.len(), 3);
        assert_eq!((dc[1].predicted_pct, dc[1].face_average_pct), (63.5, 62.0));
        let caps = capture_rows(&refs, 1, &pred, 0.5, &[iv; 3]);
        let got: Vec<(Face, f64, f64, f64)> = caps
            .iter()
            .map(|c| {
                (
                    c.face,
                    c.dc_predicted_pct,
                    c.nodes_predicted,
                    c.dc_face_drapes_pct,
                )
            })
            .collect();
        assert_eq!(
            got,
            vec![
                (Face::Up, 60.5, 7.5, 60.0),
                (Face::Down, 63.5, 9.5, 66.0),
                (Face::Unknown, 62.0, 8.5, 62.0)
            ]
        );
        assert!(caps.iter().all(|c| c.dc_carry_over_pct == 58.0));
        // The correction rounds into the whole count; the model's own count stays in its column;
        // the interval is the one given.
        assert_eq!(
            (caps[0].nodes_predicted_mode, caps[0].nodes_model_mean),
            (8, 7.0)
        );
        assert_eq!(
            (caps[0].dc_low_pct, caps[0].interval.as_str()),
            (1.0, "model spread")
        );
        // The node residual: measured 8 (ShadowRow::photo) less each face's model mean 7, 9, 8.
        assert_eq!(node_residual(&refs, 1, &pred), Some(0.0));
    }
}
