//! Photo-like renders of a simulated drape: an orthographic or pinhole camera looking along +y, the
//! sheet as shaded triangles (Lambert, 4×4 supersampling) on a plain light background, optional red
//! markers at the fixed corners, Gaussian noise, blur and a small rotation. This is how drapelab makes
//! synthetic measurements; real photos enter [`super::fit_image`] the same way.

use crate::cloth::Grid;
use image::{Rgb, RgbImage};
use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use serde::{Deserialize, Serialize};

/// The camera model.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase", tag = "kind")]
pub enum Camera {
    /// Parallel projection along +y.
    Orthographic,
    /// A pinhole at distance `distance_m` in front of the plane y = 0, looking along +y; closer parts
    /// look larger (the scale at y = 0 is `px_per_cm`).
    Pinhole {
        /// Distance from the pinhole to the plane y = 0, m.
        distance_m: f64,
    },
}

/// What to render.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RenderOptions {
    /// Camera model.
    pub camera: Camera,
    /// Scale in the plane y = 0, pixels per cm.
    pub px_per_cm: f64,
    /// Empty border around the sheet, px.
    pub margin_px: u32,
    /// Draw red discs of this radius (px) at the fixed corners; 0 = none.
    pub marker_radius_px: f64,
    /// Standard deviation of additive Gaussian noise, grey levels (0..255).
    pub noise_sigma: f64,
    /// Standard deviation of a Gaussian blur, px; 0 = none.
    pub blur_sigma_px: f64,
    /// Rotation of the camera about its axis, degrees (the image is rotated about its centre).
    pub rotation_deg: f64,
    /// Seed of the noise.
    pub seed: u64,
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            camera: Camera::Orthographic,
            px_per_cm: 8.0,
            margin_px: 30,
            marker_radius_px: 0.0,
            noise_sigma: 0.0,
            blur_sigma_px: 0.0,
            rotation_deg: 0.0,
            seed: 1,
        }
    }
}

/// A rendered photo with its exact calibration.
pub struct RenderedPhoto {
    /// The image.
    pub image: RgbImage,
    /// Image positions (u right, v down; pixel centres at integers, pixel (u, v) spanning
    /// [u − ½, u + ½) × [v − ½, v + ½)) of the left and right fixed corners.
    pub corners_px: [(f64, f64); 2],
    /// Scale in the plane of the fixed corners, px per cm.
    pub px_per_cm: f64,
    /// The pinhole camera as a camera file describes it (focal length, distance to the corners'
    /// plane, principal point); None for the orthographic camera.
    pub pinhole: Option<super::projection::Pinhole>,
}

/// Background and fabric grey levels.
const BACKGROUND: f64 = 232.0;
const ALBEDO: f64 = 150.0;

/// Renders the grid particles `x` (m); `corners` are the left and right fixed corners as grid indices.
pub fn render_drape(
    grid: &Grid,
    x: &[Vector3<f64>],
    corners: [(usize, usize); 2],
    opts: &RenderOptions,
) -> RenderedPhoto {
    let s = opts.px_per_cm * 100.0; // px per m in the plane y = 0
    let (pts, (w, h), (umin, vmin)) = projected(grid, x, opts);
    let m = opts.margin_px as f64;
    let mut img = rasterize(&pts, x, crate::cloth::grid_triangles(grid), w, h);
    // The rasterizer's pixel (u, v) spans [u, u + 1) × [v, v + 1); the photo's coordinates put pixel
    // centres at integers (as fit_image, OpenCV and imageproc do), half a pixel less.
    let corner_px = |(i, j): (usize, usize)| {
        let p = pts[grid.index(i, j)];
        (p.0 - 0.5, p.1 - 0.5)
    };
    let mut corners_px = [corner_px(corners[0]), corner_px(corners[1])];
    // The camera's axis meets every plane y = const at x = z = 0.
    let mut axis_px = (m - umin - 0.5, m - vmin - 0.5);
    draw_markers(&mut img, &corners_px, opts.marker_radius_px);
    if opts.rotation_deg != 0.0 {
        img = rotated(img, opts.rotation_deg, &mut corners_px, &mut axis_px);
    }
    if opts.blur_sigma_px > 0.0 {
        img = imageproc::filter::gaussian_blur_f32(&img, opts.blur_sigma_px as f32);
    }
    add_noise(&mut img, opts.noise_sigma, opts.seed);
    // A pinhole at y = −d has focal length s·d px; the corners' plane is d + y_c from it.
    let plane_y = 0.5
        * (x[grid.index(corners[0].0, corners[0].1)].y
            + x[grid.index(corners[1].0, corners[1].1)].y);
    let (px_per_cm, pinhole) = match opts.camera {
        Camera::Orthographic => (opts.px_per_cm, None),
        Camera::Pinhole { distance_m } => {
            let p = super::projection::Pinhole {
                focal_length_px: s * distance_m,
                distance_m: distance_m + plane_y,
                principal_point_px: Some(axis_px),
            };
            (p.focal_length_px / (100.0 * p.distance_m), Some(p))
        }
    };
    RenderedPhoto {
        image: img,
        corners_px,
        px_per_cm,
        pinhole,
    }
}

