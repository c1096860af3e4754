//! CSV rows for runs, written to `<out>.partial` as chunks finish and renamed to `<out>` only
//! when the sweep is complete (after flush and fsync). A failed sweep leaves the `.partial`
//! file with every finished row.

use crate::engine::aggregate::Aggregator;
use crate::io::atomic::{empty, open_stream};
use crate::io::journal::{Content, ContentHasher};
use crate::io::target::{PartialLock, Target};
use crate::physics::model::RunOutput;
use crate::physics::row::RowOutput;
use crate::plan::columns::{header, row};
use crate::plan::row::{RowPlan, RowRunSpec};
use crate::plan::{PairPlan, RunSpec};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// A CSV output that appears under its final name only when complete, with its rows hashed and
/// their run numbers checked as they are written ([`ContentHasher`]). A file target is written
/// into its locked `.partial` and renamed; a stream (standard output, a character device, a
/// FIFO) is written in place.
pub struct CsvOut {
    w: BufWriter<Box<dyn Write + Send>>,
    /// Where the bytes go: the `.partial` of a file, or the stream's name.
    written: PathBuf,
    /// A file target: its final name, and a handle to fsync.
    file: Option<(PathBuf, File)>,
    header: Vec<u8>,
    first_run: Option<u64>,
    hasher: ContentHasher,
}

/// CSV lines of records (quoted as the `csv` crate quotes them).
fn lines<I, R>(records: I) -> Vec<u8>
where
    I: IntoIterator<Item = R>,
    R: IntoIterator,
    R::Item: AsRef<[u8]>,
{
    let mut w = csv::WriterBuilder::new()
        .has_headers(false)
        .from_writer(Vec::new());
    for r in records {
        w.write_record(r).expect("writing to memory");
    }
    w.into_inner().expect("writing to memory")
}

