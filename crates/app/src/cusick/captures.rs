//! `predictions_by_capture.parquet` (issue 51): one row per capture of every specimen but the
//! calibration one — the model's DC and node count for the capture's face (face up at the fitted
//! curl, face down at its negative; the face average where the face is unknown or the fit is
//! face-blind), a 90 % prediction interval, and the baselines a textile lab would use beside it.
//!
//! The interval holds the specimen-to-specimen variation the model cannot know: it is the
//! prediction plus the 5 % and 95 % quantiles of the residuals (measured − predicted) of every
//! *other* fabric's captures of the same kind (known face, or face average) — leave one fabric
//! out, never this fabric's own data — widened to hold the prediction itself where those residuals
//! lie all on one side (issue 78: a point is never outside its own interval). With fewer than [`MIN_POOL`] such residuals (a dataset of
//! one or two fabrics) it falls back to ±1.645 of the model's own spread (its seeds' DC SD and the
//! calibration specimen's), and says so.

use crate::cusick::measure::ShadowRow;
use drapelab_core::cusick::{Face, NodeDistribution};
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
    /// correction ([`crate::cusick::node_prior`]).
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

/// Residuals of other fabrics' captures below this many: the interval falls back to the model's
/// own spread.
pub const MIN_POOL: usize = 10;

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

