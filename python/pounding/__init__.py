"""pounding: earthquake-induced pounding between adjacent buildings, in-process.

The engine of the ``pound`` command line, called from Python: every function mirrors a command
and returns its results as a :class:`Table` (typed columns, read without copying by pyarrow,
polars and pandas through the Arrow PyCapsule stream interface).

    >>> import pounding
    >>> runs = pounding.sweep("configs/quickstart.toml")          # pound sweep
    >>> df = runs.to_pandas()

Functions: :func:`sweep`, :func:`gap`, :func:`trace`, :func:`fragility`, :func:`ida`,
:func:`record`, :func:`spectrum`, :func:`columns`. A config is a path, a TOML string or a dict
with the config's structure (the keys of README.md, "A config"). Errors are
:class:`PoundingError` subclasses carrying the command line's messages; the engine runs with
the GIL released, and Ctrl-C stops it and raises ``KeyboardInterrupt``.
"""

from __future__ import annotations

import math
import numbers
import os
import sys
import warnings
from typing import Any, Iterable, NamedTuple, Optional, Sequence, Union

from . import _pounding as _engine
from ._pounding import (
    ConfigError,
    GpuError,
    PoundingError,
    RecordError,
    SettingsError,
    TableError,
)

__version__ = _engine.__version__

# The engine's bounds on the keywords that have one (threads, chunk, bootstrap).
_LIMITS = dict(_engine.LIMITS)

__all__ = [
    "sweep",
    "gap",
    "trace",
    "fragility",
    "ida",
    "demands",
    "record",
    "spectrum",
    "columns",
    "Table",
    "Trace",
    "Record",
    "PoundingError",
    "ConfigError",
    "RecordError",
    "SettingsError",
    "TableError",
    "GpuError",
    "PoundingWarning",
]

Config = Union[str, "os.PathLike[str]", dict]


class PoundingWarning(UserWarning):
    """What the command line prints as a warning (a config's questionable input, runs whose
    buildings move past their height)."""


class Table:
    """A table of results: typed columns (int64, float64, string; an empty cell is a null).

    It is an Arrow stream (``__arrow_c_stream__``): ``pyarrow.table(t)``, ``polars.DataFrame(t)``
    and ``t.to_pandas()`` read its numbers without copying them into Python objects.
    ``info`` holds what the command line says of the work (runs, seconds, engine, report).
    """

    def __init__(self, inner: Any, info: Optional[dict] = None):
        self._inner = inner
        self.info = dict(info or {})

    @property
    def num_rows(self) -> int:
        return self._inner.num_rows

    @property
    def column_names(self) -> list:
        return self._inner.column_names

    @property
    def metadata(self) -> dict:
        """The schema's key-value metadata (a sweep's plan fingerprint, backend, kernel)."""
        return self._inner.metadata

    def __len__(self) -> int:
        return len(self._inner)

    def __arrow_c_stream__(self, requested_schema: Any = None) -> Any:
        return self._inner.__arrow_c_stream__(requested_schema)

    def to_arrow(self) -> Any:
        """A ``pyarrow.Table`` (needs pyarrow)."""
        import pyarrow as pa

        return pa.table(self)

    def to_pandas(self) -> Any:
        """A ``pandas.DataFrame`` (needs pandas and pyarrow)."""
        return self.to_arrow().to_pandas()

    def to_polars(self) -> Any:
        """A ``polars.DataFrame`` (needs polars)."""
        import polars as pl

        return pl.DataFrame(self)

    def column(self, name: str) -> Any:
        """One column as a numpy array (needs pyarrow); nulls become NaN in a real column."""
        if name not in self.column_names:
            raise TableError(
                f"no column `{name}`; the columns are: {', '.join(self.column_names)}"
            )
        return self.to_arrow().column(name).to_numpy()

    def __repr__(self) -> str:
        names = self.column_names
        shown = ", ".join(names[:8]) + (", ..." if len(names) > 8 else "")
        return f"<pounding.Table: {self.num_rows} rows x {len(names)} columns ({shown})>"


class Trace(NamedTuple):
    """One run whole: its time history (every record step and located event) and its row as
    the sweep writes it."""

    history: Table
    row: Table