/// A cell of a CSV a study writes by hand: quoted where it holds a comma, a quote or a line
/// end (its quotes doubled), else as it is.
pub fn quote_cell(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// CSV lines of rows of cells, as written.
pub fn encode_rows(rows: &[Vec<String>]) -> Vec<u8> {
    lines(rows)
}

/// The header line of `columns`, as written.
pub fn header_line(columns: &[&str]) -> Vec<u8> {
    lines([columns])
}

fn invalid(e: impl std::fmt::Display) -> std::io::Error {
    std::io::Error::new(std::io::ErrorKind::InvalidData, e.to_string())
}

impl CsvOut {
    /// A new output with the header `columns`. A file target is written into the `.partial`
    /// that `lock` holds (emptied first); rows must hold runs from `first_run` on, in order.
    pub fn create(
        target: &Target,
        lock: Option<&PartialLock>,
        columns: &[&str],
        first_run: Option<u64>,
    ) -> std::io::Result<CsvOut> {
        let header = header_line(columns);
        let mut out = match (target, lock) {
            (Target::File(path), Some(lock)) => {
                let mut file = lock.file().map_err(std::io::Error::other)?;
                empty(&file)?;
                std::io::Seek::seek(&mut file, std::io::SeekFrom::Start(0))?;
                CsvOut::in_file(path, lock, file, &header, first_run)?
            }
            (Target::File(_), None) => {
                return Err(std::io::Error::other("a file output needs its lock"))
            }
            _ => CsvOut {
                w: BufWriter::new(open_stream(target)?),
                written: target.path().to_path_buf(),
                file: None,
                header: header.clone(),
                first_run,
                hasher: ContentHasher::new(&header, first_run),
            },
        };
        out.w.write_all(&header)?;
        Ok(out)
    }

    /// Continue the locked `.partial` of `path`, whose first `hasher.bytes()` bytes were
    /// verified ([`crate::io::journal::verify_prefix`]): anything after them (a chunk cut off
    /// mid-write) is truncated.
    pub fn resume(
        path: &Path,
        lock: &PartialLock,
        columns: &[&str],
        first_run: u64,
        hasher: ContentHasher,
    ) -> std::io::Result<CsvOut> {
        let mut file = lock.file().map_err(std::io::Error::other)?;
        file.set_len(hasher.bytes())?;
        file.sync_all()?;
        std::io::Seek::seek(&mut file, std::io::SeekFrom::End(0))?;
        let mut out = CsvOut::in_file(path, lock, file, &header_line(columns), Some(first_run))?;
        out.hasher = hasher;
        Ok(out)
    }

    /// Writing into `file`, the locked `.partial` of `path`.
    fn in_file(
        path: &Path,
        lock: &PartialLock,
        file: File,
        header: &[u8],
        first_run: Option<u64>,
    ) -> std::io::Result<CsvOut> {
        Ok(CsvOut {
            w: BufWriter::new(Box::new(file.try_clone()?)),
            written: lock.path().to_path_buf(),
            file: Some((path.into(), file)),
            header: header.to_vec(),
            first_run,
            hasher: ContentHasher::new(header, first_run),
        })
    }

    /// Where the rows are being written (the `.partial` of a file).
    pub fn partial_path(&self) -> &Path {
        &self.written
    }

    /// Push everything written to the disk (fsync for a file) and return the bytes written
    /// and their hash (what the journal vouches for).
    pub fn sync(&mut self) -> std::io::Result<(u64, String)> {
        self.w.flush()?;
        if let Some((_, f)) = &self.file {
            f.sync_data()?;
        }
        Ok((self.hasher.bytes(), self.hasher.digest()))
    }

    /// fsync what was handed to the OS, without flushing the buffer: after a failed write,
    /// every row written whole before it ([`CsvOut::write_encoded`] flushes each chunk).
    pub fn sync_written(&self) -> std::io::Result<()> {
        match &self.file {
            Some((_, f)) => f.sync_data(),
            None => Ok(()),
        }
    }

    /// Bytes written so far, header included.
    pub fn bytes(&self) -> u64 {
        self.hasher.bytes()
    }

    /// The hash of the bytes written so far.
    pub fn digest(&self) -> String {
        self.hasher.digest()
    }

    /// Append rows already encoded as CSV lines ([`encode_csv`]), pushed to the OS so a crash
    /// keeps them; refused if they do not hold the next runs in order.
    pub fn write_encoded(&mut self, lines: &[u8]) -> std::io::Result<()> {
        self.hasher.rows(lines).map_err(invalid)?;
        self.w.write_all(lines)?;
        self.w.flush()
    }

    /// Flush and fsync; for a file, re-read it and check it holds exactly what was written
    /// (rows, run order, hash) and `expect_rows` rows, call `label` with its content (to write
    /// the sidecar first: a crash before the rename leaves a labelled, resumable `.partial`),
    /// then rename it to its final name. Returns the final path and the content.
    pub fn finish(
        mut self,
        expect_rows: Option<u64>,
        label: impl FnOnce(&Content) -> std::io::Result<()>,
    ) -> std::io::Result<(PathBuf, Content)> {
        if let Some(n) = expect_rows {
            if self.hasher.rows_seen() != n {
                return Err(invalid(format!(
                    "{} rows were written where {n} were expected: the output is incomplete",
                    self.hasher.rows_seen()
                )));
            }
        }
        self.w.flush()?;
        let content = self.hasher.finish();
        match self.file {
            Some((path, file)) => {
                file.sync_all()?;
                crate::io::journal::verify_file(
                    &self.written,
                    &self.header,
                    self.first_run,
                    &content,
                )
                .map_err(invalid)?;
                label(&content)?;
                std::fs::rename(&self.written, &path)?;
                Ok((path, content))
            }
            None => Ok((self.written, content)),
        }
    }
}

/// The cells of `columns` (all of them without).
pub fn pick(row: Vec<String>, columns: Option<&[usize]>) -> Vec<String> {
    match columns {
        Some(c) => c.iter().map(|&i| row[i].clone()).collect(),
        None => row,
    }
}

/// A sweep whose finished runs become rows: the pair's plan, or a row of buildings' plan. The
/// sweep output ([`crate::io::sweep_output`]) writes either through this.
pub trait RunRows: Sync {
    type Spec: Sync;
    type Output: Sync;
    /// The run number a spec holds.
    fn run_index(spec: &Self::Spec) -> u64;
    /// The fields of one run, in header order.
    fn cells(&self, spec: &Self::Spec, out: &Self::Output) -> Vec<String>;
    /// Fold finished runs into a summary built for this sweep's columns.
    fn fold(&self, agg: &mut Aggregator, rows: &[(Self::Spec, Self::Output)]);
}

impl RunRows for PairPlan {
    type Spec = RunSpec;
    type Output = RunOutput;
    fn run_index(spec: &RunSpec) -> u64 {
        spec.index
    }
    fn cells(&self, spec: &RunSpec, out: &RunOutput) -> Vec<String> {
        row(self, spec, out)
    }
    fn fold(&self, agg: &mut Aggregator, rows: &[(RunSpec, RunOutput)]) {
        agg.add_rows(self, rows)
    }
}

impl RunRows for RowPlan {
    type Spec = RowRunSpec;
    type Output = RowOutput;
    fn run_index(spec: &RowRunSpec) -> u64 {
        spec.index
    }
    fn cells(&self, spec: &RowRunSpec, out: &RowOutput) -> Vec<String> {
        RowPlan::cells(self, spec, out)
    }
    fn fold(&self, agg: &mut Aggregator, rows: &[(RowRunSpec, RowOutput)]) {
        agg.add_row_runs(self, rows)
    }
}

/// The cells of each run's row (`columns` as in [`pick`]), formatted in parallel.
pub fn cells<T: RunRows>(
    table: &T,
    rows: &[(T::Spec, T::Output)],
    columns: Option<&[usize]>,
) -> Vec<Vec<String>> {
    use rayon::prelude::*;
    rows.par_iter()
        .map(|(s, o)| pick(table.cells(s, o), columns))
        .collect()
}

/// Rows as CSV lines (`columns` as in [`pick`]): formatted in parallel blocks, the same bytes
/// as writing them one by one. Formatting, not the GPU, limited a 1e6-run sweep on an H100
/// (BENCHMARKS.md).
pub fn encode_csv<T: RunRows>(
    table: &T,
    rows: &[(T::Spec, T::Output)],
    columns: Option<&[usize]>,
) -> Vec<u8> {
    use rayon::prelude::*;
    let blocks: Vec<Vec<u8>> = rows
        .par_chunks(512)
        .map(|block| lines(block.iter().map(|(s, o)| pick(table.cells(s, o), columns))))
        .collect();
    blocks.concat()
}

/// The column names of an output: those `--columns` chose, or all of [`header`].
pub fn header_for(columns: Option<&[String]>) -> Vec<&str> {
    match columns {
        Some(c) => c.iter().map(String::as_str).collect(),
        None => header(),
    }
}
