//! `render`, `fit-edges` and `score` as files: a solved scene rendered to a photo with its
//! `camera.json` and true edges, a photo fitted to `edges.parquet`, and two edge tables scored.

use crate::{read_edges, write_edges, write_particles};
use anyhow::{Result, bail};
use drapelab_core::atomic::write_atomic;
use drapelab_core::edges::{
    CameraFile, EdgeFit, FitImageOptions, RenderOptions, ScoreRow, edges_from_particles, fit_image,
    read_gray, scene_view, score_edges, with_systematics,
};
use drapelab_core::error::InputError;
use drapelab_core::scene::LoadedScene;
use drapelab_core::simulate::solve_scene;
use drapelab_core::solve::{NoObserver, Status};
use std::path::{Path, PathBuf};

/// Solves a scene, renders it, and writes photo, camera.json, particles.parquet and the direct
/// particle-edge fit `edges_truth.parquet` into `out`.
pub fn render_scene(
    loaded: &LoadedScene,
    out: &Path,
    opts: &RenderOptions,
    jpeg_quality: Option<u8>,
    degree: usize,
) -> Result<PathBuf> {
    let scene = &loaded.scene;
    let (view, corners) =
        scene_view(scene).map_err(|e| InputError::new(&loaded.path, e.key, e.message))?;
    let sol = solve_scene(scene, &mut NoObserver);
    if !sol.report.is_converged() {
        bail!(
            "{}: {} ({}); nothing rendered",
            scene.name,
            sol.report.status.as_str(),
            sol.report.message
        );
    }
    std::fs::create_dir_all(out)?;
    let photo = drapelab_core::edges::render_drape(&sol.grid, &sol.x, corners, opts);
    let projection = photo
        .pinhole
        .map(|p| p.projection(photo.corners_px, photo.px_per_cm, photo.image.dimensions()))
        .unwrap_or_default();
    let truth: Vec<EdgeFit> = edges_from_particles(&sol.grid, &sol.x, view, corners, projection)
        .into_iter()
        .filter_map(|(name, pts)| EdgeFit::from_points(&name, &pts, degree))
        .collect();
    let name = if jpeg_quality.is_some() {
        "photo.jpg"
    } else {
        "photo.png"
    };
    let path = out.join(name);
    write_atomic(&path, |f| {
        let mut w = std::io::BufWriter::new(f);
        match jpeg_quality {
            Some(q) => image::codecs::jpeg::JpegEncoder::new_with_quality(&mut w, q)
                .encode_image(&photo.image)?,
            None => photo.image.write_to(&mut w, image::ImageFormat::Png)?,
        }
        Ok(())
    })?;
    let cam = CameraFile {
        view,
        side_cm: scene.cloth.size_x_m * 100.0,
        px_per_cm: photo.pinhole.is_none().then_some(photo.px_per_cm),
        pinhole: photo.pinhole,
        corners_px: Some(photo.corners_px),
        markers: false,
        render: Some(opts.clone()),
    };
    let json = serde_json::to_vec_pretty(&cam)?;
    write_atomic(&out.join("camera.json"), |f| {
        use std::io::Write;
        f.write_all(&json)?;
        Ok(())
    })?;
    let truth: Vec<(String, EdgeFit)> =
        truth.into_iter().map(|f| (scene.name.clone(), f)).collect();
    write_edges(&out.join("edges_truth.parquet"), &truth)?;
    write_particles(
        &out.join("particles.parquet"),
        &sol.grid,
        &sol.x,
        &[],
        &[
            ("status", Status::Converged.as_str().into()),
            ("scene", scene.name.clone()),
        ],
    )?;
    Ok(path)
}

/// Fits a photo and writes `edges.parquet` and `overlay.png` into `out` (created only on success).
pub fn fit_photo(photo: &Path, out: &Path, opts: &FitImageOptions) -> Result<Vec<EdgeFit>> {
    let img = read_gray(photo)?;
    let fit = with_systematics(&img, opts, fit_image(&img, opts, photo)?, photo)?;
    std::fs::create_dir_all(out)?;
    write_atomic(&out.join("overlay.png"), |f| {
        fit.overlay
            .write_to(&mut std::io::BufWriter::new(f), image::ImageFormat::Png)?;
        Ok(())
    })?;
    let sample = photo
        .file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_default();
    let rows: Vec<(String, EdgeFit)> = fit
        .edges
        .iter()
        .map(|f| (sample.clone(), f.clone()))
        .collect();
    write_edges(&out.join("edges.parquet"), &rows)?;
    Ok(fit.edges)
}

/// `drapelab score`.
pub fn score_files(real: &Path, sim: &Path, side_cm: f64) -> Result<Vec<ScoreRow>> {
    if !(side_cm.is_finite() && side_cm > 0.0) {
        return Err(InputError::new("--side-cm", "", "must be a finite number > 0").into());
    }
    let (r, s) = (read_edges(real)?, read_edges(sim)?);
    let rows = score_edges(&r, &s, side_cm);
    if rows.is_empty() {
        bail!("{} and {} share no edge", real.display(), sim.display());
    }
    Ok(rows)
}
