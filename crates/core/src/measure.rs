//! Drape measured as the textile standards do (BS 5058, ISO 9073-9): the vertical projection of the
//! draped specimen, the drape coefficient DC = (S − S_s)/(S_f − S_s) (S the projected area, S_s the
//! support's, S_f the flat specimen's), and the number of folds (nodes) around a pedestal.

use nalgebra::Vector3;

/// A binary image of a vertical projection: `covered[row * nx + col]`, pixel size `pixel_m`, lower-left
/// corner at `origin_m`.
#[derive(Debug, Clone, PartialEq)]
pub struct Projection {
    /// Pixels per row.
    pub nx: usize,
    /// Rows.
    pub ny: usize,
    /// Side of a pixel, m.
    pub pixel_m: f64,
    /// (x, y) of the lower-left corner, m.
    pub origin_m: [f64; 2],
    /// Covered pixels.
    pub covered: Vec<bool>,
}

impl Projection {
    /// Covered area, m².
    pub fn area_m2(&self) -> f64 {
        self.covered.iter().filter(|c| **c).count() as f64 * self.pixel_m * self.pixel_m
    }

    /// Centre (x, y) of pixel (col, row), m.
    pub fn centre(&self, col: usize, row: usize) -> [f64; 2] {
        [
            self.origin_m[0] + (col as f64 + 0.5) * self.pixel_m,
            self.origin_m[1] + (row as f64 + 0.5) * self.pixel_m,
        ]
    }
}

/// The vertical projection of the sheet's `triangles` (indices into `x`; [`crate::build::scene_triangles`])
/// on a raster of `pixels` across the larger side of their bounding box.
pub fn vertical_projection(
    x: &[Vector3<f64>],
    triangles: &[[u32; 3]],
    pixels: usize,
) -> Projection {
    let mut used = vec![false; x.len()];
    triangles
        .iter()
        .flatten()
        .for_each(|&v| used[v as usize] = true);
    let pts: Vec<&Vector3<f64>> = (0..x.len()).filter(|&p| used[p]).map(|p| &x[p]).collect();
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in &pts {
        lo = [lo[0].min(p.x), lo[1].min(p.y)];
        hi = [hi[0].max(p.x), hi[1].max(p.y)];
    }
    let span = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(1e-12);
    let pixel = span / pixels.max(8) as f64;
    let origin = [lo[0] - pixel, lo[1] - pixel];
    let nx = ((hi[0] - origin[0]) / pixel).ceil() as usize + 2;
    let ny = ((hi[1] - origin[1]) / pixel).ceil() as usize + 2;
    let mut proj = Projection {
        nx,
        ny,
        pixel_m: pixel,
        origin_m: origin,
        covered: vec![false; nx * ny],
    };
    proj.fill_triangles(x, triangles.iter().map(|t| t.map(|v| v as usize)));
    proj
}

impl Projection {
    /// An empty raster of `nx` × `ny` pixels of side `pixel_m`, lower-left corner at `origin_m`.
    pub fn empty(nx: usize, ny: usize, pixel_m: f64, origin_m: [f64; 2]) -> Self {
        Projection {
            nx,
            ny,
            pixel_m,
            origin_m,
            covered: vec![false; nx * ny],
        }
    }

    /// Covers every pixel whose centre lies in the vertical projection of a triangle of `x`.
    pub fn fill_triangles(
        &mut self,
        x: &[Vector3<f64>],
        triangles: impl IntoIterator<Item = [usize; 3]>,
    ) {
        for [a, b, c] in triangles {
            self.fill_triangle(&x[a], &x[b], &x[c]);
        }
    }

