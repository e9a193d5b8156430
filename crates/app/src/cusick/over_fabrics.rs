//! The tables of a Cusick prediction over every fabric, each row built once with what the
//! statistics over fabrics ([`drapelab_core::cusick::gap_lines`], [`node_lines`],
//! [`prediction_intervals`], leave one fabric out) give it.

use crate::cusick::captures::{
    CaptureRow, FacePredictions, capture_rows, dc_predictions, node_residual,
};
use crate::cusick::measure::ShadowRow;
use crate::cusick::tables::PredictionRow;
use drapelab_core::cusick::{NodeLine, node_lines, prediction_intervals};
use std::collections::BTreeMap;

/// What one fabric's prediction gives the tables over fabrics.
pub struct Outcome<'a> {
    /// Its row, without the node line.
    pub row: &'a PredictionRow,
    /// Its calibration specimen.
    pub calib: i32,
    /// The model's predictions per face (none where the fabric was not predicted).
    pub faces: Option<&'a FacePredictions>,
    /// The model's own DC spread, % (the fallback interval's).
    pub spread_pct: f64,
    /// Its captures.
    pub shadows: Vec<&'a ShadowRow>,
}

/// The fabrics' rows and their captures' rows, each built once with what the statistics over
/// fabrics give it (leave one fabric out): the node line, the captures' intervals.
pub fn rows_over_fabrics(fabrics: &[Outcome<'_>]) -> (Vec<PredictionRow>, Vec<CaptureRow>) {
    let discrepancies: BTreeMap<i32, (f64, Option<f64>)> = fabrics
        .iter()
        .filter_map(|f| {
            let d = f.row.nodes_calibration_median - f.row.nodes_predicted?;
            let residual = f
                .faces
                .as_ref()
                .and_then(|p| node_residual(&f.shadows, f.calib, p));
            d.is_finite().then_some((f.row.fabric, (d, residual)))
        })
        .collect();
    let node = node_lines(&discrepancies);
    let dc: Vec<_> = fabrics
        .iter()
        .filter_map(|f| Some(dc_predictions(&f.shadows, f.calib, f.faces?)))
        .collect();
    let spread: BTreeMap<i32, f64> = fabrics
        .iter()
        .map(|f| (f.row.fabric, f.spread_pct))
        .collect();
    let intervals = prediction_intervals(&dc.concat(), |fabric| {
        spread.get(&fabric).copied().unwrap_or(f64::NAN)
    });
    let mut at = 0;
    let mut captures = Vec::new();
    for f in fabrics {
        let Some(p) = f.faces else { continue };
        let correction = node.get(&f.row.fabric).map_or(0.0, |l| l.correction);
        let built = capture_rows(&f.shadows, f.calib, p, correction, &intervals[at..]);
        at += built.len();
        captures.extend(built);
    }
    let rows = (fabrics.iter())
        .map(|f| with_node_line(f.row.clone(), node.get(&f.row.fabric)))
        .collect();
    (rows, captures)
}

/// A fabric's row with its node line and corrected count (with six seeds a face's mean estimates
/// the likeliest whole count better than their mode).
fn with_node_line(row: PredictionRow, line: Option<&NodeLine>) -> PredictionRow {
    let Some(l) = line else { return row };
    PredictionRow {
        nodes_line_intercept: l.intercept,
        nodes_line_slope: l.slope,
        nodes_correction: Some(l.correction),
        nodes_predicted_corrected: row.nodes_predicted.map(|n| n + l.correction),
        ..row
    }
}
