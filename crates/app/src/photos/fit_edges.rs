//! `fit-edges`: every input photo (PNG or JPEG) fitted with edge polynomials, calibrated by the
//! `camera.json` in its folder (as `drapelab render` writes it); one `edges.parquet` for all photos,
//! each row's `sample` being the photo's folder relative to the project root.

use crate::job::Job;
use anyhow::{Result, bail};
use drapelab_core::edges::{
    EdgeFit, FitImageOptions, fit_image, read_camera, read_gray, with_systematics,
};
use drapelab_record::write_edges;
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

/// Default of `degree`: 4 (seed 000's edge polynomials).
pub fn default_degree() -> usize {
    4
}

/// The edges of one photo, calibrated by `camera` (as `drapelab render` writes it), fitted with
/// polynomials of `degree` (seed 000 Figs 11-12), each with its systematic uncertainty.
pub fn photo_edges(
    photo: &std::path::Path,
    camera: &std::path::Path,
    degree: usize,
) -> Result<Vec<EdgeFit>> {
    let cam = read_camera(camera)?;
    let img = read_gray(photo)?;
    let opts = FitImageOptions {
        view: cam.view,
        degree,
        calibration: cam.calibration(camera)?,
        pinhole: cam.pinhole,
    };
    Ok(with_systematics(&img, &opts, fit_image(&img, &opts, photo)?, photo)?.edges)
}

/// The input of a fit-edges stage (the cameras beside the photos are read through them).
pub struct FitEdgesInputs {
    /// Photos (.png, .jpg), each with its camera.json beside it; other files are passed over.
    pub photos: Vec<std::path::PathBuf>,
}

/// Fits each photo's edge polynomials (seed 000), one fit per photo.
pub fn run(ctx: &Job<'_, FitEdgesInputs>, p: &FitEdgesParams) -> Result<Vec<(String, EdgeFit)>> {
    let photos: Vec<_> = ctx
        .inputs
        .photos
        .iter()
        .filter(|f| {
            f.extension()
                .is_some_and(|e| e == "png" || e == "jpg" || e == "jpeg")
        })
        .collect();
    if photos.is_empty() {
        bail!("no photo (.png, .jpg) in input `photos`");
    }
    ctx.started(photos.len());
    let fits: Vec<Result<Vec<(String, EdgeFit)>>> = photos
        .par_iter()
        .map(|photo| {
            let dir = photo.parent().unwrap_or(std::path::Path::new("."));
            let edges = photo_edges(photo, &dir.join("camera.json"), p.degree)?;
            let sample = dir
                .strip_prefix(&ctx.root)
                .unwrap_or(dir)
                .to_string_lossy()
                .replace('\\', "/");
            ctx.item_done();
            Ok(edges.into_iter().map(|e| (sample.clone(), e)).collect())
        })
        .collect();
    let mut rows = Vec::new();
    for f in fits {
        rows.extend(f?);
    }
    write_edges(ctx.output("edges")?, &rows)?;
    Ok(rows)
}