    fn fill_triangle(&mut self, a: &Vector3<f64>, b: &Vector3<f64>, c: &Vector3<f64>) {
        let (nx, ny, pixel, origin) = (self.nx, self.ny, self.pixel_m, self.origin_m);
        let area2 = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
        if area2.abs() < 1e-300 {
            return;
        }
        let lo = |v: f64, o: f64| ((v - o) / pixel).floor().max(0.0) as usize;
        let hi = |v: f64, o: f64, n: usize| (((v - o) / pixel).ceil().max(0.0) as usize).min(n - 1);
        let (col0, col1) = (
            lo(a.x.min(b.x).min(c.x), origin[0]),
            hi(a.x.max(b.x).max(c.x), origin[0], nx),
        );
        let (row0, row1) = (
            lo(a.y.min(b.y).min(c.y), origin[1]),
            hi(a.y.max(b.y).max(c.y), origin[1], ny),
        );
        for row in row0..=row1 {
            for col in col0..=col1 {
                let px = origin[0] + (col as f64 + 0.5) * pixel;
                let py = origin[1] + (row as f64 + 0.5) * pixel;
                let w0 = (b.x - px) * (c.y - py) - (c.x - px) * (b.y - py);
                let w1 = (c.x - px) * (a.y - py) - (a.x - px) * (c.y - py);
                let w2 = (a.x - px) * (b.y - py) - (b.x - px) * (a.y - py);
                let inside = if area2 > 0.0 {
                    w0 >= 0.0 && w1 >= 0.0 && w2 >= 0.0
                } else {
                    w0 <= 0.0 && w1 <= 0.0 && w2 <= 0.0
                };
                if inside {
                    self.covered[row * nx + col] = true;
                }
            }
        }
    }
}

/// Drape coefficient in %: 100 (S − S_s)/(S_f − S_s). 100 % for a specimen that stays flat, 0 % for
/// one that hangs straight down around its support.
pub fn drape_coefficient_pct(projected_m2: f64, flat_m2: f64, support_m2: f64) -> f64 {
    100.0 * (projected_m2 - support_m2) / (flat_m2 - support_m2)
}

/// The outline of a projection in polar form about `centre`: the largest covered radius in each of
/// `bins` equal angular sectors (0 where a sector has no covered pixel).
pub fn outline_radii(proj: &Projection, centre: [f64; 2], bins: usize) -> Vec<f64> {
    let mut r = vec![0.0f64; bins];
    for row in 0..proj.ny {
        for col in 0..proj.nx {
            if !proj.covered[row * proj.nx + col] {
                continue;
            }
            let [x, y] = proj.centre(col, row);
            let (dx, dy) = (x - centre[0], y - centre[1]);
            let t = dy.atan2(dx).rem_euclid(std::f64::consts::TAU);
            let k = ((t / std::f64::consts::TAU * bins as f64) as usize).min(bins - 1);
            r[k] = r[k].max((dx * dx + dy * dy).sqrt());
        }
    }
    r
}

/// Number of folds (nodes) of a drape: the local maxima of its outline radius r(θ), smoothed over
/// `smooth` sectors on each side, that stand above both neighbouring minima by more than
/// `prominence_rel` of the mean radius.
pub fn count_nodes(radii: &[f64], smooth: usize, prominence_rel: f64) -> usize {
    let s = smooth_circular(radii, smooth);
    let mean = s.iter().sum::<f64>() / s.len().max(1) as f64;
    count_rises(&s, prominence_rel * mean)
}

/// `radii` averaged over `smooth` sectors on each side, around the circle.
pub fn smooth_circular(radii: &[f64], smooth: usize) -> Vec<f64> {
    let n = radii.len();
    let w = 2 * smooth + 1;
    (0..n)
        .map(|k| {
            (0..w)
                .map(|d| radii[(k + n * w + d - smooth) % n])
                .sum::<f64>()
                / w as f64
        })
        .collect()
}

/// Number of maxima of the circular sequence `s` that stand above both neighbouring minima by more
/// than `threshold` (the same unit as `s`).
pub fn count_rises(s: &[f64], threshold: f64) -> usize {
    let n = s.len();
    if n < 3 {
        return 0;
    }
    // Walk the circle from its global minimum, counting rises and falls of at least the threshold.
    let start = (0..n).min_by(|&a, &b| s[a].total_cmp(&s[b])).unwrap_or(0);
    let (mut count, mut low, mut high, mut rising) = (0, s[start], s[start], true);
    for k in 1..=n {
        let v = s[(start + k) % n];
        if rising {
            if v > high {
                high = v;
            }
            if high - v > threshold && high - low > threshold {
                count += 1;
                rising = false;
                low = v;
            }
        } else {
            if v < low {
                low = v;
            }
            if v - low > threshold {
                rising = true;
                high = v;
            }
        }
    }
    count
}

