//! `pounding._pounding`: the library's commands for Python. Glue only: a config (path, TOML text
//! or dict) in, the library's settings stage, engine and studies run (the GIL released, Ctrl-C
//! watched), tables out as Arrow streams (the PyCapsule interface). The package's Python layer
//! (`pounding/__init__.py`) gives these their keyword arguments, progress and conversions.

mod arrow;

use arrow::{study_table, table_cells, Columns, Table};
use pounding::engine::Backend;
use pounding::io::parquet::{kind, Kind};
use pounding::plan::config;
use pounding::plan::settings::SchemeKind;
use pounding::studies::report::StudyReport;
use pounding::sweep::options::{FileFormat, Options, Said, SweepError};
use pounding::sweep::prepare::Prepared;
use pyo3::create_exception;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

create_exception!(
    pounding,
    PoundingError,
    PyException,
    "An error of the pounding engine."
);
create_exception!(
    pounding,
    ConfigError,
    PoundingError,
    "A config that cannot be read or planned: the message names the file (or the string or dict given), the key and what was expected."
);
create_exception!(
    pounding,
    RecordError,
    PoundingError,
    "A ground-motion record that cannot be read: the message names the file and the line."
);
create_exception!(
    pounding,
    SettingsError,
    PoundingError,
    "An option refused (a column that is not there, a target error out of range, a backend that cannot run the sweep)."
);
create_exception!(
    pounding,
    TableError,
    PoundingError,
    "A results table a study cannot read: the message names the column and what was expected."
);
create_exception!(
    pounding,
    GpuError,
    PoundingError,
    "The GPU could not run the sweep."
);

/// A library error as the Python exception of its kind, with the command line's message.
fn config_err(e: config::ConfigError) -> PyErr {
    match e {
        config::ConfigError::Record { .. } => RecordError::new_err(e.to_string()),
        e => ConfigError::new_err(e.to_string()),
    }
}

/// [`config_err`] of a config read from `text` at `path`. A dict's TOML is written here, so a
/// parse error's line and column point into text the user never saw: the error names the key
/// instead (`<config dict>: building1.period_s: invalid type: a list, expected a number`).
fn config_err_in(e: config::ConfigError, text: &str, path: &Path) -> PyErr {
    let message = e.to_string();
    if path != Path::new(DICT) {
        return config_err(e);
    }
    let Some(line) = message
        .split("TOML parse error at line ")
        .nth(1)
        .and_then(|r| r.split(',').next())
        .and_then(|n| n.trim().parse::<usize>().ok())
    else {
        return config_err(e);
    };
    let reason = message
        .lines()
        .rev()
        .map(str::trim)
        .find(|l| !l.is_empty())
        .unwrap_or("");
    ConfigError::new_err(match dict_key_at(text, line) {
        Some(key) => format!("{DICT}: {key}: {reason}"),
        None => format!("{DICT}: {reason}"),
    })
}

/// The name of a dict config's TOML text.
const DICT: &str = "<config dict>";

/// The dotted key (`building1.period_s`, `record[1].synthetic`) that line `line` (1-based) of a
/// dict config's TOML sets, from the table headers above it.
fn dict_key_at(text: &str, line: usize) -> Option<String> {
    let lines: Vec<&str> = text.lines().collect();
    let here = lines.get(line.checked_sub(1)?)?.trim();
    let key = here.split_once(" = ")?.0.trim().trim_matches('"');
    let mut table = String::new();
    for l in lines[..line - 1].iter().rev().map(|l| l.trim()) {
        if let Some(name) = l.strip_prefix("[[").and_then(|r| r.strip_suffix("]]")) {
            let index = lines[..line - 1].iter().filter(|x| x.trim() == l).count() - 1;
            table = format!("{name}[{index}].");
            break;
        }
        if let Some(name) = l.strip_prefix('[').and_then(|r| r.strip_suffix(']')) {
            table = format!("{name}.");
            break;
        }
    }
    Some(format!("{table}{key}"))
}

