//! How a camera maps a drape onto the plane of its fixed corners: a pinhole camera ([`Pinhole`])
//! and the projection it makes of a photo ([`Projection`]).

use serde::{Deserialize, Serialize};

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