/// The grid particles projected by the camera to (u, v, depth) in pixels, shifted so that the
/// image holds them with the margin; the image's size and the shift's (u, v) minimum.
type Projected = (Vec<(f64, f64, f64)>, (u32, u32), (f64, f64));

fn projected(grid: &Grid, x: &[Vector3<f64>], opts: &RenderOptions) -> Projected {
    let s = opts.px_per_cm * 100.0;
    let project = |p: &Vector3<f64>| -> (f64, f64, f64) {
        match opts.camera {
            Camera::Orthographic => (p.x * s, -p.z * s, p.y),
            Camera::Pinhole { distance_m } => {
                let k = distance_m / (distance_m + p.y);
                (p.x * s * k, -p.z * s * k, p.y)
            }
        }
    };
    let pts: Vec<(f64, f64, f64)> = x[..grid.len()].iter().map(project).collect();
    let (umin, umax, vmin, vmax) = pts.iter().fold(
        (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ),
        |a, p| (a.0.min(p.0), a.1.max(p.0), a.2.min(p.1), a.3.max(p.1)),
    );
    let m = opts.margin_px as f64;
    let (w, h) = (
        (umax - umin + 2.0 * m).ceil() as u32,
        (vmax - vmin + 2.0 * m).ceil() as u32,
    );
    let shift = |p: (f64, f64, f64)| (p.0 - umin + m, p.1 - vmin + m, p.2);
    (pts.into_iter().map(shift).collect(), (w, h), (umin, vmin))
}

/// Red discs of radius `r` px at the corners (none for r = 0): the markers a photo's corners carry.
fn draw_markers(img: &mut RgbImage, corners_px: &[(f64, f64); 2], r: f64) {
    if r <= 0.0 {
        return;
    }
    let (w, h) = img.dimensions();
    for &(cu, cv) in corners_px {
        for v in (cv - r - 1.0).floor().max(0.0) as u32..((cv + r + 1.0).ceil() as u32).min(h) {
            for u in (cu - r - 1.0).floor().max(0.0) as u32..((cu + r + 1.0).ceil() as u32).min(w) {
                if ((u as f64 - cu).powi(2) + (v as f64 - cv).powi(2)).sqrt() <= r {
                    img.put_pixel(u, v, Rgb([220, 30, 30]));
                }
            }
        }
    }
}

/// The image turned by `deg` about its centre, the corners and the camera axis turned with it.
fn rotated(
    img: RgbImage,
    deg: f64,
    corners_px: &mut [(f64, f64); 2],
    axis_px: &mut (f64, f64),
) -> RgbImage {
    let (w, h) = img.dimensions();
    let theta = deg.to_radians();
    let img = imageproc::geometric_transformations::rotate_about_center(
        &img,
        theta as f32,
        imageproc::geometric_transformations::Interpolation::Bilinear,
        imageproc::geometric_transformations::Border::Constant(Rgb([BACKGROUND as u8; 3])),
    );
    // imageproc maps p to c + R(θ)(p − c) with c = (w/2, h/2) in pixel-index coordinates (pixel
    // centres at integers), the photo's coordinates.
    let (cx, cy) = (w as f64 / 2.0, h as f64 / 2.0);
    let (sn, cs) = theta.sin_cos();
    for c in corners_px.iter_mut().chain(std::iter::once(axis_px)) {
        let (du, dv) = (c.0 - cx, c.1 - cy);
        *c = (cx + cs * du - sn * dv, cy + sn * du + cs * dv);
    }
    img
}

