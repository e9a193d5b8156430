//! `particles.parquet`: one row per particle, columns `i`, `j` (u32), `x_m`, `y_m`, `z_m` (f64),
//! `present` (bool: false for a particle outside a disc sheet, which is not part of the fabric and
//! keeps its flat start position).

use crate::table::{Table, read_table, table_batch, write_parquet};
use anyhow::Result;
use drapelab_core::cloth::Grid;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// One particle of a solved sheet: its grid indices and position.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ParticleRow {
    /// Column index along x (0 at the −x edge); of a mesh sheet (`cloth.mesh`), the OBJ file's
    /// vertex, 0-based.
    pub i: u32,
    /// Row index along y (0 at the −y edge); 0 on a mesh sheet.
    pub j: u32,
    /// Position, m.
    pub x_m: f64,
    /// Position, m.
    pub y_m: f64,
    /// Position (height), m.
    pub z_m: f64,
    /// Whether the particle is part of the fabric: false outside a disc sheet's circle (such a
    /// particle is in no energy term and stays at its flat start position; leave it out of any
    /// measure).
    pub present: bool,
}

impl Table for ParticleRow {
    const FILE: &'static str = "particles.parquet";
    const ROW: &'static str = "One grid particle of a solved sheet (also `last_state.parquet` of a solve that did not converge); key-value metadata `status`, `solver`, `scene`, `self_contact_kappa_growth` (what the solve adapted, taken up by a restart).";
}

/// Writes the grid particles' positions (flagged absent where `absent` says so; an empty slice:
/// all present), with key-value metadata (status, solver, ...).
pub fn write_particles(
    path: &Path,
    grid: &Grid,
    x: &[Vector3<f64>],
    absent: &[bool],
    metadata: &[(&str, String)],
) -> Result<()> {
    let rows: Vec<ParticleRow> = (0..grid.len())
        .map(|p| ParticleRow {
            i: grid.ij(p).0 as u32,
            j: grid.ij(p).1 as u32,
            x_m: x[p].x,
            y_m: x[p].y,
            z_m: x[p].z,
            present: !absent.get(p).copied().unwrap_or(false),
        })
        .collect();
    let kv = metadata
        .iter()
        .map(|(k, v)| parquet::file::metadata::KeyValue::new(k.to_string(), v.clone()))
        .collect();
    let props = crate::table::writer_properties()
        .set_key_value_metadata(Some(kv))
        .build();
    // The run metadata also in the Arrow schema, which pyarrow's `read_table(...).schema.metadata`
    // and polars' `read_parquet_schema`-style readers see (the Parquet key-value pairs alone are
    // dropped by most dataframe readers).
    let batch = table_batch(&rows)?;
    let schema = batch.schema().as_ref().clone().with_metadata(
        metadata
            .iter()
            .map(|(k, v)| (k.to_string(), v.clone()))
            .collect(),
    );
    write_parquet(
        path,
        &batch.with_schema(std::sync::Arc::new(schema))?,
        Some(props),
    )
}

/// Reads `particles.parquet` back as (i, j, position) rows.
pub fn read_particles(path: &Path) -> Result<Vec<(u32, u32, Vector3<f64>)>> {
    Ok(read_table::<ParticleRow>(path)?
        .into_iter()
        .map(|r| (r.i, r.j, Vector3::new(r.x_m, r.y_m, r.z_m)))
        .collect())
}

/// Particles as [`read_particles`] gives them, with the file's key-value metadata.
pub type ParticlesWithMetadata = (
    Vec<(u32, u32, Vector3<f64>)>,
    std::collections::BTreeMap<String, String>,
);

/// [`read_particles`] with the file's key-value metadata (empty for a file written without).
pub fn read_particles_with_metadata(path: &Path) -> Result<ParticlesWithMetadata> {
    let rows = read_particles(path)?;
    let mut meta = std::collections::BTreeMap::new();
    let file = std::fs::File::open(path)?;
    if let Ok(reader) = parquet::file::reader::SerializedFileReader::new(file) {
        use parquet::file::reader::FileReader;
        let kv = reader
            .metadata()
            .file_metadata()
            .key_value_metadata()
            .cloned();
        for e in kv.unwrap_or_default() {
            meta.insert(e.key, e.value.unwrap_or_default());
        }
    }
    Ok((rows, meta))
}
