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

pub use drapelab_core::table::Table;

/// The Arrow fields of `T`'s rows, traced from the type: strings and unit-only enums as `Utf8`.
pub fn table_fields<T: Table>() -> Result<Vec<arrow::datatypes::FieldRef>> {
    use arrow::datatypes::{DataType, Field};
    use serde_arrow::schema::{SchemaLike, TracingOptions};
    let opts = TracingOptions::default()
        .strings_as_large_utf8(false)
        .enums_without_data_as_strings(true);
    let fields = Vec::<arrow::datatypes::FieldRef>::from_type::<T>(opts)?;
    // Enums trace as dictionaries of strings; drapelab's tables hold them as plain strings.
    Ok(fields
        .into_iter()
        .map(|f| match f.data_type() {
            DataType::Dictionary(_, v) if **v == DataType::Utf8 => {
                std::sync::Arc::new(Field::new(f.name(), DataType::Utf8, f.is_nullable()))
            }
            _ => f,
        })
        .collect())
}

/// The rows as one record batch of `T`'s schema.
pub fn table_batch<T: Table>(rows: &[T]) -> Result<RecordBatch> {
    Ok(serde_arrow::to_record_batch(&table_fields::<T>()?, &rows)?)
}

/// Writes the rows to `path` as a Parquet table of `T`'s schema (see [`write_parquet`]).
pub fn write_table<T: Table>(path: &Path, rows: &[T]) -> Result<()> {
    write_parquet(path, &table_batch(rows)?, None)
}

/// Side by side: the columns of each batch in turn, as one batch (for a table whose middle
/// columns are known only at run time, e.g. a sweep's axes).
pub fn join_columns(batches: &[RecordBatch]) -> Result<RecordBatch> {
    let mut fields = Vec::new();
    let mut cols = Vec::new();
    for b in batches {
        fields.extend(b.schema().fields().iter().cloned());
        cols.extend(b.columns().iter().cloned());
    }
    let schema = std::sync::Arc::new(arrow::datatypes::Schema::new(fields));
    Ok(RecordBatch::try_new(schema, cols)?)
}

/// `T`'s columns as a Markdown section: the file, what a row is, then name | type | nullable.
pub fn table_markdown<T: Table>() -> Result<String> {
    let mut s = format!(
        "#### `{}`\n\n{}\n\n| column | type | nullable |\n| --- | --- | --- |\n",
        T::FILE,
        T::ROW
    );
    for f in table_fields::<T>()? {
        s.push_str(&format!(
            "| `{}` | {} | {} |\n",
            f.name(),
            f.data_type(),
            if f.is_nullable() { "yes" } else { "no" }
        ));
    }
    Ok(s)
}

/// Reads the rows of a table of `T`'s schema back, every batch in file order. A file that cannot
/// be opened, is not Parquet, or does not hold `T`'s columns is an
/// [`InputError`](drapelab_core::error::InputError) naming it (exit 2).
pub fn read_table<T: Table>(path: &Path) -> Result<Vec<T>> {
    read_table_renamed(path, &[])
}

/// [`read_table`] of a file whose columns may carry older names: each `(old, new)` of `renames`
/// is read as `new` (a column renamed when its unit joined its name).
pub fn read_table_renamed<T: Table>(path: &Path, renames: &[(&str, &str)]) -> Result<Vec<T>> {
    use drapelab_core::error::InputError;
    let bad = |what: String| InputError::new(path, "", what);
    let f = std::fs::File::open(path).map_err(|e| bad(format!("cannot open: {e}")))?;
    let reader = parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder::try_new(f)
        .and_then(|b| b.build())
        .map_err(|e| {
            bad(format!(
                "not a readable Parquet file ({e}); expected {}",
                T::FILE
            ))
        })?;
    let mut out = Vec::new();
    for batch in reader {
        let batch = batch.map_err(|e| bad(format!("corrupt Parquet data: {e}")))?;
        let batch = renamed(batch, renames)?;
        let rows: Vec<T> = serde_arrow::from_record_batch(&batch)
            .map_err(|e| bad(format!("not a {} table: {e}", T::FILE)))?;
        out.extend(rows);
    }
    Ok(out)
}

/// `batch` with its columns named `old` renamed `new` (those it has).
fn renamed(batch: RecordBatch, renames: &[(&str, &str)]) -> Result<RecordBatch> {
    let schema = batch.schema();
    if !schema
        .fields()
        .iter()
        .any(|f| renames.iter().any(|(o, _)| f.name() == o))
    {
        return Ok(batch);
    }
    let fields: Vec<arrow::datatypes::Field> = schema
        .fields()
        .iter()
        .map(|f| match renames.iter().find(|(o, _)| f.name() == o) {
            Some((_, n)) => f.as_ref().clone().with_name(*n),
            None => f.as_ref().clone(),
        })
        .collect();
    let schema = arrow::datatypes::Schema::new_with_metadata(fields, schema.metadata().clone());
    Ok(RecordBatch::try_new(
        std::sync::Arc::new(schema),
        batch.columns().to_vec(),
    )?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde::{Deserialize, Serialize};

    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    #[serde(rename_all = "lowercase")]
    enum Kind {
        A,
        B,
    }

    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    struct Row {
        name: String,
        kind: Kind,
        n: u32,
        length_m: Option<f64>,
    }

    impl Table for Row {
        const FILE: &'static str = "rows.parquet";
        const ROW: &'static str = "A row.";
    }

    #[test]
    fn a_table_round_trips_with_the_schema_its_row_type_gives() {
        let rows = vec![
            Row {
                name: "x".into(),
                kind: Kind::B,
                n: 3,
                length_m: Some(0.5),
            },
            Row {
                name: "y".into(),
                kind: Kind::A,
                n: 4,
                length_m: None,
            },
        ];
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("rows.parquet");
        write_table(&path, &rows).unwrap();
        assert_eq!(read_table::<Row>(&path).unwrap(), rows);
        let f = table_fields::<Row>().unwrap();
        let shown: Vec<String> = f
            .iter()
            .map(|f| format!("{} {} {}", f.name(), f.data_type(), f.is_nullable()))
            .collect();
        assert_eq!(
            shown,
            [
                "name Utf8 false",
                "kind Utf8 false",
                "n UInt32 false",
                "length_m Float64 true"
            ]
        );
    }
}