/// The mean of `v`; none when it is empty.
pub fn mean(v: &[f64]) -> Option<f64> {
    (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
}

/// Mean and sample standard deviation of `v` (0 and 0 when empty; SD 0 for one value).
pub fn mean_sd(v: &[f64]) -> (f64, f64) {
    let n = v.len().max(1) as f64;
    let m = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
    (m, var.sqrt())
}

/// The least-squares line through `pts` (x, y): the means (x̄, ȳ) it passes through (0 for no
/// point) and its slope, none where the x do not spread.
pub fn least_squares_line(pts: &[(f64, f64)]) -> ([f64; 2], Option<f64>) {
    let n = pts.len().max(1) as f64;
    let (mx, my) = pts
        .iter()
        .fold((0.0, 0.0), |a, p| (a.0 + p.0 / n, a.1 + p.1 / n));
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    ([mx, my], (sxx > 0.0).then(|| sxy / sxx))
}

/// The median of the finite values of `v` (the mean of the middle two for an even count); NaN when
/// none is finite.
pub fn median(v: &[f64]) -> f64 {
    let mut s: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
    s.sort_by(f64::total_cmp);
    match s.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => s[n / 2],
        n => 0.5 * (s[n / 2 - 1] + s[n / 2]),
    }
}

/// The measures of a solved drape (see [`drape_measures`]).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct DrapeMeasures {
    /// Area of the vertical projection, m² (of the whole sheet, for a quarter or half model).
    pub projected_area_m2: f64,
    /// Area of the flat specimen's projection on the same raster, m² (a garment's: its pattern's area).
    pub flat_area_m2: f64,
    /// Area of the support's top face (pedestal or table), m²; None without one.
    pub support_area_m2: Option<f64>,
    /// Drape coefficient, %; None without a support.
    pub drape_coefficient_pct: Option<f64>,
    /// Folds (nodes) around the support; None without a support.
    pub folds: Option<usize>,
    /// Largest penetration of a particle into an obstacle, m (0 when none).
    pub max_penetration_m: f64,
}

/// Pixels across a projection.
const PIXELS: usize = 600;