class Record:
    """A ground-motion record file as read: name, npts, dt (s), t0 (s), duration (s), pga_g,
    pga_m_s2, pga_time (s), pgv_m_s, pgd_m (from rest, no baseline correction), and the samples
    (``accel_m_s2``, ``accel_g``, ``time``: numpy arrays)."""

    def __init__(self, path: str, options: dict, info: dict, samples: bytes):
        self.path = path
        self._options = options
        self._samples = samples
        for k, v in info.items():
            setattr(self, k, v)

    @property
    def accel_m_s2(self) -> Any:
        import numpy as np

        return np.frombuffer(self._samples, dtype="<f8")

    @property
    def accel_g(self) -> Any:
        return self.accel_m_s2 / 9.80665

    @property
    def time(self) -> Any:
        import numpy as np

        return self.t0 + self.dt * np.arange(self.npts)

    def __repr__(self) -> str:
        return (
            f"<pounding.Record {self.name}: {self.npts} samples at dt {self.dt} s, "
            f"PGA {self.pga_g:.4f} g, PGV {self.pgv_m_s:.4f} m/s>"
        )


def _config(config: Config, name: str = "config") -> tuple:
    """A config as the engine takes it: (value, kind).

    A string is a path unless it holds a line break (a config's TOML has several lines, a
    path none) or names a file that exists: decided by the string alone, so a missing path
    (``runs/pga=0.3/cfg.toml``) is said to be missing rather than read as TOML."""
    if isinstance(config, dict):
        return config, "dict"
    if isinstance(config, os.PathLike):
        config = os.fspath(config)
        if isinstance(config, str):
            return config, "path"
    if isinstance(config, str):
        if "\n" in config and not os.path.isfile(config):
            return config, "text"
        if not os.path.exists(config) and ("=" in config or config.lstrip().startswith("[")):
            raise ConfigError(
                f"{name}={config!r}: no such file (a string is read as a config's TOML only "
                "where it spans lines; else it is a path)"
            )
        return config, "path"
    raise ConfigError(
        f"{name}: a {type(config).__name__} is not a config: expected a path, a TOML string "
        "or a dict"
    )


def _refuse(name: str, value: Any, expected: str) -> SettingsError:
    return SettingsError(f"{name}={value!r}: expected {expected}")


def _text(name: str, value: Any, optional: bool = True) -> Optional[str]:
    """A keyword that takes a name (None stays None where `optional`)."""
    if value is None and optional:
        return None
    if not isinstance(value, str) or not value.strip():
        raise _refuse(name, value, "a non-empty string" + (" or None" if optional else ""))
    return value


def _flag(name: str, value: Any) -> bool:
    """A yes-or-no keyword: a bool (numpy's too), not a number or a string."""
    if isinstance(value, bool) or type(value).__name__ == "bool_":
        return bool(value)
    raise _refuse(name, value, "True or False")


def _real(name: str, value: Any, optional: bool = True) -> Optional[float]:
    """A number keyword (numpy's numbers too; not a bool), finite (None stays None where
    `optional`)."""
    if value is None and optional:
        return None
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise _refuse(name, value, "a number")
    try:
        x = float(value)
    except OverflowError:
        x = float("inf")
    if not math.isfinite(x):
        raise _refuse(name, value, "a finite number")
    return x


def _names(value: Union[None, str, Iterable[str]], what: str) -> Optional[list]:
    """Column names: a list of strings or one string "a,b"; an empty one is refused (leave the
    keyword out for the default), as the command line refuses an empty flag."""
    if value is None:
        return None
    if isinstance(value, str):
        names = [v.strip() for v in value.split(",")]
    elif isinstance(value, Iterable):
        names = list(value)
        if not all(isinstance(v, str) for v in names):
            raise _refuse(what, value, "column names (strings, or one string a,b)")
        names = [v.strip() for v in names]
    else:
        raise _refuse(what, value, "column names (a list of strings, or one string a,b)")
    if not names or not any(names):
        raise _refuse(what, value, "at least one column name (leave it out for the default)")
    if not all(names):
        raise _refuse(what, value, "column names, none empty")
    return names


