//! What a fabric's calibration specimen says of its other specimens, read off the *other* fabrics
//! (leave one fabric out; issues 51 and 78): each a pure function of typed captures returning typed
//! values, which the tables take where they are written.
//!
//! - The face gap Δ = DC_down − DC_up of one specimen reads its fabric's with a large
//!   specimen-to-specimen scatter, so a prediction shrinks it toward the population: the
//!   least-squares line Δ_others ≈ a + b Δ_calibration over the other fabrics ([`gap_lines`]),
//!   empirical Bayes, b the share of one specimen's gap that is its fabric's.
//! - The node count: how much of the calibration specimen's discrepancy D = n_calibration − n̄_model
//!   is the fabric's, read off the same way ([`node_lines`]).
//! - The 90 % prediction interval of a capture's DC: the 5 % and 95 % quantiles of the other
//!   fabrics' residuals of the same kind ([`prediction_intervals`]).

use super::{Face, FaceGap};
use crate::measure::{least_squares_line, mean_sd};
use std::collections::BTreeMap;

/// Fabrics with both values needed, besides the predicted one, to fit a line; with fewer, a fabric
/// is predicted from its calibration specimen alone.
pub const MIN_FABRICS: usize = 3;

/// Residuals of other fabrics' captures below this many: the interval falls back to the model's
/// own spread.
pub const MIN_POOL: usize = 10;

/// One capture's measured DC.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DcCapture {
    /// Fabric number.
    pub fabric: i32,
    /// Specimen number (the lowest of a fabric is its calibration specimen).
    pub sample: i32,
    /// The face the capture shows.
    pub face: Face,
    /// Its DC, %.
    pub dc_pct: f64,
}

/// The gap line of one fabric, fitted on the other fabrics.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GapLine {
    /// The line's value at a calibration gap of zero, points.
    pub intercept_pct: f64,
    /// Its slope, kept within [0, 1] (a shrinkage: a specimen's gap can neither reverse nor amplify
    /// its fabric's).
    pub slope: f64,
    /// Fabrics it was fitted on.
    pub fabrics: usize,
    /// The gap it gives the fabric's other specimens, points.
    pub predicted_pct: f64,
}

/// The node correction of one fabric.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NodeLine {
    /// The line's intercept, nodes (None: too few other fabrics, no line).
    pub intercept: Option<f64>,
    /// Its slope in [0, 1]: the share of the calibration specimen's discrepancy that is its fabric's.
    pub slope: Option<f64>,
    /// The calibration specimen's discrepancy D: its median count less the model's mean, nodes.
    pub discrepancy: f64,
    /// What is added to the model's mean count for the other specimens, nodes.
    pub correction: f64,
}

/// The face gap of one specimen's captures (face, DC %): mean DC face down less face up, with its
/// standard error from the SD pooled within the faces (repeated captures of one face); none
/// without a capture on each face. With one capture per face (no repeat) the error is the gap
/// itself: the curl is then fitted but not identifiable.
pub fn face_gap(captures: impl IntoIterator<Item = (Face, f64)>) -> Option<FaceGap> {
    let (mut up, mut down) = (Vec::new(), Vec::new());
    for (face, dc) in captures {
        match face {
            Face::Up => up.push(dc),
            Face::Down => down.push(dc),
            Face::Unknown => {}
        }
    }
    if up.is_empty() || down.is_empty() {
        return None;
    }
    let ((mu, _), (md, _)) = (mean_sd(&up), mean_sd(&down));
    let gap_pct = md - mu;
    let squares: f64 = up.iter().map(|v| (v - mu).powi(2)).sum::<f64>()
        + down.iter().map(|v| (v - md).powi(2)).sum::<f64>();
    let dof = up.len() + down.len() - 2;
    let gap_se_pct = if dof == 0 {
        gap_pct.abs()
    } else {
        (squares / dof as f64 * (1.0 / up.len() as f64 + 1.0 / down.len() as f64)).sqrt()
    };
    Some(FaceGap {
        gap_pct,
        gap_se_pct,
    })
}

/// Each fabric's (calibration specimen's gap, the other specimens' pooled gap), where the first
/// exists.
fn gaps(captures: &[DcCapture]) -> BTreeMap<i32, (f64, Option<f64>)> {
    let mut by_fabric: BTreeMap<i32, Vec<&DcCapture>> = BTreeMap::new();
    for c in captures {
        by_fabric.entry(c.fabric).or_default().push(c);
    }
    by_fabric
        .into_iter()
        .filter_map(|(fabric, caps)| {
            let calib = caps.iter().map(|c| c.sample).min()?;
            let of = |own: bool| {
                let keep = caps.iter().filter(move |c| (c.sample == calib) == own);
                face_gap(keep.map(|c| (c.face, c.dc_pct)))
            };
            Some((fabric, (of(true)?.gap_pct, of(false).map(|g| g.gap_pct))))
        })
        .collect()
}

