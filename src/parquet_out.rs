//! Parquet output (`pound sweep --format parquet`): the same columns as the CSV (or those
//! `--columns` names), typed (integers, text, doubles; an empty CSV cell is a null), one row group
//! per chunk, and the plan fingerprint in the file's key-value metadata. Written to
//! `OUT.partial` and renamed when complete (Parquet's footer comes last, so an unfinished file is
//! not readable; `--resume` is CSV only).

use crate::shard::Meta;
use parquet::basic::{ConvertedType, Repetition, Type as Physical};
use parquet::data_type::{ByteArray, ByteArrayType, DoubleType, Int64Type};
use parquet::file::metadata::KeyValue;
use parquet::file::properties::WriterProperties;
use parquet::file::writer::SerializedFileWriter;
use parquet::schema::types::Type;
use std::fs::File;
use std::path::{Path, PathBuf};
use std::sync::Arc;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Int,
    Text,
    Real,
}

fn kind(column: &str) -> Kind {
    match column {
        "run" | "impacts" | "substeps" | "sample" => Kind::Int,
        "law" | "formula" | "record" | "status" => Kind::Text,
        _ => Kind::Real,
    }
}

/// A Parquet file that appears under its final name only when complete.
pub struct ParquetOut {
    path: PathBuf,
    partial: PathBuf,
    kinds: Vec<Kind>,
    writer: SerializedFileWriter<File>,
}

fn err(e: impl std::fmt::Display) -> std::io::Error {
    std::io::Error::other(e.to_string())
}

impl ParquetOut {
    /// Columns `columns` (names of `output::header`), and `meta` as key-value metadata
    /// (`pound.fingerprint.plan`, `.records`, `.engine`, `pound.runs`, `pound.backend`).
    pub fn create(path: &Path, columns: &[&str], meta: &Meta) -> std::io::Result<ParquetOut> {
        let partial = crate::output::sibling(path, ".partial");
        let kinds: Vec<Kind> = columns.iter().map(|c| kind(c)).collect();
        let fields = columns
            .iter()
            .zip(&kinds)
            .map(|(c, k)| {
                let b = match k {
                    Kind::Int => Type::primitive_type_builder(c, Physical::INT64),
                    Kind::Text => Type::primitive_type_builder(c, Physical::BYTE_ARRAY)
                        .with_converted_type(ConvertedType::UTF8),
                    Kind::Real => Type::primitive_type_builder(c, Physical::DOUBLE),
                };
                b.with_repetition(Repetition::OPTIONAL)
                    .build()
                    .map(Arc::new)
                    .map_err(err)
            })
            .collect::<std::io::Result<Vec<_>>>()?;
        let schema = Type::group_type_builder("run")
            .with_fields(fields)
            .build()
            .map_err(err)?;
        let kv = |k: &str, v: String| KeyValue::new(k.to_string(), v);
        let props = WriterProperties::builder()
            .set_key_value_metadata(Some(vec![
                kv("pound.fingerprint.plan", meta.fingerprint.plan.clone()),
                kv(
                    "pound.fingerprint.records",
                    meta.fingerprint.records.clone(),
                ),
                kv("pound.fingerprint.engine", meta.fingerprint.engine.clone()),
                kv(
                    "pound.runs",
                    format!("{}..{} of {}", meta.first_run, meta.end_run, meta.plan_runs),
                ),
                kv("pound.backend", meta.backend.clone()),
            ]))
            .build();
        let file = File::create(&partial)?;
        let writer =
            SerializedFileWriter::new(file, Arc::new(schema), Arc::new(props)).map_err(err)?;
        Ok(ParquetOut {
            path: path.into(),
            partial,
            kinds,
            writer,
        })
    }

    pub fn partial_path(&self) -> &Path {
        &self.partial
    }

    /// One row group of `rows` (cells as in the CSV, in the columns given to `create`).
    pub fn write(&mut self, rows: &[Vec<String>]) -> std::io::Result<()> {
        let mut rg = self.writer.next_row_group().map_err(err)?;
        let mut c = 0;
        while let Some(mut col) = rg.next_column().map_err(err)? {
            let cells = rows.iter().map(|r| r[c].as_str());
            let defs: Vec<i16> = cells.clone().map(|v| (!v.is_empty()) as i16).collect();
            let present = cells.filter(|v| !v.is_empty());
            match self.kinds[c] {
                Kind::Int => {
                    let v: Vec<i64> = present.map(|x| x.parse().unwrap_or(0)).collect();
                    col.typed::<Int64Type>()
                        .write_batch(&v, Some(&defs), None)
                        .map_err(err)?;
                }
                Kind::Real => {
                    let v: Vec<f64> = present.map(|x| x.parse().unwrap_or(f64::NAN)).collect();
                    col.typed::<DoubleType>()
                        .write_batch(&v, Some(&defs), None)
                        .map_err(err)?;
                }
                Kind::Text => {
                    let v: Vec<ByteArray> = present.map(ByteArray::from).collect();
                    col.typed::<ByteArrayType>()
                        .write_batch(&v, Some(&defs), None)
                        .map_err(err)?;
                }
            }
            col.close().map_err(err)?;
            c += 1;
        }
        rg.close().map_err(err)?;
        Ok(())
    }

    /// Write the footer, fsync, rename to the final name.
    pub fn finish(self) -> std::io::Result<PathBuf> {
        let file = self.writer.into_inner().map_err(err)?;
        file.sync_all()?;
        drop(file);
        std::fs::rename(&self.partial, &self.path)?;
        Ok(self.path)
    }
}