/// The drape coefficient, folds and penetration of a drape `x` of `scene` (its sheet's triangles). The support is the
/// first pedestal or box among the obstacles (its area: the part of the flat specimen above it); folds
/// are counted about its centre (outline in 360
/// sectors smoothed over ±3°, prominence 8 % of the mean radius: more than the steps of a disc cut
/// from a square grid, far less than a fold).
pub fn drape_measures(scene: &crate::scene::Scene, x: &[Vector3<f64>]) -> DrapeMeasures {
    use crate::obstacle::Obstacle;
    let x0 = crate::build::initial_positions(scene);
    let triangles = crate::build::scene_triangles(scene);
    let proj = vertical_projection(x, &triangles, PIXELS);
    let flat_proj = vertical_projection(&x0, &triangles, PIXELS);
    // The support: the first table or pedestal; its area is the part of the flat specimen above its
    // top face (on the same raster, so that a flat specimen reads DC = 100 % exactly).
    let support = scene
        .obstacles
        .iter()
        .find(|o| matches!(o, Obstacle::Pedestal { .. } | Obstacle::Box { .. }))
        .map(|o| {
            let mut cells = 0usize;
            for row in 0..flat_proj.ny {
                for col in 0..flat_proj.nx {
                    let [px, py] = flat_proj.centre(col, row);
                    if flat_proj.covered[row * flat_proj.nx + col] && o.top_at(px, py).is_some() {
                        cells += 1;
                    }
                }
            }
            let centre = match o {
                Obstacle::Pedestal { centre_m, .. } => [centre_m[0], centre_m[1]],
                Obstacle::Box { min_m, max_m } => {
                    [0.5 * (min_m[0] + max_m[0]), 0.5 * (min_m[1] + max_m[1])]
                }
                _ => [0.0, 0.0],
            };
            (cells as f64 * flat_proj.pixel_m * flat_proj.pixel_m, centre)
        });
    // A quarter or half model stands for 2^k times itself (k symmetry planes); its outline covers a
    // sector only, so its folds are not counted.
    let k = scene.boundary.symmetry_edges.len();
    let factor = (1u32 << k) as f64;
    let s = proj.area_m2() * factor;
    // A garment starts placed in 3D: its flat area is its pattern's.
    let flat = match scene.pattern().filter(|p| !p.is_flat()) {
        Some(p) => p.rest_area_m2(),
        None => flat_proj.area_m2() * factor,
    };
    let support = support.map(|(a, c)| (a * factor, c));
    let n = x0.len();
    DrapeMeasures {
        projected_area_m2: s,
        flat_area_m2: flat,
        support_area_m2: support.map(|(a, _)| a),
        drape_coefficient_pct: support.map(|(a, _)| drape_coefficient_pct(s, flat, a)),
        folds: support
            .filter(|_| k == 0)
            .map(|(_, c)| count_nodes(&outline_radii(&proj, c, 360), 3, 0.08)),
        max_penetration_m: crate::physics::max_penetration_m(&scene.obstacles, &x[..n]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_least_squares_line_through_points_on_a_line_is_that_line() {
        let pts: Vec<(f64, f64)> = (0..5).map(|i| (i as f64, 1.5 - 0.25 * i as f64)).collect();
        let ([mx, my], slope) = least_squares_line(&pts);
        assert!((mx - 2.0).abs() < 1e-15 && (my - 1.0).abs() < 1e-15);
        assert!((slope.unwrap() + 0.25).abs() < 1e-15);
        // Symmetric scatter about it leaves it where it is; x that do not spread give no slope.
        let noisy = [(0.0, 1.6), (0.0, 1.4), (4.0, 0.6), (4.0, 0.4)];
        assert!((least_squares_line(&noisy).1.unwrap() + 0.25).abs() < 1e-15);
        assert_eq!(
            least_squares_line(&[(1.0, 2.0), (1.0, 4.0)]),
            ([1.0, 3.0], None)
        );
    }

    fn lobed(k: usize, amp: f64) -> Projection {
        let (nx, pixel) = (400, 0.001);
        let mut covered = vec![false; nx * nx];
        for row in 0..nx {
            for col in 0..nx {
                let (x, y) = (
                    (col as f64 + 0.5) * pixel - 0.2,
                    (row as f64 + 0.5) * pixel - 0.2,
                );
                let r = 0.12 * (1.0 + amp * (k as f64 * y.atan2(x)).cos());
                covered[row * nx + col] = (x * x + y * y).sqrt() <= r;
            }
        }
        Projection {
            nx,
            ny: nx,
            pixel_m: pixel,
            origin_m: [-0.2, -0.2],
            covered,
        }
    }

    #[test]
    fn a_projection_with_k_lobes_has_k_nodes() {
        for k in 3..=10 {
            let p = lobed(k, 0.15);
            let r = outline_radii(&p, [0.0, 0.0], 360);
            assert_eq!(count_nodes(&r, 3, 0.03), k, "k = {k}");
        }
        // A circle has none.
        let r = outline_radii(&lobed(5, 0.0), [0.0, 0.0], 360);
        assert_eq!(count_nodes(&r, 3, 0.03), 0);
    }

    #[test]
    fn the_projected_area_of_a_flat_square_is_its_area() {
        let g = crate::cloth::Grid::uniform(11, 11, 0.2, 0.2);
        let x = g.flat_positions();
        let p = vertical_projection(&x, &crate::cloth::grid_triangles(&g), 800);
        assert!((p.area_m2() - 0.04).abs() < 0.005 * 0.04, "{}", p.area_m2());
        assert!((drape_coefficient_pct(p.area_m2(), 0.04, 0.01) - 100.0).abs() < 1.0);
    }
}