/// The least-squares line through `pairs` with its slope clamped to [0, 1] (the intercept then
/// refitted through the means); none for fewer than [`MIN_FABRICS`] pairs.
pub fn shrinkage_line(pairs: &[(f64, f64)]) -> Option<(f64, f64)> {
    if pairs.len() < MIN_FABRICS {
        return None;
    }
    let ([mx, my], slope) = least_squares_line(pairs);
    let b = slope.map_or(0.0, |b| b.clamp(0.0, 1.0));
    Some((my - b * mx, b))
}

/// The [`shrinkage_line`] through the (x, y) of every fabric of `all` but `fabric` that has both
/// (leave one fabric out), with how many fabrics it was fitted on.
fn line_without(
    all: &BTreeMap<i32, (f64, Option<f64>)>,
    fabric: i32,
) -> (Option<(f64, f64)>, usize) {
    let pairs: Vec<(f64, f64)> = all
        .iter()
        .filter(|(f, _)| **f != fabric)
        .filter_map(|(_, &(x, y))| Some((x, y?)))
        .collect();
    (shrinkage_line(&pairs), pairs.len())
}

/// Every fabric's gap line (for fabrics whose calibration specimen shows both faces and which have
/// [`MIN_FABRICS`] others with both gaps): no fabric's own other specimens enter its line.
pub fn gap_lines(captures: &[DcCapture]) -> BTreeMap<i32, GapLine> {
    let all = gaps(captures);
    all.iter()
        .filter_map(|(&fabric, &(own, _))| {
            let (line, fabrics) = line_without(&all, fabric);
            let (a, b) = line?;
            let line = GapLine {
                intercept_pct: a,
                slope: b,
                fabrics,
                predicted_pct: a + b * own,
            };
            Some((fabric, line))
        })
        .collect()
}

/// Every fabric's node line from each fabric's (discrepancy D, its other specimens' mean residual
/// against the model, none without one): the line of the residual on D through the other fabrics
/// (slope in [0, 1]), the correction a + bD, or the whole of D with fewer than [`MIN_FABRICS`]
/// others. No fabric's own other specimens enter its line.
pub fn node_lines(discrepancies: &BTreeMap<i32, (f64, Option<f64>)>) -> BTreeMap<i32, NodeLine> {
    discrepancies
        .iter()
        .map(|(&fabric, &(d, _))| {
            let (line, _) = line_without(discrepancies, fabric);
            let correction = line.map_or(d, |(a, b)| a + b * d);
            let line = NodeLine {
                intercept: line.map(|l| l.0),
                slope: line.map(|l| l.1),
                discrepancy: d,
                correction,
            };
            (fabric, line)
        })
        .collect()
}

/// One predicted capture's DC, as the intervals need it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DcPrediction {
    /// Fabric number.
    pub fabric: i32,
    /// The face the capture shows.
    pub face: Face,
    /// Its measured DC, %.
    pub measured_pct: f64,
    /// The model's DC for its face, %.
    pub predicted_pct: f64,
    /// The model's face-average DC, %.
    pub face_average_pct: f64,
}

/// Where an interval came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IntervalSource {
    /// The other fabrics' residuals.
    LeaveOneFabricOut,
    /// Too few of those: ±1.645 of the model's own spread.
    ModelSpread,
}

impl IntervalSource {
    /// The words the tables carry.
    pub fn label(self) -> &'static str {
        match self {
            IntervalSource::LeaveOneFabricOut => "leave-one-fabric-out",
            IntervalSource::ModelSpread => "model spread",
        }
    }
}

/// A 90 % prediction interval of a capture's DC.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Interval {
    /// Lower end, %.
    pub low_pct: f64,
    /// Upper end, %.
    pub high_pct: f64,
    /// Where it came from.
    pub source: IntervalSource,
}

/// The `q`-quantile of sorted `v` (linear between order statistics).
fn quantile(v: &[f64], q: f64) -> f64 {
    let at = q * (v.len() - 1) as f64;
    let (lo, hi) = (at.floor() as usize, at.ceil() as usize);
    v[lo] + (v[hi] - v[lo]) * (at - lo as f64)
}

