//! The Cusick report's opening (issue 78): the model against the simplest baseline — the
//! calibration specimen's own measurement carried over to the fabric's other specimens — by every
//! criterion the report scores, and where that baseline does as well, said first.

use drapelab_app::cusick::captures::CaptureRow;
use drapelab_app::cusick::tables::PredictionRow;
use std::collections::BTreeMap;

/// One criterion: its name, the model's score and the baseline's, and whether larger is better.
struct Score {
    name: &'static str,
    model: f64,
    baseline: f64,
    unit: &'static str,
    higher_is_better: bool,
}

impl Score {
    /// Whether the baseline scores as well as the model or better.
    fn baseline_holds(&self) -> bool {
        match self.higher_is_better {
            true => self.baseline >= self.model,
            false => self.baseline <= self.model,
        }
    }
}

/// The per-fabric scores: DC within the band, nodes within 1 of the measured median.
fn per_fabric(rows: &[PredictionRow]) -> Vec<Score> {
    let count = |f: &dyn Fn(&PredictionRow) -> bool| rows.iter().filter(|r| f(r)).count() as f64;
    let band = |r: &PredictionRow| (2.0 * r.dc_measured_sd_pct).max(4.0);
    vec![
        Score {
            name: "fabrics with DC within the measured mean ± max(2 SD, 4 points)",
            model: count(&|r| dc_within(r) == Some(true)),
            baseline: count(&|r| (r.dc_calibration_pct - r.dc_measured_mean_pct).abs() <= band(r)),
            unit: "of fabrics",
            higher_is_better: true,
        },
        Score {
            name: "fabrics with nodes within 1 of the measured median",
            model: count(&|r| nodes_within(r) == Some(true)),
            baseline: count(&|r| nodes_near(r, r.nodes_calibration_median)),
            unit: "of fabrics",
            higher_is_better: true,
        },
    ]
}

/// The per-capture scores: DC mean absolute error against the face-matched carry-over, nodes
/// within 1 of the capture's own count (`nodes_predicted_mode`) against the median carried over.
fn per_capture(rows: &[PredictionRow], caps: &[CaptureRow]) -> Vec<Score> {
    let pairs: Vec<(f64, f64)> = caps
        .iter()
        .filter_map(|c| {
            Some((
                c.dc_predicted_pct,
                c.dc_carry_over_face_pct?,
                c.dc_measured_pct,
            ))
        })
        .map(|(m, b, y)| ((m - y).abs(), (b - y).abs()))
        .collect();
    let n = pairs.len().max(1) as f64;
    let median: BTreeMap<i32, f64> = rows
        .iter()
        .map(|r| (r.fabric, r.nodes_calibration_median))
        .collect();
    let within = |pred: &dyn Fn(&CaptureRow) -> Option<f64>| {
        let hits = caps
            .iter()
            .filter(|c| pred(c).is_some_and(|p| (p - c.nodes_measured as f64).abs() <= 1.0))
            .count();
        hits as f64
    };
    vec![
        Score {
            name: "captures' DC, mean absolute error (the baseline: the face-matched mean)",
            model: pairs.iter().map(|p| p.0).sum::<f64>() / n,
            baseline: pairs.iter().map(|p| p.1).sum::<f64>() / n,
            unit: "points",
            higher_is_better: false,
        },
        Score {
            name: "captures with nodes within 1 of their own count",
            model: within(&|c| Some(c.nodes_predicted_mode as f64)),
            baseline: within(&|c| median.get(&c.fabric).copied()),
            unit: "of captures",
            higher_is_better: true,
        },
    ]
}

/// The opening section: a table of the model against the baseline and a sentence naming where the
/// baseline does as well.
pub fn headline(rows: &[PredictionRow], caps: &[CaptureRow]) -> String {
    let scores: Vec<Score> = per_fabric(rows)
        .into_iter()
        .chain(per_capture(rows, caps))
        .collect();
    let mut s = String::from(
        "## The model against the simplest baseline\n\nThe simplest prediction of a fabric's other specimens is its calibration specimen's own measurement carried over (for a capture, that specimen's mean on the same face). Scored by every criterion below:\n\n| criterion | model | calibration specimen carried over | unit |\n|---|---:|---:|---|\n",
    );
    let total = |c: &Score| match c.unit {
        "of fabrics" => format!("of {}", rows.len()),
        "of captures" => format!("of {}", caps.len()),
        u => u.to_string(),
    };
    for c in &scores {
        let digits = if c.unit == "points" { 2 } else { 0 };
        s += &format!(
            "| {} | {:.*} | {:.*} | {} |\n",
            c.name,
            digits,
            c.model,
            digits,
            c.baseline,
            total(c)
        );
    }
    let holds: Vec<&str> = scores
        .iter()
        .filter(|c| c.baseline_holds())
        .map(|c| c.name)
        .collect();
    s += &match holds.len() {
        0 => "\nThe model beats the baseline by every criterion.\n".to_string(),
        k if k == scores.len() => "\n**The baseline does as well as the model or better by every criterion**: on these fabrics the simulation adds no predictive skill over carrying the calibration specimen's measurement over; what it adds is the fabric's parameters (a fabric file for other scenes) and the drapes' shapes.\n".to_string(),
        _ => format!(
            "\n**The baseline does as well as the model or better on: {}.** The model does better on the rest.\n",
            holds.join("; ")
        ),
    };
    s
}

/// Whether the predicted DC lies within the measured mean ± max(2 SD, 4 points).
pub fn dc_within(r: &PredictionRow) -> Option<bool> {
    let band = (2.0 * r.dc_measured_sd_pct).max(4.0);
    r.dc_predicted_pct
        .map(|p| (p - r.dc_measured_mean_pct).abs() <= band)
}

/// Whether a node count `n` lies within 1 of the fabric's measured median.
pub fn nodes_near(r: &PredictionRow, n: f64) -> bool {
    (n - r.nodes_measured_median).abs() <= 1.0
}

/// Whether the predicted mean node count lies within 1 of the measured median.
pub fn nodes_within(r: &PredictionRow) -> Option<bool> {
    r.nodes_predicted.map(|n| nodes_near(r, n))
}