/// The engine's refusal: of the device (none found, a scene it does not take) or of a setting.
fn engine_err(e: pounding::engine::EngineError) -> PyErr {
    use pounding::engine::EngineError as E;
    match e {
        E::Chunk { .. } => SettingsError::new_err(e.to_string()),
        E::GpuNeedsFast | E::GpuUnfit(_) | E::Gpu(_) => GpuError::new_err(e.to_string()),
    }
}

fn settings_err(e: impl std::fmt::Display) -> PyErr {
    SettingsError::new_err(e.to_string())
}

/// The config given: its text, and the path records are found from and messages name (a
/// string's or dict's records are found from the working folder).
fn config_text(config: &Bound<'_, PyAny>, kind: &str) -> PyResult<(String, PathBuf)> {
    match kind {
        "path" => {
            let path = PathBuf::from(config.extract::<String>()?);
            let text = config::read_text(&path).map_err(config_err)?;
            Ok((text, path))
        }
        "text" => Ok((config.extract()?, PathBuf::from("<config string>"))),
        "dict" => {
            let table = toml_table(config.cast::<PyDict>()?, "")?;
            let text = toml::to_string(&table)
                .map_err(|e| ConfigError::new_err(format!("<config dict>: {e}")))?;
            Ok((text, PathBuf::from(DICT)))
        }
        other => Err(settings_err(format!(
            "config kind `{other}`: expected path, text or dict"
        ))),
    }
}

/// A dict with a config's structure as a TOML table (keys as written; values: str, bool, int,
/// float, lists and dicts of them).
fn toml_table(d: &Bound<'_, PyDict>, at: &str) -> PyResult<toml::Table> {
    let mut t = toml::Table::new();
    for (k, v) in d.iter() {
        let key: String = k.extract().map_err(|_| {
            ConfigError::new_err(format!(
                "<config dict>: {at}a key is not a string ({k:?}): keys are the config's names"
            ))
        })?;
        let here = format!("{at}{key}");
        t.insert(key, toml_value(&v, &here)?);
    }
    Ok(t)
}

fn toml_value(v: &Bound<'_, PyAny>, at: &str) -> PyResult<toml::Value> {
    use pyo3::types::{PyBool, PyFloat, PyInt, PyString, PyTuple};
    Ok(if v.is_instance_of::<PyBool>() {
        toml::Value::Boolean(v.extract()?)
    } else if v.is_instance_of::<PyInt>() {
        toml::Value::Integer(v.extract().map_err(|_| {
            ConfigError::new_err(format!(
                "<config dict>: {at}: {v} is beyond a 64-bit integer"
            ))
        })?)
    } else if v.is_instance_of::<PyFloat>() {
        toml::Value::Float(v.extract()?)
    } else if v.is_instance_of::<PyString>() {
        toml::Value::String(v.extract()?)
    } else if let Ok(d) = v.cast::<PyDict>() {
        toml::Value::Table(toml_table(d, &format!("{at}."))?)
    } else if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        let items: Vec<Bound<'_, PyAny>> = v.try_iter()?.collect::<PyResult<_>>()?;
        toml::Value::Array(
            items
                .iter()
                .enumerate()
                .map(|(i, x)| toml_value(x, &format!("{at}[{i}]")))
                .collect::<PyResult<_>>()?,
        )
    } else if v.hasattr("tolist")? {
        // numpy's arrays and numbers (pandas' series): as the list or number they hold.
        let plain = v.call_method0("tolist").map_err(|e| {
            ConfigError::new_err(format!("<config dict>: {at}: {v}.tolist() failed: {e}"))
        })?;
        if plain.get_type().is(v.get_type()) {
            return Err(ConfigError::new_err(format!(
                "<config dict>: {at}: a {} is not a config value (expected a string, number, bool, list or dict)",
                v.get_type().name()?
            )));
        }
        toml_value(&plain, at)?
    } else if matches!(v.get_type().name()?.to_string().as_str(), "bool_" | "bool") {
        // numpy's bool: as the bool it holds (before __index__, which numpy refuses on it).
        toml::Value::Boolean(v.is_truthy()?)
    } else if v.hasattr("__index__")? {
        // numpy's integers and the like: whole numbers stay whole.
        toml::Value::Integer(v.call_method0("__index__")?.extract().map_err(|_| {
            ConfigError::new_err(format!(
                "<config dict>: {at}: {v} is beyond a 64-bit integer"
            ))
        })?)
    } else {
        // numpy's floats and the like: as the float they hold.
        toml::Value::Float(v.extract().map_err(|_| {
            ConfigError::new_err(format!(
                "<config dict>: {at}: a {} is not a config value (expected a string, number, bool, list or dict)",
                v.get_type().name().map(|n| n.to_string()).unwrap_or_default(),
            ))
        })?)
    })
}

