//! Photos of hangs: which hang a scene is and where its fixed corners are (the camera's view), the
//! `camera.json` written beside a rendered photo, and seed 000's Eq. 5 between two sets of edges.

use super::{
    Camera, EdgeFit, RenderOptions, View, curve_distance_pct, eq5_objective_pct, eq5_uncentred_pct,
};
use crate::cloth::Corner;
use crate::error::InputError;
use crate::scene::Scene;
use serde::{Deserialize, Serialize};
use std::path::Path;

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

/// Reads a `camera.json`.
pub fn read_camera(path: &Path) -> Result<CameraFile, InputError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| InputError::new(path, "", format!("cannot read: {e}")))?;
    serde_json::from_str(&text)
        .map_err(|e| InputError::new(path, "", format!("not a camera file: {e}")))
}

/// One row of a score: per sample and edge, Eq. 5 and the curve distance.
#[derive(Debug, Clone, Serialize, Deserialize)]
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

impl crate::table::Table for ScoreRow {
    const FILE: &'static str = "score.parquet";
    const ROW: &'static str = "One edge of one sample: a simulation's edge polynomial scored against a photo's (seed 000 Eq. 5).";
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

/// Default render options with the given camera.
pub fn render_options(camera: Camera, px_per_cm: f64) -> RenderOptions {
    RenderOptions {
        camera,
        px_per_cm,
        ..Default::default()
    }
}
