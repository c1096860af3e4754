//! Tables between the library and Python: the library's cells (the text the CSV holds) built
//! into typed Arrow columns, handed out as an Arrow C stream in a PyCapsule (`pyarrow`,
//! `polars` and `pandas` read it without copying the numbers), and any Arrow stream read back
//! into the cells the studies read.

use arrow_array::builder::{Float64Builder, Int64Builder, StringBuilder};
use arrow_array::ffi_stream::{ArrowArrayStreamReader, FFI_ArrowArrayStream};
use arrow_array::{Array, ArrayRef, RecordBatch, RecordBatchIterator, RecordBatchReader};
use arrow_schema::{DataType, Field, Schema};
use pounding::io::parquet::Kind;
use pyo3::prelude::*;
use pyo3::types::PyCapsule;
use std::collections::HashMap;
use std::ffi::CString;
use std::sync::Arc;

/// A column being built, of its kind.
enum Builder {
    Int(Int64Builder),
    Real(Float64Builder),
    Text(StringBuilder),
}

/// Typed columns built from cells, chunk by chunk (an empty cell is a null, as in Parquet).
pub struct Columns {
    names: Vec<String>,
    builders: Vec<Builder>,
}

impl Columns {
    pub fn new(names: &[String], kinds: Vec<Kind>) -> Columns {
        let builders = kinds
            .into_iter()
            .map(|k| match k {
                Kind::Int => Builder::Int(Int64Builder::new()),
                Kind::Real => Builder::Real(Float64Builder::new()),
                Kind::Text => Builder::Text(StringBuilder::new()),
            })
            .collect();
        Columns {
            names: names.to_vec(),
            builders,
        }
    }

    /// Append rows of cells (in the columns' order). A number that does not parse is an
    /// error naming the column: the cells are the engine's own, so it would be a fault.
    pub fn append(&mut self, rows: &[Vec<String>]) -> Result<(), String> {
        for (c, b) in self.builders.iter_mut().enumerate() {
            let bad = |v: &str, what: &str| {
                format!("column `{}`: the cell `{v}` is not {what}", self.names[c])
            };
            for r in rows {
                let v = r[c].as_str();
                match b {
                    Builder::Int(b) if v.is_empty() => b.append_null(),
                    Builder::Real(b) if v.is_empty() => b.append_null(),
                    Builder::Text(b) if v.is_empty() => b.append_null(),
                    Builder::Int(b) => b.append_value(v.parse().map_err(|_| bad(v, "an integer"))?),
                    Builder::Real(b) => b.append_value(v.parse().map_err(|_| bad(v, "a number"))?),
                    Builder::Text(b) => b.append_value(v),
                }
            }
        }
        Ok(())
    }

    /// The table, with `meta` as the schema's key-value metadata.
    pub fn finish(mut self, meta: &[(String, String)]) -> Result<Table, String> {
        let mut fields = Vec::new();
        let mut arrays: Vec<ArrayRef> = Vec::new();
        for (name, b) in self.names.iter().zip(&mut self.builders) {
            let a: ArrayRef = match b {
                Builder::Int(b) => Arc::new(b.finish()),
                Builder::Real(b) => Arc::new(b.finish()),
                Builder::Text(b) => Arc::new(b.finish()),
            };
            // Each column's unit (as `pound columns` gives it) in its field's metadata.
            let mut field = Field::new(name, a.data_type().clone(), true);
            if let Some(m) = pounding::plan::meaning::meaning(name) {
                field = field.with_metadata(HashMap::from([("unit".into(), m.unit.into())]));
            }
            fields.push(field);
            arrays.push(a);
        }
        let meta: HashMap<String, String> = meta.iter().cloned().collect();
        let schema = Arc::new(Schema::new_with_metadata(fields, meta));
        let batch = if arrays.is_empty() {
            RecordBatch::new_empty(schema)
        } else {
            RecordBatch::try_new(schema, arrays).map_err(|e| e.to_string())?
        };
        Ok(Table { batch })
    }
}