def _exceed(exceed: Union[None, str, dict, Iterable[str]]) -> list:
    if exceed is None:
        return []
    if isinstance(exceed, dict):
        out = []
        for k, v in exceed.items():
            if not isinstance(k, str):
                raise _refuse("exceed", exceed, "{column: threshold} with column names as keys")
            if isinstance(v, bool) or not isinstance(v, numbers.Real):
                raise _refuse("exceed", exceed, "{column: threshold} with numbers as thresholds")
            # numpy's numbers too: as the int or float they hold, in Python's own spelling.
            out.append(f"{k}={int(v)}" if isinstance(v, numbers.Integral) else f"{k}={float(v)!r}")
        return out
    if isinstance(exceed, str):
        return [exceed]
    if isinstance(exceed, Iterable):
        items = list(exceed)
        if all(isinstance(v, str) for v in items):
            return items
    raise _refuse(
        "exceed", exceed, "{column: threshold}, \"column=threshold\" or a list of such strings"
    )


class _QuietVulkanProbe:
    """Mesa's software Vulkan driver probes for a Wayland display and prints
    "XDG_RUNTIME_DIR is invalid" twice when there is none (as `pound` avoids in its main): while
    a GPU may be opened, an absolute WAYLAND_DISPLAY that does not exist makes the probe fail
    quietly. The environment is restored after."""

    def __init__(self, backend: str):
        self.active = (
            backend != "cpu"
            and "XDG_RUNTIME_DIR" not in os.environ
            and "WAYLAND_DISPLAY" not in os.environ
        )

    def __enter__(self) -> None:
        if self.active:
            os.environ["WAYLAND_DISPLAY"] = "/nonexistent/pound-compute-only"

    def __exit__(self, *exc: Any) -> None:
        if self.active:
            os.environ.pop("WAYLAND_DISPLAY", None)


# The largest whole number the engine takes where no tighter bound is known (64 bits).
_U64 = 2**64 - 1


def _count(name: str, value: Any, least: int = 0, most: int = _U64) -> Optional[int]:
    """A whole number keyword (numpy's integers too; not a bool), from `least` to `most`
    (None stays None)."""
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise _refuse(name, value, "a whole number")
    if not least <= value <= most:
        raise SettingsError(f"{name}={value}: expected a whole number from {least} to {most}")
    return int(value)


def _studied(inner: Any, tables: Sequence, report: str, notices: Sequence[str]) -> "Table":
    """A study's table, its notices told, its report and other tables (by name) in ``info``."""
    _say(notices)
    info = {"report": report, "notices": notices}
    info.update((name, Table(t)) for name, t in tables)
    return Table(inner, info)


def _renamed(given: Any, old: Any, old_name: str, name: str) -> Any:
    """A keyword under its name or its old spelling, which still works with a notice: ``by``
    meant two things (ida's curves, fragility's bootstrap groups)."""
    if old is not None:
        if given is not None:
            raise SettingsError(f"{old_name}= and {name}= are one setting: give {name}= only")
        _say([f"notice: {old_name}= is spelled {name}= now (what it does); {old_name}= still works"])
        return old
    return given


def _say(lines: Sequence[str]) -> None:
    for line in lines:
        print(line, file=sys.stderr)


def _warn(lines: Sequence[str]) -> None:
    for line in lines:
        warnings.warn(line, PoundingWarning, stacklevel=3)


class _Progress:
    """Runs done: a tqdm bar where tqdm is installed (a notebook's widget or a terminal's bar),
    else a line on standard error rewritten in place. Called as (done, total)."""

    def __init__(self, label: str, enabled: bool):
        self.label, self.enabled, self.bar, self.shown = label, enabled, None, False
        # The line rewritten in place reads on a terminal or in a notebook, not in a log.
        self.line = sys.stderr.isatty() or "ipykernel" in sys.modules

    def __call__(self, done: int, total: int) -> None:
        if not self.enabled or total <= 0:
            return
        if self.bar is None and not self.shown:
            try:
                from tqdm.auto import tqdm

                self.bar = tqdm(total=total, desc=self.label, unit="runs", leave=False)
            except ImportError:
                self.bar = None
        if self.bar is not None:
            self.bar.update(done - self.bar.n)
        elif self.line:
            sys.stderr.write(f"\r{self.label}: {done}/{total} runs ({100.0 * done / total:.0f} %)")
            sys.stderr.flush()
            self.shown = True

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
        elif self.shown:
            sys.stderr.write("\r" + " " * (len(self.label) + 40) + "\r")
            sys.stderr.flush()


