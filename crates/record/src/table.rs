//! One Arrow record batch to a Parquet file, atomically.

use crate::write_atomic;
use anyhow::Result;
use arrow::array::RecordBatch;
use parquet::arrow::ArrowWriter;
use parquet::file::properties::WriterProperties;
use std::path::Path;

/// Writes `batch` to `path` (temporary file, then rename) with optional writer properties.
pub fn write_parquet(
    path: &Path,
    batch: &RecordBatch,
    props: Option<WriterProperties>,
) -> Result<()> {
    write_atomic(path, |f| {
        let mut w = ArrowWriter::try_new(f, batch.schema(), props)?;
        w.write(batch)?;
        w.close()?;
        Ok(())
    })?;
    Ok(())
}
