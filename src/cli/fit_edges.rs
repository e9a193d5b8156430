//! `drapelab fit-edges`: fit a photo's edges with polynomials (seed 000).

use super::{ViewArg, args, edges};
use crate::error::{EXIT_OK, InputError};
use anyhow::Result;
use std::path::{Path, PathBuf};

/// The flags of `drapelab fit-edges`.
#[derive(Debug, clap::Args)]
pub struct FitEdgesArgs {
    /// The photo (PNG or JPEG).
    pub photo: PathBuf,
    /// Output folder.
    #[arg(long)]
    pub out: PathBuf,
    /// Scale in the plane of the fixed corners, px per cm.
    #[arg(long, value_parser = args::positive)]
    pub px_per_cm: Option<f64>,
    /// Pixel positions of the two fixed corners: x1,y1,x2,y2 (pixel centres at integers, as
    /// image viewers and OpenCV number them).
    #[arg(long)]
    pub corners: Option<String>,
    /// Find the corners from two red markers (needs --side-cm).
    #[arg(long)]
    pub markers: bool,
    /// Distance between the fixed corners, cm (with --markers).
    #[arg(long, value_parser = args::positive)]
    pub side_cm: Option<f64>,
    /// A camera.json: view, side_cm, the scale (px_per_cm or a pinhole) and the corners
    /// (corners_px or markers); `render`'s own settings are optional.
    #[arg(long)]
    pub camera_json: Option<PathBuf>,
    /// Which hang the photo shows (ignored with --camera-json, which names it).
    #[arg(long, value_enum, default_value_t = ViewArg::Hang4)]
    pub view: ViewArg,
    /// Polynomial degree (1..=8).
    #[arg(long, default_value_t = 4, value_parser = args::degree())]
    pub degree: usize,
}

/// `drapelab fit-edges`: the flags into a calibration, then the fit.
pub fn run(a: FitEdgesArgs) -> Result<i32> {
    let calibration = FitCalibration {
        px_per_cm: a.px_per_cm,
        corners: a.corners,
        markers: a.markers,
        side_cm: a.side_cm,
        camera_json: a.camera_json,
    };
    fit_edges(&a.photo, &a.out, calibration, a.view, a.degree)
}

/// The calibration flags of `drapelab fit-edges`.
struct FitCalibration {
    px_per_cm: Option<f64>,
    corners: Option<String>,
    markers: bool,
    side_cm: Option<f64>,
    camera_json: Option<PathBuf>,
}

/// `drapelab fit-edges`.
fn fit_edges(
    photo: &Path,
    out: &Path,
    c: FitCalibration,
    view: ViewArg,
    degree: usize,
) -> Result<i32> {
    let mut view: crate::edges::View = view.into();
    let mut pinhole = None;
    let calibration = if let Some(cj) = c.camera_json {
        let cam = crate::edges::read_camera(&cj)?;
        view = cam.view;
        pinhole = cam.pinhole;
        cam.calibration(&cj)?
    } else if c.markers {
        let side = c.side_cm.ok_or_else(|| {
            InputError::new(
                "--side-cm",
                "",
                "--markers needs --side-cm (the distance between the corners)",
            )
        })?;
        crate::edges::Calibration::Markers { side_cm: side }
    } else {
        let (Some(s), Some(corners)) = (c.px_per_cm, c.corners) else {
            return Err(InputError::new(photo, "--corners", "give --px-per-cm and --corners x1,y1,x2,y2, or --markers --side-cm L, or --camera-json").into());
        };
        crate::edges::Calibration::Given {
            px_per_cm: s,
            corners: edges::parse_corners(&corners)?,
        }
    };
    let fits = crate::io::fit_photo(
        photo,
        out,
        &crate::edges::FitImageOptions {
            view,
            degree,
            calibration,
            pinhole,
        },
    )?;
    for f in &fits {
        eprintln!(
            "{}: {} points, RMS residual {:.4} cm, coefficients {:?}",
            f.edge, f.n_points, f.rms_residual_cm, f.coefficients
        );
    }
    Ok(EXIT_OK)
}
