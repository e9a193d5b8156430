//! Gathering the parts of a stage that runs by items (one Parquet part, and optionally one rerun
//! recording, per item) into the stage's outputs: rows in part order with one schema, and one
//! recording holding every part's chunks.

use crate::rerun;
use crate::table::write_parquet;
use anyhow::{Context, Result, bail};
use arrow::array::RecordBatch;
use arrow::datatypes::SchemaRef;
use drapelab_core::atomic::Staged;
use std::path::{Path, PathBuf};

/// The schema and every record batch of a Parquet file.
fn read_batches(path: &Path) -> Result<(SchemaRef, Vec<RecordBatch>)> {
    let f = std::fs::File::open(path).with_context(|| format!("cannot open {}", path.display()))?;
    let reader = parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder::try_new(f)
        .with_context(|| format!("{}: not a Parquet file", path.display()))?;
    let schema = reader.schema().clone();
    let batches = reader
        .build()?
        .map(|b| b.with_context(|| format!("cannot read {}", path.display())))
        .collect::<Result<_>>()?;
    Ok((schema, batches))
}

/// Writes the rows of every part, in order, as one Parquet table at `out` (atomically). The parts
/// must share one schema (that of the first); an empty list is an error (the schema is unknown).
pub fn gather_parquet(parts: &[PathBuf], out: &Path) -> Result<()> {
    let Some(first) = parts.first() else {
        bail!("no parts to gather into {}", out.display());
    };
    let (schema, mut batches) = read_batches(first)?;
    for p in &parts[1..] {
        let (s, b) = read_batches(p)?;
        if s != schema {
            bail!(
                "the parts of {} differ in schema ({} against {})",
                out.display(),
                p.display(),
                first.display()
            );
        }
        batches.extend(b);
    }
    let batch = arrow::compute::concat_batches(&schema, &batches)?;
    // Which drapelab made the table, where and when, in the Arrow schema (pyarrow's
    // `read_table(...).schema.metadata`) and as Parquet key-value pairs.
    let meta = run_metadata();
    let schema = schema
        .as_ref()
        .clone()
        .with_metadata(meta.iter().cloned().collect());
    let kv = meta
        .into_iter()
        .map(|(k, v)| parquet::file::metadata::KeyValue::new(k, v))
        .collect();
    let props = crate::table::writer_properties()
        .set_key_value_metadata(Some(kv))
        .build();
    write_parquet(
        out,
        &batch.with_schema(std::sync::Arc::new(schema))?,
        Some(props),
    )
}

/// The run metadata of a gathered table: `drapelab_version`, `build_id`, `host`, `finished_utc`.
pub fn run_metadata() -> Vec<(String, String)> {
    use drapelab_core::provenance::{build_id, host, unix_now_s, utc};
    vec![
        ("drapelab_version".into(), drapelab_core::VERSION.into()),
        ("build_id".into(), build_id().into()),
        ("host".into(), host()),
        ("finished_utc".into(), utc(unix_now_s())),
    ]
}

/// Writes one rerun recording at `out` (atomically, application `app`) holding every chunk of the
/// recordings `parts`, in order: the per-item recordings of a stage become one file.
pub fn merge_recordings(parts: &[PathBuf], out: &Path, app: &str) -> Result<()> {
    use rerun::external::re_log_encoding::DecoderApp;
    use rerun::log::{Chunk, LogMsg};
    let staged = Staged::new(out)?;
    let rec = rerun::RecordingStreamBuilder::new(rerun::ApplicationId::new_or_unknown(app))
        .save(staged.path())?;
    for p in parts {
        let f = std::fs::File::open(p).with_context(|| format!("cannot open {}", p.display()))?;
        for msg in DecoderApp::decode_lazy(std::io::BufReader::new(f)) {
            let msg = msg.with_context(|| format!("{}: not a rerun recording", p.display()))?;
            if let LogMsg::ArrowMsg(_, arrow) = msg {
                let chunk = Chunk::from_arrow_msg(&arrow)
                    .with_context(|| format!("{}: a chunk rerun cannot read", p.display()))?;
                rec.send_chunk(chunk);
            }
        }
    }
    rec.flush_blocking()?;
    drop(rec);
    staged.commit()?;
    Ok(())
}
