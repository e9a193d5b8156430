//! Texture mapping (seed 003 §10.8, Fig. 10.28): a fabric image laid on the material coordinates
//! with a number of repeats along the warp and the weft and an optional rotation, and the small
//! fabric textures drapelab draws itself.

use image::{Rgb, RgbImage};

/// How a texture image lies on the fabric.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TextureMapping {
    /// Repeats of the image across the fabric along the warp (x) and the weft (y); > 0. Default
    /// (1, 1): the image once over the whole sheet.
    pub repeats: [f64; 2],
    /// Rotation of the image on the fabric about the sheet's centre, degrees counter-clockwise seen
    /// from +z. Default 0: the image's horizontal runs along the warp.
    pub rotation_deg: f64,
}

impl Default for TextureMapping {
    fn default() -> Self {
        Self {
            repeats: [1.0, 1.0],
            rotation_deg: 0.0,
        }
    }
}

impl TextureMapping {
    /// Texture coordinates (s, t) of the material point `m` (m) on a sheet with lower corner
    /// `origin` and `size` (m): s grows along the warp, t against the weft (the image upright seen
    /// from above), one image per tile of size/repeats; s, t ∈ [0, repeats] when not rotated.
    pub fn texcoord(&self, m: [f64; 2], (origin, size): ([f64; 2], [f64; 2])) -> [f64; 2] {
        let c = [origin[0] + size[0] / 2.0, origin[1] + size[1] / 2.0];
        let (s, co) = (-self.rotation_deg).to_radians().sin_cos();
        let d = [m[0] - c[0], m[1] - c[1]];
        let r = [co * d[0] - s * d[1], s * d[0] + co * d[1]];
        let tile = [size[0] / self.repeats[0], size[1] / self.repeats[1]];
        [
            r[0] / tile[0] + self.repeats[0] / 2.0,
            self.repeats[1] / 2.0 - r[1] / tile[1],
        ]
    }
}

/// The colour (0..255 per channel) of `img` at texture coordinates (s, t), bilinear, repeating:
/// s = 0 is the image's left edge and t = 0 its top.
pub fn sample(img: &RgbImage, [s, t]: [f64; 2]) -> [f64; 3] {
    let (w, h) = (img.width() as i64, img.height() as i64);
    let (x, y) = (s * w as f64 - 0.5, t * h as f64 - 0.5);
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let px = |a: i64, b: i64| {
        img.get_pixel(a.rem_euclid(w) as u32, b.rem_euclid(h) as u32)
            .0
    };
    let (x0, y0) = (x0 as i64, y0 as i64);
    let mut out = [0.0; 3];
    for (dx, dy, wgt) in [
        (0, 0, (1.0 - fx) * (1.0 - fy)),
        (1, 0, fx * (1.0 - fy)),
        (0, 1, (1.0 - fx) * fy),
        (1, 1, fx * fy),
    ] {
        let p = px(x0 + dx, y0 + dy);
        for c in 0..3 {
            out[c] += wgt * p[c] as f64;
        }
    }
    out
}

/// A woven check drawn procedurally (`side` px square, tileable): navy and cream bands of yarn in
/// both directions, each yarn 4 px wide and shaded as a round thread, interlaced in plain weave so
/// the mixed squares show both colours.
pub fn woven_check(side: u32) -> RgbImage {
    const NAVY: [f64; 3] = [38.0, 52.0, 96.0];
    const CREAM: [f64; 3] = [226.0, 214.0, 184.0];
    const RED: [f64; 3] = [160.0, 40.0, 44.0];
    let yarn = 4u32;
    let band = |k: u32| {
        // Along one direction: half navy, half cream, with a thin red line in the cream.
        let f = (k % side) as f64 / side as f64;
        if f < 0.5 {
            NAVY
        } else if (0.72..0.78).contains(&f) {
            RED
        } else {
            CREAM
        }
    };
    RgbImage::from_fn(side, side, |x, y| {
        let (tx, ty) = (x / yarn, y / yarn);
        // Plain weave: the warp yarn (running along x, coloured by its y band) is on top where the
        // thread indices' sum is even.
        let warp_on_top = (tx + ty) % 2 == 0;
        let (colour, across) = if warp_on_top {
            (band(y), (y % yarn) as f64 + 0.5)
        } else {
            (band(x), (x % yarn) as f64 + 0.5)
        };
        let r = (across / yarn as f64 - 0.5) * 2.0;
        let lum = 0.72 + 0.28 * (1.0 - r * r).max(0.0).sqrt();
        Rgb(colour.map(|c| (c * lum).round().clamp(0.0, 255.0) as u8))
    })
}

/// Stripes along the warp (`side` px square, tileable): bands of colour that change along the
/// image's vertical, so on the fabric they run parallel to the warp.
pub fn warp_stripes(side: u32) -> RgbImage {
    const COLOURS: [[u8; 3]; 4] = [
        [196, 60, 52],
        [240, 232, 216],
        [44, 84, 132],
        [240, 232, 216],
    ];
    RgbImage::from_fn(side, side, |_, y| {
        let k = (y * COLOURS.len() as u32 / side) as usize;
        Rgb(COLOURS[k.min(COLOURS.len() - 1)])
    })
}

/// A checkerboard of `squares` × `squares` black and white squares, `side` px: for checking that a
/// mapping keeps shapes.
pub fn checkerboard(side: u32, squares: u32) -> RgbImage {
    RgbImage::from_fn(side, side, |x, y| {
        let k = (x * squares / side + y * squares / side) % 2;
        Rgb(if k == 0 { [20; 3] } else { [235; 3] })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texcoords_span_the_repeats_and_rotate_about_the_centre() {
        let ext = ([-0.45, -0.3], [0.9, 0.6]);
        let m = TextureMapping {
            repeats: [6.0, 4.0],
            rotation_deg: 0.0,
        };
        let a = m.texcoord([-0.45, 0.3], ext);
        let b = m.texcoord([0.45, -0.3], ext);
        assert!((a[0]).abs() < 1e-12 && (a[1]).abs() < 1e-12, "{a:?}");
        assert!(
            (b[0] - 6.0).abs() < 1e-12 && (b[1] - 4.0).abs() < 1e-12,
            "{b:?}"
        );
        // A quarter turn: a step along the warp becomes a step along the image's vertical.
        let r = TextureMapping {
            repeats: [1.0, 1.0],
            rotation_deg: 90.0,
        };
        let sq = ([-0.5, -0.5], [1.0, 1.0]);
        let (p, q) = (r.texcoord([0.0, 0.0], sq), r.texcoord([0.1, 0.0], sq));
        assert!(
            (q[0] - p[0]).abs() < 1e-12 && (q[1] - p[1] - 0.1).abs() < 1e-12,
            "{p:?} {q:?}"
        );
    }

    #[test]
    fn sampling_repeats_the_image() {
        let img = checkerboard(8, 2);
        assert_eq!(sample(&img, [0.25, 0.25]), sample(&img, [1.25, 3.25]));
        assert!(sample(&img, [0.25, 0.25])[0] < 50.0 && sample(&img, [0.75, 0.25])[0] > 200.0);
    }
}
