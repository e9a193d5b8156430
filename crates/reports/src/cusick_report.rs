//! `cusick-report` (issue 16): the predictions of every fabric against its measurements, as Markdown,
//! with the criteria counted (DC within the measured mean ± max(2 SD, 4 points), nodes within
//! 1 of the measured median), the misses explained, the shadows and height profiles as pictures, and
//! the run time per drape solve.

use crate::cusick_faces::faces_section;
use crate::cusick_plots::{profiles_svg, shadows_svg};
pub use crate::format::opt;
use anyhow::Result;
use drapelab_app::Job;
use drapelab_app::cusick::captures::CaptureRow;
use drapelab_app::cusick::tables::{OutlineRow, PredictionRow, ProfileRow};
use drapelab_core::cusick::Tester;
use drapelab_record::{read_table, write_text};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Parameters of a cusick-report stage (none yet).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CusickReportParams {}

pub use crate::cusick_headline::{dc_within, nodes_near, nodes_within};

/// "yes", "no" or "–".
pub fn yes(b: Option<bool>) -> &'static str {
    b.map_or("–", |b| if b { "yes" } else { "no" })
}

/// The head of the Cusick report.
pub const INTRO: &str = "# Real fabrics on a Cusick drape tester\n\nWritten by `drapelab run pipelines/cusick.toml` (stage `report`). Data: the Cusick drape dataset of Gong, Mao & Wang, \"Bayesian Differentiable Physics for Cloth Digitalization\", CVPR 2024 (fabrics 1–15 in `datasets/cusick/`: specimens 1–4 of fabrics 1–10, both specimens of 11–15). The model: a disc on the dataset's own template mesh (2699 vertices), stiff edge springs, orthotropic hinge bending (Bergou et al. 2006; a sheet rolled at φ from the warp has rigidity B_warp cos²φ + B_weft sin²φ) with geometric-mean rigidity B = w g c³ and anisotropy ρ = B_warp/B_weft, optionally saturating (a hinge of curvature κ stores B κ₀² (√(1 + κ²/κ₀²) − 1) per area: ½ B κ² below κ₀, a moment levelling off at B κ₀ above, as inter-fibre friction makes it in fabric), gravity, the pedestal's vertices held. The folds come from lowering the specimen into a 60° cone with a seeded smooth perturbation of the material angle (16 angular modes, 2 mm RMS: the same field on every mesh, so the fold count converges with the mesh). Per fabric, what the lowest-numbered specimen's photos show is fitted: its mean DC sets c (a secant on ln c over the seed-0 drape, each step within 10 % continued from the last drape along its tangent dx/dc, the first law from the bracket's middle and each further law from the last one's c), its median node count chooses the bending law among five (linear with ρ = 1, 2, 4; isotropic with a moment that levels off beyond κ₀ = 2/c or 1/c): the law whose drapes' mean node count over six seeds lies nearest the target. Drapes at the fitted (c, ρ) from other seeds are then the prediction for the other specimens: DC mean ± SD, the node count's distribution, and the RMS of the azimuthally averaged height profile z(r) against the registered meshes. B is given where the areal density w is known; elsewhere only c is (absolute rigidity needs the weight).\n\n";

