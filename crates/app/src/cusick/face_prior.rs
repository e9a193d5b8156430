//! The face gap expected of a fabric's other specimens (issue 51). One specimen's face gap
//! Δ = DC_down − DC_up reads its fabric's with a large specimen-to-specimen scatter (on fabrics
//! 1–15 the calibration specimen's gap and the other specimens' correlate at 0.42: fabric 10's are
//! 1.3 and 10.5 points, fabric 14's 0.7 and −4.9), so a prediction shrinks it toward the
//! population: the least-squares line Δ_others ≈ a + b Δ_calibration, fitted on the *other*
//! fabrics only (leave one fabric out) — empirical Bayes, b the share of one specimen's gap that is
//! its fabric's and a the population's face effect where b is small.

use crate::cusick::measure::ShadowRow;
use drapelab_core::cusick::{Face, FaceGap};
use drapelab_core::measure::{least_squares_line, mean_sd};
use std::collections::BTreeMap;

/// Fabrics with both gaps needed, besides the predicted one, to fit a line; with fewer, a fabric
/// is predicted at its calibration specimen's own gap.
pub const MIN_FABRICS: usize = 3;

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

/// The face gap of one specimen's captures `own`: mean DC face down less face up, with its
/// standard error from the SD pooled within the faces (repeated captures of one face); none
/// without a capture on each face. With one capture per face (no repeat) the error is the gap
/// itself: the curl is then fitted but not identifiable.
pub fn face_gap(own: &[&&ShadowRow]) -> Option<FaceGap> {
    let of = |face: Face| -> Vec<f64> {
        own.iter()
            .filter(|r| r.face == face)
            .map(|r| r.dc_photo_pct)
            .collect()
    };
    let (up, down) = (of(Face::Up), of(Face::Down));
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

/// Each fabric's (calibration specimen's gap, the other specimens' pooled gap), where both exist.
fn gaps(shadows: &[ShadowRow]) -> BTreeMap<i32, (f64, Option<f64>)> {
    let mut by_fabric: BTreeMap<i32, Vec<&ShadowRow>> = BTreeMap::new();
    for r in shadows {
        by_fabric.entry(r.fabric).or_default().push(r);
    }
    by_fabric
        .into_iter()
        .filter_map(|(fabric, rows)| {
            let calib = rows.iter().map(|r| r.sample).min()?;
            let (own, others): (Vec<&&ShadowRow>, Vec<&&ShadowRow>) =
                rows.iter().partition(|r| r.sample == calib);
            let own = face_gap(&own)?.gap_pct;
            Some((fabric, (own, face_gap(&others).map(|g| g.gap_pct))))
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
pub fn line_without(
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
pub fn gap_lines(shadows: &[ShadowRow]) -> BTreeMap<i32, GapLine> {
    let all = gaps(shadows);
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

#[cfg(test)]
mod tests {
    use super::*;

    fn capture(fabric: i32, sample: i32, face: Face, dc: f64) -> ShadowRow {
        let number = if face == Face::Up { 1 } else { 3 };
        ShadowRow::photo(fabric, sample, number, face, dc)
    }

    /// A fabric whose calibration specimen (1) shows face gap `own` and specimen 2 gap `other`.
    fn fabric(f: i32, own: f64, other: f64) -> Vec<ShadowRow> {
        vec![
            capture(f, 1, Face::Up, 50.0),
            capture(f, 1, Face::Down, 50.0 + own),
            capture(f, 2, Face::Up, 60.0),
            capture(f, 2, Face::Down, 60.0 + other),
        ]
    }

    #[test]
    fn a_known_line_is_recovered_and_a_fabrics_own_siblings_never_enter_it() {
        // Others' gap = 1 + 0.5 × own on fabrics 1–4; fabric 5's siblings are far off the line.
        let mut rows: Vec<ShadowRow> = (1..=4)
            .flat_map(|f| fabric(f, 2.0 * f as f64 - 4.0, 1.0 + 0.5 * (2.0 * f as f64 - 4.0)))
            .collect();
        rows.extend(fabric(5, 6.0, -30.0));
        let lines = gap_lines(&rows);
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
}
