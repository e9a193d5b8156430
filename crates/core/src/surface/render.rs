//! Pictures of a smooth drape surface for designers and reports: orthographic, lit by a key and a fill
//! light with the surface's own normals (so folds read), coloured by a texture or a plain albedo.

use super::{SurfaceMesh, sample};
use crate::raster::rasterize;
use image::RgbImage;
use nalgebra::Vector3;

/// Where the camera looks from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct View {
    /// Turn about the vertical, degrees (0: looking along +y).
    pub azimuth_deg: f64,
    /// Height above the horizon, degrees (90: straight down, the vertical projection).
    pub elevation_deg: f64,
}

/// What colours the surface.
pub enum Paint<'a> {
    /// One colour (0..255 per channel).
    Plain([f64; 3]),
    /// A texture image at each vertex's texture coordinates.
    Texture(&'a RgbImage, &'a [[f64; 2]]),
}

/// Background grey of the pictures.
const BACKGROUND: [f64; 3] = [246.0, 246.0, 244.0];

/// Renders `mesh` from `view` into a picture of `size` (w, h) px, the drape scaled to fit with a
/// `margin` px border and centred; 3 × 3 samples a pixel. Lighting: ambient 0.25, a key light from
/// the camera's upper left 0.6 and a fill from the right 0.15, both sides of the cloth lit alike.
pub fn render_surface(
    mesh: &SurfaceMesh,
    paint: &Paint<'_>,
    view: View,
    size: (u32, u32),
    margin: u32,
) -> RgbImage {
    let [r, d, u] = crate::raster::camera_frame(view.azimuth_deg, view.elevation_deg);
    let proj: Vec<(f64, f64, f64)> = mesh
        .positions
        .iter()
        .map(|p| (p.dot(&r), -p.dot(&u), p.dot(&d)))
        .collect();
    let (lo, hi) = proj.iter().fold(
        ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]),
        |(lo, hi), p| {
            (
                [lo[0].min(p.0), lo[1].min(p.1)],
                [hi[0].max(p.0), hi[1].max(p.1)],
            )
        },
    );
    let avail = [
        (size.0 as f64 - 2.0 * margin as f64).max(1.0),
        (size.1 as f64 - 2.0 * margin as f64).max(1.0),
    ];
    let span = [(hi[0] - lo[0]).max(1e-9), (hi[1] - lo[1]).max(1e-9)];
    let scale = (avail[0] / span[0]).min(avail[1] / span[1]);
    let off = [
        (size.0 as f64 - span[0] * scale) / 2.0,
        (size.1 as f64 - span[1] * scale) / 2.0,
    ];
    let pts: Vec<(f64, f64, f64)> = proj
        .iter()
        .map(|p| {
            (
                (p.0 - lo[0]) * scale + off[0],
                (p.1 - lo[1]) * scale + off[1],
                p.2,
            )
        })
        .collect();
    let key = (-0.55 * r + 0.6 * u - 0.6 * d).normalize();
    let fill = (0.8 * r + 0.2 * u - 0.5 * d).normalize();
    rasterize(&pts, &mesh.triangles, size, 3, BACKGROUND, |f| {
        let t = mesh.triangles[f.triangle];
        let n: Vector3<f64> = t
            .iter()
            .zip(f.weights)
            .map(|(&k, w)| w * mesh.normals[k as usize])
            .sum();
        let n = n.try_normalize(1e-12).unwrap_or(-d);
        let lum = 0.25 + 0.6 * n.dot(&key).abs() + 0.15 * n.dot(&fill).abs();
        let albedo = match paint {
            Paint::Plain(c) => *c,
            Paint::Texture(img, st) => {
                let mut s = [0.0; 2];
                for (&k, w) in t.iter().zip(f.weights) {
                    s[0] += w * st[k as usize][0];
                    s[1] += w * st[k as usize][1];
                }
                sample(img, s)
            }
        };
        albedo.map(|c| c * lum)
    })
}