fn backend_of(b: &str) -> PyResult<Backend> {
    match b {
        "auto" => Ok(Backend::Auto),
        "gpu" => Ok(Backend::Gpu),
        "cpu" => Ok(Backend::Cpu),
        _ => Err(settings_err(format!(
            "backend `{b}`: expected auto, gpu or cpu"
        ))),
    }
}

fn precision_of(p: Option<&str>) -> PyResult<pounding::engine::gpu::Precision> {
    use pounding::engine::gpu::Precision;
    match p {
        None | Some("f32") => Ok(Precision::F32),
        Some("f64") => Ok(Precision::F64),
        Some(p) => Err(settings_err(format!(
            "precision `{p}`: expected f32 or f64"
        ))),
    }
}

fn scheme_of(s: Option<&str>) -> PyResult<Option<SchemeKind>> {
    match s {
        None => Ok(None),
        Some("fast") => Ok(Some(SchemeKind::Fast)),
        Some("reference") => Ok(Some(SchemeKind::Reference)),
        Some(s) => Err(settings_err(format!(
            "scheme `{s}`: expected fast or reference"
        ))),
    }
}

/// What the engine's thread tells the waiting Python thread.
enum Told {
    Progress(u64),
}

/// Run `work` on `pool` in another thread while this (the Python) thread waits with the GIL
/// released, calls `progress` with the runs done, and watches for Ctrl-C: an interrupt sets
/// `stop` (the work looks at it between runs) and is raised once the work has stopped.
fn run_watched<T: Send>(
    py: Python<'_>,
    pool: &rayon::ThreadPool,
    progress: Option<(&Bound<'_, PyAny>, u64)>,
    work: impl FnOnce(&AtomicBool, &dyn Fn(u64)) -> T + Send,
) -> PyResult<T> {
    let stop = AtomicBool::new(false);
    let (tx, rx) = std::sync::mpsc::channel::<Told>();
    // Received with the GIL released, which wants a receiver it may share.
    let rx = std::sync::Mutex::new(rx);
    let mut interrupted: Option<PyErr> = None;
    if let Some((cb, total)) = progress {
        cb.call1((0u64, total))?;
    }
    let out = std::thread::scope(|s| {
        let stop = &stop;
        let worker = s.spawn(move || {
            let tell = move |n: u64| {
                let _ = tx.send(Told::Progress(n));
            };
            pool.install(|| work(stop, &tell))
        });
        loop {
            let got = py.detach(|| {
                rx.lock()
                    .expect("one receiver")
                    .recv_timeout(Duration::from_millis(50))
            });
            match got {
                Ok(Told::Progress(n)) => {
                    if let (Some((cb, total)), None) = (progress, &interrupted) {
                        if let Err(e) = cb.call1((n, total)) {
                            stop.store(true, Ordering::Relaxed);
                            interrupted = Some(e);
                        }
                    }
                }
                Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {}
                Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => break,
            }
            if interrupted.is_none() {
                if let Err(e) = py.check_signals() {
                    stop.store(true, Ordering::Relaxed);
                    interrupted = Some(e);
                }
            }
        }
        py.detach(|| worker.join())
    });
    if let Some(e) = interrupted {
        return Err(e);
    }
    out.map_err(|_| PoundingError::new_err("the engine's thread panicked"))
}

/// Run `work`, which takes no stop flag (a trace's one run, a study of a table), in a thread of
/// its own while this (the Python) thread waits with the GIL released and watches for Ctrl-C:
/// an interrupt is raised at once, and the work, which writes nothing, ends unseen in the
/// background and its result is dropped.
fn run_detached<T: Send + 'static>(
    py: Python<'_>,
    work: impl FnOnce() -> T + Send + 'static,
) -> PyResult<T> {
    let (tx, rx) = std::sync::mpsc::channel::<T>();
    let rx = std::sync::Mutex::new(rx);
    std::thread::Builder::new()
        .name("pounding-study".into())
        .spawn(move || {
            let _ = tx.send(work());
        })
        .map_err(|e| PoundingError::new_err(format!("starting a worker thread: {e}")))?;
    loop {
        let got = py.detach(|| {
            rx.lock()
                .expect("one receiver")
                .recv_timeout(Duration::from_millis(50))
        });
        match got {
            Ok(out) => return Ok(out),
            Err(std::sync::mpsc::RecvTimeoutError::Timeout) => py.check_signals()?,
            Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => {
                return Err(PoundingError::new_err("the engine's thread panicked"))
            }
        }
    }
}

