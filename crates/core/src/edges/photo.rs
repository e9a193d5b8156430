//! Photos of hangs: which hang a scene is and where its fixed corners are (the camera's view), the
//! `camera.json` written beside a rendered photo, and seed 000's Eq. 5 between two sets of edges.

use super::projection::Pinhole;
use super::{
    Calibration, Camera, EdgeFit, RenderOptions, View, curve_distance_pct, eq5_objective_pct,
    eq5_uncentred_pct,
};
use crate::cloth::Corner;
use crate::error::InputError;
use crate::scene::Scene;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// What a camera gives about a photo (`camera.json`, read by `fit-edges --camera-json` and the
/// `fit-edges` stage): the hang it shows, the scale at the sheet (`px_per_cm`, or a `pinhole`
/// camera's focal length and distance, or the corners' distance over `side_cm`), and where the fixed
/// corners are (`corners_px`, or `markers`: two red markers). Pixel coordinates put pixel centres at
/// integers (u right, v down), as OpenCV and most image tools do. drapelab's own render settings,
/// when it made the photo, ride along as provenance in `render`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraFile {
    /// Which hang the photo shows: `hang4` or `hang2`.
    pub view: View,
    /// Distance between the two fixed corners, cm (the sheet's side).
    pub side_cm: f64,
    /// Pixels per cm in the plane of the fixed corners. Optional: else from `pinhole`, else from
    /// the corners' distance in pixels over `side_cm`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub px_per_cm: Option<f64>,
    /// A pinhole camera looking square at the sheet.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pinhole: Option<Pinhole>,
    /// Left and right fixed corners in the image, px. Optional: else `markers` must be true.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub corners_px: Option<[(f64, f64); 2]>,
    /// Find the corners as the two largest red blobs in the photo. Default false.
    #[serde(default)]
    pub markers: bool,
    /// drapelab's render settings, when drapelab rendered the photo (provenance only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub render: Option<RenderOptions>,
}

impl CameraFile {
    /// The scale at the sheet, px per cm, if the file gives one (directly or by its pinhole).
    pub fn scale_px_per_cm(&self) -> Option<f64> {
        self.px_per_cm.or(self
            .pinhole
            .map(|p| p.focal_length_px / (100.0 * p.distance_m)))
    }

    /// How the photo's pixels become centimetres; `path` names the file in errors.
    pub fn calibration(&self, path: &Path) -> Result<Calibration, InputError> {
        if !(self.side_cm.is_finite() && self.side_cm > 0.0) {
            return Err(InputError::new(path, "side_cm", "must be a number > 0"));
        }
        if let Some(p) = self.pinhole
            && !(p.focal_length_px > 0.0 && p.distance_m > 0.0)
        {
            return Err(InputError::new(
                path,
                "pinhole",
                "focal_length_px and distance_m must be > 0",
            ));
        }
        match (self.corners_px, self.markers) {
            (Some(corners), _) => {
                let d = (corners[1].0 - corners[0].0).hypot(corners[1].1 - corners[0].1);
                Ok(Calibration::Given {
                    px_per_cm: self.scale_px_per_cm().unwrap_or(d / self.side_cm),
                    corners,
                })
            }
            (None, true) => Ok(Calibration::Markers {
                side_cm: self.side_cm,
            }),
            (None, false) => Err(InputError::new(
                path,
                "corners_px",
                "give the fixed corners' pixels (corners_px) or set markers = true",
            )),
        }
    }
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
