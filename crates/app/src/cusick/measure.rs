//! `cusick-measure` (issue 16): every capture of a Cusick dataset measured as the tester does, from
//! its silhouette photo and from its 3D mesh (or hem), so that each measure checks the other:
//! the drape coefficient (BS 5058) and the node count of the shadow's outline.

use crate::cusick::tables::OutlineRow;
use crate::job::Job;
use anyhow::Result;
use drapelab_core::cusick::{
    DcCapture, Face, ShadowMeasures, SilhouetteScale, Tester, hem_projection, mesh_projection,
    sector_angle_rad, shadow_measures, silhouette_projection,
};
use drapelab_core::table::Table;
use drapelab_record::cusick::{CusickDataset, Template};
use drapelab_record::write_table;
use nalgebra::Vector3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Parameters of a cusick-measure stage.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CusickMeasureParams {
    /// How the photos map to metres. Default: the BDP dataset's (723.2 px/m, centre (126.95, 127.44),
    /// shadow below grey 128).
    #[serde(default)]
    pub scale: SilhouetteScale,
}

/// One capture measured from its photo and from its mesh.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ShadowRow {
    /// Fabric number.
    pub fabric: i32,
    /// Specimen number.
    pub sample: i32,
    /// Capture number.
    pub capture: i32,
    /// "up", "down", or "unknown" where the dataset's index does not say.
    pub face: Face,
    /// `template_registered`, `hem_curve_loft`, or empty without a mesh.
    pub mesh_kind: String,
    /// Whether the mesh is stored in a frame rotated by 90° about +z (irrelevant to DC and nodes).
    pub mesh_rotated: bool,
    /// DC of the capture's own silhouette photo, %.
    pub dc_photo_pct: f64,
    /// Nodes of that photo's outline.
    pub nodes_photo: u32,
    /// DC of the vertical projection of its mesh (or hem), % (None without one).
    pub dc_mesh_pct: Option<f64>,
    /// Nodes of the mesh projection's outline.
    pub nodes_mesh: Option<u32>,
    /// DC of the photo that matches the mesh (its own, but for a few mislabelled captures), %.
    pub dc_matching_photo_pct: Option<f64>,
    /// Nodes of that photo.
    pub nodes_matching_photo: Option<u32>,
    /// Smallest radius of the photo's smoothed outline, m.
    pub r_outline_min_m: f64,
    /// Largest radius of the photo's smoothed outline, m.
    pub r_outline_max_m: f64,
}

impl ShadowRow {
    /// The capture's photo DC as the statistics over fabrics take it.
    pub fn dc_capture(&self) -> DcCapture {
        DcCapture {
            fabric: self.fabric,
            sample: self.sample,
            face: self.face,
            dc_pct: self.dc_photo_pct,
        }
    }
}

#[cfg(test)]
impl ShadowRow {
    /// A capture of fabric `fabric`, specimen `sample` on `face` whose photo shows DC `dc_pct` and
    /// eight nodes, with no mesh: for tests of what is made of the photos' DC.
    pub(crate) fn photo(fabric: i32, sample: i32, capture: i32, face: Face, dc_pct: f64) -> Self {
        ShadowRow {
            fabric,
            sample,
            capture,
            face,
            mesh_kind: String::new(),
            mesh_rotated: false,
            dc_photo_pct: dc_pct,
            nodes_photo: 8,
            dc_mesh_pct: None,
            nodes_mesh: None,
            dc_matching_photo_pct: None,
            nodes_matching_photo: None,
            r_outline_min_m: 0.1,
            r_outline_max_m: 0.15,
        }
    }
}

impl Table for ShadowRow {
    const FILE: &'static str = "shadows.parquet";
    const ROW: &'static str = "One Cusick capture: DC and nodes of its silhouette photo and of its mesh's vertical projection.";
}

/// The outline rows of a capture's photo.
pub fn photo_outline<'a>(
    r: &'a ShadowRow,
    outline_m: &'a [f64],
) -> impl Iterator<Item = OutlineRow> + 'a {
    outline_m
        .iter()
        .enumerate()
        .map(|(k, &radius_m)| OutlineRow {
            fabric: r.fabric,
            sample: Some(r.sample),
            capture: Some(r.capture),
            seed: None,
            theta_rad: sector_angle_rad(k, outline_m.len()),
            radius_m,
        })
}

