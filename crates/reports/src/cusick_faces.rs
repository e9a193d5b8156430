//! The Cusick report's section on the two faces (issue 51): the curls fitted to the calibration
//! specimens' face gaps, every predicted capture scored per face against the baselines a lab would
//! use, the 90 % intervals' coverage, and the harder test — face-down DC from face-up captures only.

use crate::format::opt;
use drapelab_app::cusick::captures::CaptureRow;
use drapelab_app::cusick::tables::PredictionRow;
use drapelab_core::cusick::Face;
use drapelab_core::measure::mean;
use std::collections::BTreeMap;

/// The other specimens' mean face gap of each fabric (mean DC face down less face up over its
/// predicted captures), points.
fn measured_gaps(caps: &[CaptureRow]) -> BTreeMap<i32, f64> {
    let mut by: BTreeMap<i32, (Vec<f64>, Vec<f64>)> = BTreeMap::new();
    for c in caps {
        let e = by.entry(c.fabric).or_default();
        match c.face {
            Face::Up => e.0.push(c.dc_measured_pct),
            Face::Down => e.1.push(c.dc_measured_pct),
            Face::Unknown => {}
        }
    }
    by.into_iter()
        .filter_map(|(f, (u, d))| Some((f, mean(&d)? - mean(&u)?)))
        .collect()
}

/// The curl table: per fabric, the calibration specimen's face gap beside its other specimens',
/// the fitted curl with its 2σ interval, the gap's slope and the predicted DC of each face.
fn curl_table(rows: &[PredictionRow], caps: &[CaptureRow]) -> String {
    let others = measured_gaps(caps);
    let mut s = String::from(
        "| fabric | calibration face gap, down − up (points) | the other specimens' face gap (points) | curl κ (1/m) | κ, 2σ interval (1/m) | side identifiable | gap slope dΔ/dκ (points·m) | gap line a + bΔ (points) | gap predicted (points) | curl predicted (1/m) | DC predicted face up (%) | DC predicted face down (%) |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let interval = match (r.curl_lo_per_m, r.curl_hi_per_m) {
            (Some(a), Some(b)) => format!("[{a:.1}, {b:.1}]"),
            _ => "–".into(),
        };
        let line = match (r.gap_line_intercept_pct, r.gap_line_slope) {
            (Some(a), Some(b)) => format!("{a:.1} + {b:.2}Δ"),
            _ => "–".into(),
        };
        s += &format!(
            "| {} | {} | {} | {} | {} | {} | {} | {line} | {} | {} | {} | {} |\n",
            r.fabric,
            opt(r.calibration_face_gap_pct, 1),
            opt(others.get(&r.fabric).copied(), 1),
            opt(r.curl_per_m, 1),
            interval,
            r.curl_identifiable
                .map_or("–", |b| if b { "yes" } else { "no" }),
            opt(r.face_gap_slope_pct_m, 3),
            opt(r.face_gap_model_pct, 1),
            opt(r.curl_predicted_per_m, 1),
            opt(r.dc_predicted_face_up_pct, 1),
            opt(r.dc_predicted_face_down_pct, 1),
        );
    }
    s
}

/// Mean absolute DC error of `predict` over the captures of `face` (any face: None) where it gives
/// a value: (MAE, captures scored).
fn mae(
    caps: &[CaptureRow],
    face: Option<Face>,
    predict: impl Fn(&CaptureRow) -> Option<f64>,
) -> (Option<f64>, usize) {
    let errors: Vec<f64> = caps
        .iter()
        .filter(|c| face.is_none_or(|f| c.face == f))
        .filter_map(|c| Some((predict(c)? - c.dc_measured_pct).abs()))
        .filter(|e| e.is_finite())
        .collect();
    (mean(&errors), errors.len())
}

/// A prediction of a capture's DC, % (None where it gives none).
type Predictor = Box<dyn Fn(&CaptureRow) -> Option<f64>>;

