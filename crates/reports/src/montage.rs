//! The montage of seed 003's drapes (`reports/seed003_drapes.png`): every drape as its smooth
//! B-spline surface (seed 003 §10.8; a disc trimmed along its outline), lit so that folds read, in a
//! labelled tile; a drape on a table or pedestal also from straight above.

use drapelab_core::cloth::Grid;
use drapelab_core::surface::{DrapeSurface, Paint, Parametrization, View, render_surface};
use image::{Rgb, RgbImage};
use nalgebra::Vector3;

/// One drape of the montage.
pub struct Tile<'a> {
    /// The label's first line (the scene's name).
    pub name: &'a str,
    /// The drape's grid.
    pub grid: &'a Grid,
    /// Its particles' positions (the grid's first), m.
    pub x: &'a [Vector3<f64>],
    /// Which particles belong to the sheet.
    pub present: Vec<bool>,
    /// Also show it from above (a drape on a table or pedestal).
    pub from_above: bool,
}

/// Side of a tile, px.
pub const TILE_PX: u32 = 350;
/// Height of a tile's label band, px.
pub const LABEL_PX: u32 = 40;
/// The cloth's colour in the montage.
pub const CLOTH: [f64; 3] = [214.0, 178.0, 140.0];

/// Writes `text` in `img` at (x, y) with the 8 × 8 font scaled `scale` times (ASCII; other characters
/// as '?'), clipped to the image.
pub fn draw_text(img: &mut RgbImage, text: &str, (x, y): (u32, u32), scale: u32, colour: [u8; 3]) {
    for (k, ch) in text.chars().enumerate() {
        let glyph = font8x8::legacy::BASIC_LEGACY[if ch.is_ascii() {
            ch as usize
        } else {
            '?' as usize
        }];
        for (row, bits) in glyph.iter().enumerate() {
            for col in 0..8u32 {
                if bits & (1 << col) == 0 {
                    continue;
                }
                for dy in 0..scale {
                    for dx in 0..scale {
                        let px = x + (k as u32 * 8 + col) * scale + dx;
                        let py = y + row as u32 * scale + dy;
                        if px < img.width() && py < img.height() {
                            img.put_pixel(px, py, Rgb(colour));
                        }
                    }
                }
            }
        }
    }
}

/// A drape's picture for a tile: its smooth surface, or the flat-shaded grid where it cannot be
/// interpolated.
pub fn picture(t: &Tile<'_>, view: View, size: (u32, u32)) -> RgbImage {
    match DrapeSurface::new(t.grid, t.x, &t.present, Parametrization::Uniform) {
        Some(s) => render_surface(&s.tessellate(120), &Paint::Plain(CLOTH), view, size, 12),
        None => drapelab_core::edges::render_view(
            t.grid,
            t.x,
            &t.present,
            view.azimuth_deg,
            view.elevation_deg,
            4.0,
            10,
        ),
    }
}

/// The montage: four tiles a row, each labelled with the scene and the view.
pub fn montage(tiles: &[Tile<'_>]) -> RgbImage {
    let mut pics: Vec<(String, RgbImage)> = Vec::new();
    let size = (TILE_PX, TILE_PX - LABEL_PX);
    for t in tiles {
        let oblique = View {
            azimuth_deg: 30.0,
            elevation_deg: 30.0,
        };
        pics.push((
            "30 deg above, turned 30 deg".into(),
            picture(t, oblique, size),
        ));
        if t.from_above {
            let above = View {
                azimuth_deg: 0.0,
                elevation_deg: 90.0,
            };
            pics.push(("from above".into(), picture(t, above, size)));
        }
    }
    let names: Vec<&str> = tiles
        .iter()
        .flat_map(|t| std::iter::repeat_n(t.name, if t.from_above { 2 } else { 1 }))
        .collect();
    let cols = 4u32;
    let rows = (pics.len() as u32).div_ceil(cols).max(1);
    let mut canvas = RgbImage::from_pixel(cols * TILE_PX, rows * TILE_PX, Rgb([255; 3]));
    for (k, ((view, pic), name)) in pics.iter().zip(&names).enumerate() {
        let (x0, y0) = ((k as u32 % cols) * TILE_PX, (k as u32 / cols) * TILE_PX);
        let pic =
            image::imageops::crop_imm(pic, 0, 0, pic.width().min(size.0), pic.height().min(size.1))
                .to_image();
        image::imageops::overlay(
            &mut canvas,
            &pic,
            (x0 + (size.0 - pic.width()) / 2) as i64,
            (y0 + LABEL_PX) as i64,
        );
        let scale = if name.len() as u32 * 16 <= TILE_PX - 8 {
            2
        } else {
            1
        };
        draw_text(&mut canvas, name, (x0 + 6, y0 + 4), scale, [20, 20, 20]);
        draw_text(
            &mut canvas,
            view,
            (x0 + 6, y0 + 4 + 8 * scale + 4),
            1,
            [90, 90, 90],
        );
        // A hairline between tiles.
        for d in 0..TILE_PX {
            canvas.put_pixel(x0 + TILE_PX - 1, y0 + d, Rgb([220; 3]));
            canvas.put_pixel(x0 + d, y0 + TILE_PX - 1, Rgb([220; 3]));
        }
    }
    canvas
}