/// Measures every capture of `data` (in parallel), calling `done` after each: its row and its
/// photo's smoothed outline r(θ), m.
pub fn measure_dataset(
    data: &CusickDataset,
    scale: &SilhouetteScale,
    done: &(dyn Fn() + Sync),
) -> Result<Vec<(ShadowRow, Vec<f64>)>> {
    let tester = Tester::default();
    let template = data.template()?;
    let meshes = data.meshes()?;
    let hems = data.hems()?;
    data.captures
        .par_iter()
        .map(|c| {
            let photo = shadow_measures(
                &silhouette_projection(&data.photo(&c.silhouette)?, scale),
                &tester,
            );
            let mesh = mesh_measures(&template, meshes.get(&c.key()), hems.get(&c.key()), &tester);
            let matching = match (&mesh, c.silhouette_matching_mesh.as_str()) {
                (None, _) | (_, "") => None,
                (_, m) if m == c.silhouette => Some(photo.clone()),
                (_, m) => Some(shadow_measures(
                    &silhouette_projection(&data.photo(m)?, scale),
                    &tester,
                )),
            };
            done();
            let r = row(c, &photo, mesh.as_ref(), matching.as_ref());
            Ok((r, photo.outline_m))
        })
        .collect()
}

/// The shadow measures of a capture's mesh (or of its hem where only the hem was scanned), if
/// either matches the template.
pub fn mesh_measures(
    t: &Template,
    mesh: Option<&Vec<Vector3<f64>>>,
    hem: Option<&Vec<Vector3<f64>>>,
    tester: &Tester,
) -> Option<ShadowMeasures> {
    match (mesh, hem) {
        (Some(x), _) if x.len() == t.rest_xy.len() => {
            Some(shadow_measures(&mesh_projection(x, &t.triangles), tester))
        }
        (_, Some(h)) => Some(shadow_measures(&hem_projection(h), tester)),
        _ => None,
    }
}

/// One capture's row of the measure table.
pub fn row(
    c: &drapelab_record::cusick::CaptureLabel,
    photo: &ShadowMeasures,
    mesh: Option<&ShadowMeasures>,
    matching: Option<&ShadowMeasures>,
) -> ShadowRow {
    let (rmin, rmax) = photo
        .outline_m
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(a, b), &r| (a.min(r), b.max(r)));
    ShadowRow {
        fabric: c.fabric,
        sample: c.sample,
        capture: c.capture,
        face: Face::of(&c.face),
        mesh_kind: c.mesh_kind.clone(),
        mesh_rotated: c.mesh_rotated(),
        dc_photo_pct: photo.dc_pct,
        nodes_photo: photo.nodes as u32,
        dc_mesh_pct: mesh.map(|m| m.dc_pct),
        nodes_mesh: mesh.map(|m| m.nodes as u32),
        dc_matching_photo_pct: matching.map(|m| m.dc_pct),
        nodes_matching_photo: matching.map(|m| m.nodes as u32),
        r_outline_min_m: rmin,
        r_outline_max_m: rmax,
    }
}

/// The input of a cusick-measure stage (its other files are read through the index's folder).
pub struct CusickMeasureInputs {
    /// captures_index.csv of a Cusick dataset.
    pub index: std::path::PathBuf,
}

/// The `run` of the stage kind over this workflow.
pub fn run(ctx: &Job<'_, CusickMeasureInputs>, p: &CusickMeasureParams) -> Result<Vec<ShadowRow>> {
    let index = &ctx.inputs.index;
    let data = CusickDataset::open(index.parent().unwrap_or(std::path::Path::new(".")))?;
    ctx.started(data.captures.len());
    let measured = measure_dataset(&data, &p.scale, &|| ctx.item_done())?;
    let outlines: Vec<OutlineRow> = measured
        .iter()
        .flat_map(|(r, outline)| photo_outline(r, outline))
        .collect();
    let rows: Vec<ShadowRow> = measured.into_iter().map(|(r, _)| r).collect();
    write_table(ctx.output("table")?, &rows)?;
    write_table(ctx.output("outlines")?, &outlines)?;
    Ok(rows)
}