/// A sweep's refusal or failure as the Python exception of its kind, with the command line's
/// message (a config's as [`config_err_in`] gives it).
fn sweep_err(e: SweepError, text: &str, path: &Path) -> PyErr {
    match e {
        SweepError::Config(e) => config_err_in(e, text, path),
        SweepError::Options(_) | SweepError::Settings(_) | SweepError::Aggregate(_) => {
            settings_err(e)
        }
        SweepError::Engine(e) => engine_err(e),
        SweepError::Gpu(e) => GpuError::new_err(e.to_string()),
        SweepError::Interrupted => pyo3::exceptions::PyKeyboardInterrupt::new_err(e.to_string()),
        e => PoundingError::new_err(e.to_string()),
    }
}

/// A sweep's table, its totals, and the notices and warnings said.
type Swept<'py> = (Table, Bound<'py, PyDict>, Vec<String>, Vec<String>);

/// `pounding.sweep`: every run of a config, as `pound sweep` runs it; the rows (or with
/// `aggregate`, the summary) as a table, the sweep's totals, and the lines the command line
/// says (notices, then warnings).
#[pyfunction]
#[pyo3(signature = (config, config_kind, backend, precision, threads, target_error, columns, aggregate, exceed, scheme, energy, chunk, progress))]
#[allow(clippy::too_many_arguments)]
fn sweep<'py>(
    py: Python<'py>,
    config: &Bound<'py, PyAny>,
    config_kind: &str,
    backend: &str,
    precision: Option<&str>,
    threads: Option<usize>,
    target_error: Option<f64>,
    columns: Option<Vec<String>>,
    aggregate: Option<Vec<String>>,
    exceed: Vec<String>,
    scheme: Option<&str>,
    energy: bool,
    chunk: Option<usize>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Swept<'py>> {
    let (text, path) = config_text(config, config_kind)?;
    let options = Options {
        scheme: scheme_of(scheme)?,
        energy,
        target_error,
        backend: backend_of(backend)?,
        precision: precision_of(precision)?,
        chunk,
        threads,
        columns,
        aggregate,
        exceed,
        format: FileFormat::Csv,
        shard: None,
        resume: false,
    };
    let failed = |e| sweep_err(e, &text, &path);
    options.check().map_err(failed)?;
    let pool = options.pool().map_err(failed)?;
    let (mut notices, mut warnings) = (Vec::new(), Vec::new());
    let prepared = Prepared::new(&options, &path, text.clone(), &mut |said| match said {
        Said::Notice(n) => notices.push(n),
        Said::Warning(w) => warnings.push(w),
    })
    .map_err(failed)?;
    let runs = prepared.plan.len();
    let names = prepared.names.clone();
    let (swept, rows) = run_watched(
        py,
        &pool,
        progress.as_ref().map(|p| (p, runs)),
        move |stop, tell| {
            let mut rows = Columns::new(&names, names.iter().map(|n| kind(n)).collect());
            let swept = prepared.run_to_table(stop, tell, &mut |cells| rows.append(&cells));
            (swept, rows)
        },
    )?;
    let swept = swept.map_err(failed)?;
    warnings.extend(swept.warnings);
    let s = swept.totals;
    let totals = PyDict::new(py);
    totals.set_item("runs", s.runs)?;
    totals.set_item("seconds", s.seconds)?;
    totals.set_item("runs_per_second", s.runs_per_second())?;
    totals.set_item("runs_with_impacts", s.runs_with_impacts)?;
    totals.set_item("impacts", s.impacts)?;
    totals.set_item("failures", s.failures)?;
    totals.set_item("collapsed", s.collapsed)?;
    totals.set_item("engine", swept.describe)?;
    totals.set_item("kernel", swept.kernel)?;
    totals.set_item("scene", swept.scene)?;
    let table = match swept.summary {
        Some(t) => {
            let mut cols = Columns::new(&t.header, t.kinds);
            cols.append(&t.rows).map_err(PoundingError::new_err)?;
            cols.finish(&swept.meta)
        }
        None => rows.finish(&swept.meta),
    }
    .map_err(PoundingError::new_err)?;
    Ok((table, totals, notices, warnings))
}