/// The model's variants and the baselines scored per capture, by name.
fn predictors(rows: &[PredictionRow]) -> Vec<(&'static str, Predictor)> {
    let own_gap: BTreeMap<i32, f64> = rows
        .iter()
        .filter_map(|r| Some((r.fabric, r.calibration_face_gap_pct?)))
        .collect();
    let curled: BTreeMap<i32, bool> = rows
        .iter()
        .map(|r| (r.fabric, r.face_gap_model_pct.is_some()))
        .collect();
    vec![
        (
            "model (its face: the faces' mean ± half the predicted gap)",
            Box::new(|c| Some(c.dc_predicted_pct)),
        ),
        (
            "model, its face's own drapes (the mean of six seeds)",
            Box::new(|c| Some(c.dc_face_drapes_pct)),
        ),
        (
            "model without the gap line (± half the calibration specimen's own gap)",
            Box::new(move |c| {
                let gap = match (curled.get(&c.fabric), own_gap.get(&c.fabric)) {
                    (Some(true), Some(g)) => *g,
                    _ => 0.0,
                };
                Some(c.dc_face_average_pct + 0.5 * gap * c.face.gap_sign())
            }),
        ),
        (
            "model, face-blind (both faces' seeds)",
            Box::new(|c| Some(c.dc_face_average_pct)),
        ),
        (
            "calibration specimen's mean carried over",
            Box::new(|c| Some(c.dc_carry_over_pct)),
        ),
        (
            "calibration specimen's face-matched mean carried over",
            Box::new(|c| c.dc_carry_over_face_pct),
        ),
        (
            "the other specimens' mean (not this one, not the calibration one)",
            Box::new(|c| c.dc_other_specimens_pct),
        ),
        (
            "the other specimens' face-matched mean",
            Box::new(|c| c.dc_other_specimens_face_pct),
        ),
    ]
}

/// The per-capture scores: DC mean absolute error of the model and the baselines, overall and per
/// face, the intervals' coverage, nodes within 1.
fn score_table(caps: &[CaptureRow], rows: &[PredictionRow]) -> String {
    let predictors = predictors(rows);
    let mut s = String::from(
        "| prediction per capture | DC mean abs. error, all (points) | face up | face down | captures |\n|---|---|---|---|---|\n",
    );
    for (name, p) in &predictors {
        let (all, n) = mae(caps, None, p);
        let (up, _) = mae(caps, Some(Face::Up), p);
        let (down, _) = mae(caps, Some(Face::Down), p);
        s += &format!(
            "| {name} | {} | {} | {} | {n} |\n",
            opt(all, 2),
            opt(up, 2),
            opt(down, 2)
        );
    }
    let covered = caps
        .iter()
        .filter(|c| c.dc_low_pct <= c.dc_measured_pct && c.dc_measured_pct <= c.dc_high_pct)
        .count();
    let calib_nodes: BTreeMap<i32, f64> = rows
        .iter()
        .map(|r| (r.fabric, r.nodes_calibration_median))
        .collect();
    let within = |pred: &dyn Fn(&CaptureRow) -> Option<f64>| {
        let scored: Vec<bool> = caps
            .iter()
            .filter_map(|c| Some((pred(c)? - c.nodes_measured as f64).abs() <= 1.0))
            .collect();
        (scored.iter().filter(|b| **b).count(), scored.len())
    };
    let (model_in, n) = within(&|c| Some(c.nodes_model_mean));
    let (mode_in, _) = within(&|c| Some(c.nodes_model_mode as f64));
    let (carry_in, _) = within(&|c| calib_nodes.get(&c.fabric).copied());
    let both_mode: BTreeMap<i32, f64> = rows
        .iter()
        .filter_map(|r| Some((r.fabric, r.nodes_predicted_mode? as f64)))
        .collect();
    let (both_in, _) = within(&|c| both_mode.get(&c.fabric).copied());
    let (line_in, _) = within(&|c| Some(c.nodes_predicted_mode as f64));
    let slopes: Vec<f64> = rows.iter().filter_map(|r| r.nodes_line_slope).collect();
    let (lo, hi) = slopes
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |a, &b| {
            (a.0.min(b), a.1.max(b))
        });
    let pct = |k: usize| 100.0 * k as f64 / n.max(1) as f64;
    s += &format!(
        "\nThe 90 % intervals (each from the other fabrics' residuals only) cover {covered} of {} captures ({:.0} %).\n\nNodes within 1 of the capture's own count (`nodes_predicted_mode`, the prediction: **{line_in} of {n} ({:.0} %)**) — the model's face mean plus the node line's correction, rounded: the line (`core::cusick::node_lines`, fitted on the other fabrics only) gives the other specimens the share {} of the calibration specimen's discrepancy, its median count less the model's mean. Uncorrected, the model's mean for the capture's face scores {model_in} ({:.0} %), its mode {mode_in} ({:.0} %), the mode of both faces' drapes (twelve seeds; the two faces' node means differ by 0.3 on average here, within their six seeds' noise) {both_in} ({:.0} %); the calibration specimen's median carried over {carry_in} ({:.0} %). A mean within 1 of a whole count covers two counts, a whole number three: the prediction is scored as the whole number.\n",
        caps.len(),
        pct(covered),
        pct(line_in),
        if slopes.is_empty() {
            "1 (too few fabrics for a line)".to_string()
        } else {
            format!("{lo:.2}–{hi:.2}")
        },
        pct(model_in),
        pct(mode_in),
        pct(both_in),
        pct(carry_in),
    );
    s
}

