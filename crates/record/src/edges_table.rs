//! `edges.parquet`: one row per sample, edge and power: `sample` (photo or simulation name), `edge`,
//! `power` (u32), `coefficient` (f64, of x^power, x and y in cm), and per edge `rms_residual_cm`,
//! `n_points` (u32), `x_min_cm`, `x_max_cm`.

use crate::write_parquet;
use anyhow::{Context, Result};
use arrow::array::{Array, Float64Array, RecordBatch, StringArray, UInt32Array};
use arrow::datatypes::{DataType, Field, Schema};
use drapelab_core::edges::EdgeFit;
use parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder;
use std::path::Path;
use std::sync::Arc;

/// Writes (sample, fit) pairs atomically.
pub fn write_edges(path: &Path, fits: &[(String, EdgeFit)]) -> Result<()> {
    let rows: Vec<(&str, &EdgeFit, usize, f64)> = fits
        .iter()
        .flat_map(|(s, f)| {
            f.coefficients
                .iter()
                .enumerate()
                .map(move |(p, c)| (s.as_str(), f, p, *c))
        })
        .collect();
    let schema = Arc::new(Schema::new(vec![
        Field::new("sample", DataType::Utf8, false),
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
            Arc::new(StringArray::from_iter_values(rows.iter().map(|r| r.0))),
            Arc::new(StringArray::from_iter_values(
                rows.iter().map(|r| r.1.edge.clone()),
            )),
            Arc::new(UInt32Array::from_iter_values(
                rows.iter().map(|r| r.2 as u32),
            )),
            Arc::new(Float64Array::from_iter_values(rows.iter().map(|r| r.3))),
            Arc::new(Float64Array::from_iter_values(
                rows.iter().map(|r| r.1.rms_residual_cm),
            )),
            Arc::new(UInt32Array::from_iter_values(
                rows.iter().map(|r| r.1.n_points as u32),
            )),
            Arc::new(Float64Array::from_iter_values(
                rows.iter().map(|r| r.1.x_min_cm),
            )),
            Arc::new(Float64Array::from_iter_values(
                rows.iter().map(|r| r.1.x_max_cm),
            )),
        ],
    )?;
    write_parquet(path, &batch, None)?;
    Ok(())
}

/// Reads (sample, fit) pairs back, in file order, coefficients by power.
pub fn read_edges(path: &Path) -> Result<Vec<(String, EdgeFit)>> {
    let f = std::fs::File::open(path).with_context(|| format!("cannot open {}", path.display()))?;
    let mut out: Vec<(String, EdgeFit)> = Vec::new();
    for batch in ParquetRecordBatchReaderBuilder::try_new(f)?.build()? {
        let b = batch?;
        let col = |n: &str| {
            b.column_by_name(n)
                .with_context(|| format!("{}: no column {n}", path.display()))
        };
        let strings = |n: &str| -> Result<StringArray> {
            Ok(col(n)?
                .as_any()
                .downcast_ref::<StringArray>()
                .with_context(|| format!("{n}: not strings"))?
                .clone())
        };
        let u32s = |n: &str| -> Result<UInt32Array> {
            Ok(col(n)?
                .as_any()
                .downcast_ref::<UInt32Array>()
                .with_context(|| format!("{n}: not u32"))?
                .clone())
        };
        let f64s = |n: &str| -> Result<Float64Array> {
            Ok(col(n)?
                .as_any()
                .downcast_ref::<Float64Array>()
                .with_context(|| format!("{n}: not f64"))?
                .clone())
        };
        let (sample, edge, power, npts) = (
            strings("sample")?,
            strings("edge")?,
            u32s("power")?,
            u32s("n_points")?,
        );
        let (coef, rms, xmin, xmax) = (
            f64s("coefficient")?,
            f64s("rms_residual_cm")?,
            f64s("x_min_cm")?,
            f64s("x_max_cm")?,
        );
        for r in 0..b.num_rows() {
            let (smp, name) = (sample.value(r), edge.value(r));
            let k = match out.iter().position(|(s, e)| s == smp && e.edge == name) {
                Some(k) => k,
                None => {
                    let fit = EdgeFit {
                        edge: name.to_string(),
                        coefficients: Vec::new(),
                        rms_residual_cm: rms.value(r),
                        n_points: npts.value(r) as usize,
                        x_min_cm: xmin.value(r),
                        x_max_cm: xmax.value(r),
                    };
                    out.push((smp.to_string(), fit));
                    out.len() - 1
                }
            };
            let c = &mut out[k].1.coefficients;
            let p = power.value(r) as usize;
            if c.len() <= p {
                c.resize(p + 1, 0.0);
            }
            c[p] = coef.value(r);
        }
    }
    Ok(out)
}