/// A study's CSV (a trace, a gap study, a fragility table) as a typed table: a column is text
/// where any cell is not a number, else of its name's kind (counts are integers, measures
/// reals: [`pounding::io::parquet::kind`]), so a column has one type whatever the run's values.
/// An empty cell is a null.
pub fn study_table(csv_text: &str, meta: &[(String, String)]) -> Result<Table, String> {
    let mut r = csv::ReaderBuilder::new().from_reader(csv_text.as_bytes());
    let header: Vec<String> = r
        .headers()
        .map_err(|e| e.to_string())?
        .iter()
        .map(String::from)
        .collect();
    let rows: Vec<Vec<String>> = r
        .records()
        .map(|rec| rec.map(|r| r.iter().map(String::from).collect()))
        .collect::<Result<_, _>>()
        .map_err(|e| e.to_string())?;
    let kinds = (0..header.len())
        .map(|c| {
            let mut cells = rows.iter().map(|r| r[c].as_str()).filter(|v| !v.is_empty());
            match pounding::io::parquet::kind(&header[c]) {
                Kind::Int if cells.all(|v| v.parse::<i64>().is_ok()) => Kind::Int,
                _ if rows
                    .iter()
                    .map(|r| r[c].as_str())
                    .filter(|v| !v.is_empty())
                    .all(|v| v.parse::<f64>().is_ok()) =>
                {
                    Kind::Real
                }
                _ => Kind::Text,
            }
        })
        .collect();
    let mut cols = Columns::new(&header, kinds);
    cols.append(&rows)?;
    cols.finish(meta)
}

/// A table of results: typed columns, handed to Python as an Arrow C stream.
#[pyclass(module = "pounding._pounding", frozen)]
pub struct Table {
    batch: RecordBatch,
}

#[pymethods]
impl Table {
    #[getter]
    fn num_rows(&self) -> usize {
        self.batch.num_rows()
    }

    #[getter]
    fn column_names(&self) -> Vec<String> {
        self.batch
            .schema()
            .fields()
            .iter()
            .map(|f| f.name().clone())
            .collect()
    }

    /// The schema's key-value metadata (a sweep's fingerprint, backend and kernel).
    #[getter]
    fn metadata(&self) -> HashMap<String, String> {
        self.batch.schema().metadata().clone()
    }

    fn __len__(&self) -> usize {
        self.batch.num_rows()
    }

    /// The Arrow PyCapsule stream interface: one batch, every column.
    #[pyo3(signature = (requested_schema=None))]
    fn __arrow_c_stream__<'py>(
        &self,
        py: Python<'py>,
        requested_schema: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyCapsule>> {
        // A requested schema is a hint (the interface's words): the table's own is given.
        let _ = requested_schema;
        let reader = RecordBatchIterator::new(vec![Ok(self.batch.clone())], self.batch.schema());
        let reader: Box<dyn RecordBatchReader + Send> = Box::new(reader);
        let stream = FFI_ArrowArrayStream::new(reader);
        let name = CString::new("arrow_array_stream").expect("no nul");
        PyCapsule::new(py, stream, Some(name))
    }
}

