//! A sweep's options (the flags of `pound sweep`, the keywords of `pounding.sweep`), checked
//! against each other before any file is read; the errors and lines a sweep says.

use crate::engine::gpu::{GpuError, Precision};
use crate::engine::{Backend, EngineError};
use crate::plan::settings::{check_threads, SchemeKind};
use crate::plan::shard::Shard;
use std::path::Path;

/// How a sweep's rows are written to a file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FileFormat {
    Csv,
    Parquet,
}

impl FileFormat {
    /// The format asked for, else Parquet for a `.parquet` name (but a summary is CSV), else CSV.
    pub fn for_output(asked: Option<FileFormat>, output: &Path, aggregate: bool) -> FileFormat {
        let parquet_name = output
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("parquet"));
        asked.unwrap_or(if parquet_name && !aggregate {
            FileFormat::Parquet
        } else {
            FileFormat::Csv
        })
    }
}

/// What a sweep asks on top of its config.
#[derive(Debug, Clone)]
pub struct Options {
    /// A scheme over the config's (`--scheme`).
    pub scheme: Option<SchemeKind>,
    /// Each run's energy balance (`--energy`).
    pub energy: bool,
    /// The relative peak-force error accepted (`--target-error`).
    pub target_error: Option<f64>,
    pub backend: Backend,
    pub precision: Precision,
    /// Runs per CPU task or GPU chunk (`--chunk`).
    pub chunk: Option<usize>,
    /// Worker threads (`--threads`; default all cores).
    pub threads: Option<usize>,
    /// Only these columns (`--columns`).
    pub columns: Option<Vec<String>>,
    /// A row per group of these columns instead of a row per run (`--aggregate`).
    pub aggregate: Option<Vec<String>>,
    /// `COLUMN=THRESHOLD` counts of the summary (`--exceed`).
    pub exceed: Vec<String>,
    /// The file format (a table in memory: CSV, which takes every other option).
    pub format: FileFormat,
    /// Only this part of the plan (`--shard`).
    pub shard: Option<Shard>,
    /// Continue the output an interrupted sweep left (`--resume`).
    pub resume: bool,
}

impl Options {
    /// The options refused together, and the thread count, before any file is read.
    pub fn check(&self) -> Result<(), SweepError> {
        let refuse = |m: &str| Err(SweepError::Options(m.to_string()));
        if self.format == FileFormat::Parquet && self.resume {
            return refuse("--resume continues CSV output only: a Parquet file is readable only once its footer is written at the end");
        }
        if self.aggregate.is_some()
            && (self.format == FileFormat::Parquet || self.columns.is_some())
        {
            return refuse(
                "--aggregate writes its own summary columns: --format and --columns do not apply",
            );
        }
        if self.aggregate.is_some() && (self.resume || self.shard.is_some()) {
            return refuse("--aggregate keeps its summary in memory until the sweep ends: it cannot be combined with --resume or --shard");
        }
        if self.aggregate.is_none() && !self.exceed.is_empty() {
            return refuse("--exceed counts runs per group: it needs --aggregate");
        }
        if let Some(t) = self.threads {
            check_threads(t)?;
        }
        Ok(())
    }

    /// The worker threads (`--threads`, default all cores).
    pub fn pool(&self) -> Result<rayon::ThreadPool, SweepError> {
        pool(self.threads)
    }
}

/// `threads` worker threads (default all cores), checked as `--threads` is.
pub fn pool(threads: Option<usize>) -> Result<rayon::ThreadPool, SweepError> {
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(t) = threads {
        pool = pool.num_threads(check_threads(t)?);
    }
    pool.build()
        .map_err(|e| SweepError::Threads(format!("starting worker threads: {e}")))
}

/// A line a sweep says, for the front end to show its own way (standard error, Python's
/// warnings).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Said {
    /// As it is shown (`notice: ...`, a shard's runs, a resume).
    Notice(String),
    /// What follows `warning: `.
    Warning(String),
}

/// Why a sweep was refused or stopped, in the command line's words.
#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    /// Options refused together.
    #[error("{0}")]
    Options(String),
    #[error(transparent)]
    Config(#[from] crate::plan::config::ConfigError),
    /// A setting refused (the scheme, `--target-error`, a column, `--threads`).
    #[error(transparent)]
    Settings(#[from] crate::plan::settings::SettingsError),
    #[error(transparent)]
    Aggregate(#[from] crate::engine::aggregate::AggregateError),
    /// The engine refused (no GPU, a scene it does not take, a chunk out of bounds).
    #[error(transparent)]
    Engine(#[from] EngineError),
    /// The GPU failed, or refused the plan before any file was made.
    #[error(transparent)]
    Gpu(GpuError),
    #[error(transparent)]
    Output(#[from] crate::io::sweep_output::OutputError),
    /// The worker threads could not start.
    #[error("{0}")]
    Threads(String),
    /// Writing a file output failed; its finished rows stay in its `.partial`.
    #[error("writing {} (finished rows are kept there)", partial.display())]
    Writing {
        partial: std::path::PathBuf,
        #[source]
        source: Box<SweepError>,
    },
    /// A record changed on disk during the sweep.
    #[error("{0}")]
    Changed(String),
    /// A table in memory could not take the rows.
    #[error("{0}")]
    Table(String),
    /// The stop flag was raised (Ctrl-C in Python): the table is not whole.
    #[error("the sweep was stopped")]
    Interrupted,
}

impl From<GpuError> for SweepError {
    /// The GPU's answer to a raised stop flag is the interrupt, not a fault of the device.
    fn from(e: GpuError) -> Self {
        match e {
            GpuError::Interrupted => SweepError::Interrupted,
            e => SweepError::Gpu(e),
        }
    }
}