/// `pounding.columns`: a sweep's columns (of `config`, or of a pair without one) with units,
/// meanings and the type each has in a table.
#[pyfunction]
#[pyo3(signature = (config=None, config_kind="path"))]
fn columns(config: Option<&Bound<'_, PyAny>>, config_kind: &str) -> PyResult<Table> {
    let names: Vec<String> = match config {
        Some(c) => {
            let (text, path) = config_text(c, config_kind)?;
            config::load_text(&text, &path)
                .map_err(|e| config_err_in(e, &text, &path))?
                .header()
        }
        None => pounding::plan::columns::header()
            .into_iter()
            .map(String::from)
            .collect(),
    };
    let rows: Vec<Vec<String>> = names
        .iter()
        .map(|c| {
            let m =
                pounding::plan::meaning::meaning(c).expect("every written column has a meaning");
            let ty = match kind(c) {
                Kind::Int => "int64",
                Kind::Real => "float64",
                Kind::Text => "string",
            };
            vec![
                c.clone(),
                m.unit.to_string(),
                m.text.to_string(),
                m.label.to_string(),
                ty.to_string(),
            ]
        })
        .collect();
    let head: Vec<String> = ["column", "unit", "meaning", "label", "type"]
        .map(String::from)
        .to_vec();
    let mut cols = Columns::new(&head, vec![Kind::Text; 5]);
    cols.append(&rows).map_err(PoundingError::new_err)?;
    cols.finish(&[]).map_err(PoundingError::new_err)
}

/// `pounding.trace`: one run whole: its time history (as `pound trace` writes it) and its row as
/// the sweep writes it.
#[pyfunction]
fn trace(
    py: Python<'_>,
    config: &Bound<'_, PyAny>,
    config_kind: &str,
    run: u64,
) -> PyResult<(Table, Table)> {
    let (text, path) = config_text(config, config_kind)?;
    let plan = config::load_text(&text, &path).map_err(|e| config_err_in(e, &text, &path))?;
    let t = run_detached(py, move || {
        pounding::studies::trace::trace(&plan, run).map_err(|e| e.to_string())
    })?
    .map_err(|e| SettingsError::new_err(format!("{}: {e}", path.display())))?;
    let history = py
        .detach(|| study_table(&t.csv(), &[]))
        .map_err(PoundingError::new_err)?;
    let kinds = t.header.iter().map(|n| kind(n)).collect();
    let mut row = Columns::new(&t.header, kinds);
    row.append(std::slice::from_ref(&t.row))
        .map_err(PoundingError::new_err)?;
    Ok((history, row.finish(&[]).map_err(PoundingError::new_err)?))
}