/// The cells of any Arrow table (an object with `__arrow_c_stream__`: this package's tables,
/// pyarrow's, polars', pandas' through pyarrow), as text the way the CSV writes it: integers
/// and reals in their shortest round trip, an empty cell for a null.
pub fn table_cells(obj: &Bound<'_, PyAny>) -> PyResult<pounding::io::table::Table> {
    let bad = |m: String| crate::TableError::new_err(m);
    if !obj.hasattr("__arrow_c_stream__")? {
        return Err(bad(format!(
            "a {} is not a table: expected a table from pounding.sweep, a pyarrow or polars table, a pandas DataFrame, or the path of a results CSV",
            obj.get_type().name()?
        )));
    }
    let capsule = obj.call_method0("__arrow_c_stream__")?;
    let capsule = capsule.cast::<PyCapsule>()?;
    let ptr = capsule
        .pointer_checked(Some(c"arrow_array_stream"))?
        .as_ptr() as *mut FFI_ArrowArrayStream;
    // SAFETY: the capsule named arrow_array_stream holds an ArrowArrayStream (the interface's
    // contract); from_raw moves it out, leaving a released stream for the capsule to drop.
    let reader = unsafe { ArrowArrayStreamReader::from_raw(ptr) }
        .map_err(|e| bad(format!("reading the table: {e}")))?;
    let header: Vec<String> = reader
        .schema()
        .fields()
        .iter()
        .map(|f| f.name().clone())
        .collect();
    // A column of neither numbers nor text (a timestamp, say) is left out, and named in the
    // table's label that a study's messages show.
    let mut left_out: Vec<String> = Vec::new();
    let mut keep: Vec<bool> = vec![true; header.len()];
    let mut rows: Vec<Vec<String>> = Vec::new();
    for batch in reader {
        let batch = batch.map_err(|e| bad(format!("reading the table: {e}")))?;
        let first = rows.len();
        rows.extend((0..batch.num_rows()).map(|_| Vec::with_capacity(header.len())));
        for (c, col) in batch.columns().iter().enumerate() {
            if !keep[c] {
                continue;
            }
            match cells_of(col.as_ref()) {
                Ok(cells) => {
                    for (i, v) in cells.into_iter().enumerate() {
                        rows[first + i].push(v);
                    }
                }
                Err(ty) => {
                    keep[c] = false;
                    left_out.push(format!("{} ({ty})", header[c]));
                    for r in &mut rows[..first] {
                        r.remove(keep[..c].iter().filter(|k| **k).count());
                    }
                }
            }
        }
    }
    let header: Vec<String> = header
        .into_iter()
        .zip(&keep)
        .filter(|(_, k)| **k)
        .map(|(h, _)| h)
        .collect();
    let path = if left_out.is_empty() {
        "<table>".to_string()
    } else {
        format!(
            "<table, without {}: neither numbers nor text>",
            left_out.join(", ")
        )
    };
    Ok(pounding::io::table::Table {
        path: path.into(),
        header,
        rows,
    })
}

/// An Arrow array's values as cells; Err: its type, where it holds neither numbers nor text.
fn cells_of(a: &dyn Array) -> Result<Vec<String>, String> {
    use arrow_array::cast::AsArray;
    use arrow_array::types::*;
    // Each value as `value` writes it, a null as an empty cell.
    let each = |value: &dyn Fn(usize) -> String| -> Vec<String> {
        (0..a.len())
            .map(|i| {
                if a.is_null(i) {
                    String::new()
                } else {
                    value(i)
                }
            })
            .collect()
    };
    macro_rules! prim {
        ($t:ty) => {{
            let p = a.as_primitive::<$t>();
            each(&|i| format!("{}", p.value(i)))
        }};
    }
    Ok(match a.data_type() {
        DataType::Int8 => prim!(Int8Type),
        DataType::Int16 => prim!(Int16Type),
        DataType::Int32 => prim!(Int32Type),
        DataType::Int64 => prim!(Int64Type),
        DataType::UInt8 => prim!(UInt8Type),
        DataType::UInt16 => prim!(UInt16Type),
        DataType::UInt32 => prim!(UInt32Type),
        DataType::UInt64 => prim!(UInt64Type),
        DataType::Float32 => prim!(Float32Type),
        DataType::Float64 => prim!(Float64Type),
        DataType::Boolean => {
            let b = a.as_boolean();
            each(&|i| b.value(i).to_string())
        }
        DataType::Utf8 => {
            let s = a.as_string::<i32>();
            each(&|i| s.value(i).to_string())
        }
        DataType::LargeUtf8 => {
            let s = a.as_string::<i64>();
            each(&|i| s.value(i).to_string())
        }
        DataType::Utf8View => {
            let s = a.as_string_view();
            each(&|i| s.value(i).to_string())
        }
        DataType::Null => vec![String::new(); a.len()],
        DataType::Dictionary(_, _) => {
            // Categories (pandas' category, polars' Categorical): each key's value.
            let d = a.as_any_dictionary();
            let values = cells_of(d.values().as_ref())?;
            let keys = d.normalized_keys();
            each(&|i| values[keys[i]].clone())
        }
        other => return Err(other.to_string()),
    })
}
