//! One Arrow record batch to a Parquet file, atomically, zstd-compressed.

use crate::write_atomic;
use anyhow::Result;
use arrow::array::RecordBatch;
use parquet::arrow::ArrowWriter;
use parquet::basic::{Compression, ZstdLevel};
use parquet::file::properties::{WriterProperties, WriterPropertiesBuilder};
use std::path::Path;

/// drapelab's Parquet writer settings: zstd (level 3) for every column.
pub fn writer_properties() -> WriterPropertiesBuilder {
    WriterProperties::builder().set_compression(Compression::ZSTD(ZstdLevel::default()))
}

/// Writes `batch` to `path` (temporary file, then rename) with the given writer properties, or
/// [`writer_properties`] when none.
pub fn write_parquet(
    path: &Path,
    batch: &RecordBatch,
    props: Option<WriterProperties>,
) -> Result<()> {
    let props = props.unwrap_or_else(|| writer_properties().build());
    write_atomic(path, |f| {
        let mut w = ArrowWriter::try_new(f, batch.schema(), Some(props))?;
        w.write(batch)?;
        w.close()?;
        Ok(())
    })?;
    Ok(())
}