/// The main table: one row per fabric, DC and nodes predicted against measured.
pub fn main_table(rows: &[PredictionRow]) -> String {
    let mut s = String::from(
        "| fabric | calibrated on | bending length c (mm) | c, 2σ interval (mm) | law | laws within 1 node | B (µN·m) | DC target (%) | DC predicted (%) | DC measured (%) | DC ok | nodes target | nodes predicted: mean, mode, histogram | nodes measured | nodes ok | profile RMS (mm) | status |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let interval = match (r.bending_length_lo_m, r.bending_length_hi_m) {
            (Some(lo), Some(hi)) => format!("[{:.1}, {:.1}]", 1e3 * lo, 1e3 * hi),
            _ => "–".into(),
        };
        let law = match (r.bending_ratio_warp_over_weft, r.bending_length_mean_m) {
            (Some(rho), Some(c)) => match r.bending_saturation_curvature_per_m {
                Some(k) => format!("ρ={rho},κ₀c={:.0}", k * c),
                None => format!("ρ={rho}"),
            },
            _ => "–".into(),
        };
        let within = format!(
            "{}{}",
            r.laws_within_one_node,
            if r.law_identifiable == Some(false) {
                " (not identifiable)"
            } else {
                ""
            }
        );
        s += &format!(
            "| {} | {} | {} | {} | {} | {} | {} | {:.1} | {} ± {} | {:.1} ± {:.1} | {} | {:.1} | {}, {}, {} | {:.1} | {} | {} | {} |\n",
            r.fabric,
            r.calibration_sample,
            opt(r.bending_length_mean_m.map(|c| 1e3 * c), 1),
            interval,
            law,
            within,
            opt(r.bending_rigidity_N_m.map(|b| 1e6 * b), 1),
            r.dc_calibration_pct,
            opt(r.dc_predicted_pct, 1),
            opt(r.dc_predicted_sd_pct, 1),
            r.dc_measured_mean_pct,
            r.dc_measured_sd_pct,
            yes(dc_within(r)),
            r.nodes_calibration_median,
            opt(r.nodes_predicted, 2),
            r.nodes_predicted_mode.map_or("–".into(), |m| m.to_string()),
            r.nodes_predicted_histogram,
            r.nodes_measured_median,
            yes(nodes_within(r)),
            opt(r.profile_rms_mm, 1),
            r.status
        );
    }
    s
}

/// The least-squares line through `pts` (x, y) evaluated at `x` (the mean of y where the x do not
/// spread).
pub fn line_at(pts: &[(f64, f64)], x: f64) -> f64 {
    let ([mx, my], slope) = drapelab_core::measure::least_squares_line(pts);
    slope.map_or(my, |b| my + b * (x - mx))
}

/// Predictions of the baselines for fabric `i`, each fitted on the other fabrics (leave one fabric
/// out): (constant nodes, line nodes(DC of the calibration specimen), constant DC, line DC(DC of
/// the calibration specimen)).
pub fn baseline_predictions(rows: &[PredictionRow], i: usize) -> [f64; 4] {
    let others: Vec<&PredictionRow> = rows
        .iter()
        .enumerate()
        .filter(|(k, _)| *k != i)
        .map(|(_, r)| r)
        .collect();
    let nodes: Vec<(f64, f64)> = others
        .iter()
        .map(|r| (r.dc_calibration_pct, r.nodes_measured_median))
        .collect();
    let dc: Vec<(f64, f64)> = others
        .iter()
        .map(|r| (r.dc_calibration_pct, r.dc_measured_mean_pct))
        .collect();
    let x = rows[i].dc_calibration_pct;
    [
        line_at(&nodes.iter().map(|p| (0.0, p.1)).collect::<Vec<_>>(), 0.0),
        line_at(&nodes, x),
        line_at(&dc.iter().map(|p| (0.0, p.1)).collect::<Vec<_>>(), 0.0),
        line_at(&dc, x),
    ]
}