/// The harder test: each predicted specimen's face-down captures from its face-up captures only —
/// carried over, shifted by the population's mean face gap (the other fabrics' specimens), and
/// shifted by the model's gap for this fabric at the other fabrics' mean curl (linearised:
/// slope × κ̄). Returns the table and its text.
fn face_down_from_face_up(caps: &[CaptureRow], rows: &[PredictionRow]) -> String {
    // Each specimen's face means.
    let mut faces: BTreeMap<(i32, i32), (Vec<f64>, Vec<f64>)> = BTreeMap::new();
    for c in caps {
        let e = faces.entry((c.fabric, c.sample)).or_default();
        match c.face {
            Face::Up => e.0.push(c.dc_measured_pct),
            Face::Down => e.1.push(c.dc_measured_pct),
            Face::Unknown => {}
        }
    }
    let up_mean: BTreeMap<(i32, i32), f64> = faces
        .iter()
        .filter_map(|(k, v)| Some((*k, mean(&v.0)?)))
        .collect();
    let gaps: Vec<(i32, f64)> = faces
        .iter()
        .filter_map(|(k, v)| Some((k.0, mean(&v.1)? - mean(&v.0)?)))
        .collect();
    let curls: Vec<(i32, f64)> = rows
        .iter()
        .filter_map(|r| Some((r.fabric, r.curl_per_m?)))
        .collect();
    let slope: BTreeMap<i32, f64> = rows
        .iter()
        .filter_map(|r| Some((r.fabric, r.face_gap_slope_pct_m?)))
        .collect();
    let others = |v: &[(i32, f64)], f: i32| {
        mean(
            &v.iter()
                .filter(|x| x.0 != f)
                .map(|x| x.1)
                .collect::<Vec<_>>(),
        )
    };
    let median_of_others = |v: &[(i32, f64)], f: i32| {
        let mut o: Vec<f64> = v.iter().filter(|x| x.0 != f).map(|x| x.1).collect();
        o.sort_by(f64::total_cmp);
        (!o.is_empty()).then(|| 0.5 * (o[(o.len() - 1) / 2] + o[o.len() / 2]))
    };
    let (mut carry, mut population, mut model, mut robust) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for c in caps.iter().filter(|c| c.face == Face::Down) {
        let Some(up) = up_mean.get(&(c.fabric, c.sample)) else {
            continue;
        };
        carry.push((up - c.dc_measured_pct).abs());
        if let Some(g) = others(&gaps, c.fabric) {
            population.push((up + g - c.dc_measured_pct).abs());
        }
        if let (Some(k), Some(s)) = (others(&curls, c.fabric), slope.get(&c.fabric)) {
            model.push((up + s * k - c.dc_measured_pct).abs());
        }
        if let (Some(k), Some(s)) = (median_of_others(&curls, c.fabric), slope.get(&c.fabric)) {
            robust.push((up + s * k - c.dc_measured_pct).abs());
        }
    }
    format!(
        "| face-down DC from the same specimen's face-up captures | mean abs. error (points) | face-down captures |\n|---|---|---|\n| the face-up mean carried over | {} | {} |\n| shifted by the other fabrics' mean face gap (population) | {} | {} |\n| shifted by the model's gap at the other fabrics' mean curl (slope × κ̄, linearised) | {} | {} |\n| the same at their median curl (a curl stopped at its bound counts once) | {} | {} |\n",
        opt(mean(&carry), 2),
        carry.len(),
        opt(mean(&population), 2),
        population.len(),
        opt(mean(&model), 2),
        model.len(),
        opt(mean(&robust), 2),
        robust.len(),
    )
}

