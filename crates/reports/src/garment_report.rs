//! `garment-report` (issue 77): the garment draped in each calibrated fabric — a table of the
//! solves and the hem's flare with its interval from the fabric's 2σ bending, whether the limpest
//! and stiffest fabrics' flares lie outside each other's intervals, and the drapes' pictures.

use anyhow::{Result, bail};
use drapelab_app::Job;
use drapelab_app::garment::GarmentRow;
use drapelab_record::{read_table, write_text};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Parameters of a garment-report stage (none).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GarmentReportParams {}

/// The inputs of a garment-report stage.
pub struct GarmentReportInputs {
    /// Garment stages' garment.parquet files, one per fabric.
    pub measures: Vec<PathBuf>,
    /// Pictures of the drapes (PNG or SVG), linked in the given order.
    pub pictures: Vec<PathBuf>,
}

/// Millimetres of an optional length in metres.
fn mm(v: Option<f64>) -> String {
    v.map_or("—".into(), |v| format!("{:.1}", v * 1e3))
}

/// The table of the garments, one row each.
fn table(rows: &[GarmentRow]) -> String {
    let mut s = String::from(
        "| fabric | particles | status | iterations | time (s) | hem flare r̄ (mm) | its interval (mm) | dr̄/d ln B (mm) | crossing edges |\n\
         |---|---:|---|---:|---:|---:|---|---:|---:|\n",
    );
    for r in rows {
        let interval = match (r.hem_radius_lo_m, r.hem_radius_hi_m) {
            (Some(lo), Some(hi)) => format!("[{}, {}]", mm(Some(lo)), mm(Some(hi))),
            _ => format!("— ({})", r.interval_note),
        };
        s += &format!(
            "| {} | {} | {} | {} | {:.1} | {} | {} | {} | {} |\n",
            r.fabric,
            r.particles,
            r.status,
            r.iterations,
            r.wall_time_s,
            mm(r.hem_radius_m),
            interval,
            mm(r.hem_radius_per_ln_bending_m),
            r.crossing_edges.map_or("—".into(), |c| c.to_string())
        );
    }
    s
}

/// Whether the limpest fabric's flare (the smallest) lies below the stiffest's with neither inside
/// the other's interval, said in a sentence.
fn verdict(rows: &[GarmentRow]) -> String {
    let measured: Vec<&GarmentRow> = rows.iter().filter(|r| r.hem_radius_m.is_some()).collect();
    let r = |g: &&&GarmentRow| g.hem_radius_m.unwrap_or(f64::NAN);
    let by = |a: &&&GarmentRow, b: &&&GarmentRow| r(a).total_cmp(&r(b));
    let (Some(limp), Some(stiff)) = (measured.iter().min_by(by), measured.iter().max_by(by)) else {
        return "No garment converged: nothing to compare.".into();
    };
    let inside = |v: Option<f64>, r: &GarmentRow| match (v, r.hem_radius_lo_m, r.hem_radius_hi_m) {
        (Some(v), Some(lo), Some(hi)) => Some(lo <= v && v <= hi),
        _ => None,
    };
    let apart = match (
        inside(limp.hem_radius_m, stiff),
        inside(stiff.hem_radius_m, limp),
    ) {
        (Some(false), Some(false)) => {
            "neither lies inside the other's interval: the tester's measurement tells the two garments apart"
        }
        (Some(_), Some(_)) => {
            "one lies inside the other's interval: the tester's measurement does not tell the two garments apart"
        }
        _ => "an interval is missing, so whether they are told apart is not known",
    };
    format!(
        "The limpest fabric, {}, flares least (r̄ = {} mm) and the stiffest, {}, most ({} mm); {apart}.",
        limp.fabric,
        mm(limp.hem_radius_m),
        stiff.fabric,
        mm(stiff.hem_radius_m)
    )
}

/// The report's text; `pictures` are links relative to the report.
pub fn report_markdown(rows: &[GarmentRow], pictures: &[String]) -> String {
    let mut s = String::from(
        "# A garment in calibrated fabrics\n\n\
         Printed by `drapelab run pipelines/garment.toml`. Each fabric's bending is calibrated on the \
         Cusick drape tester (`cusick-predict`), written as a fabric file (`cusick-fabric`: bending \
         warp/weft with their 2σ intervals, tensile and shear stated defaults), and the three-gore \
         skirt of `datasets/bodies/skirt_dress_form.toml` is draped in it on the dress form \
         (`garment`). The measure is the hem's flare r̄: the mean horizontal distance of the hem's \
         vertices from the form's axis. Its interval is the fabric's 2σ bending interval carried \
         through the drape's sensitivity dx*/dB (linearized: r̄ + Σ ∂r̄/∂B_k ΔB_k at each end).\n\n",
    );
    s += &table(rows);
    s += &format!("\n{}\n", verdict(rows));
    if !pictures.is_empty() {
        s += "\n## The drapes\n\n";
        for (p, r) in pictures
            .iter()
            .zip(rows.iter().map(Some).chain(std::iter::repeat(None)))
        {
            let name = r.map_or("drape", |r| r.fabric.as_str());
            s += &format!("![{name}]({p})\n\n");
        }
    }
    s
}

/// The `run` of the stage kind over this workflow.
pub fn run(ctx: &Job<'_, GarmentReportInputs>, _: &GarmentReportParams) -> Result<()> {
    let files = &ctx.inputs;
    let mut rows = Vec::new();
    for m in &files.measures {
        rows.extend(read_table::<GarmentRow>(m)?);
    }
    if rows.is_empty() {
        bail!("no garment rows in {} files", files.measures.len());
    }
    let md = ctx.output("markdown")?;
    let rel = |p: &Path| {
        p.strip_prefix(md.parent().unwrap_or(Path::new("")))
            .unwrap_or(p)
            .to_string_lossy()
            .to_string()
    };
    let pictures: Vec<String> = files.pictures.iter().map(|p| rel(p)).collect();
    write_text(md, &report_markdown(&rows, &pictures))?;
    Ok(())
}
