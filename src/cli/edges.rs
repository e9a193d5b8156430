//! `render`, `fit-edges` and `score`: photos of simulated drapes, edge polynomials from photos, and
//! seed 000's Eq. 5 between two sets of edges.

use crate::cloth::Corner;
use crate::edges::{
    Camera, EdgeFit, FitImageOptions, RenderOptions, View, curve_distance_pct,
    edges_from_particles, eq5_objective_pct, eq5_uncentred_pct, fit_image, read_edges, read_gray,
    write_edges,
};
use crate::error::InputError;
use crate::io::{write_atomic, write_particles};
use crate::scene::{LoadedScene, Scene};
use crate::simulate::solve_scene;
use crate::solve::NoObserver;
use anyhow::{Result, bail};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The calibration written beside a rendered photo (`camera.json`), readable by `fit-edges --camera-json`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct CameraFile {
    /// Which hang the photo shows.
    pub view: View,
    /// Pixels per cm in the plane of the fixed corners.
    pub px_per_cm: f64,
    /// Left and right fixed corners in the image, px (u right, v down).
    pub corners_px: [(f64, f64); 2],
    /// Side of the sheet, cm.
    pub side_cm: f64,
    /// The render options.
    pub render: RenderOptions,
}

/// The view of a scene (4 pinned corners: hang4; otherwise hang2) and its left/right fixed corners as
/// grid indices, as the camera looking along +y sees them.
pub fn scene_view(scene: &Scene) -> Result<(View, [(usize, usize); 2]), InputError> {
    let (nx, ny) = (scene.cloth.nx, scene.cloth.ny);
    let pins = &scene.boundary.pin_corners;
    let ij = |c: &Corner| match c {
        Corner::XminYmin => (0, 0),
        Corner::XmaxYmin => (nx - 1, 0),
        Corner::XminYmax => (0, ny - 1),
        Corner::XmaxYmax => (nx - 1, ny - 1),
    };
    match pins.len() {
        4 => Ok((View::Hang4, [(0, 0), (nx - 1, 0)])),
        2 => {
            let (mut a, mut b) = (ij(&pins[0]), ij(&pins[1]));
            if a.1 != b.1 {
                return Err(InputError::new(
                    "",
                    "boundary.pin_corners",
                    "a 2-corner hang needs the two ends of one edge along x",
                ));
            }
            if a.0 > b.0 {
                std::mem::swap(&mut a, &mut b);
            }
            Ok((View::Hang2, [a, b]))
        }
        _ => Err(InputError::new(
            "",
            "boundary.pin_corners",
            "photos are made of 4-corner or 2-corner hangs",
        )),
    }
}

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
    let photo = crate::edges::render_drape(&sol.grid, &sol.x, corners, opts);
    let truth: Vec<EdgeFit> = edges_from_particles(&sol.grid, &sol.x, view, corners)
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
        px_per_cm: photo.px_per_cm,
        corners_px: photo.corners_px,
        side_cm: scene.cloth.size_x_m * 100.0,
        render: opts.clone(),
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
        &[
            ("status", "converged".into()),
            ("scene", scene.name.clone()),
        ],
    )?;
    Ok(path)
}

/// Parses `x1,y1,x2,y2`.
pub fn parse_corners(s: &str) -> Result<[(f64, f64); 2], InputError> {
    let v: Vec<f64> = s
        .split(',')
        .map(|t| t.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| {
            InputError::new(
                "--corners",
                "",
                format!("expected x1,y1,x2,y2 in pixels, got `{s}`"),
            )
        })?;
    if v.len() != 4 {
        return Err(InputError::new(
            "--corners",
            "",
            format!("expected four numbers x1,y1,x2,y2, got {}", v.len()),
        ));
    }
    Ok([(v[0], v[1]), (v[2], v[3])])
}

/// Fits a photo and writes `edges.parquet` and `overlay.png` into `out` (created only on success).
pub fn fit_photo(photo: &Path, out: &Path, opts: &FitImageOptions) -> Result<Vec<EdgeFit>> {
    let img = read_gray(photo)?;
    let fit = fit_image(&img, opts, photo)?;
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

/// Reads a `camera.json`.
pub fn read_camera(path: &Path) -> Result<CameraFile, InputError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| InputError::new(path, "", format!("cannot read: {e}")))?;
    serde_json::from_str(&text)
        .map_err(|e| InputError::new(path, "", format!("not a camera file: {e}")))
}

/// One row of a score: per sample and edge, Eq. 5 and the curve distance.
#[derive(Debug, Clone, Serialize)]
pub struct ScoreRow {
    /// Sample (of the measured table).
    pub sample: String,
    /// Edge name.
    pub edge: String,
    /// Seed 000 Eq. 5 in centred coordinates, % (see [`eq5_objective_pct`]).
    pub objective_pct: f64,
    /// Seed 000 Eq. 5 with coefficients taken from the corner (x/L), % (ill-conditioned; for comparison).
    pub objective_uncentred_pct: f64,
    /// RMS vertical distance between the curves, % of the side.
    pub curve_distance_pct: f64,
}

/// Scores `sim` against `real`, pairing fits by sample and edge; when each table holds a single sample
/// (one photo against one simulation) fits are paired by edge alone.
pub fn score_edges(
    real: &[(String, EdgeFit)],
    sim: &[(String, EdgeFit)],
    side_cm: f64,
) -> Vec<ScoreRow> {
    let single = |t: &[(String, EdgeFit)]| t.iter().all(|(s, _)| *s == t[0].0);
    let by_edge = !real.is_empty() && !sim.is_empty() && single(real) && single(sim);
    real.iter()
        .filter_map(|(rs, r)| {
            let (_, s) = sim
                .iter()
                .find(|(ss, s)| s.edge == r.edge && (by_edge || ss == rs))?;
            let span = r.x_max_cm.max(s.x_max_cm);
            Some(ScoreRow {
                sample: rs.clone(),
                edge: r.edge.clone(),
                objective_pct: eq5_objective_pct(r, s, side_cm),
                objective_uncentred_pct: eq5_uncentred_pct(r, s, side_cm),
                curve_distance_pct: curve_distance_pct(r, s, span, side_cm),
            })
        })
        .collect()
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

/// Default render options with the given camera.
pub fn render_options(camera: Camera, px_per_cm: f64) -> RenderOptions {
    RenderOptions {
        camera,
        px_per_cm,
        ..Default::default()
    }
}

/// Loads a scene for rendering.
pub fn load_scene(path: &Path, sets: &[(String, toml::Value)]) -> Result<LoadedScene, InputError> {
    Scene::load(path, sets)
}
