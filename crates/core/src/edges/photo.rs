//! Photos of hangs: which hang a scene is and where its fixed corners are (the camera's view), the
//! `camera.json` written beside a rendered photo, and seed 000's Eq. 5 between two sets of edges.

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

/// A pinhole camera whose axis meets the sheet's plane square on.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Pinhole {
    /// Focal length, px.
    pub focal_length_px: f64,
    /// Distance from the pinhole to the plane of the fixed corners, m.
    pub distance_m: f64,
    /// Principal point (u, v), px. Default: the image centre.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub principal_point_px: Option<(f64, f64)>,
}

impl Pinhole {
    /// The projection this camera makes of a photo whose fixed corners are at `corners` (px) with
    /// `px_per_cm` in their plane, in an image of `size` (w, h) px.
    pub fn projection(
        &self,
        corners: [(f64, f64); 2],
        px_per_cm: f64,
        size: (u32, u32),
    ) -> Projection {
        let pp = self
            .principal_point_px
            .unwrap_or(((size.0 as f64 - 1.0) / 2.0, (size.1 as f64 - 1.0) / 2.0));
        let [c0, c1] = corners;
        let len = (c1.0 - c0.0).hypot(c1.1 - c0.1);
        let along = ((c1.0 - c0.0) / len, (c1.1 - c0.1) / len);
        // Image v runs down, so "up" in the image is (along.v, −along.u).
        let up = (along.1, -along.0);
        let d = (pp.0 - c0.0, pp.1 - c0.1);
        Projection::Pinhole {
            distance_m: self.distance_m,
            axis_cm: (
                (d.0 * along.0 + d.1 * along.1) / px_per_cm,
                (d.0 * up.0 + d.1 * up.1) / px_per_cm,
            ),
        }
    }
}

/// How the camera that took a photo maps the drape onto the plane of its fixed corners, in the
/// photo's reference frame (cm along the line through the corners from the left one, and up from it).
/// A photo's edge points are positions in that plane, so a simulated drape is projected the same way
/// before its edges are compared (issue 17).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase", tag = "kind")]
pub enum Projection {
    /// Parallel projection: a point's position in the plane is its own.
    #[default]
    Orthographic,
    /// Central projection through a pinhole `distance_m` in front of the corners' plane, whose axis
    /// meets that plane at `axis_cm` (along, up), cm: a point `depth` behind the plane lands at
    /// axis + (p − axis) · distance / (distance + depth).
    Pinhole {
        /// Distance from the pinhole to the plane of the fixed corners, m.
        distance_m: f64,
        /// Where the camera's axis meets the corners' plane, (along, up) cm.
        axis_cm: (f64, f64),
    },
}

impl Projection {
    /// Where a point at (along, up) `p` (cm) and `depth_m` behind the corners' plane (away from the
    /// camera) appears in that plane, cm.
    pub fn project(&self, p: (f64, f64), depth_m: f64) -> (f64, f64) {
        match *self {
            Projection::Orthographic => p,
            Projection::Pinhole {
                distance_m,
                axis_cm,
            } => {
                let k = distance_m / (distance_m + depth_m);
                (
                    axis_cm.0 + (p.0 - axis_cm.0) * k,
                    axis_cm.1 + (p.1 - axis_cm.1) * k,
                )
            }
        }
    }
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
