//! `fit-edges`: every input photo (PNG or JPEG) fitted with edge polynomials, calibrated by the
//! `camera.json` in its folder (as `drapelab render` writes it); one `edges.parquet` for all photos,
//! each row's `sample` being the photo's folder relative to the project root.

use super::StageContext;
use crate::cli::edges::read_camera;
use crate::edges::{Calibration, EdgeFit, FitImageOptions, fit_image, read_gray, write_edges};
use anyhow::{Result, bail};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Parameters of a fit-edges stage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FitEdgesParams {
    /// Polynomial degree. Default 4 (seed 000).
    #[serde(default = "default_degree")]
    pub degree: usize,
}

fn default_degree() -> usize {
    4
}

/// Runs the stage.
pub fn run(ctx: &StageContext<'_>, p: &FitEdgesParams) -> Result<()> {
    let photos: Vec<_> = ctx
        .inputs
        .iter()
        .filter(|f| {
            f.extension()
                .is_some_and(|e| e == "png" || e == "jpg" || e == "jpeg")
        })
        .collect();
    if photos.is_empty() {
        bail!("no photo (.png, .jpg) among the inputs");
    }
    ctx.progress
        .stage_started(&ctx.stage.name, photos.len() as u64);
    let fits: Vec<Result<Vec<(String, EdgeFit)>>> = photos
        .par_iter()
        .map(|photo| {
            let dir = photo.parent().unwrap_or(std::path::Path::new("."));
            let cam = read_camera(&dir.join("camera.json"))?;
            let img = read_gray(photo)?;
            let opts = FitImageOptions {
                view: cam.view,
                degree: p.degree,
                calibration: Calibration::Given {
                    px_per_cm: cam.px_per_cm,
                    corners: cam.corners_px,
                },
            };
            let fit = fit_image(&img, &opts, photo)?;
            let sample = dir
                .strip_prefix(&ctx.plan.root)
                .unwrap_or(dir)
                .to_string_lossy()
                .replace('\\', "/");
            ctx.progress.item_done(&ctx.stage.name);
            Ok(fit.edges.into_iter().map(|e| (sample.clone(), e)).collect())
        })
        .collect();
    let mut rows = Vec::new();
    for f in fits {
        rows.extend(f?);
    }
    write_edges(&ctx.outputs[0], &rows)
}