/// Gaussian noise of standard deviation `sigma` (grey levels) on every channel, seeded (Box–Muller).
fn add_noise(img: &mut RgbImage, sigma: f64, seed: u64) {
    if sigma <= 0.0 {
        return;
    }
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    for p in img.pixels_mut() {
        let (u1, u2): (f64, f64) = (rng.random::<f64>().max(1e-300), rng.random());
        let z = (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos() * sigma;
        for ch in p.0.iter_mut() {
            *ch = (*ch as f64 + z).round().clamp(0.0, 255.0) as u8;
        }
    }
}

/// Draws the triangles (indices into `x`) whose image positions `pts` are (u, v, depth) into a
/// `w × h` grey image: Lambert shading of each triangle's normal, nearest triangle wins, 4×4
/// supersampling.
fn rasterize(
    pts: &[(f64, f64, f64)],
    x: &[Vector3<f64>],
    triangles: impl IntoIterator<Item = [u32; 3]>,
    w: u32,
    h: u32,
) -> RgbImage {
    let light = Vector3::new(-0.3, -0.8, 0.5).normalize();
    let tris: Vec<[u32; 3]> = triangles.into_iter().collect();
    let grey: Vec<f64> = tris
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|k| k as usize);
            let n = (x[b] - x[a]).cross(&(x[c] - x[a]));
            let lum = if n.norm() > 0.0 {
                0.35 + 0.65 * n.normalize().dot(&light).abs()
            } else {
                1.0
            };
            ALBEDO * lum
        })
        .collect();
    crate::raster::rasterize(pts, &tris, (w, h), 4, [BACKGROUND; 3], |f| {
        [grey[f.triangle]; 3]
    })
}

/// A shaded picture of a drape for reports: an orthographic camera `elevation_deg` above the horizon
/// (90: from above, the vertical projection; 0: from the side along +y), turned `azimuth_deg` about the
/// vertical, `px_per_cm` pixels per cm, a `margin_px` border; triangles with a particle that is not
/// `present` (a disc's corners) are left out.
pub fn render_view(
    grid: &Grid,
    x: &[Vector3<f64>],
    present: &[bool],
    azimuth_deg: f64,
    elevation_deg: f64,
    px_per_cm: f64,
    margin_px: u32,
) -> RgbImage {
    let [r, d, u] = crate::raster::camera_frame(azimuth_deg, elevation_deg);
    let s = px_per_cm * 100.0;
    let keep = |k: usize| present.get(k).copied().unwrap_or(true);
    let pts: Vec<(f64, f64, f64)> = x[..grid.len()]
        .iter()
        .map(|p| (p.dot(&r) * s, -p.dot(&u) * s, p.dot(&d)))
        .collect();
    let (umin, umax, vmin, vmax) = pts.iter().enumerate().filter(|(k, _)| keep(*k)).fold(
        (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ),
        |a, (_, p)| (a.0.min(p.0), a.1.max(p.0), a.2.min(p.1), a.3.max(p.1)),
    );
    let m = margin_px as f64;
    let (w, h) = (
        (umax - umin + 2.0 * m).ceil().max(1.0) as u32,
        (vmax - vmin + 2.0 * m).ceil().max(1.0) as u32,
    );
    let pts: Vec<(f64, f64, f64)> = pts
        .into_iter()
        .map(|p| (p.0 - umin + m, p.1 - vmin + m, p.2))
        .collect();
    let tris = crate::cloth::grid_triangles(grid)
        .into_iter()
        .filter(|t| t.iter().all(|&k| keep(k as usize)));
    rasterize(&pts, x, tris, w, h)
}
