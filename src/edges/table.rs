//! `edges.parquet`: one row per edge and power: `edge`, `power` (u32), `coefficient` (f64, of x^power,
//! x and y in cm), and per edge `rms_residual_cm`, `n_points` (u32), `x_min_cm`, `x_max_cm`.

use super::EdgeFit;
use crate::io::write_atomic;
use anyhow::{Context, Result};
use arrow::array::{Array, Float64Array, RecordBatch, StringArray, UInt32Array};
use arrow::datatypes::{DataType, Field, Schema};
use parquet::arrow::ArrowWriter;
use parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder;
use std::path::Path;
use std::sync::Arc;

/// Writes the fits atomically.
pub fn write_edges(path: &Path, fits: &[EdgeFit]) -> Result<()> {
    let rows: Vec<(&EdgeFit, usize, f64)> = fits
        .iter()
        .flat_map(|f| {
            f.coefficients
                .iter()
                .enumerate()
                .map(move |(p, c)| (f, p, *c))
        })
        .collect();
    let schema = Arc::new(Schema::new(vec![
        Field::new("edge", DataType::Utf8, false),
        Field::new("power", DataType::UInt32, false),
        Field::new("coefficient", DataType::Float64, false),
        Field::new("rms_residual_cm", DataType::Float64, false),
        Field::new("n_points", DataType::UInt32, false),
        Field::new("x_min_cm", DataType::Float64, false),
        Field::new("x_max_cm", DataType::Float64, false),
    ]));
    let batch = RecordBatch::try_new(
        schema.clone(),
        vec![
            Arc::new(StringArray::from_iter_values(
                rows.iter().map(|r| r.0.edge.clone()),
            )),
            Arc::new(UInt32Array::from_iter_values(
                rows.iter().map(|r| r.1 as u32),
            )),
            Arc::new(Float64Array::from_iter_values(rows.iter().map(|r| r.2))),
            Arc::new(Float64Array::from_iter_values(
                rows.iter().map(|r| r.0.rms_residual_cm),
            )),
            Arc::new(UInt32Array::from_iter_values(
                rows.iter().map(|r| r.0.n_points as u32),
            )),
            Arc::new(Float64Array::from_iter_values(
                rows.iter().map(|r| r.0.x_min_cm),
            )),
            Arc::new(Float64Array::from_iter_values(
                rows.iter().map(|r| r.0.x_max_cm),
            )),
        ],
    )?;
    write_atomic(path, |f| {
        let mut w = ArrowWriter::try_new(f, schema, None)?;
        w.write(&batch)?;
        w.close()?;
        Ok(())
    })?;
    Ok(())
}

/// Reads fits back (edges in file order, coefficients by power).
pub fn read_edges(path: &Path) -> Result<Vec<EdgeFit>> {
    let f = std::fs::File::open(path).with_context(|| format!("cannot open {}", path.display()))?;
    let mut out: Vec<EdgeFit> = Vec::new();
    for batch in ParquetRecordBatchReaderBuilder::try_new(f)?.build()? {
        let b = batch?;
        let col = |n: &str| {
            b.column_by_name(n)
                .with_context(|| format!("{}: no column {n}", path.display()))
        };
        let edge = col("edge")?
            .as_any()
            .downcast_ref::<StringArray>()
            .context("edge: not a string column")?
            .clone();
        let power = col("power")?
            .as_any()
            .downcast_ref::<UInt32Array>()
            .context("power: not u32")?
            .clone();
        let f64col = |n: &str| -> Result<Float64Array> {
            Ok(col(n)?
                .as_any()
                .downcast_ref::<Float64Array>()
                .with_context(|| format!("{n}: not f64"))?
                .clone())
        };
        let (coef, rms, xmin, xmax) = (
            f64col("coefficient")?,
            f64col("rms_residual_cm")?,
            f64col("x_min_cm")?,
            f64col("x_max_cm")?,
        );
        let npts = col("n_points")?
            .as_any()
            .downcast_ref::<UInt32Array>()
            .context("n_points: not u32")?
            .clone();
        for r in 0..b.num_rows() {
            let name = edge.value(r).to_string();
            let fit = match out.iter_mut().find(|e| e.edge == name) {
                Some(e) => e,
                None => {
                    out.push(EdgeFit {
                        edge: name,
                        coefficients: Vec::new(),
                        rms_residual_cm: rms.value(r),
                        n_points: npts.value(r) as usize,
                        x_min_cm: xmin.value(r),
                        x_max_cm: xmax.value(r),
                    });
                    out.last_mut().expect("just pushed")
                }
            };
            let p = power.value(r) as usize;
            if fit.coefficients.len() <= p {
                fit.coefficients.resize(p + 1, 0.0);
            }
            fit.coefficients[p] = coef.value(r);
        }
    }
    Ok(out)
}