def sweep(
    config: Config,
    *,
    backend: str = "auto",
    precision: Optional[str] = None,
    threads: Optional[int] = None,
    target_error: Optional[float] = None,
    columns: Union[None, str, Iterable[str]] = None,
    aggregate: Union[None, str, Iterable[str]] = None,
    exceed: Union[None, str, dict, Iterable[str]] = None,
    scheme: Optional[str] = None,
    energy: bool = False,
    chunk: Optional[int] = None,
    progress: bool = True,
) -> Table:
    """Every run of a sweep config, as ``pound sweep`` runs it: a row per run (the CSV's
    columns, typed), or with ``aggregate`` (columns to group by, e.g. ``["record", "pga_g"]``)
    the summary per group, with ``exceed`` counts (``{"peak_force_n": 1e6}`` or
    ``["peak_force_n=1e6"]``).

    backend: "auto" (a hardware GPU if one is found, else the CPU), "gpu" or "cpu";
    precision: "f32" (default) or "f64" on the GPU; threads: CPU worker threads (default all);
    target_error: the relative error accepted (the fast scheme's cheapest calibrated setting);
    columns: only these columns (``run`` is kept, first); scheme: "fast" or "reference" over
    the config's; energy: each run's energy balance; progress: a progress bar.

    The table's ``info`` holds the sweep's totals (runs, seconds, runs_per_second, impacts,
    runs_with_impacts, failures, collapsed, engine, kernel, scene).
    """
    value, kind = _config(config)
    args = (
        value,
        kind,
        _text("backend", backend, optional=False),
        _text("precision", precision),
        _count("threads", threads, 1, _LIMITS["threads"]),
        _real("target_error", target_error),
        _names(columns, "columns"),
        _names(aggregate, "aggregate"),
        _exceed(exceed),
        _text("scheme", scheme),
        _flag("energy", energy),
        _count("chunk", chunk, 1, max(_LIMITS["cpu_chunk"], _LIMITS["gpu_chunk"])),
    )
    progress = _flag("progress", progress)
    bar = _Progress("sweep", progress)
    try:
        with _QuietVulkanProbe(backend):
            inner, totals, notices, warned = _engine.sweep(*args, bar if progress else None)
    finally:
        bar.close()
    _say(notices)
    _warn(warned)
    totals["notices"] = notices
    return Table(inner, totals)


def columns(config: Optional[Config] = None) -> Table:
    """A sweep's columns (of ``config``, or of a pair's sweep without one): column, unit,
    meaning, label (as plots name it) and type (int64, float64 or string), as
    ``pound columns`` lists them."""
    if config is None:
        return Table(_engine.columns(None))
    value, kind = _config(config)
    return Table(_engine.columns(value, kind))


def trace(config: Config, run: int) -> Trace:
    """One run of a sweep whole, as ``pound trace --run RUN``: its time history (every record
    step and located event: displacements, velocities, accelerations, each level's
    penetration, force and mode, yielding storeys' drifts) and its row as the sweep writes it."""
    value, kind = _config(config)
    history, row = _engine.trace(value, kind, _count("run", run, 0, _U64))
    return Trace(Table(history), Table(row))


def gap(config: Config, *, threads: Optional[int] = None) -> Table:
    """The separation each adjacent pair of a sweep's buildings needs, run by run, as
    ``pound gap`` writes it: exactly from the time histories, and by the ABS, SRSS and DDC
    rules, with their ratios to the exact gap."""
    value, kind = _config(config)
    inner, warned = _engine.gap(value, kind, _count("threads", threads, 1, _LIMITS["threads"]))
    _warn(warned)
    return Table(inner)


def _named_once(table: Any) -> None:
    """A DataFrame naming a column twice is refused naming it, as a CSV or an Arrow table is
    (pandas' own conversion would raise a ValueError naming every column)."""
    # pyarrow's `columns` are the arrays; its names are `column_names` (pandas, polars: `columns`).
    columns = getattr(table, "column_names", None)
    if columns is None:
        columns = getattr(table, "columns", None)
    if columns is None or isinstance(columns, str) or not isinstance(columns, Iterable):
        return
    names = [str(c) for c in columns]
    for name in dict.fromkeys(names):
        at = [i + 1 for i, c in enumerate(names) if c == name]
        if len(at) > 1:
            raise TableError(
                f"<table>: the column `{name}` appears {len(at)} times (columns "
                f"{', '.join(map(str, at))}): a study cannot tell which to read; rename or drop "
                "all but one"
            )


