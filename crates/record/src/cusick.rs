//! A Cusick drape dataset laid out as `datasets/cusick/` (the BDP dataset of Gong, Mao & Wang, CVPR
//! 2024): `fabrics.csv`, `captures_index.csv`, the silhouette photos, the template disc and the
//! captures' registered meshes or hem curves. Every bad or missing file is an `InputError` naming it.

use crate::table::{Table, read_table};
use anyhow::Result;
use drapelab_core::error::InputError;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// A row of `fabrics.csv`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct Fabric {
    /// Fabric number.
    pub fabric: i32,
    /// Name, when known.
    #[serde(default)]
    pub name: String,
    /// Areal density, kg/m² (None where unknown).
    pub areal_density_kg_per_m2: Option<f64>,
    /// Specimen diameter, m.
    pub specimen_diameter_m: f64,
    /// Pedestal diameter, m.
    pub pedestal_diameter_m: f64,
}

/// A row of `captures_index.csv`: one capture of one specimen.
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct CaptureLabel {
    /// Fabric number.
    pub fabric: i32,
    /// Specimen ("sample") number.
    pub sample: i32,
    /// Capture number (1–2 face up, 3–4 face down).
    pub capture: i32,
    /// "up" or "down".
    pub face: String,
    /// `template_registered`, `hem_curve_loft`, or empty when the capture has no mesh.
    #[serde(default)]
    pub mesh_kind: String,
    /// Its silhouette photo, relative to the dataset folder.
    pub silhouette: String,
    /// The silhouette that matches its mesh (usually its own).
    #[serde(default)]
    pub silhouette_matching_mesh: String,
    /// The packager's note (e.g. that the mesh is stored in a frame rotated by 90°).
    #[serde(default)]
    pub note: String,
}

/// The (fabric, sample, capture) of a capture.
pub type CaptureKey = (i32, i32, i32);

impl CaptureLabel {
    /// Its key.
    pub fn key(&self) -> CaptureKey {
        (self.fabric, self.sample, self.capture)
    }
    /// Whether its mesh is stored in a frame rotated by 90° about +z relative to its photo.
    pub fn mesh_rotated(&self) -> bool {
        self.note.contains("mesh frame rotated")
    }
}

/// One vertex of one capture's registered template (`captures.parquet`).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct CaptureVertex {
    /// Fabric number.
    pub fabric: i32,
    /// Specimen number.
    pub sample: i32,
    /// Capture number.
    pub capture: i32,
    /// "up" or "down".
    pub face: String,
    /// Template vertex (the same material point in every capture).
    pub vertex: i32,
    /// Position, m (z up, origin at the pedestal centre on its top).
    pub x_m: f32,
    /// Position, m.
    pub y_m: f32,
    /// Position, m.
    pub z_m: f32,
}

impl Table for CaptureVertex {
    const FILE: &'static str = "captures.parquet";
    const ROW: &'static str =
        "One vertex of one capture's registered template mesh (Cusick dataset).";
}

/// One point of one capture's hem polyline (`hem_curves.parquet`).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct HemPoint {
    /// Fabric number.
    pub fabric: i32,
    /// Specimen number.
    pub sample: i32,
    /// Capture number.
    pub capture: i32,
    /// "up" or "down".
    pub face: String,
    /// Order along the hem, counter-clockwise.
    pub point: i32,
    /// Position, m.
    pub x_m: f32,
    /// Position, m.
    pub y_m: f32,
    /// Position, m.
    pub z_m: f32,
}

impl Table for HemPoint {
    const FILE: &'static str = "hem_curves.parquet";
    const ROW: &'static str = "One point of one capture's hem polyline (Cusick dataset).";
}

#[derive(Serialize, Deserialize)]
struct Face {
    a: i32,
    b: i32,
    c: i32,
}
impl Table for Face {
    const FILE: &'static str = "template_faces.parquet";
    const ROW: &'static str = "One triangle of the template disc.";
}

#[derive(Serialize, Deserialize)]
struct Rest {
    vertex: i32,
    x_m: f64,
    y_m: f64,
}
impl Table for Rest {
    const FILE: &'static str = "template_rest.parquet";
    const ROW: &'static str = "One vertex of the flat template disc.";
}

/// The template disc: every vertex's flat (material) position and the triangles.
#[derive(Debug, Clone)]
pub struct Template {
    /// Flat position of each vertex, m.
    pub rest_xy: Vec<[f64; 2]>,
    /// Triangles (vertex indices).
    pub triangles: Vec<[usize; 3]>,
}

/// A Cusick dataset folder.
#[derive(Debug, Clone)]
pub struct CusickDataset {
    /// The folder.
    pub dir: PathBuf,
    /// `fabrics.csv`.
    pub fabrics: Vec<Fabric>,
    /// `captures_index.csv`, in file order.
    pub captures: Vec<CaptureLabel>,
}

