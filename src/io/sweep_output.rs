//! Where a sweep's rows go, and the protocol that keeps them honest: a CSV row per run (journaled
//! after every chunk, resumable), Parquet, or a summary per group (`--aggregate`). A file output
//! is written into `OUT.partial` under an exclusive lock held for the sweep's life; `--resume`
//! re-reads and verifies what the journal vouches for before continuing; the output is renamed
//! into place only after its row count, run sequence and hash are checked against the plan, with
//! its sidecar (`OUT.meta.toml`) written first. Standard output, character devices and FIFOs are
//! written in place, with no journal and no sidecar.

use crate::engine::aggregate::Aggregator;
use crate::io::atomic::partial_path;
use crate::io::csv::{header_for, header_line, CsvOut, RunRows};
use crate::io::journal::{verify_file, verify_prefix, Content};
use crate::io::parquet::ParquetOut;
use crate::io::provenance::{meta_path, progress_path, read_toml, write_toml, Meta, Progress};
use crate::io::target::{PartialLock, Target};
use std::path::{Path, PathBuf};

#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    #[error("{}: {message}", path.display())]
    At { path: PathBuf, message: String },
    #[error(transparent)]
    Target(#[from] crate::io::target::TargetError),
}

fn at(path: &Path, message: impl std::fmt::Display) -> OutputError {
    OutputError::At {
        path: path.into(),
        message: message.to_string(),
    }
}

/// How rows are written.
pub enum Format {
    Csv,
    Parquet,
    /// One row per group ([`Aggregator`]).
    Summary(Box<Aggregator>),
}

enum Sink {
    Csv {
        out: Box<CsvOut>,
        /// The journal (file outputs only).
        journal: Option<Box<Journal>>,
    },
    Parquet(Box<ParquetOut>),
    Summary(Box<Aggregator>),
}

/// Seconds between two commits of a CSV output's journal (an fsync of the rows, then the
/// journal rewritten): a commit per chunk cost 86 s where /dev/null took 12.6 s on 500,000 cheap
/// runs (issue 65; BENCHMARKS.md, "What a file output costs"). A kill loses at most the rows of
/// the last second, which `--resume` computes again; an error or an unfinished drop commits
/// every row already written.
pub const COMMIT_EVERY_S: f64 = 1.0;

/// The journal of a CSV file output ([`Progress`], rewritten atomically), and what may be
/// committed to it next.
struct Journal {
    progress: Progress,
    file: PathBuf,
    /// The rows handed to the OS whole (runs of the range, bytes and their hash): what the
    /// next commit vouches for.
    written: (u64, u64, String),
    /// When the journal last vouched for rows (None: not yet for any row of this sweep).
    committed: Option<std::time::Instant>,
    every: std::time::Duration,
}

impl Journal {
    /// fsync the rows written so far, then record them in the journal; nothing to do where the
    /// journal already vouches for them.
    fn commit(&mut self, out: &CsvOut) -> Result<(), OutputError> {
        let (done, bytes, sha) = &self.written;
        if (*done, *bytes) == (self.progress.done, self.progress.bytes) {
            return Ok(());
        }
        out.sync_written().map_err(|e| at(out.partial_path(), e))?;
        self.progress.done = *done;
        self.progress.bytes = *bytes;
        self.progress.sha256 = sha.clone();
        write_toml(&self.file, &self.progress).map_err(|e| at(&self.file, e))?;
        self.committed = Some(std::time::Instant::now());
        Ok(())
    }

    /// Is a commit due: the first rows of the sweep, or [`COMMIT_EVERY_S`] since the last?
    fn due(&self) -> bool {
        self.committed.is_none_or(|t| t.elapsed() >= self.every)
    }
}

/// The commit interval: [`COMMIT_EVERY_S`], or `POUND_COMMIT_S` seconds (tests; 0 commits after
/// every chunk, as pound did before).
fn commit_every() -> std::time::Duration {
    let s = std::env::var("POUND_COMMIT_S")
        .ok()
        .and_then(|s| s.parse::<f64>().ok())
        .filter(|s| s.is_finite() && *s >= 0.0)
        .unwrap_or(COMMIT_EVERY_S);
    std::time::Duration::from_secs_f64(s)
}