/// Each capture's 90 % interval: its prediction plus the 5 % and 95 % quantiles of the residuals
/// (measured − predicted) of every *other* fabric's captures of the same kind (known face, or face
/// average where its face is unknown), widened to hold the prediction itself (issue 78); with fewer
/// than [`MIN_POOL`] such residuals ±1.645 of `spread(fabric)` (the model's own DC spread, %).
pub fn prediction_intervals(
    captures: &[DcPrediction],
    spread: impl Fn(i32) -> f64,
) -> Vec<Interval> {
    let residual = |c: &DcPrediction, average: bool| {
        let p = if average {
            c.face_average_pct
        } else {
            c.predicted_pct
        };
        c.measured_pct - p
    };
    captures
        .iter()
        .map(|c| {
            let average = c.face == Face::Unknown;
            let mut pool: Vec<f64> = (captures.iter())
                .filter(|o| o.fabric != c.fabric && (average || o.face != Face::Unknown))
                .map(|o| residual(o, average))
                .filter(|v| v.is_finite())
                .collect();
            pool.sort_by(f64::total_cmp);
            let (lo, hi, source) = if pool.len() >= MIN_POOL {
                let lo = quantile(&pool, 0.05).min(0.0);
                (
                    lo,
                    quantile(&pool, 0.95).max(0.0),
                    IntervalSource::LeaveOneFabricOut,
                )
            } else {
                let h = 1.645 * spread(c.fabric);
                (-h, h, IntervalSource::ModelSpread)
            };
            Interval {
                low_pct: c.predicted_pct + lo,
                high_pct: c.predicted_pct + hi,
                source,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn capture(fabric: i32, sample: i32, face: Face, dc_pct: f64) -> DcCapture {
        DcCapture {
            fabric,
            sample,
            face,
            dc_pct,
        }
    }

    /// A fabric whose calibration specimen (1) shows face gap `own` and specimen 2 gap `other`.
    fn fabric(f: i32, own: f64, other: f64) -> Vec<DcCapture> {
        vec![
            capture(f, 1, Face::Up, 50.0),
            capture(f, 1, Face::Down, 50.0 + own),
            capture(f, 2, Face::Up, 60.0),
            capture(f, 2, Face::Down, 60.0 + other),
        ]
    }

    #[test]
    fn a_known_gap_line_is_recovered_and_a_fabrics_own_siblings_never_enter_it() {
        // Others' gap = 1 + 0.5 × own on fabrics 1–4; fabric 5's siblings are far off the line.
        let mut caps: Vec<DcCapture> = (1..=4)
            .flat_map(|f| fabric(f, 2.0 * f as f64 - 4.0, 1.0 + 0.5 * (2.0 * f as f64 - 4.0)))
            .collect();
        caps.extend(fabric(5, 6.0, -30.0));
        let lines = gap_lines(&caps);
        let five = lines[&5];
        assert_eq!(five.fabrics, 4);
        assert!((five.intercept_pct - 1.0).abs() < 1e-12 && (five.slope - 0.5).abs() < 1e-12);
        assert!((five.predicted_pct - 4.0).abs() < 1e-12, "{five:?}");
        // Fabric 1's line sees fabric 5's outlier, so it is no longer the exact one.
        assert!((lines[&1].slope - 0.5).abs() > 1e-3, "{:?}", lines[&1]);
    }

    #[test]
    fn the_slope_is_a_shrinkage_and_too_few_fabrics_give_no_line() {
        // Siblings whose gap falls as the specimen's rises: the slope stops at 0 (the population's
        // mean gap); siblings twice the specimen's: at 1 (its own gap, shifted).
        let down = [(0.0, 4.0), (2.0, 2.0), (4.0, 0.0)];
        assert_eq!(shrinkage_line(&down), Some((2.0, 0.0)));
        let up = [(0.0, 0.0), (1.0, 2.0), (2.0, 4.0)];
        assert_eq!(shrinkage_line(&up), Some((1.0, 1.0)));
        assert_eq!(shrinkage_line(&up[..2]), None);
        assert!(gap_lines(&fabric(1, 3.0, 1.0)).is_empty());
    }

    #[test]
    fn a_face_gap_pools_the_sd_within_faces_and_needs_both_faces() {
        // Up 50, 52 (mean 51), down 55, 57 (mean 56): gap 5, pooled SD √2, SE √2 · √(½ + ½).
        let g = face_gap([
            (Face::Up, 50.0),
            (Face::Up, 52.0),
            (Face::Down, 55.0),
            (Face::Down, 57.0),
            (Face::Unknown, 0.0),
        ])
        .unwrap();
        assert!((g.gap_pct - 5.0).abs() < 1e-12);
        assert!((g.gap_se_pct - 2f64.sqrt()).abs() < 1e-12, "{g:?}");
        assert_eq!(face_gap([(Face::Up, 50.0), (Face::Unknown, 3.0)]), None);
    }

    #[test]
    fn a_known_share_of_the_node_discrepancy_is_recovered_and_the_own_siblings_never_enter() {
        // Siblings' residual = 1 + 0.5 D on fabrics 1–4 (D = −2, 0, 2, 4); fabric 5 (D = 2) has
        // siblings far off the line: its correction is the line's, 1 + 0.5 × 2 = 2.
        let mut all: BTreeMap<i32, (f64, Option<f64>)> = (1..=4)
            .map(|f| {
                let d = 2.0 * f as f64 - 4.0;
                (f, (d, Some(1.0 + 0.5 * d)))
            })
            .collect();
        all.insert(5, (2.0, Some(22.0)));
        let lines = node_lines(&all);
        let five = lines[&5];
        assert_eq!((five.intercept, five.slope), (Some(1.0), Some(0.5)));
        assert_eq!((five.discrepancy, five.correction), (2.0, 2.0));
        assert!(
            (lines[&1].intercept.unwrap() - 1.0).abs() > 1.0,
            "{:?}",
            lines[&1]
        );
        // With too few other fabrics the whole discrepancy is carried.
        let two: BTreeMap<i32, (f64, Option<f64>)> =
            [(1, (1.6, Some(1.6))), (2, (0.0, Some(0.0)))].into();
        let l = node_lines(&two)[&1];
        assert_eq!((l.slope, l.correction), (None, 1.6));
    }

    fn dc(fabric: i32, face: Face, measured: f64, predicted: f64) -> DcPrediction {
        DcPrediction {
            fabric,
            face,
            measured_pct: measured,
            predicted_pct: predicted,
            face_average_pct: predicted,
        }
    }

    #[test]
    fn an_interval_is_made_of_the_other_fabrics_residuals_only() {
        // Fabric 1's residuals are all +50; the others' spread uniformly over −10…+10: fabric 1's
        // interval ignores its own and spans the others' 5–95 %, the others' include fabric 1's.
        let mut caps: Vec<DcPrediction> = (0..21)
            .map(|k| dc(2 + k % 3, Face::Up, 50.0 + (k as f64 - 10.0), 50.0))
            .collect();
        caps.extend((0..4).map(|_| dc(1, Face::Down, 100.0, 50.0)));
        let iv = prediction_intervals(&caps, |_| 1.0);
        let own = iv[21];
        assert_eq!(own.source, IntervalSource::LeaveOneFabricOut);
        assert!((own.low_pct - 41.0).abs() < 1e-9 && (own.high_pct - 59.0).abs() < 1e-9);
        assert!(iv[0].high_pct > 60.0, "{:?}", iv[0]);
        // A capture of unknown face: the face-average prediction's residuals of the others (here
        // fabric 1's, +50 against its face average) and its interval built on them.
        let mut unknown = dc(3, Face::Unknown, 50.0, 50.0);
        unknown.face_average_pct = 48.0;
        let mut mixed = caps.clone();
        mixed.push(unknown);
        let u = *prediction_intervals(&mixed, |_| 1.0).last().unwrap();
        assert!(u.high_pct >= 50.0 + 49.0, "{u:?}");
        // The others' residuals all positive (a model that predicts too low on them): the
        // interval reaches down to the point itself, never above it.
        let mut biased: Vec<DcPrediction> = (0..21)
            .map(|k| dc(2 + k % 3, Face::Up, 55.0 + k as f64 * 0.5, 50.0))
            .collect();
        biased.push(dc(1, Face::Up, 60.0, 50.0));
        let iv = prediction_intervals(&biased, |_| 1.0);
        for (c, i) in biased.iter().zip(&iv) {
            assert!(
                i.low_pct <= c.predicted_pct && c.predicted_pct <= i.high_pct,
                "{i:?}"
            );
        }
        let own = *iv.last().unwrap();
        assert_eq!(own.low_pct, 50.0);
        assert!(own.high_pct > 60.0, "{own:?}");
        // One fabric alone: the model's own spread, ±1.645 of it.
        let lone = [dc(5, Face::Up, 52.0, 50.0), dc(5, Face::Down, 49.0, 50.0)];
        let iv = prediction_intervals(&lone, |_| 2.0);
        assert_eq!(iv[0].source, IntervalSource::ModelSpread);
        assert!((iv[0].high_pct - 53.29).abs() < 1e-9 && (iv[0].low_pct - 46.71).abs() < 1e-9);
    }
}
