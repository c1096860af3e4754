//! A prepared sweep run into its sink: a file output (fresh or resumed, put in place when
//! complete) or a table in memory.

use crate::engine::aggregate::Aggregator;
use crate::engine::{Chunk, Engine, Kernel, Report, Summary};
use crate::io::sweep_output::{Format, Opened, SweepOutput};
use crate::io::target::Target;
use crate::plan::settings::sweep_warnings;
use crate::plan::{config, Plan};
use crate::sweep::options::{FileFormat, Said, SweepError};
use crate::sweep::prepare::Prepared;
use std::ops::Range;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};

/// What runs a sweep: it hears what the sweep says and how far it got.
pub trait Front {
    fn say(&mut self, said: Said);
    /// `runs` runs are about to be computed.
    fn start(&mut self, runs: u64);
    /// Runs done so far.
    fn progress(&mut self, done: u64);
    /// The runs are over (before the output is put in place).
    fn end(&mut self);
}

/// A file output put in place: the sweep's totals, its path and what it holds.
pub struct Finished {
    pub summary: Summary,
    pub path: PathBuf,
    /// What the file holds, in words (`rows 0..180, sha256 ...`).
    pub what: String,
}

/// Where a sweep's runs go: folded into a summary, or each chunk to a sink of rows.
enum Into<'a> {
    Summary(&'a mut Aggregator),
    Rows(&'a mut dyn FnMut(Chunk<'_>) -> Result<(), SweepError>),
}

/// Run `runs` of `plan` on `engine` into `into`, watching `stop` if there is one (None: the
/// GPU's dispatches keep their whole budget, as the command line runs them): the report, the
/// runs whose peak displacement passed a building's height and those with a storey past the
/// collapse drift ratio (counted where rows come back; a summary folds them unseen).
fn integrate(
    engine: &Engine,
    plan: &Plan,
    runs: Range<u64>,
    stop: Option<&AtomicBool>,
    into: Into<'_>,
    progress: impl FnMut(u64),
) -> Result<(Report, u64, u64), SweepError> {
    let (mut above, mut past) = (0u64, 0u64);
    let report = match into {
        Into::Summary(agg) => match stop {
            Some(stop) => engine.summarise_until(plan, runs, stop, agg, progress)?,
            None => engine.summarise(plan, runs, agg, progress)?,
        },
        Into::Rows(sink) => {
            let sink = |c: Chunk<'_>| {
                above += c.above_height();
                past += c.past_collapse_drift();
                sink(c)
            };
            match stop {
                Some(stop) => engine.sweep_until(plan, runs, stop, sink, progress)?,
                None => engine.sweep(plan, runs, sink, progress)?,
            }
        }
    };
    Ok((report, above, past))
}

impl Prepared {
    /// Run the sweep into the file `target` (checked by the caller against the config's
    /// inputs), fresh or with `--resume` continued: None where a resume found it complete.
    /// The runs are written as they finish; the output is put in place only when every run is
    /// there and no record changed on disk meanwhile.
    pub fn run_to_file(
        mut self,
        target: Target,
        front: &mut (dyn Front + Send),
    ) -> Result<Option<Finished>, SweepError> {
        let range = match self.options.shard {
            Some(s) => crate::plan::shard::shard_range(&self.plan, s),
            None => 0..self.plan.len(),
        };
        let meta = self.meta(range.clone());
        let format = match self.summary.take() {
            Some(agg) => Format::Summary(Box::new(agg)),
            None if self.options.format == FileFormat::Parquet => Format::Parquet,
            None => Format::Csv,
        };
        let output = target.path().to_path_buf();
        let opened = SweepOutput::open(
            target,
            meta,
            format,
            self.picked.clone(),
            self.options.resume,
            &mut |l| front.say(Said::Notice(l)),
        )?;
        let mut out = match opened {
            Opened::Ready(o) => o,
            Opened::Complete(_) => return Ok(None),
        };
        if let Some(s) = self.options.shard {
            front.say(Said::Notice(format!(
                "shard {}/{}: runs {}..{} of {}",
                s.index,
                s.count,
                range.start,
                range.end,
                self.plan.len()
            )));
        }
        if out.done() > 0 {
            front.say(Said::Notice(format!(
                "resuming {}: {} runs already on disk",
                output.display(),
                out.done()
            )));
        }
        let pool = self.options.pool()?;
        let engine = self.engine();
        let plan = &self.plan;
        let todo = out.todo();
        front.say(Said::Notice(format!(
            "{}: {} runs of {}, {} scheme, {} kernel on the {}",
            self.config.display(),
            todo.end - todo.start,
            plan.scene(),
            plan.scheme().key(),
            Kernel::of(plan).key(),
            pool.install(|| engine.describe()),
        )));
        let partial = out.partial_path();
        front.start(todo.end - todo.start);
        let summarised = out.aggregator().is_some();
        let ran = pool.install(|| {
            let progress = |done| front.progress(done);
            match out.aggregator() {
                Some(agg) => integrate(&engine, plan, todo, None, Into::Summary(agg), progress),
                None => {
                    let mut sink = |c: Chunk<'_>| out.take_chunk(c).map_err(SweepError::from);
                    integrate(&engine, plan, todo, None, Into::Rows(&mut sink), progress)
                }
            }
        });
        let (report, above, past) = ran.map_err(|e| SweepError::Writing {
            partial,
            source: Box::new(e),
        })?;
        for n in gpu_notices(&engine, &report, summarised) {
            front.say(Said::Notice(n));
        }
        front.end();
        // Records are read once, at the start: a file changed since then no longer matches the
        // rows (or the fingerprint), so the output is not put in place.
        let changed = config::changed_records(&self.config_text, &self.config, plan);
        if !changed.is_empty() {
            let partial = out.partial_path();
            drop(out);
            return Err(SweepError::Changed(format!(
                "{} changed on disk during the sweep; the runs were computed from the content read at the start ({}); rerun the sweep (without --resume) to use the new content",
                changed.join(", "),
                if summarised {
                    "no summary was written".to_string()
                } else {
                    format!("their rows are left in {}", partial.display())
                }
            )));
        }
        let (path, what) = out.finish()?;
        for w in sweep_warnings(plan, above, past) {
            front.say(Said::Warning(w));
        }
        Ok(Some(Finished {
            summary: report.summary,
            path,
            what,
        }))
    }