/// The rows of one fabric's predicted captures (`rows`: all its captures; `calib`: the calibration
/// specimen), intervals not yet set (NaN; [`fill_intervals`] sets them).
pub fn capture_rows(rows: &[&ShadowRow], calib: i32, pred: &FacePredictions) -> Vec<CaptureRow> {
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
    rows.iter()
        .filter(|r| r.sample != calib)
        .map(|r| {
            let face = r.face;
            let p = pred.of(face);
            let known = face != Face::Unknown;
            let same_face = |o: &ShadowRow| known && o.face == face;
            CaptureRow {
                fabric: r.fabric,
                sample: r.sample,
                capture: r.capture,
                face,
                dc_predicted_pct: pred.dc_pct(face),
                dc_low_pct: f64::NAN,
                dc_high_pct: f64::NAN,
                nodes_predicted: p.nodes_mean,
                nodes_predicted_mode: p.nodes_mode as i32,
                nodes_model_mean: p.nodes_mean,
                nodes_model_mode: p.nodes_mode as i32,
                interval: String::new(),
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

/// The `q`-quantile of sorted `v` (linear between order statistics).
fn quantile(v: &[f64], q: f64) -> f64 {
    let at = q * (v.len() - 1) as f64;
    let (lo, hi) = (at.floor() as usize, at.ceil() as usize);
    v[lo] + (v[hi] - v[lo]) * (at - lo as f64)
}

/// Sets every row's 90 % interval from the other fabrics' residuals (see the module), or from
/// `spread(fabric)` (the model's own DC spread, %) where they are too few.
pub fn fill_intervals(rows: &mut [CaptureRow], spread: impl Fn(i32) -> f64) {
    let residual = |r: &CaptureRow, average: bool| {
        r.dc_measured_pct
            - if average {
                r.dc_face_average_pct
            } else {
                r.dc_predicted_pct
            }
    };
    let snapshot = rows.to_vec();
    for r in rows.iter_mut() {
        let average = r.face == Face::Unknown;
        let mut pool: Vec<f64> = snapshot
            .iter()
            .filter(|o| o.fabric != r.fabric && (average || o.face != Face::Unknown))
            .map(|o| residual(o, average))
            .filter(|v| v.is_finite())
            .collect();
        pool.sort_by(f64::total_cmp);
        let (lo, hi, how) = if pool.len() >= MIN_POOL {
            // Widened to hold the point itself where the others' residuals lie all on one side
            // (a model biased on them): a prediction is never outside its own interval.
            (
                quantile(&pool, 0.05).min(0.0),
                quantile(&pool, 0.95).max(0.0),
                "leave-one-fabric-out",
            )
        } else {
            let h = 1.645 * spread(r.fabric);
            (-h, h, "model spread")
        };
        r.dc_low_pct = r.dc_predicted_pct + lo;
        r.dc_high_pct = r.dc_predicted_pct + hi;
        r.interval = how.into();
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    pub(crate) fn row(fabric: i32, face: &str, measured: f64, predicted: f64) -> CaptureRow {
        CaptureRow {
            fabric,
            sample: 2,
            capture: 1,
            face: Face::of(face),
            dc_predicted_pct: predicted,
            dc_low_pct: f64::NAN,
            dc_high_pct: f64::NAN,
            nodes_predicted: 7.0,
            nodes_predicted_mode: 7,
            nodes_model_mean: 7.0,
            nodes_model_mode: 7,
            interval: String::new(),
            dc_measured_pct: measured,
            nodes_measured: 7,
            dc_face_average_pct: predicted,
            dc_face_drapes_pct: predicted,
            dc_carry_over_pct: predicted,
            dc_carry_over_face_pct: None,
            dc_other_specimens_pct: None,
            dc_other_specimens_face_pct: None,
        }
    }

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
        let caps = capture_rows(&refs, 1, &pred);
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
                (Face::Up, 60.5, 7.0, 60.0),
                (Face::Down, 63.5, 9.0, 66.0),
                (Face::Unknown, 62.0, 8.0, 62.0)
            ]
        );
        assert!(caps.iter().all(|c| c.dc_carry_over_pct == 58.0));
    }

    #[test]
    fn an_interval_is_made_of_the_other_fabrics_residuals_only() {
        // Fabric 1's residuals are all +50; the others' spread uniformly over −10…+10: fabric 1's
        // interval ignores its own and spans the others' 5–95 %, the others' include fabric 1's.
        let mut rows: Vec<CaptureRow> = (0..21)
            .map(|k| row(2 + k % 3, "up", 50.0 + (k as f64 - 10.0), 50.0))
            .collect();
        rows.extend((0..4).map(|_| row(1, "down", 100.0, 50.0)));
        fill_intervals(&mut rows, |_| 1.0);
        let own = rows.iter().find(|r| r.fabric == 1).unwrap();
        assert_eq!(own.interval, "leave-one-fabric-out");
        assert!((own.dc_low_pct - 41.0).abs() < 1e-9 && (own.dc_high_pct - 59.0).abs() < 1e-9);
        let other = rows.iter().find(|r| r.fabric == 2).unwrap();
        assert!(other.dc_high_pct > 60.0, "{}", other.dc_high_pct);
        // A capture of unknown face: the face-average prediction's residuals of the others (here
        // fabric 1's, +50 against its face average) and its interval built on them.
        let mut unknown = row(3, "unknown", 50.0, 50.0);
        unknown.dc_face_average_pct = 48.0;
        let mut mixed = rows.clone();
        mixed.push(unknown);
        fill_intervals(&mut mixed, |_| 1.0);
        let u = mixed.last().unwrap();
        assert!(u.dc_high_pct >= 50.0 + 49.0, "{u:?}");
        // The others' residuals all positive (a model that predicts too low on them): the
        // interval reaches down to the point itself, never above it.
        let mut biased: Vec<CaptureRow> = (0..21)
            .map(|k| row(2 + k % 3, "up", 55.0 + k as f64 * 0.5, 50.0))
            .collect();
        biased.push(row(1, "up", 60.0, 50.0));
        fill_intervals(&mut biased, |_| 1.0);
        for r in &biased {
            assert!(
                r.dc_low_pct <= r.dc_predicted_pct && r.dc_predicted_pct <= r.dc_high_pct,
                "{r:?}"
            );
        }
        let own = biased.last().unwrap();
        assert_eq!(own.dc_low_pct, 50.0);
        assert!(own.dc_high_pct > 60.0, "{own:?}");
        // One fabric alone: the model's own spread.
        let mut lone = vec![row(5, "up", 52.0, 50.0), row(5, "down", 49.0, 50.0)];
        fill_intervals(&mut lone, |_| 2.0);
        assert_eq!(lone[0].interval, "model spread");
        assert!((lone[0].dc_high_pct - 53.29).abs() < 1e-9);
    }
}