/// The rows of a CSV file with a header line (`#` lines are comments), each deserialized as `T`; a
/// file that cannot be read or a row that does not fit is an [`InputError`] naming the file and row.
pub fn read_csv<T: serde::de::DeserializeOwned>(path: &Path) -> Result<Vec<T>, InputError> {
    let mut r = csv::ReaderBuilder::new()
        .comment(Some(b'#'))
        .from_path(path)
        .map_err(|e| InputError::new(path, "", format!("cannot read: {e}")))?;
    r.deserialize()
        .enumerate()
        .map(|(k, row)| {
            row.map_err(|e| InputError::new(path, format!("row {}", k + 1), e.to_string()))
        })
        .collect()
}

impl CusickDataset {
    /// Reads the folder's `fabrics.csv` and `captures_index.csv`; refuses a fabric with no capture.
    pub fn open(dir: &Path) -> Result<Self, InputError> {
        let fabrics: Vec<Fabric> = read_csv(&dir.join("fabrics.csv"))?;
        let index = dir.join("captures_index.csv");
        let captures: Vec<CaptureLabel> = read_csv(&index)?;
        if fabrics.is_empty() {
            return Err(InputError::new(dir.join("fabrics.csv"), "", "no fabric"));
        }
        for f in &fabrics {
            if !captures.iter().any(|c| c.fabric == f.fabric) {
                return Err(InputError::new(
                    &index,
                    format!("fabric {}", f.fabric),
                    "the fabric has no capture: add its rows or remove it from fabrics.csv",
                ));
            }
        }
        Ok(CusickDataset {
            dir: dir.to_path_buf(),
            fabrics,
            captures,
        })
    }

    /// A silhouette photo (a path relative to the folder) as a grey image.
    pub fn photo(&self, rel: &str) -> Result<image::GrayImage, InputError> {
        let path = self.dir.join(rel);
        let img = image::open(&path)
            .map_err(|e| InputError::new(&path, "", format!("cannot read the photo: {e}")))?;
        Ok(img.to_luma8())
    }

    /// The template disc.
    pub fn template(&self) -> Result<Template> {
        let mut rest = read_table::<Rest>(&self.dir.join("template_rest.parquet"))?;
        rest.sort_by_key(|r| r.vertex);
        let n = rest.len();
        let faces = read_table::<Face>(&self.dir.join("template_faces.parquet"))?;
        let mut triangles = Vec::with_capacity(faces.len());
        for f in faces {
            let t = [f.a, f.b, f.c].map(|v| v as usize);
            if t.iter().any(|&v| v >= n) {
                return Err(InputError::new(
                    self.dir.join("template_faces.parquet"),
                    "a, b, c",
                    format!("a vertex index ≥ {n} (the template's vertex count)"),
                )
                .into());
            }
            triangles.push(t);
        }
        Ok(Template {
            rest_xy: rest.iter().map(|r| [r.x_m, r.y_m]).collect(),
            triangles,
        })
    }

    /// Every registered capture mesh, vertices in template order.
    pub fn meshes(&self) -> Result<BTreeMap<CaptureKey, Vec<Vector3<f64>>>> {
        let rows = read_table::<CaptureVertex>(&self.dir.join("captures.parquet"))?;
        Ok(group_sorted(rows.iter().map(|v| {
            let p = Vector3::new(v.x_m as f64, v.y_m as f64, v.z_m as f64);
            ((v.fabric, v.sample, v.capture), v.vertex, p)
        })))
    }

    /// Every stored hem polyline, points in order (none when the folder has no `hem_curves.parquet`).
    pub fn hems(&self) -> Result<BTreeMap<CaptureKey, Vec<Vector3<f64>>>> {
        let path = self.dir.join("hem_curves.parquet");
        if !path.exists() {
            return Ok(BTreeMap::new());
        }
        let rows = read_table::<HemPoint>(&path)?;
        Ok(group_sorted(rows.iter().map(|h| {
            let p = Vector3::new(h.x_m as f64, h.y_m as f64, h.z_m as f64);
            ((h.fabric, h.sample, h.capture), h.point, p)
        })))
    }
}

/// Points grouped by capture, each group in the order of its index (vertex or hem point).
fn group_sorted(
    rows: impl Iterator<Item = (CaptureKey, i32, Vector3<f64>)>,
) -> BTreeMap<CaptureKey, Vec<Vector3<f64>>> {
    let mut out: BTreeMap<CaptureKey, Vec<(i32, Vector3<f64>)>> = BTreeMap::new();
    for (k, i, p) in rows {
        out.entry(k).or_default().push((i, p));
    }
    out.into_iter()
        .map(|(k, mut v)| {
            v.sort_by_key(|(i, _)| *i);
            (k, v.into_iter().map(|(_, p)| p).collect())
        })
        .collect()
}