def _study_input(table: Any) -> Any:
    if isinstance(table, (str, os.PathLike)) and isinstance(os.fspath(table), str):
        return os.fspath(table), "path"
    if isinstance(table, Table):
        return table._inner, "arrow"
    _named_once(table)
    if hasattr(table, "__arrow_c_stream__"):
        return table, "arrow"
    # A pandas DataFrame without the stream interface (pandas < 2.2): through pyarrow.
    try:
        import pyarrow as pa

        return pa.table(table), "arrow"
    except Exception:
        raise TableError(
            f"a {type(table).__name__} is not a table: expected a table from pounding.sweep, "
            "a pyarrow or polars table, a pandas DataFrame, or the path of a results CSV"
        ) from None


def _where(where: Union[None, str, Iterable[str]]) -> list:
    """Row filters (COLUMN=VALUE, also !=, <, <=, >, >=), each whole: a filter's value may
    hold a comma."""
    if where is None:
        return []
    if isinstance(where, str):
        return [where]
    if isinstance(where, Iterable):
        filters = list(where)
        if all(isinstance(w, str) for w in filters):
            return filters
    raise _refuse("where", where, 'row filters: "COLUMN=VALUE" or a list of them')


def _list(name: str, value: Union[None, float, str, Iterable[Any]]) -> list:
    """Numbers: one, a list (a numpy array too) or a string a,b,c; each finite, none a bool."""
    if value is None:
        return []
    if hasattr(value, "tolist") and not isinstance(value, (str, numbers.Number)):
        value = value.tolist()  # a numpy array (a 0-d one is its number)
    expected = "finite numbers (a number, a list of numbers, or a string a,b,c)"
    if isinstance(value, str):
        items: list = [v for v in value.split(",") if v.strip()]
    elif isinstance(value, Iterable):
        items = list(value)
    else:
        items = [value]
    out = []
    for v in items:
        if isinstance(v, bool) or not isinstance(v, (numbers.Real, str)):
            raise _refuse(name, value, expected)
        try:
            x = float(v)
        except (ValueError, OverflowError):
            raise _refuse(name, value, expected) from None
        if not math.isfinite(x):
            raise _refuse(name, value, expected)
        out.append(x)
    return out


def fragility(
    table: Any,
    *,
    im: Optional[str] = None,
    edp: str = "peak_force_n",
    thresholds: Union[None, float, str, Iterable[float]] = None,
    damage_states: Optional[str] = None,
    bootstrap: int = 0,
    seed: Optional[int] = None,
    bootstrap_groups: Optional[str] = None,
    where: Union[None, str, Iterable[str]] = None,
    series: Optional[str] = None,
    by: Optional[str] = None,
) -> Table:
    """Fragility curves from a sweep's results, as ``pound fragility``: per threshold (or named
    damage state: ``"hazus-c1l-high"``, ``"fema-p58-residual"``, a TOML file) and intensity
    level, the runs that exceed it, with the lognormal fitted by maximum likelihood (median,
    beta) and, with ``bootstrap`` replicates over the groups of ``bootstrap_groups`` (default:
    records), 90 % bands (``by``: its old spelling, which still works with a notice).

    ``table``: a table from :func:`sweep` (or any Arrow table or DataFrame) or a results CSV's
    path. ``info["fits"]`` holds the fitted curves as a table (``pound fragility --fits``: per
    threshold or state the median, beta, their standard errors, log-likelihood, deviance, p,
    runs, levels, and with ``bootstrap`` the 90 % bands); ``info["report"]`` the command's report.
    ``series``: a column whose every value gets its own curves (``--series``), that column first
    in both tables.
    """
    args = (
        _text("im", im),
        _text("edp", edp, optional=False),
        _list("thresholds", thresholds),
        _text("damage_states", damage_states),
        _count("bootstrap", bootstrap, 0, _LIMITS["bootstrap"]),
        _count("seed", seed, 0, _U64),
        _text(
            "by" if by is not None else "bootstrap_groups",
            _renamed(bootstrap_groups, by, "by", "bootstrap_groups"),
        ),
        _where(where),
        _text("series", series),
    )
    source, kind = _study_input(table)
    return _studied(*_engine.fragility(source, kind, *args))


