"""Shared by the package's tests: the repository, the `pound` binary the results are compared
with, and a cell-by-cell comparison of a table with the CSV the command line writes."""

import csv
import os
import subprocess
from pathlib import Path

import pyarrow as pa
import pytest

REPO = Path(__file__).resolve().parents[2]
CONFIGS = REPO / "configs"


def pound_binary() -> Path:
    """`POUND_BIN`, else the newest `pound` built in this clone (release or the tests' debug)."""
    given = os.environ.get("POUND_BIN")
    if given:
        return Path(given)
    built = [p for p in (REPO / "target/release/pound", REPO / "target/debug/pound") if p.exists()]
    if not built:
        raise RuntimeError(
            "no pound binary: build it (cargo build --release) or set POUND_BIN; the tests compare the package with it"
        )
    return max(built, key=lambda p: p.stat().st_mtime)


@pytest.fixture(scope="session")
def pound():
    """Run `pound ARGS...` from the repository root; its completed process (stdout, stderr)."""
    binary = pound_binary()

    def run(*args, check=True):
        return subprocess.run(
            [str(binary), *map(str, args)],
            cwd=REPO,
            capture_output=True,
            text=True,
            check=check,
        )

    return run


@pytest.fixture(autouse=True)
def _from_repo(monkeypatch):
    # Configs name records relative to themselves; strings and dicts from the working folder.
    monkeypatch.chdir(REPO)


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], rows[1:]


def cell_equal(value, cell):
    """A table's value against the CLI's cell: the same text, integer or f64 (an empty cell is
    a null)."""
    if cell == "":
        return value is None
    if isinstance(value, str):
        return value == cell
    if isinstance(value, bool):
        return str(value).lower() == cell
    if isinstance(value, int):
        return value == int(cell)
    return value == float(cell)


def assert_same_cells(table, path):
    """Every cell of `table` equals the CSV's at `path`: the same columns in the same order, the
    same rows, each value the cell's text, integer or f64 exactly."""
    header, rows = read_csv(path)
    at = pa.table(table)
    assert at.column_names == header
    assert at.num_rows == len(rows)
    assert rows, f"{path} holds no rows: a comparison of nothing"
    columns = at.to_pydict()
    for j, name in enumerate(header):
        values = columns[name]
        for i, row in enumerate(rows):
            assert cell_equal(values[i], row[j]), (
                f"row {i}, column {name}: table {values[i]!r}, CLI {row[j]!r}"
            )