/// `pounding.gap`: the separation each adjacent pair needs, run by run, exactly and by the code
/// rules (the table `pound gap` writes).
#[pyfunction]
#[pyo3(signature = (config, config_kind, threads=None))]
fn gap(
    py: Python<'_>,
    config: &Bound<'_, PyAny>,
    config_kind: &str,
    threads: Option<usize>,
) -> PyResult<(Table, Vec<String>)> {
    use pounding::studies::gap::{GapPlanError, GapStudy};
    let (text, path) = config_text(config, config_kind)?;
    let pool = pounding::sweep::options::pool(threads).map_err(|e| sweep_err(e, &text, &path))?;
    let plan = GapStudy::plan_of(&text, &path).map_err(|e| match e {
        GapPlanError::Config(e) => config_err_in(e, &text, &path),
        GapPlanError::Refused(why) => settings_err(why),
    })?;
    let warnings: Vec<String> = plan
        .input_warnings()
        .into_iter()
        .map(|w| format!("{}: {w}", path.display()))
        .collect();
    let plan = &plan;
    let csv = run_watched(py, &pool, None, move |stop, _| {
        GapStudy::run_until(plan, stop).map(|s| s.csv())
    })?
    .map_err(|e| PoundingError::new_err(format!("{}: {e}", path.display())))?;
    let text = String::from_utf8(csv).map_err(|e| PoundingError::new_err(e.to_string()))?;
    let table = py
        .detach(|| study_table(&text, &[]))
        .map_err(PoundingError::new_err)?;
    Ok((table, warnings))
}

/// A record file read as `pound record info` reads it.
fn read_record(
    path: &str,
    format: &str,
    dt: Option<f64>,
    units: Option<&str>,
    skip_lines: usize,
    window: Option<(f64, f64)>,
) -> PyResult<pounding::record::Record> {
    use pounding::record::{Format, ReadOptions, Units};
    let format = Format::parse(format)
        .ok_or_else(|| settings_err(format!("format `{format}`: expected {}", Format::KEYS)))?;
    let units = units
        .map(|u| {
            Units::parse(u)
                .ok_or_else(|| settings_err(format!("units `{u}`: expected {}", Units::KEYS)))
        })
        .transpose()?;
    let rec = pounding::record::read_record(
        Path::new(path),
        &ReadOptions {
            format,
            units,
            dt,
            skip_lines,
        },
    )
    .map_err(|e| RecordError::new_err(e.to_string()))?;
    match window {
        Some((a, b)) => rec
            .windowed([a, b])
            .map_err(|m| settings_err(format!("window ({a}, {b}): {m}"))),
        None => Ok(rec),
    }
}

/// `pounding.record`: what a record file holds (the numbers `pound record info` gives) and its
/// samples (m/s^2, little-endian f64 bytes for numpy).
#[pyfunction]
#[pyo3(signature = (path, format="auto", dt=None, units=None, skip_lines=0, window=None))]
fn record<'py>(
    py: Python<'py>,
    path: &str,
    format: &str,
    dt: Option<f64>,
    units: Option<&str>,
    skip_lines: usize,
    window: Option<(f64, f64)>,
) -> PyResult<(Bound<'py, PyDict>, Bound<'py, pyo3::types::PyBytes>)> {
    use pounding::record::{intensity, G};
    let rec = read_record(path, format, dt, units, skip_lines, window)?;
    let pga = rec.pga();
    let (pgv, pgd) = intensity::pgv_pgd(&rec);
    let d = PyDict::new(py);
    d.set_item("name", &rec.name)?;
    d.set_item("npts", rec.npts())?;
    d.set_item("dt", rec.dt)?;
    d.set_item("t0", rec.t0)?;
    d.set_item("duration", rec.duration())?;
    d.set_item("pga_g", pga.value / G)?;
    d.set_item("pga_m_s2", pga.value)?;
    d.set_item("pga_time", pga.time)?;
    d.set_item("pgv_m_s", pgv)?;
    d.set_item("pgd_m", pgd)?;
    let bytes: Vec<u8> = rec.accel.iter().flat_map(|a| a.to_le_bytes()).collect();
    Ok((d, pyo3::types::PyBytes::new(py, &bytes)))
}

