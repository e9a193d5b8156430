//! `calibration.rrd`: every ICA decade of every calibration run, for replay in the rerun viewer. Per
//! sample and run: the best and mean cost as scalars over the `decade` timeline (seed 000 Fig. 13), the
//! countries as points in the normalised (stiffness, natural length, topology) box coloured by empire,
//! and the decade's best drape as a mesh with its fitted edge curves (red) and the measured ones (blue)
//! drawn in the camera plane just in front of the sheet.

use crate::Staged;
use crate::rerun;
use anyhow::Result;
use drapelab_core::cloth::Grid;
use drapelab_core::edges::EdgeFit;
use drapelab_core::optim::DecadeEvent;
use nalgebra::Vector3;
use std::path::Path;

/// A drape to log: its grid, particle positions (m) and fitted edges.
pub type Drape<'a> = (&'a Grid, &'a [Vector3<f64>], &'a [EdgeFit]);

/// Writes a calibration recording.
pub struct CalibrationRecorder {
    rec: rerun::RecordingStream,
    staged: Staged,
}

const PALETTE: [[u8; 3]; 10] = [
    [228, 26, 28],
    [55, 126, 184],
    [77, 175, 74],
    [152, 78, 163],
    [255, 127, 0],
    [166, 86, 40],
    [247, 129, 191],
    [153, 153, 153],
    [23, 190, 207],
    [188, 189, 34],
];

/// An edge curve (cm, relative to the reference line through `origin_m` along +x, up +z) as 3D points.
fn curve_points(e: &EdgeFit, origin_m: Vector3<f64>, span_cm: f64) -> Vec<[f32; 3]> {
    (0..=60)
        .map(|k| {
            let x = e.x_min_cm + (e.x_max_cm - e.x_min_cm) * k as f64 / 60.0;
            let y = e.eval(x);
            let (along, up) = match e.edge.as_str() {
                "left" => (y, -x),
                "right" => (y + span_cm, -x),
                _ => (x, y),
            };
            [
                (origin_m.x + along / 100.0) as f32,
                (origin_m.y - 0.01) as f32,
                (origin_m.z + up / 100.0) as f32,
            ]
        })
        .collect()
}

impl CalibrationRecorder {
    /// Starts a recording at `path` (renamed into place by [`Self::finish`]).
    pub fn new(path: &Path) -> Result<Self> {
        let staged = Staged::new(path)?;
        let rec = rerun::RecordingStreamBuilder::new(rerun::ApplicationId::new_or_unknown(
            "drapelab_calibration",
        ))
        .save(staged.path())?;
        rec.log_static("/", &rerun::ViewCoordinates::RIGHT_HAND_Z_UP())?;
        Ok(Self { rec, staged })
    }

    /// Logs one decade of `run` of `sample`. `coords` maps a country to its normalised plotting
    /// position; `drape` is the decade's best drape with its fitted edges; `origin_m` the left fixed corner.
    #[allow(clippy::too_many_arguments)]
    pub fn decade(
        &self,
        sample: &str,
        run: usize,
        ev: &DecadeEvent<'_>,
        coords: impl Fn(&[f64]) -> [f32; 3],
        drape: Option<Drape<'_>>,
        measured: &[EdgeFit],
        origin_m: Vector3<f64>,
        span_cm: f64,
    ) -> Result<()> {
        let base = format!("{}/run_{run}", sample.replace('/', "_"));
        self.rec.set_time_sequence("decade", ev.decade as i64);
        self.rec.log(
            format!("{base}/cost/best_pct"),
            &rerun::Scalars::single(ev.best_cost),
        )?;
        self.rec.log(
            format!("{base}/cost/mean_pct"),
            &rerun::Scalars::single(ev.mean_cost),
        )?;
        let mut pts = Vec::new();
        let mut colors = Vec::new();
        for (k, e) in ev.empires.iter().enumerate() {
            let [r, g, b] = PALETTE[k % PALETTE.len()];
            for c in std::iter::once(&e.imperialist).chain(&e.colonies) {
                pts.push(coords(&c.x));
                colors.push(rerun::Color::from_rgb(r, g, b));
            }
        }
        self.rec.log(
            format!("{base}/countries"),
            &rerun::Points3D::new(pts)
                .with_colors(colors)
                .with_radii([0.01f32]),
        )?;
        if let Some((grid, x, fitted)) = drape {
            let verts: Vec<[f32; 3]> = x[..grid.len()]
                .iter()
                .map(|p| [p.x as f32, p.y as f32, p.z as f32])
                .collect();
            self.rec.log(
                format!("{base}/drape/mesh"),
                &rerun::Mesh3D::new(verts)
                    .with_triangle_indices(drapelab_core::cloth::grid_triangles(grid)),
            )?;
            let lines: Vec<Vec<[f32; 3]>> = fitted
                .iter()
                .map(|e| curve_points(e, origin_m, span_cm))
                .collect();
            self.rec.log(
                format!("{base}/drape/fitted_edges"),
                &rerun::LineStrips3D::new(lines).with_colors([rerun::Color::from_rgb(230, 20, 20)]),
            )?;
        }
        let lines: Vec<Vec<[f32; 3]>> = measured
            .iter()
            .map(|e| curve_points(e, origin_m, span_cm))
            .collect();
        self.rec.log(
            format!("{base}/drape/measured_edges"),
            &rerun::LineStrips3D::new(lines).with_colors([rerun::Color::from_rgb(30, 60, 230)]),
        )?;
        Ok(())
    }

    /// Flushes and renames the recording into place.
    pub fn finish(self) -> Result<()> {
        self.rec.flush_blocking()?;
        drop(self.rec);
        self.staged.commit()?;
        Ok(())
    }
}
