//! A small triangle rasterizer for pictures: depth-buffered, supersampled, shaded per sample after
//! visibility is settled (each visible sample is shaded once). Used by the photo-like renders of
//! [`crate::edges`] and the textured surfaces of [`crate::surface`].

use image::{Rgb, RgbImage};
use nalgebra::Vector3;

/// An orthographic camera's frame for a view `elevation_deg` above the horizon (90: straight down),
/// turned `azimuth_deg` about the vertical (0: looking along +y): right r, forward (into the picture)
/// d, up u.
pub fn camera_frame(azimuth_deg: f64, elevation_deg: f64) -> [Vector3<f64>; 3] {
    let (sa, ca) = azimuth_deg.to_radians().sin_cos();
    let (se, ce) = elevation_deg.to_radians().sin_cos();
    [
        Vector3::new(ca, -sa, 0.0),
        Vector3::new(sa * ce, ca * ce, -se),
        Vector3::new(sa * se, ca * se, ce),
    ]
}

/// What the rasterizer hands the shader for a visible sample: the triangle (its position in the
/// list given) and the sample's barycentric weights of its three corners.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fragment {
    /// Index of the triangle in the list given to [`rasterize`].
    pub triangle: usize,
    /// Barycentric weights of corners a, b, c (sum 1).
    pub weights: [f64; 3],
}

/// Draws `triangles` (indices into `pts`, each an image position (u, v) in px and a depth, smaller
/// nearer) into a `w × h` image, `ss × ss` samples a pixel, nearest triangle wins; `shade` gives the
/// colour (0..255 per channel) of a visible sample, `background` that of an empty one. Pixel (u, v)
/// spans [u, u + 1) × [v, v + 1); triangles of zero image area are skipped.
pub fn rasterize(
    pts: &[(f64, f64, f64)],
    triangles: &[[u32; 3]],
    (w, h): (u32, u32),
    ss: usize,
    background: [f64; 3],
    shade: impl Fn(Fragment) -> [f64; 3],
) -> RgbImage {
    let (sw, sh) = (w as usize * ss, h as usize * ss);
    let mut depth = vec![f64::INFINITY; sw * sh];
    let mut frag: Vec<Option<Fragment>> = vec![None; sw * sh];
    for (t, tri) in triangles.iter().enumerate() {
        let [pa, pb, pc] = tri.map(|k| pts[k as usize]);
        let area = (pb.0 - pa.0) * (pc.1 - pa.1) - (pb.1 - pa.1) * (pc.0 - pa.0);
        if area.abs() < 1e-12 {
            continue;
        }
        let s = ss as f64;
        let x0 = ((pa.0.min(pb.0).min(pc.0)) * s).floor().max(0.0) as usize;
        let x1 = ((pa.0.max(pb.0).max(pc.0)) * s).ceil().min(sw as f64) as usize;
        let y0 = ((pa.1.min(pb.1).min(pc.1)) * s).floor().max(0.0) as usize;
        let y1 = ((pa.1.max(pb.1).max(pc.1)) * s).ceil().min(sh as f64) as usize;
        for sy in y0..y1 {
            for sx in x0..x1 {
                let (px, py) = ((sx as f64 + 0.5) / s, (sy as f64 + 0.5) / s);
                let w0 = ((pb.0 - px) * (pc.1 - py) - (pb.1 - py) * (pc.0 - px)) / area;
                let w1 = ((pc.0 - px) * (pa.1 - py) - (pc.1 - py) * (pa.0 - px)) / area;
                let w2 = 1.0 - w0 - w1;
                if w0 < 0.0 || w1 < 0.0 || w2 < 0.0 {
                    continue;
                }
                let d = w0 * pa.2 + w1 * pb.2 + w2 * pc.2;
                let k = sy * sw + sx;
                if d < depth[k] {
                    depth[k] = d;
                    frag[k] = Some(Fragment {
                        triangle: t,
                        weights: [w0, w1, w2],
                    });
                }
            }
        }
    }
    let mut img = RgbImage::new(w, h);
    for v in 0..h as usize {
        for u in 0..w as usize {
            let mut acc = [0.0; 3];
            for dy in 0..ss {
                for dx in 0..ss {
                    let c = frag[(v * ss + dy) * sw + u * ss + dx].map_or(background, &shade);
                    acc.iter_mut().zip(c).for_each(|(a, c)| *a += c);
                }
            }
            let px = acc.map(|a| (a / (ss * ss) as f64).round().clamp(0.0, 255.0) as u8);
            img.put_pixel(u as u32, v as u32, Rgb(px));
        }
    }
    img
}