/// `pounding.spectrum`: the damped pseudo-acceleration response spectrum of a record file at
/// `periods` (the table `pound record spectrum` writes).
#[pyfunction]
#[pyo3(signature = (path, periods, damping, format="auto", dt=None, units=None, skip_lines=0, window=None))]
#[allow(clippy::too_many_arguments)]
fn spectrum(
    py: Python<'_>,
    path: &str,
    periods: Vec<f64>,
    damping: f64,
    format: &str,
    dt: Option<f64>,
    units: Option<&str>,
    skip_lines: usize,
    window: Option<(f64, f64)>,
) -> PyResult<Table> {
    use pounding::record::G;
    pounding::plan::limits::check_periods(&periods)
        .map_err(|m| settings_err(format!("periods: {m}")))?;
    if !(damping.is_finite() && (0.0..1.0).contains(&damping)) {
        return Err(settings_err(format!(
            "damping {damping}: expected a ratio from 0 to below 1 (0.05 for 5 %)"
        )));
    }
    let rec = read_record(path, format, dt, units, skip_lines, window)?;
    let rows: Vec<Vec<String>> = py
        .detach(|| pounding::record::intensity::spectrum(&rec, &periods, damping))
        .iter()
        .map(|o| {
            vec![
                format!("{}", o.period_s),
                format!("{}", o.sa_m_s2 / G),
                format!("{}", o.sa_m_s2),
                format!("{}", o.sd_m),
            ]
        })
        .collect();
    let head: Vec<String> = ["period_s", "sa_g", "sa_m_s2", "sd_m"]
        .map(String::from)
        .to_vec();
    let mut cols = Columns::new(&head, vec![Kind::Real; 4]);
    cols.append(&rows).map_err(PoundingError::new_err)?;
    cols.finish(&[]).map_err(PoundingError::new_err)
}

/// A study's input: a results CSV's path (read as the command reads it) or an Arrow table.
fn study_input(table: &Bound<'_, PyAny>, kind: &str) -> PyResult<pounding::io::table::Table> {
    match kind {
        "path" => {
            let path = PathBuf::from(table.extract::<String>()?);
            pounding::io::table::Table::read(&path).map_err(|e| TableError::new_err(e.to_string()))
        }
        _ => table_cells(table),
    }
}

/// A study's report: its table, its other tables by name (a fragility's `fits`, an IDA's
/// `long`), what the command prints on standard output, and its notices.
type Studied = (Table, Vec<(String, Table)>, String, Vec<String>);

/// A study of a table of results, as its command runs it: its settings `check`ed before the
/// table is read, then the `study` (the GIL released), its refusals `refused` as exceptions.
fn run_study<E: Send + 'static>(
    py: Python<'_>,
    table: &Bound<'_, PyAny>,
    table_kind: &str,
    check: impl FnOnce() -> Result<(), E>,
    study: impl FnOnce(&pounding::io::table::Table) -> Result<StudyReport, E> + Send + 'static,
    refused: impl Fn(E) -> PyErr,
) -> PyResult<Studied> {
    check().map_err(&refused)?;
    let rows = study_input(table, table_kind)?;
    // A bootstrap of many replicates takes seconds: Ctrl-C is answered at once.
    let r = run_detached(py, move || study(&rows))?.map_err(&refused)?;
    let t = py
        .detach(|| study_table(&r.csv, &[]))
        .map_err(PoundingError::new_err)?;
    let mut tables = Vec::new();
    for (name, csv) in &r.tables {
        let table = py
            .detach(|| study_table(csv, &[]))
            .map_err(PoundingError::new_err)?;
        tables.push((name.to_string(), table));
    }
    Ok((t, tables, r.said, r.notices))
}