/// The section.
pub fn faces_section(rows: &[PredictionRow], caps: &[CaptureRow]) -> String {
    let mut s = String::from(
        "\n## Both faces of every capture\n\nISO 9073-9 and BS 5058 drape every specimen face up and face down (captures 1–2 up, 3–4 down), and the faces differ with a sign that is the fabric's own. The model gives the fabric a natural curl κ (the curvature a free strip rolls up to toward the fabric's face; `physics::hinge_curl`, the linear term −Bκ∫2H dA of a spontaneous curvature), positive lifting the rim face up and lowering it face down. κ is fitted to the calibration specimen's face gap Δ = DC_down − DC_up after c (the faces' mean DC is the curl-free DC to second order in κ): the gap's slope comes from the seed-0 drape's sensitivity dx/dκ, then the faces at ±κ are solved and κ corrected by a secant until the solved gap is within 0.3 points. Its 2σ interval is the gap's standard error (pooled over repeated captures of a face) over the slope; the side is identifiable where the interval excludes zero. One specimen's gap is a noisy reading of its fabric's (the calibration specimens' gaps and their siblings' correlate at about 0.4 here), so the other specimens are predicted at a shrunk gap: the least-squares line of the other specimens' gap on the calibration specimen's gap, fitted on the *other* fabrics only (leave one fabric out; slope kept in [0, 1]) — empirical Bayes, the slope the share of one specimen's gap that is its fabric's. The predicted curl moves the fitted one along its gap slope to that gap, and the prediction's drapes (six seeds per face) lie at ± it. Each capture's DC is the mean of both faces' drapes shifted by half the model's gap at that curl (the difference of the faces' seed means would add their seeds' spread to the gap); its nodes are its face's drapes' mean plus the fabric's node correction (below). The 90 % interval is made of the other fabrics' residuals only (leave one fabric out).\n\n",
    );
    s += &curl_table(rows, caps);
    s += "\n### Every predicted capture, per face\n\nThe baselines beside the model: the calibration specimen's mean (both faces) and its face-matched mean carried over, and — using data of the predicted fabric's other specimens, which the model never sees — their mean and face-matched mean.\n\n";
    s += &score_table(caps, rows);
    s += "\n### The harder test: face down from face up only\n\nEach predicted specimen's face-down captures from its own face-up captures only, against carrying the face-up mean over and against the population's mean face effect (the other fabrics' specimens). The model's version shifts the face-up mean by the gap its drapes give at the other fabrics' mean curl, slope × κ̄ — linearised, with the slope taken at c as fitted on both faces of the calibration specimen (a fit on face-up captures alone would move c by the O(κ²) that the faces' mean differs from the curl-free DC).\n\n";
    s += &face_down_from_face_up(caps, rows);
    s
}