/// The model against the baselines, fabric by fabric and counted by the criteria.
pub fn baselines_table(rows: &[PredictionRow]) -> String {
    let mut s = String::from(
        "| fabric | nodes measured | model | model + node line | constant | line nodes(DC) | calibration specimen's own | DC measured (%) | model | constant | line DC(DC) | calibration specimen's own |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    let nodes_ok = nodes_near;
    let dc_ok = |r: &PredictionRow, d: f64| {
        (d - r.dc_measured_mean_pct).abs() <= (2.0 * r.dc_measured_sd_pct).max(4.0)
    };
    let mark = |ok: bool| if ok { "" } else { " ✗" };
    let mut counts = [0usize; 9];
    for (i, r) in rows.iter().enumerate() {
        let [nc, nl, dcc, dcl] = baseline_predictions(rows, i);
        let model_n = r.nodes_predicted.unwrap_or(f64::NAN);
        let model_dc = r.dc_predicted_pct.unwrap_or(f64::NAN);
        let corrected = r.nodes_predicted_corrected.unwrap_or(f64::NAN);
        let n_ok = [
            nodes_ok(r, model_n),
            nodes_ok(r, corrected),
            nodes_ok(r, nc),
            nodes_ok(r, nl),
            nodes_ok(r, r.nodes_calibration_median),
        ];
        let d_ok = [
            dc_ok(r, model_dc),
            dc_ok(r, dcc),
            dc_ok(r, dcl),
            dc_ok(r, r.dc_calibration_pct),
        ];
        for (k, ok) in n_ok.iter().chain(&d_ok).enumerate() {
            counts[k] += usize::from(*ok);
        }
        s += &format!(
            "| {} | {:.1} | {model_n:.2}{} | {corrected:.2}{} | {nc:.2}{} | {nl:.2}{} | {:.1}{} | {:.1} | {model_dc:.1}{} | {dcc:.1}{} | {dcl:.1}{} | {:.1}{} |\n",
            r.fabric,
            r.nodes_measured_median,
            mark(n_ok[0]),
            mark(n_ok[1]),
            mark(n_ok[2]),
            mark(n_ok[3]),
            r.nodes_calibration_median,
            mark(n_ok[4]),
            r.dc_measured_mean_pct,
            mark(d_ok[0]),
            mark(d_ok[1]),
            mark(d_ok[2]),
            r.dc_calibration_pct,
            mark(d_ok[3]),
        );
    }
    let n = rows.len();
    s += &format!(
        "| within the band | | {} of {n} | {} of {n} | {} of {n} | {} of {n} | {} of {n} | | {} of {n} | {} of {n} | {} of {n} | {} of {n} |\n",
        counts[0],
        counts[1],
        counts[2],
        counts[3],
        counts[4],
        counts[5],
        counts[6],
        counts[7],
        counts[8]
    );
    s += "\n\"Model + node line\": the model's mean count plus the share of the calibration specimen's discrepancy (its median less the model's mean) that the other fabrics' specimens carry (`nodes_line_slope`; `core::cusick::node_lines`): with a slope near 1 this is close to carrying the calibration specimen's count over, and says that the model's fold count adds little to it.\n";
    s
}

/// One line per fabric the model misses, with the numbers that say why.
pub fn misses(rows: &[PredictionRow]) -> String {
    let mut s = String::new();
    for r in rows {
        let band = (2.0 * r.dc_measured_sd_pct).max(4.0);
        let offset = r.dc_calibration_pct - r.dc_measured_mean_pct;
        if r.dc_predicted_pct.is_none() {
            s += &format!("- Fabric {}: no prediction ({}).\n", r.fabric, r.status);
            continue;
        }
        if dc_within(r) == Some(false) {
            let why = if offset.abs() > 0.5 * band {
                format!(
                    "its calibration specimen drapes at {:.1} %, {:+.1} points from the other specimens' mean, and the model reproduces that specimen ({}): the miss is specimen-to-specimen variation, which a calibration on one specimen cannot know",
                    r.dc_calibration_pct,
                    offset,
                    opt(r.dc_predicted_pct, 1)
                )
            } else {
                format!(
                    "the model's DC at the calibrated c ({}) is off its own target {:.1} %",
                    opt(r.dc_predicted_pct, 1),
                    r.dc_calibration_pct
                )
            };
            s += &format!(
                "- Fabric {}: DC predicted {} % against {:.1} ± {:.1} % measured (band ± {band:.1}): {why}.\n",
                r.fabric,
                opt(r.dc_predicted_pct, 1),
                r.dc_measured_mean_pct,
                r.dc_measured_sd_pct
            );
        }
        if nodes_within(r) == Some(false) {
            s += &format!(
                "- Fabric {}: {} nodes predicted (mean over the perturbations) against a median of {:.0} measured: the model's folds are {} than the fabric's at the same DC.\n",
                r.fabric,
                opt(r.nodes_predicted, 2),
                r.nodes_measured_median,
                if r.nodes_predicted.unwrap_or(0.0) > r.nodes_measured_median {
                    "more and narrower"
                } else {
                    "fewer and wider"
                }
            );
        }
    }
    if s.is_empty() {
        s = "- No fabric misses its bands. Weakest points:\n".into();
    }
    s + &weakest(rows)
}

/// Lines on the predictions that hold but are weakest: DC more than 2.5 points off the measured
/// mean, or a height profile off by more than 3 mm RMS.
pub fn weakest(rows: &[PredictionRow]) -> String {
    let mut s = String::new();
    for r in rows {
        let (Some(p), true) = (r.dc_predicted_pct, dc_within(r) == Some(true)) else {
            continue;
        };
        let offset = r.dc_calibration_pct - r.dc_measured_mean_pct;
        if (p - r.dc_measured_mean_pct).abs() > 2.5 {
            s += &format!(
                "- Fabric {}: DC {p:.1} % against {:.1} ± {:.1} % measured; its calibration specimen lies {offset:+.1} points from the others.\n",
                r.fabric, r.dc_measured_mean_pct, r.dc_measured_sd_pct
            );
        }
        if r.profile_rms_mm.is_some_and(|e| e > 3.0) {
            s += &format!(
                "- Fabric {}: the height profile misses the registered meshes by {} mm RMS (profile plot below), with the specimens' DC spreading {:.1} points.\n",
                r.fabric,
                opt(r.profile_rms_mm, 1),
                r.dc_measured_sd_pct
            );
        }
    }
    s
}

/// The specimens' own spread against the model's spread over perturbations.
pub fn spread_table(rows: &[PredictionRow]) -> String {
    let mut s = String::from(
        "| fabric | specimens' DC SD (%) | model's DC SD over seeds (%) | share of the specimens' variance the perturbations reproduce | calibration specimen − others (points) | specimens' nodes (captures) | model's nodes (seeds) | nodes SD: specimens, model | two-fold outline amplitude (mm): calibration photos, model | warp from the photos (°) |\n|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let share = r
            .dc_predicted_sd_pct
            .map(|m| (m / r.dc_measured_sd_pct.max(1e-9)).powi(2).min(1.0) * 100.0);
        s += &format!(
            "| {} | {:.1} | {} | {} % | {:+.1} | {} | {} | {:.2}, {} | {}, {} | {} |\n",
            r.fabric,
            r.dc_measured_sd_pct,
            opt(r.dc_predicted_sd_pct, 1),
            opt(share, 0),
            r.dc_calibration_pct - r.dc_measured_mean_pct,
            r.nodes_measured_histogram,
            r.nodes_predicted_histogram,
            r.nodes_measured_sd,
            opt(r.nodes_predicted_sd, 2),
            opt(r.outline_two_fold_measured_m.map(|a| 1e3 * a), 1),
            opt(r.outline_two_fold_predicted_m.map(|a| 1e3 * a), 1),
            opt(r.warp_direction_deg, 0)
        );
    }
    s
}

/// The timing table: each fabric's calibration and prediction time.
pub fn timing_table(rows: &[PredictionRow]) -> String {
    let mut s = String::from(
        "| fabric | drape solves | mean time per solve (s) | fabric wall time (s) |\n|---|---|---|---|\n",
    );
    for r in rows {
        s += &format!(
            "| {} | {} | {:.2} | {:.0} |\n",
            r.fabric, r.solves, r.solve_time_mean_s, r.wall_time_s
        );
    }
    let (n, t): (i32, f64) = rows
        .iter()
        .fold((0, 0.0), |a, r| (a.0 + r.solves, a.1 + r.wall_time_s));
    s += &format!(
        "\n{n} drape solves, {t:.0} s of fabric wall time in all (the fabrics run in parallel, one per core); {:.2} s per solve on average.\n",
        t / f64::from(n.max(1))
    );
    s
}

/// The report's Markdown; `shadows_svg` and `profiles_svg` are the pictures' paths relative to it.
pub fn report_markdown(
    rows: &[PredictionRow],
    captures: &[CaptureRow],
    shadows_svg: &str,
    profiles_svg: &str,
) -> String {
    let count = |f: &dyn Fn(&PredictionRow) -> Option<bool>| {
        rows.iter().filter(|r| f(r) == Some(true)).count()
    };
    let widths: Vec<f64> = rows
        .iter()
        .filter_map(|r| Some(50.0 * (r.bending_length_hi_m? / r.bending_length_lo_m?).ln()))
        .collect();
    let (wmin, wmax) = widths
        .iter()
        .fold((f64::INFINITY, 0.0f64), |a, &w| (a.0.min(w), a.1.max(w)));
    let mut s = String::from(INTRO);
    s += &crate::cusick_headline::headline(rows, captures);
    s += "\n## Every fabric\n\n";
    s += &main_table(rows);
    s += &format!(
        "\nDC within the measured mean ± max(2 SD, 4 points): {} of {} fabrics. Nodes within 1 of the measured median: {} of {} (the model's mean), {} of {} with the node line's correction (`nodes_predicted_corrected`, below).\n",
        count(&dc_within),
        rows.len(),
        count(&nodes_within),
        rows.len(),
        count(&|r| r.nodes_predicted_corrected.map(|n| nodes_near(r, n))),
        rows.len()
    );
    s += "\n## Against baselines (leave one fabric out)\n\nWhat a prediction without the simulation would score, each baseline fitted on the other fabrics only: a constant (their mean), a straight line against the calibration specimen's DC (fitted on their calibration specimens), and — the strongest — the calibration specimen's own measured value carried over to the other specimens. Nodes within 1 of the measured median, DC within the measured mean ± max(2 SD, 4 points) (✗ marks a miss). No fabric's data enters another fabric's prediction. The model's choices that hold for every fabric (the cone start, the template mesh, 16 perturbation modes of 2 mm, the five bending laws, six seeds per law) are the same for all; how they were chosen among the configurations tried on the bundled fabrics, with the leave-one-fabric-out score of that choice, is in the README (\"Cusick: what sets the fold count\").\n\n";
    s += &baselines_table(rows);
    s += "\n## Where the model misses\n\n";
    s += &misses(rows);
    s += &faces_section(rows, captures);
    s += &format!(
        "\n## What the data pin down\n\nTwo numbers per fabric are fitted: the calibration specimen's mean DC and its median node count. The DC pins the bending length c: its 2σ interval comes from the uncertainty of that DC (the SD of the specimen's photos over √n, and the model's seed-to-seed SD) divided by the sensitivity dDC/d ln c of the simulated drapes near c: ± {wmin:.0}–{wmax:.0} % of c here. The node count chooses the bending law; \"laws within 1 node\" lists every law whose drapes' mean node count lies within one node of the target, and the law is marked not identifiable where the laws' mean node counts span no more than one node. Anisotropy moves the fold count only on stiff fabrics (at DC ≈ 80 %, ρ = 4 gives ~4.5 nodes against ~6 isotropic; at DC ≈ 55 % it moves it by < 0.5); saturation moves it at every DC (at DC ≈ 58 %: 8.0 nodes linear, 7.1 with κ₀c = 2, 6.6 with κ₀c = 1, eight seeds each). The direction of the warp does not enter the predicted DC or node count (the specimens lie on the tester at unknown orientations), so it is not fitted. The other specimens' DC, node counts and height profiles are not fitted; they test the model.\n\n## The specimens' own spread\n\nThe specimens of one fabric differ by more than the model's perturbations move its DC: the model, given one (c, law), explains the specimens' mean DC, not their spread. Their node counts are another matter: the node histograms of the other specimens' captures and of the model's prediction seeds stand side by side here, with their SDs. The outline's two-fold component (r(θ) ≈ r̄ + a₂ cos 2(θ − θ₂)) is what an anisotropy shows: its amplitude in the calibration specimen's face-up photos against the model's, and its direction θ₂ in the photos, the estimated warp. The rest is the fabric (specimen-to-specimen variation of bending, anisotropy, how each was laid on the pedestal).\n\n"
    );
    s += &spread_table(rows);
    s += &format!(
        "\n## Shadows\n\nSeen from above, per fabric: the outlines of the photographed shadows of the predicted specimens (blue, one line per capture) and of the simulated drapes (red, one per perturbation seed), with the pedestal and the flat specimen (grey).\n\n![shadows]({shadows_svg})\n\n## Height profiles\n\nThe azimuthally averaged height z(r) over the rest radius: the registered meshes of the predicted specimens (blue, mean ± SD) and the simulated drapes (red, mean ± SD over the seeds). Fabric 10 has only hem curves, no meshes.\n\n![height profiles]({profiles_svg})\n\n## Run time\n\n"
    );
    s += &timing_table(rows);
    s += "\n## Replay\n\n`runs/cusick/predict/drapes.rrd` overlays, per fabric (a grid of fabrics 0.4 m apart), every registered mesh (`fabric_NN/measured/sS_cC`, in the photos' frame) and every simulated drape (`fabric_NN/simulated/seed_K`); open it with `rerun runs/cusick/predict/drapes.rrd` (rerun-sdk 0.36.3) and hide either group to compare.\n";
    s
}

/// The tables a cusick-report reads.
pub struct CusickReportInputs {
    /// A cusick-predict stage's predictions.parquet.
    pub predictions: PathBuf,
    /// A cusick-measure stage's outlines.parquet (the photos).
    pub photo_outlines: PathBuf,
    /// A cusick-predict stage's outlines.parquet (the simulated drapes).
    pub model_outlines: PathBuf,
    /// A cusick-predict stage's profiles.parquet.
    pub profiles: PathBuf,
    /// A cusick-predict stage's predictions_by_capture.parquet.
    pub by_capture: PathBuf,
}

/// The `run` of the stage kind over this workflow.
pub fn run(ctx: &Job<'_, CusickReportInputs>, _: &CusickReportParams) -> Result<()> {
    let files = &ctx.inputs;
    let rows = read_table::<PredictionRow>(&files.predictions)?;
    let captures = read_table::<CaptureRow>(&files.by_capture)?;
    let photos = read_table::<OutlineRow>(&files.photo_outlines)?;
    let model = read_table::<OutlineRow>(&files.model_outlines)?;
    let profiles = read_table::<ProfileRow>(&files.profiles)?;
    let t = Tester::default();
    let md = ctx.output("markdown")?;
    let (shadows, profile_plot) = (ctx.output("shadows")?, ctx.output("profile_plot")?);
    let svg = shadows_svg(
        &rows,
        &photos,
        &model,
        t.pedestal_radius_m,
        t.specimen_radius_m,
    )?;
    write_text(shadows, &svg)?;
    write_text(profile_plot, &profiles_svg(&rows, &profiles)?)?;
    let rel = |p: &Path| {
        p.strip_prefix(md.parent().unwrap_or(Path::new("")))
            .unwrap_or(p)
            .to_string_lossy()
            .to_string()
    };
    write_text(
        md,
        &report_markdown(&rows, &captures, &rel(shadows), &rel(profile_plot)),
    )?;
    Ok(())
}
