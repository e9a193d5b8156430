//! `cusick-report` (issue 16): the predictions of every fabric against its measurements, as Markdown,
//! with the criteria counted (DC within the measured mean ± max(2 SD, 4 points), nodes within
//! 1 of the measured median).

use crate::cusick_predict::PredictionRow;
use anyhow::Result;
use drapelab_pipeline::{Slot, StageContext, StageKind};
use drapelab_record::{read_table, write_text};
use serde::{Deserialize, Serialize};

/// Parameters of a cusick-report stage (none yet).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CusickReportParams {}

/// The `cusick-report` stage kind.
pub struct CusickReport;

impl StageKind for CusickReport {
    type Params = CusickReportParams;
    const KIND: &'static str = "cusick-report";
    const SUMMARY: &'static str = "Markdown of the Cusick predictions against the measurements";
    const INPUTS: &'static [Slot] = &[Slot::one(
        "predictions",
        "a cusick-predict stage's predictions.parquet",
    )];
    const OUTPUTS: &'static [Slot] = &[Slot::one("markdown", "the report, .md")];
    fn run(ctx: &StageContext<'_>, _: &CusickReportParams) -> Result<()> {
        let rows = read_table::<PredictionRow>(ctx.input("predictions")?)?;
        write_text(ctx.output("markdown")?, &report_markdown(&rows))?;
        Ok(())
    }
}

fn opt(v: Option<f64>, digits: usize) -> String {
    v.map_or("–".into(), |x| format!("{x:.digits$}"))
}

/// Whether the predicted DC lies within the measured mean ± max(2 SD, 4 points).
pub fn dc_within(r: &PredictionRow) -> Option<bool> {
    let band = (2.0 * r.dc_measured_sd_pct).max(4.0);
    r.dc_predicted_pct
        .map(|p| (p - r.dc_measured_mean_pct).abs() <= band)
}

/// Whether the predicted mean node count lies within 1 of the measured median.
pub fn nodes_within(r: &PredictionRow) -> Option<bool> {
    r.nodes_predicted
        .map(|n| (n - r.nodes_measured_median).abs() <= 1.0)
}

/// The report's Markdown.
pub fn report_markdown(rows: &[PredictionRow]) -> String {
    let mut s = String::from(
        "# Real fabrics on a Cusick drape tester\n\nWritten by `drapelab run pipelines/cusick.toml` (stage `report`). Data: the Cusick drape dataset of Gong, Mao & Wang, \"Bayesian Differentiable Physics for Cloth Digitalization\", CVPR 2024 (specimens 1–4 of ten fabrics in `datasets/cusick/`). Per fabric, the bending length c of an isotropic disc model (cotangent-Laplacian bending, stiff edge springs, the pedestal's vertices held, the dataset's own template mesh) is calibrated on the mean DC of the lowest-numbered specimen's photos; drapes at that c from several seeded perturbations are then compared with the other specimens: DC mean ± SD, nodes, and the RMS of the azimuthally averaged height profile z(r) against the registered meshes. B = w g c³ is given where the areal density w is known. Warp and weft are not told apart: the data do not say which way they run.\n\n| fabric | calibrated on | bending length (mm) | B (µN·m) | DC target (%) | DC predicted (%) | DC measured (%) | DC ok | nodes predicted | nodes measured | nodes ok | profile RMS (mm) | time (s) | status |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let yes = |b: Option<bool>| b.map_or("–", |b| if b { "yes" } else { "no" });
        s += &format!(
            "| {} | {} | {} | {} | {:.1} | {} ± {} | {:.1} ± {:.1} | {} | {} | {:.0} | {} | {} | {:.0} | {} |\n",
            r.fabric,
            r.calibration_sample,
            opt(r.bending_length_warp_m.map(|c| 1e3 * c), 1),
            opt(r.bending_rigidity_N_m.map(|b| 1e6 * b), 1),
            r.dc_calibration_pct,
            opt(r.dc_predicted_pct, 1),
            opt(r.dc_predicted_sd_pct, 1),
            r.dc_measured_mean_pct,
            r.dc_measured_sd_pct,
            yes(dc_within(r)),
            opt(r.nodes_predicted, 2),
            r.nodes_measured_median,
            yes(nodes_within(r)),
            opt(r.profile_rms_mm, 1),
            r.wall_time_s,
            r.status
        );
    }
    let count = |f: &dyn Fn(&PredictionRow) -> Option<bool>| {
        rows.iter().filter(|r| f(r) == Some(true)).count()
    };
    s += &format!(
        "\nDC within the measured mean ± max(2 SD, 4 points): {} of {} fabrics. Nodes within 1 of the measured median: {} of {}.\n",
        count(&dc_within),
        rows.len(),
        count(&nodes_within),
        rows.len()
    );
    s
}