/// `pounding.fragility`: `pound fragility` on a table of results.
#[pyfunction]
#[pyo3(signature = (table, table_kind, im, edp, thresholds, damage_states, bootstrap, seed, by, filters, series))]
#[allow(clippy::too_many_arguments)]
fn fragility(
    py: Python<'_>,
    table: &Bound<'_, PyAny>,
    table_kind: &str,
    im: Option<String>,
    edp: String,
    thresholds: Vec<f64>,
    damage_states: Option<String>,
    bootstrap: usize,
    seed: Option<u64>,
    by: Option<String>,
    filters: Vec<String>,
    series: Option<String>,
) -> PyResult<Studied> {
    use pounding::studies::fragility::{study, FragilityError, FragilityOptions};
    let options = FragilityOptions {
        im,
        edp,
        thresholds,
        damage_states,
        bootstrap,
        seed,
        by,
        filters,
        series,
    };
    let refused = |e: FragilityError| match e {
        FragilityError::Table(e) => TableError::new_err(e.to_string()),
        e => SettingsError::new_err(e.to_string()),
    };
    let checked = options.check();
    run_study(
        py,
        table,
        table_kind,
        || checked,
        move |rows| study(rows, &options),
        refused,
    )
}

/// `pounding.ida`: `pound ida` on a table of results.
#[pyfunction]
#[pyo3(signature = (table, table_kind, im, edp, by, filters))]
fn ida(
    py: Python<'_>,
    table: &Bound<'_, PyAny>,
    table_kind: &str,
    im: Option<String>,
    edp: String,
    by: Vec<String>,
    filters: Vec<String>,
) -> PyResult<Studied> {
    use pounding::studies::ida::{study, IdaError, IdaOptions};
    let options = IdaOptions {
        im,
        edp,
        by,
        filters,
    };
    let refused = |e: IdaError| match e {
        IdaError::Refused(m) => SettingsError::new_err(m),
        e => TableError::new_err(e.to_string()),
    };
    let checked = options.check();
    run_study(
        py,
        table,
        table_kind,
        || checked,
        move |rows| study(rows, &options),
        refused,
    )
}

/// `pounding.demands`: `pound demands` on a table of results; the SimCenter demand file's text,
/// what the command prints on standard output, and its notices.
#[pyfunction]
#[pyo3(signature = (table, table_kind, building, filters))]
fn demands(
    py: Python<'_>,
    table: &Bound<'_, PyAny>,
    table_kind: &str,
    building: usize,
    filters: Vec<String>,
) -> PyResult<(String, String, Vec<String>)> {
    use pounding::studies::demands::{study, DemandsError, DemandsOptions};
    let rows = study_input(table, table_kind)?;
    let options = DemandsOptions { building, filters };
    let r = py.detach(|| study(&rows, &options)).map_err(|e| match e {
        DemandsError::Table(e) => TableError::new_err(e.to_string()),
        e => SettingsError::new_err(e.to_string()),
    })?;
    Ok((r.csv, r.said, r.notices))
}

#[pymodule]
fn _pounding(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("PoundingError", py.get_type::<PoundingError>())?;
    m.add("ConfigError", py.get_type::<ConfigError>())?;
    m.add("RecordError", py.get_type::<RecordError>())?;
    m.add("SettingsError", py.get_type::<SettingsError>())?;
    m.add("TableError", py.get_type::<TableError>())?;
    m.add("GpuError", py.get_type::<GpuError>())?;
    m.add_class::<Table>()?;
    m.add_function(wrap_pyfunction!(sweep, m)?)?;
    m.add_function(wrap_pyfunction!(columns, m)?)?;
    m.add_function(wrap_pyfunction!(trace, m)?)?;
    m.add_function(wrap_pyfunction!(gap, m)?)?;
    m.add_function(wrap_pyfunction!(record, m)?)?;
    m.add_function(wrap_pyfunction!(spectrum, m)?)?;
    m.add_function(wrap_pyfunction!(fragility, m)?)?;
    m.add_function(wrap_pyfunction!(ida, m)?)?;
    m.add_function(wrap_pyfunction!(demands, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    // The bounds the Python layer names when a keyword is past them (the engine checks too).
    let limits = PyDict::new(py);
    limits.set_item("threads", pounding::plan::limits::MAX_THREADS)?;
    limits.set_item("cpu_chunk", pounding::plan::limits::MAX_CPU_CHUNK)?;
    limits.set_item("gpu_chunk", pounding::plan::limits::MAX_GPU_CHUNK)?;
    limits.set_item("bootstrap", pounding::studies::fragility::MAX_BOOTSTRAP)?;
    m.add("LIMITS", limits)?;
    Ok(())
}