/// An open sweep output.
pub struct SweepOutput {
    target: Target,
    /// Held until the output is in place (file outputs).
    lock: Option<PartialLock>,
    meta: Meta,
    columns: Option<Vec<usize>>,
    /// None once finished.
    sink: Option<Sink>,
    /// Runs of the range already on disk when it was opened (`--resume`).
    done: u64,
    /// The run the next row must be.
    next_run: u64,
}

/// What [`SweepOutput::open`] found.
pub enum Opened {
    Ready(Box<SweepOutput>),
    /// `--resume` of an output that is already complete (and checked).
    Complete(PathBuf),
}

/// Does the journal `progress` say 0 runs are done, and `partial` hold at most a header line
/// (no row)? An edited journal beside rows is not such a journal: the rows decide.
fn holds_no_rows(partial: &Path, progress: &Path) -> bool {
    use std::io::{BufRead, Read};
    if !read_toml::<Progress>(progress).is_ok_and(|p| p.done == 0) {
        return false;
    }
    // The header line, then nothing: read no further than one byte past it.
    let Ok(f) = std::fs::File::open(partial) else {
        return false;
    };
    let mut r = std::io::BufReader::new(f);
    let mut header = Vec::new();
    let mut next = [0u8; 1];
    r.read_until(b'\n', &mut header).is_ok() && r.read(&mut next).is_ok_and(|n| n == 0)
}

/// What `--resume` found at `path` where no journal is: an output of this sweep already
/// complete, or nothing to protect (no file, or an empty one).
enum Existing {
    Complete,
    Absent,
}

/// Classify the file at `path` for a `--resume` that found no journal ([`Existing`]); Err, naming
/// the file and why, where it holds something `--resume` would destroy: a finished output of
/// another sweep (the keys that differ named, as for a journal), of another shard or columns,
/// one edited since its sweep wrote it, or a file without a sidecar.
fn existing_output(path: &Path, meta: &Meta, header: &[u8]) -> Result<Existing, OutputError> {
    match std::fs::metadata(path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Existing::Absent),
        Err(e) => return Err(at(path, e)),
        Ok(m) if m.len() == 0 => return Ok(Existing::Absent),
        Ok(_) => {}
    }
    let meta_file = meta_path(path);
    let refuse = |why: String| {
        at(
            path,
            format!(
                "--resume found no unfinished sweep to continue here ({} does not exist), and {why}: refusing to overwrite it; rerun without --resume to replace it, or name another output with -o",
                progress_path(path).display()
            ),
        )
    };
    let m: Meta = match read_toml(&meta_file) {
        Ok(m) => m,
        Err(_) if !meta_file.exists() => {
            return Err(refuse(format!(
                "the file is not an output of this sweep (it has no sidecar {})",
                meta_file.display()
            )))
        }
        Err(e) => return Err(refuse(format!("its sidecar cannot be read ({e})"))),
    };
    let there = meta_file.display().to_string();
    if let Some(d) = meta.differs(&m, &there) {
        return Err(refuse(format!(
            "it is the finished output of another sweep: {}",
            d.differs_from("the sweep that wrote it")
        )));
    }
    if (m.first_run, m.end_run) != (meta.first_run, meta.end_run) {
        return Err(refuse(format!(
            "it is the finished output of runs {}..{} of this config, not {}..{} (another --shard)",
            m.first_run, m.end_run, meta.first_run, meta.end_run
        )));
    }
    if m.columns != meta.columns {
        return Err(refuse(
            "it is the finished output of this config with other columns (--columns)".into(),
        ));
    }
    let Some(content) = m.content.as_ref() else {
        return Err(refuse(format!(
            "its sidecar {} carries no content hash, so it cannot be checked as complete",
            meta_file.display()
        )));
    };
    if let Err(e) = verify_file(path, header, Some(meta.first_run), content) {
        return Err(refuse(format!("it is not what its sweep wrote ({e})")));
    }
    Ok(Existing::Complete)
}

