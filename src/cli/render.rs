//! `drapelab render`: solve a 4- or 2-corner hang and render it as a photo.

use super::{args, load_scene};
use crate::error::{EXIT_OK, InputError};
use anyhow::Result;
use std::path::PathBuf;

/// The flags of `drapelab render`.
#[derive(Debug, clap::Args)]
pub struct RenderArgs {
    /// The scene (4 or 2 pinned corners).
    pub scene: PathBuf,
    /// Output folder.
    #[arg(long)]
    pub out: PathBuf,
    /// Scene overrides, as for simulate.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Scale in the plane of the fixed corners, px per cm (> 0, ≤ 200).
    #[arg(long, default_value_t = 8.0, value_parser = args::px_per_cm)]
    pub px_per_cm: f64,
    /// Pinhole camera at this distance (m) in front of the corners' plane; default orthographic.
    #[arg(long, value_parser = args::positive)]
    pub pinhole_distance_m: Option<f64>,
    /// Draw red markers at the two fixed corners.
    #[arg(long)]
    pub markers: bool,
    /// Gaussian noise, grey levels (σ ≥ 0).
    #[arg(long, default_value_t = 0.0, value_parser = args::non_negative)]
    pub noise: f64,
    /// Gaussian blur, px (σ ≥ 0).
    #[arg(long, default_value_t = 0.0, value_parser = args::non_negative)]
    pub blur_px: f64,
    /// Camera rotation about its axis, degrees (negative: clockwise).
    #[arg(long, default_value_t = 0.0, value_parser = args::finite)]
    pub rotate_deg: f64,
    /// Save as JPEG with this quality (1..=100) instead of PNG.
    #[arg(long, value_parser = clap::value_parser!(u8).range(1..=100))]
    pub jpeg_quality: Option<u8>,
    /// Seed of the noise.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

/// `drapelab render`: solve a hang and render it as a photo.
pub fn run(a: RenderArgs) -> Result<i32> {
    let loaded = load_scene(&a.scene, &a.set)?;
    let opts = render_options(
        a.px_per_cm,
        a.pinhole_distance_m,
        a.markers,
        a.noise,
        a.blur_px,
        a.rotate_deg,
        a.seed,
    )?;
    let _out = args::out_dir(&a.out)?;
    let path = crate::io::render_scene(&loaded, &a.out, &opts, a.jpeg_quality, 4)?;
    eprintln!("rendered {} → {}", loaded.scene.name, path.display());
    Ok(EXIT_OK)
}

/// The render options of `drapelab render`, checked.
fn render_options(
    px_per_cm: f64,
    pinhole_distance_m: Option<f64>,
    markers: bool,
    noise: f64,
    blur_px: f64,
    rotate_deg: f64,
    seed: u64,
) -> Result<crate::edges::RenderOptions, InputError> {
    // The numbers were checked by their value parsers (args.rs).
    let camera = match pinhole_distance_m {
        Some(d) => crate::edges::Camera::Pinhole { distance_m: d },
        None => crate::edges::Camera::Orthographic,
    };
    Ok(crate::edges::RenderOptions {
        camera,
        px_per_cm,
        marker_radius_px: if markers { 4.0 } else { 0.0 },
        noise_sigma: noise,
        blur_sigma_px: blur_px,
        rotation_deg: rotate_deg,
        seed,
        ..Default::default()
    })
}
