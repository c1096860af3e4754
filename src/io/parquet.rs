//! Parquet output (`pound sweep --format parquet`): the same columns as the CSV (or those
//! `--columns` names), typed (integers, text, doubles; an empty CSV cell is a null), one row group
//! per chunk, and the plan fingerprint in the file's key-value metadata. Written to
//! `OUT.partial` and renamed when complete (Parquet's footer comes last, so an unfinished file is
//! not readable; `--resume` is CSV only).

use crate::io::journal::{Content, HashingWriter};
use crate::io::provenance::Meta;
use crate::io::target::{PartialLock, Target};
use parquet::basic::{ConvertedType, Repetition, Type as Physical};
use parquet::data_type::{ByteArray, ByteArrayType, DoubleType, Int64Type};
use parquet::file::metadata::KeyValue;
use parquet::file::properties::WriterProperties;
use parquet::file::writer::SerializedFileWriter;
use parquet::schema::types::Type;
use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// A column's type in typed outputs (Parquet, the Python package's Arrow tables).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    Int,
    Text,
    Real,
}

/// A column's type, from its name: counts and numbers of storeys and floors are integers (a
/// row's per-building and per-level columns end as the pair's do: `b2_drift_storey`,
/// `level_b1f3_b2f3_impacts`).
pub fn kind(column: &str) -> Kind {
    match column {
        "run" | "impacts" | "substeps" | "sample" => Kind::Int,
        // The counts of a study's table (fragility, IDA): no sweep column has these names.
        "runs" | "exceed" | "collapsed" | "undecided" | "curves" | "pounding" => Kind::Int,
        "law" | "formula" | "record" | "status" | "record_component" | "record_event" => Kind::Text,
        "record_rsn" => Kind::Int,
        c if [
            "_impacts",
            "_storeys",
            "_drift_storey",
            "_accel_floor",
            "_residual_storey",
            "_ductility_storey",
            "_collapsed",
            "_collapse_storey",
            "_capped",
        ]
        .iter()
        .any(|end| c.ends_with(end)) =>
        {
            Kind::Int
        }
        _ => Kind::Real,
    }
}

/// A Parquet file that appears under its final name only when complete (or a stream written in
/// place), hashed as it is written.
pub struct ParquetOut {
    /// Where the bytes go: the `.partial` of a file, or the stream's name.
    partial: PathBuf,
    /// A file target: its final name, and a handle to fsync.
    file: Option<(PathBuf, File)>,
    kinds: Vec<Kind>,
    rows: u64,
    writer: SerializedFileWriter<HashingWriter<Box<dyn Write + Send>>>,
}

fn err(e: impl std::fmt::Display) -> std::io::Error {
    std::io::Error::other(e.to_string())
}

impl ParquetOut {
    /// Columns `columns` (names of `output::header`), and `meta` as key-value metadata
    /// ([`Meta::key_values`]).
    pub fn create(
        target: &Target,
        lock: Option<&PartialLock>,
        columns: &[&str],
        meta: &Meta,
    ) -> std::io::Result<ParquetOut> {
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
        // Each column's unit (as `pound columns` gives it), as one JSON object: Parquet's
        // schema has no field metadata outside an embedded Arrow schema.
        let units: Vec<String> = (columns.iter())
            .filter_map(|c| {
                let m = crate::plan::meaning::meaning(c)?;
                Some(format!("{:?}:{:?}", c, m.unit))
            })
            .collect();
        let mut key_values: Vec<KeyValue> = (meta.key_values().into_iter())
            .map(|(k, v)| KeyValue::new(k, v))
            .collect();
        key_values.push(KeyValue::new(
            "units".to_string(),
            format!("{{{}}}", units.join(",")),
        ));
        let props = WriterProperties::builder()
            .set_key_value_metadata(Some(key_values))
            .build();
        let (partial, file, sink): (_, _, Box<dyn Write + Send>) = match (target, lock) {
            (Target::File(p), Some(lock)) => {
                let f = lock.file().map_err(err)?;
                crate::io::atomic::empty(&f)?;
                (
                    lock.path().to_path_buf(),
                    Some((p.clone(), f.try_clone()?)),
                    Box::new(f),
                )
            }
            (Target::File(_), None) => return Err(err("a file output needs its lock")),
            _ => (
                target.path().to_path_buf(),
                None,
                crate::io::atomic::open_stream(target)?,
            ),
        };
        let writer =
            SerializedFileWriter::new(HashingWriter::new(sink), Arc::new(schema), Arc::new(props))
                .map_err(err)?;
        Ok(ParquetOut {
            partial,
            file,
            kinds,
            rows: 0,
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
        self.rows += rows.len() as u64;
        Ok(())
    }

    /// Write the footer and fsync; for a file, check the row count against `expect_rows`, call
    /// `label` with the content (the sidecar goes first) and rename to the final name.
    pub fn finish(
        self,
        expect_rows: u64,
        label: impl FnOnce(&Content) -> std::io::Result<()>,
    ) -> std::io::Result<(PathBuf, Content)> {
        if self.rows != expect_rows {
            return Err(err(format!(
                "{} rows were written where {expect_rows} were expected: the output is incomplete",
                self.rows
            )));
        }
        let hashing = self.writer.into_inner().map_err(err)?;
        let (mut sink, sha256) = hashing.into_parts();
        sink.flush()?;
        let content = Content {
            rows: self.rows,
            sha256,
            blocks: Vec::new(),
        };
        match self.file {
            Some((path, file)) => {
                file.sync_all()?;
                label(&content)?;
                std::fs::rename(&self.partial, &path)?;
                Ok((path, content))
            }
            None => Ok((self.partial, content)),
        }
    }
}