impl SweepOutput {
    /// Open `target` for the runs `meta.first_run..meta.end_run`: a fresh output, or with
    /// `resume` the verified prefix an interrupted sweep left. `columns` are indices into
    /// [`crate::plan::columns::header`] (`--columns`). `note` receives one-line notices.
    pub fn open(
        target: Target,
        meta: Meta,
        format: Format,
        columns: Option<Vec<usize>>,
        resume: bool,
        note: &mut dyn FnMut(String),
    ) -> Result<Opened, OutputError> {
        let path = target.path().to_path_buf();
        if resume && !matches!(format, Format::Csv) {
            return Err(at(
                &path,
                "--resume continues CSV output only (a Parquet file is readable only once its footer is written; a summary is kept in memory)",
            ));
        }
        if resume && !target.is_file() {
            return Err(at(
                &path,
                "--resume needs a file output: standard output, devices and FIFOs keep no journal",
            ));
        }
        let lock = match &target {
            Target::File(p) => {
                let partial = partial_path(p);
                let existed = partial.exists();
                let lock = PartialLock::acquire(&partial)?;
                Some((lock, existed))
            }
            _ => None,
        };
        let opened = Self::open_locked(&target, &meta, format, resume, &lock, note);
        match opened {
            Ok(Some((sink, done))) => Ok(Opened::Ready(Box::new(SweepOutput {
                lock: lock.map(|(l, _)| l),
                next_run: meta.first_run + done,
                target,
                meta,
                columns,
                sink: Some(sink),
                done,
            }))),
            Ok(None) | Err(_) => {
                // Leave no empty `.partial` behind that this call created.
                if let Some((l, false)) = &lock {
                    let _ = std::fs::remove_file(l.path());
                }
                opened.map(|_| Opened::Complete(path))
            }
        }
    }