    /// Run the whole sweep into memory until `stop` is raised, each chunk's rows (their cells,
    /// the columns of [`Prepared::names`]) to `rows`, or folded into the summary; `progress`
    /// hears the runs done. Call on the worker threads' pool ([`super::options::Options::pool`]).
    pub fn run_to_table(
        mut self,
        stop: &AtomicBool,
        progress: &dyn Fn(u64),
        rows: &mut dyn FnMut(Vec<Vec<String>>) -> Result<(), String>,
    ) -> Result<InMemory, SweepError> {
        let runs = self.plan.len();
        let mut meta = self.meta(0..runs).key_values();
        meta.push(("pound.kernel".into(), Kernel::of(&self.plan).key().into()));
        let mut summary = self.summary.take();
        let engine = self.engine();
        let plan = &self.plan;
        let picked = self.picked.as_deref();
        let describe = engine.describe();
        let mut written = 0u64;
        let (report, above, past) = match summary.as_mut() {
            Some(agg) => integrate(
                &engine,
                plan,
                0..runs,
                Some(stop),
                Into::Summary(agg),
                progress,
            )?,
            None => {
                let mut sink = |c: Chunk<'_>| {
                    if stop.load(Ordering::Relaxed) {
                        return Err(SweepError::Interrupted);
                    }
                    let cells = match c {
                        Chunk::Pairs(p, rows) => crate::io::csv::cells(p, rows, picked),
                        Chunk::Rows(r, rows) => crate::io::csv::cells(r, rows, picked),
                    };
                    written += cells.len() as u64;
                    rows(cells).map_err(SweepError::Table)
                };
                integrate(
                    &engine,
                    plan,
                    0..runs,
                    Some(stop),
                    Into::Rows(&mut sink),
                    progress,
                )?
            }
        };
        // A stopped CPU sweep ends early without an error: its table is not whole.
        if stop.load(Ordering::Relaxed) {
            return Err(SweepError::Interrupted);
        }
        let summary = match summary {
            Some(agg) if agg.runs() != runs => {
                return Err(SweepError::Table(format!(
                    "the summary folded {} runs where the sweep has {runs}",
                    agg.runs()
                )))
            }
            Some(agg) => Some(crate::io::summary::table(&agg)),
            None if written != runs => {
                return Err(SweepError::Table(format!(
                    "{written} rows where the sweep has {runs}: the table is incomplete"
                )))
            }
            None => None,
        };
        Ok(InMemory {
            totals: report.summary,
            warnings: sweep_warnings(plan, above, past),
            describe,
            kernel: Kernel::of(plan).key(),
            scene: plan.scene().to_string(),
            meta,
            summary,
        })
    }
}

/// A sweep run into memory.
pub struct InMemory {
    pub totals: Summary,
    /// What follows `warning: ` (absurd displacements, drifts past collapse).
    pub warnings: Vec<String>,
    /// The engine, in words.
    pub describe: String,
    pub kernel: &'static str,
    pub scene: String,
    /// The table's key-value metadata: the fingerprint, runs, backend and kernel.
    pub meta: Vec<(String, String)>,
    /// The summary (`--aggregate`), where the rows were folded.
    pub summary: Option<crate::io::summary::SummaryTable>,
}

/// What a GPU sweep tells after its runs: the device's folding of a summary, and the runs
/// handed to the CPU.
fn gpu_notices(engine: &Engine, report: &Report, summarised: bool) -> Vec<String> {
    let Engine::Gpu { opts, .. } = engine else {
        return Vec::new();
    };
    let t = report.gpu;
    let mut said = Vec::new();
    if summarised && t.aggregate > 0.0 {
        said.push(format!(
            "aggregated on the device: {:.2} s folding; {} chunks with more than {} groups folded on the host; histograms flushed {} times",
            t.aggregate,
            t.host_folded_chunks,
            crate::engine::gpu::reduce::DEFAULT_SLOTS,
            t.slot_flushes
        ));
    }
    if t.handed_off > 0 {
        said.push(format!(
            "{} runs needed more than {} RK4 substeps per record step, past what {} resolves: finished on the CPU in f64",
            t.handed_off,
            opts.handoff(),
            opts.precision.key()
        ));
    }
    said
}
