//! `particles.parquet`: one row per particle, columns `i`, `j` (u32), `x_m`, `y_m`, `z_m` (f64).

use crate::write_parquet;
use anyhow::{Context, Result};
use arrow::array::{Array, Float64Array, RecordBatch, UInt32Array};
use arrow::datatypes::{DataType, Field, Schema};
use drapelab_core::cloth::Grid;
use nalgebra::Vector3;
use parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder;
use std::path::Path;
use std::sync::Arc;

/// Writes the grid particles' positions, with key-value metadata (status, solver, ...).
pub fn write_particles(
    path: &Path,
    grid: &Grid,
    x: &[Vector3<f64>],
    metadata: &[(&str, String)],
) -> Result<()> {
    let n = grid.len();
    let schema = Arc::new(Schema::new(vec![
        Field::new("i", DataType::UInt32, false),
        Field::new("j", DataType::UInt32, false),
        Field::new("x_m", DataType::Float64, false),
        Field::new("y_m", DataType::Float64, false),
        Field::new("z_m", DataType::Float64, false),
    ]));
    let i: UInt32Array = (0..n).map(|p| grid.ij(p).0 as u32).collect();
    let j: UInt32Array = (0..n).map(|p| grid.ij(p).1 as u32).collect();
    let col = |c: usize| -> Float64Array { x[..n].iter().map(|v| v[c]).collect() };
    let batch = RecordBatch::try_new(
        schema.clone(),
        vec![
            Arc::new(i),
            Arc::new(j),
            Arc::new(col(0)),
            Arc::new(col(1)),
            Arc::new(col(2)),
        ],
    )?;
    let kv = metadata
        .iter()
        .map(|(k, v)| parquet::file::metadata::KeyValue::new(k.to_string(), v.clone()))
        .collect();
    let props = crate::table::writer_properties()
        .set_key_value_metadata(Some(kv))
        .build();
    write_parquet(path, &batch, Some(props))?;
    Ok(())
}

/// Reads `particles.parquet` back as (i, j, position) rows.
pub fn read_particles(path: &Path) -> Result<Vec<(u32, u32, Vector3<f64>)>> {
    let f = std::fs::File::open(path).with_context(|| format!("cannot open {}", path.display()))?;
    let reader = ParquetRecordBatchReaderBuilder::try_new(f)?.build()?;
    let mut out = Vec::new();
    for batch in reader {
        let b = batch?;
        let get_u = |name: &str| {
            b.column_by_name(name)
                .and_then(|c| c.as_any().downcast_ref::<UInt32Array>().cloned())
        };
        let get_f = |name: &str| {
            b.column_by_name(name)
                .and_then(|c| c.as_any().downcast_ref::<Float64Array>().cloned())
        };
        let (Some(i), Some(j), Some(x), Some(y), Some(z)) = (
            get_u("i"),
            get_u("j"),
            get_f("x_m"),
            get_f("y_m"),
            get_f("z_m"),
        ) else {
            anyhow::bail!("{}: not a particles table", path.display());
        };
        for r in 0..i.len() {
            out.push((
                i.value(r),
                j.value(r),
                Vector3::new(x.value(r), y.value(r), z.value(r)),
            ));
        }
    }
    Ok(out)
}