    #[allow(clippy::type_complexity)]
    fn open_locked(
        target: &Target,
        meta: &Meta,
        format: Format,
        resume: bool,
        lock: &Option<(PartialLock, bool)>,
        note: &mut dyn FnMut(String),
    ) -> Result<Option<(Sink, u64)>, OutputError> {
        let path = target.path();
        let lock = lock.as_ref().map(|(l, _)| l);
        let names = header_for(meta.columns.as_deref());
        let header = header_line(&names);
        let progress_file = progress_path(path);
        // A journal of 0 runs beside a `.partial` of no rows (a sweep stopped before its first
        // chunk) holds nothing to continue or protect: it never blocks a new sweep.
        if let Some(l) = lock {
            if progress_file.exists() && holds_no_rows(l.path(), &progress_file) {
                std::fs::remove_file(&progress_file)
                    .map_err(|e| at(&progress_file, e.to_string()))?;
                note(format!(
                    "notice: {} recorded 0 finished runs: starting afresh",
                    progress_file.display()
                ));
            }
        }
        // An unfinished CSV sweep's rows are only ever continued (CSV, --resume), never
        // overwritten by a fresh sweep of any format.
        if let Some(l) = lock {
            if progress_file.exists() && !(resume && matches!(format, Format::Csv)) {
                let held = read_toml::<Progress>(&progress_file)
                    .map(|p| format!("holds {} finished runs of", p.done))
                    .unwrap_or_else(|_| "belongs to".into());
                return Err(at(
                    l.path(),
                    format!(
                        "{held} an unfinished CSV sweep: rerun with --resume to continue it, or delete {} and {} to start over",
                        l.path().display(),
                        progress_file.display()
                    ),
                ));
            }
        }
        match format {
            Format::Summary(agg) => return Ok(Some((Sink::Summary(agg), 0))),
            Format::Parquet => {
                let out = ParquetOut::create(target, lock, &names, meta)
                    .map_err(|e| at(path, format!("cannot create it: {e}")))?;
                return Ok(Some((Sink::Parquet(Box::new(out)), 0)));
            }
            Format::Csv => {}
        }
        let Some(lock) = lock else {
            let out = CsvOut::create(target, None, &names, Some(meta.first_run))
                .map_err(|e| at(path, format!("cannot write it: {e}")))?;
            return Ok(Some((
                Sink::Csv {
                    out: Box::new(out),
                    journal: None,
                },
                0,
            )));
        };
        let start_over = format!(
            "delete {} and {} to start over",
            lock.path().display(),
            progress_file.display()
        );
        let (out, done) = if resume && progress_file.exists() {
            let p: Progress = read_toml(&progress_file)
                .map_err(|e| at(path, format!("cannot resume: {e}; {start_over}")))?;
            let cannot = |what: &str| {
                at(
                    path,
                    format!(
                        "cannot resume: {what} differs from the sweep that wrote it; rerun without --resume after deleting {} to start over",
                        progress_file.display()
                    ),
                )
            };
            // The keys that differ are named where the journal records them.
            if let Some(d) = meta.differs(&p.meta, &progress_file.display().to_string()) {
                return Err(at(
                    path,
                    format!(
                        "cannot resume: {}; rerun without --resume after deleting {} to start over",
                        d.differs_from("the sweep that wrote it"),
                        progress_file.display()
                    ),
                ));
            }
            if (p.meta.first_run, p.meta.end_run, p.meta.shard)
                != (meta.first_run, meta.end_run, meta.shard)
            {
                return Err(cannot("the shard (--shard)"));
            }
            if p.meta.backend != meta.backend {
                return Err(cannot("the backend (--backend, --precision)"));
            }
            // Kernels chosen from the scene by another pound (recorded since it was).
            if p.meta.kernel.is_some() && p.meta.kernel != meta.kernel {
                return Err(cannot(
                    "the kernel the scene takes (a pound of another version wrote it)",
                ));
            }
            if p.meta.columns != meta.columns {
                return Err(cannot("the columns (--columns)"));
            }
            if p.sha256.is_empty() {
                return Err(at(
                    path,
                    format!("cannot resume: its journal {} carries no checksum (written by an older pound); {start_over}", progress_file.display()),
                ));
            }
            if p.done > meta.end_run - meta.first_run {
                return Err(at(
                    path,
                    format!(
                        "cannot resume: its journal claims {} runs of a range of {}: it was edited; {start_over}",
                        p.done,
                        meta.end_run - meta.first_run
                    ),
                ));
            }
            // The journal is a hint: what the `.partial` holds is checked, row by row.
            let hasher = verify_prefix(
                lock.path(),
                &header,
                meta.first_run,
                p.done,
                p.bytes,
                &p.sha256,
            )
            .map_err(|e| at(path, format!("cannot resume: {e}; {start_over}")))?;
            let out = CsvOut::resume(path, lock, &names, meta.first_run, hasher)
                .map_err(|e| at(path, format!("cannot resume: {e}")))?;
            (out, p.done)
        } else {
            if resume {
                // No journal: the output is complete, or absent (nothing to resume), or a file
                // that `--resume` must not replace: another sweep's output, an edited one, a file
                // pound did not write. Only a plain `-o` (no --resume) overwrites.
                match existing_output(path, meta, &header)? {
                    Existing::Complete => {
                        note(format!("{} is already complete", path.display()));
                        return Ok(None);
                    }
                    Existing::Absent => note(format!(
                        "nothing to resume for {}: starting",
                        path.display()
                    )),
                }
            }
            let out = CsvOut::create(target, Some(lock), &names, Some(meta.first_run))
                .map_err(|e| at(path, format!("cannot create it: {e}")))?;
            (out, 0)
        };
        let mut out = out;
        let (bytes, sha256) = out.sync().map_err(|e| at(lock.path(), e))?;
        let progress = Progress {
            meta: meta.clone(),
            done,
            bytes,
            sha256: sha256.clone(),
        };
        write_toml(&progress_file, &progress).map_err(|e| at(path, e))?;
        Ok(Some((
            Sink::Csv {
                out: Box::new(out),
                journal: Some(Box::new(Journal {
                    progress,
                    file: progress_file,
                    written: (done, bytes, sha256),
                    committed: None,
                    every: commit_every(),
                })),
            },
            done,
        )))
    }

    /// Runs of the range already on disk (resumed).
    pub fn done(&self) -> u64 {
        self.done
    }

    /// The runs still to compute.
    pub fn todo(&self) -> std::ops::Range<u64> {
        self.next_run..self.meta.end_run
    }

    /// Where rows are being written (`OUT.partial` for a file).
    pub fn partial_path(&self) -> PathBuf {
        match &self.lock {
            Some(l) => l.path().to_path_buf(),
            None => self.target.path().to_path_buf(),
        }
    }

    /// The summary being folded (`--aggregate`), for the device fold.
    pub fn aggregator(&mut self) -> Option<&mut Aggregator> {
        match &mut self.sink {
            Some(Sink::Summary(a)) => Some(a),
            _ => None,
        }
    }