def ida(
    table: Any,
    *,
    edp: str,
    im: Optional[str] = None,
    curves: Union[None, str, Iterable[str]] = None,
    where: Union[None, str, Iterable[str]] = None,
    by: Union[None, str, Iterable[str]] = None,
) -> Table:
    """Incremental dynamic analysis from a sweep's results, as ``pound ida``: per record (or
    the columns ``curves`` names; ``by``: its old spelling, which still works with a notice) the demand ``edp`` against the intensity ``im``, and the 16, 50
    and 84 % fractiles across the curves at each intensity level (a collapse is an infinite
    demand). ``info["long"]`` holds the curves in long form (``pound ida --long``: curve,
    intensity, demand, collapsed); ``info["report"]`` the command's report."""
    named = _renamed(curves, by, "by", "curves")
    args = (
        _text("im", im),
        _text("edp", edp, optional=False),
        _names(named, "curves" if curves is not None else "by") or [],
    )
    source, kind = _study_input(table)
    return _studied(*_engine.ida(source, kind, *args, _where(where)))


def demands(
    table: Any,
    *,
    building: int,
    where: Union[None, str, Iterable[str]] = None,
    path: Union[None, str, "os.PathLike[str]"] = None,
) -> str:
    """One building's demands in the SimCenter format pelicun reads, as ``pound demands``: a
    row per run of a sweep written with ``columns=["+storeys", "+floors"]``, ``1-PID-j-1``,
    ``1-RID-j-1``, ``1-PFA-j-1``, ``1-COL-0-1`` and a units row. Returns the file's text (to
    ``path`` too where given): ``pelicun``'s ``DemandModel.load_sample(path)`` reads it."""
    source, kind = _study_input(table)
    text, _report, notices = _engine.demands(
        source, kind, _count("building", building, 1, _U64), _where(where)
    )
    _say(notices)
    if path is not None:
        with open(path, "w", newline="") as f:
            f.write(text)
    return text


def record(
    path: Union[str, "os.PathLike[str]"],
    *,
    format: str = "auto",
    dt: Optional[float] = None,
    units: Optional[str] = None,
    skip_lines: int = 0,
    window: Optional[tuple] = None,
) -> Record:
    """A ground-motion record file, read as ``pound record info`` reads it (format: auto, at2,
    values or two_column; units: g, m/s2 or cm/s2; window: (start, end) s on the record's
    clock, as a config's ``window_s``)."""
    # Absolute: spectrum() reads the file again, perhaps from another working folder.
    path = os.path.abspath(_path("path", path))
    options = {
        "format": _text("format", format, optional=False),
        "dt": _real("dt", dt),
        "units": _text("units", units),
        "skip_lines": _count("skip_lines", skip_lines, 0, _U64),
        "window": _window(window),
    }
    info, samples = _engine.record(path, **options)
    return Record(path, options, info, samples)


def spectrum(
    record: Union[Record, str, "os.PathLike[str]"],
    periods: Union[float, Iterable[float]],
    damping: float = 0.05,
) -> Table:
    """The damped pseudo-acceleration response spectrum of a record at ``periods`` (s), as
    ``pound record spectrum``: period_s, sa_g, sa_m_s2, sd_m (each an exact response over the
    whole record)."""
    if isinstance(record, Record):
        path, options = record.path, record._options
    else:
        path, options = _path("record", record), {}
    periods = _list("periods", periods)
    return Table(_engine.spectrum(path, periods, _real("damping", damping, False), **options))


def _path(name: str, value: Any) -> str:
    """A file's path: a string or an os.PathLike naming one."""
    if isinstance(value, (str, os.PathLike)):
        value = os.fspath(value)
        if isinstance(value, str):
            return value
    raise _refuse(name, value, "a file's path (a string or a pathlib.Path)")


def _window(window: Any) -> Optional[tuple]:
    """A record's window: (start, end) s, two finite numbers."""
    if window is None:
        return None
    if hasattr(window, "tolist") and not isinstance(window, numbers.Number):
        window = window.tolist()
    if isinstance(window, Iterable) and not isinstance(window, str):
        pair = list(window)
        if len(pair) == 2 and all(
            not isinstance(v, bool) and isinstance(v, numbers.Real) and math.isfinite(v)
            for v in pair
        ):
            return (float(pair[0]), float(pair[1]))
    raise _refuse("window", window, "(start, end): two finite numbers of seconds")