    /// Write a chunk of finished runs of any plan ([`crate::engine::Engine::sweep`]), which must
    /// be the next runs in order ([`SweepOutput::take`]).
    pub fn take_chunk(&mut self, chunk: crate::engine::Chunk<'_>) -> Result<(), OutputError> {
        match chunk {
            crate::engine::Chunk::Pairs(plan, rows) => self.take(plan, rows),
            crate::engine::Chunk::Rows(plan, rows) => self.take(plan, rows),
        }
    }

    /// Write a chunk of finished runs, which must be the next runs in order. CSV rows are
    /// fsynced before the journal counts them, so a crash leaves a consistent prefix; the
    /// journal is committed after the sweep's first chunk, then at most every
    /// [`COMMIT_EVERY_S`], and on an error with every row written whole before it.
    pub fn take<T: RunRows>(
        &mut self,
        plan: &T,
        rows: &[(T::Spec, T::Output)],
    ) -> Result<(), OutputError> {
        let path = self.partial_path();
        for (k, (s, _)) in rows.iter().enumerate() {
            let index = T::run_index(s);
            if index != self.next_run + k as u64 {
                return Err(at(
                    &path,
                    format!(
                        "run {} came where run {} was due: refusing to write rows out of order",
                        index,
                        self.next_run + k as u64
                    ),
                ));
            }
        }
        self.next_run += rows.len() as u64;
        let columns = self.columns.as_deref();
        let Some(sink) = &mut self.sink else {
            return Err(at(&path, "rows after the output was finished"));
        };
        match sink {
            Sink::Csv { out, journal } => {
                let written = out.write_encoded(&crate::io::csv::encode_csv(plan, rows, columns));
                if let Some(j) = journal {
                    if let Err(e) = written {
                        // Keep what was written whole before this chunk; the error is the news.
                        let kept = j.commit(out).err().map(|k| format!(" (and {k})"));
                        return Err(at(&path, format!("{e}{}", kept.unwrap_or_default())));
                    }
                    j.written = (j.written.0 + rows.len() as u64, out.bytes(), out.digest());
                    if j.due() {
                        j.commit(out)?;
                    }
                } else {
                    written.map_err(|e| at(&path, e))?;
                }
            }
            Sink::Parquet(out) => {
                let cells = crate::io::csv::cells(plan, rows, columns);
                out.write(&cells).map_err(|e| at(&path, e))?;
            }
            Sink::Summary(agg) => plan.fold(agg, rows),
        }
        Ok(())
    }

    /// Put the output in place once it holds every run of its range: checked, labelled with
    /// its sidecar (file outputs), renamed; the journal removed last. Returns the final path
    /// and a line about the output (groups of a summary).
    pub fn finish(mut self) -> Result<(PathBuf, String), OutputError> {
        let sink = self.sink.take().expect("finished once");
        let resumable = matches!(sink, Sink::Csv { .. });
        let (target, lock, mut meta) = (self.target.clone(), self.lock.take(), self.meta.clone());
        let path = target.path().to_path_buf();
        let expect = meta.end_run - meta.first_run;
        let is_file = target.is_file();
        let meta_file = meta_path(&path);
        let mut label = |c: &Content| -> std::io::Result<()> {
            if is_file {
                meta.content = Some(c.clone());
                write_toml(&meta_file, &meta).map_err(std::io::Error::other)?;
            }
            Ok(())
        };
        let done = (|| -> Result<(PathBuf, String), OutputError> {
            Ok(match sink {
                Sink::Csv { out, mut journal } => {
                    // Every row in the journal first: an output not put in place stays
                    // resumable from its last row.
                    if let Some(j) = &mut journal {
                        j.commit(&out)?;
                    }
                    let (p, c) = out
                        .finish(Some(expect), &mut label)
                        .map_err(|e| at(&path, format!("not put in place: {e}")))?;
                    if let Some(j) = journal {
                        std::fs::remove_file(&j.file).map_err(|e| at(&j.file, e))?;
                    }
                    (p, format!("{} rows", c.rows))
                }
                Sink::Parquet(out) => {
                    let (p, c) = out
                        .finish(expect, &mut label)
                        .map_err(|e| at(&path, format!("not put in place: {e}")))?;
                    (p, format!("{} rows", c.rows))
                }
                Sink::Summary(agg) => {
                    if agg.runs() != expect {
                        return Err(at(
                            &path,
                            format!(
                                "not written: the summary folded {} runs where the sweep has {expect}",
                                agg.runs()
                            ),
                        ));
                    }
                    let text = crate::io::summary::csv(&agg);
                    write_summary(&target, lock.as_ref(), text.as_bytes(), &mut label)
                        .map_err(|e| at(&path, e))?;
                    (path.clone(), format!("{} groups", agg.groups()))
                }
            })
        })();
        if done.is_err() && is_file {
            if !path.exists() {
                // No sidecar for an output that is not there (disk full, say).
                let _ = std::fs::remove_file(&meta_file);
            }
            if let (false, Some(l)) = (resumable, &lock) {
                // Only CSV can be resumed; nothing else of an unfinished output is kept.
                let _ = std::fs::remove_file(l.path());
            }
        }
        drop(lock);
        done
    }
}

/// Dropped unfinished (an error, a changed record): CSV rows stay in the `.partial` with their
/// journal, for `--resume`; an unfinished Parquet file or summary cannot be continued and is
/// removed.
impl Drop for SweepOutput {
    fn drop(&mut self) {
        if let Some(Sink::Csv {
            out,
            journal: Some(j),
        }) = &mut self.sink
        {
            // Every row written whole is kept for --resume (the journal is committed only every
            // [`COMMIT_EVERY_S`] while the sweep runs).
            if let Err(e) = j.commit(out) {
                crate::note(format_args!(
                    "warning: the journal of {} could not record its last rows ({e}): --resume computes them again",
                    out.partial_path().display()
                ));
            }
        }
        if matches!(self.sink, Some(Sink::Parquet(_) | Sink::Summary(_))) {
            if let Some(l) = &self.lock {
                let _ = std::fs::remove_file(l.path());
            }
        }
    }
}

/// Write a summary whole: into the locked `.partial` (fsync, label, rename) or a stream.
fn write_summary(
    target: &Target,
    lock: Option<&PartialLock>,
    bytes: &[u8],
    label: &mut dyn FnMut(&Content) -> std::io::Result<()>,
) -> std::io::Result<()> {
    use std::io::Write;
    let content = Content {
        rows: bytes
            .iter()
            .filter(|&&b| b == b'\n')
            .count()
            .saturating_sub(1) as u64,
        sha256: {
            use sha2::Digest;
            sha2::Sha256::digest(bytes)
                .iter()
                .map(|b| format!("{b:02x}"))
                .collect()
        },
        blocks: Vec::new(),
    };
    match (target, lock) {
        (Target::File(p), Some(l)) => {
            let written = (|| {
                let mut f = l.file().map_err(std::io::Error::other)?;
                crate::io::atomic::empty(&f)?;
                f.write_all(bytes)?;
                f.sync_all()?;
                label(&content)?;
                std::fs::rename(l.path(), p)
            })();
            if written.is_err() {
                let _ = std::fs::remove_file(l.path());
            }
            written
        }
        _ => {
            let mut w = crate::io::atomic::open_stream(target)?;
            w.write_all(bytes)?;
            w.flush()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::provenance::Fingerprint;
    use crate::physics::model::RunOutput;
    use crate::plan::{PairPlan, RunSpec};

    const CFG: &str = r#"
[building1]
mass_kg = 1.0e5
period_s = [0.3, 0.6]
damping_ratio = 0.05
[building2]
mass_kg = 1.0e5
period_s = 0.9
damping_ratio = 0.05
[contact]
law = "linear"
k_n_per_m = 1e9
gap_m = [0.0, 0.01, 0.02]
[[record]]
synthetic = { seed = 2, duration_s = 2.0 }
"#;

    fn rows(plan: &PairPlan) -> Vec<(RunSpec, RunOutput)> {
        let mut all = Vec::new();
        crate::engine::Engine::cpu(plan.contact.spec.scheme, Some(2))
            .unwrap()
            .run(
                plan,
                0..plan.len(),
                |c: &[(RunSpec, RunOutput)]| -> Result<(), crate::engine::gpu::GpuError> {
                    all.extend_from_slice(c);
                    Ok(())
                },
                |_| {},
            )
            .unwrap();
        all
    }

    fn meta(plan: &PairPlan) -> Meta {
        Meta {
            fingerprint: Fingerprint::of(plan),
            plan_runs: plan.len(),
            first_run: 0,
            end_run: plan.len(),
            shard: None,
            backend: "cpu".into(),
            kernel: None,
            columns: None,
            content: None,
            target_error: None,
            settings: None,
        }
    }

    fn open(out: &Path, plan: &PairPlan, resume: bool) -> Result<Opened, OutputError> {
        SweepOutput::open(
            Target::File(out.into()),
            meta(plan),
            Format::Csv,
            None,
            resume,
            &mut |_| {},
        )
    }

    fn ready(o: Result<Opened, OutputError>) -> Box<SweepOutput> {
        match o.unwrap() {
            Opened::Ready(o) => o,
            Opened::Complete(p) => panic!("{} already complete", p.display()),
        }
    }

    #[test]
    fn an_interrupted_output_resumes_to_the_whole_and_is_labelled() {
        let plan = crate::plan::config::parse_builtin(CFG, "t.toml").unwrap();
        let all = rows(&plan);
        assert_eq!(all.len(), 6);
        let d = tempfile::tempdir().unwrap();
        let whole = d.path().join("whole.csv");
        let mut o = ready(open(&whole, &plan, false));
        o.take(&plan, &all).unwrap();
        o.finish().unwrap();
        // Rows out of order are refused.
        let mut o = ready(open(&d.path().join("order.csv"), &plan, false));
        let e = o.take(&plan, &all[1..2]).unwrap_err();
        assert!(
            e.to_string().contains("run 1 came where run 0 was due"),
            "{e}"
        );
        // Half the runs, then a crash (dropped unfinished): the CSV keeps its journal.
        let out = d.path().join("o.csv");
        let mut o = ready(open(&out, &plan, false));
        o.take(&plan, &all[..3]).unwrap();
        drop(o);
        assert!(progress_path(&out).exists());
        // A plain open refuses to overwrite it; a resume continues at run 3.
        assert!(open(&out, &plan, false).is_err());
        let mut o = ready(open(&out, &plan, true));
        assert_eq!((o.done(), o.todo()), (3, 3..6));
        o.take(&plan, &all[3..]).unwrap();
        let (path, _) = o.finish().unwrap();
        assert_eq!(path, out);
        assert_eq!(std::fs::read(&out).unwrap(), std::fs::read(&whole).unwrap());
        let m: Meta = read_toml(&meta_path(&out)).unwrap();
        let c = m.content.unwrap();
        assert_eq!(c.rows, 6);
        assert_eq!(c.sha256, crate::io::journal::file_sha256(&out).unwrap());
        // Resuming a complete, intact output does nothing.
        assert!(matches!(
            open(&out, &plan, true).unwrap(),
            Opened::Complete(_)
        ));
    }

    #[test]
    fn an_output_missing_runs_is_not_put_in_place() {
        let plan = crate::plan::config::parse_builtin(CFG, "t.toml").unwrap();
        let all = rows(&plan);
        let d = tempfile::tempdir().unwrap();
        let out = d.path().join("o.csv");
        let mut o = ready(open(&out, &plan, false));
        o.take(&plan, &all[..5]).unwrap();
        let e = o.finish().unwrap_err();
        assert!(e.to_string().contains("5 rows were written where 6"), "{e}");
        assert!(!out.exists() && !meta_path(&out).exists());
        // A summary that folded fewer runs than the range is not written either.
        let agg = Aggregator::new(&["gap_m".into()], &[]).unwrap();
        let sum = d.path().join("s.csv");
        let mut o = ready(SweepOutput::open(
            Target::File(sum.clone()),
            meta(&plan),
            Format::Summary(Box::new(agg)),
            None,
            false,
            &mut |_| {},
        ));
        o.take(&plan, &all[..4]).unwrap();
        let e = o.finish().unwrap_err();
        assert!(
            e.to_string()
                .contains("folded 4 runs where the sweep has 6"),
            "{e}"
        );
        assert!(!sum.exists() && !partial_path(&sum).exists());
    }
}
