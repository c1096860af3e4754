"""`pounding.sweep` against `pound sweep`: the same cells for the same config (pairs, rows,
yielding, collapse, floor/column contact, chosen columns, aggregate summaries), configs as
paths, TOML strings and dicts, typed buffers, errors as exceptions, Ctrl-C."""

import os
from pathlib import Path
import signal
import subprocess
import sys
import textwrap
import time

import pyarrow as pa
import pytest

import pounding
from conftest import CONFIGS, REPO, assert_same_cells

try:
    import tomllib
except ImportError:  # Python < 3.11
    tomllib = None


@pytest.mark.parametrize(
    "config",
    [
        "quickstart.toml",  # a pair, 2,700 runs
        "row-of-two.toml",  # a row of two one-storey buildings on the pair's kernels
        "row-3-6.toml",  # multi-storey row
        "inelastic-row.toml",  # yielding storeys, real records
        "inelastic-fragility.toml",  # yielding, scaled to Sa(T1)
        "collapse-ida.toml",  # P-Delta and collapse
        "floor-column.toml",  # floors that strike columns
    ],
)
def test_rows_are_the_command_lines_cell_for_cell(config, pound, tmp_path):
    out = tmp_path / "runs.csv"
    pound("sweep", CONFIGS / config, "-o", out, "--backend", "cpu")
    table = pounding.sweep(CONFIGS / config, backend="cpu", progress=False)
    assert_same_cells(table, out)
    assert table.info["runs"] == table.num_rows
    assert table.metadata["pound.backend"] == "cpu"


def test_chosen_columns_and_settings_are_the_command_lines(pound, tmp_path):
    out = tmp_path / "runs.csv"
    args = ["--columns", "b2_peak_drift_ratio,impacts,peak_force_n", "--target-error", "1e-2", "--energy"]
    pound("sweep", CONFIGS / "row-3-6.toml", "-o", out, "--backend", "cpu", *args)
    table = pounding.sweep(
        CONFIGS / "row-3-6.toml",
        backend="cpu",
        columns=["b2_peak_drift_ratio", "impacts", "peak_force_n"],
        target_error=1e-2,
        energy=True,
        progress=False,
    )
    assert table.column_names[0] == "run"
    assert_same_cells(table, out)


@pytest.mark.parametrize(
    "config, by, exceed",
    [
        ("quickstart.toml", "formula,gap_m", ["peak_force_n=1e6", "impacts=0"]),
        ("row-3-6.toml", "gap_1_2_m", ["b2_peak_drift_ratio=0.005"]),
        ("inelastic-fragility.toml", "record", ["b1_residual_drift_ratio=0.002"]),
    ],
)
def test_aggregate_is_the_command_lines_summary(config, by, exceed, pound, tmp_path):
    out = tmp_path / "summary.csv"
    flags = [f for e in exceed for f in ("--exceed", e)]
    pound("sweep", CONFIGS / config, "-o", out, "--backend", "cpu", "--aggregate", by, *flags)
    table = pounding.sweep(
        CONFIGS / config, backend="cpu", aggregate=by.split(","), exceed=exceed, progress=False
    )
    assert_same_cells(table, out)
    types = dict(zip(table.column_names, pa.table(table).schema.types))
    assert types["runs"] == pa.int64()


def test_a_config_as_a_dict_or_a_string_is_the_same_sweep():
    assert tomllib is not None, "tests run on Python 3.11 or later (tomllib)"
    path = CONFIGS / "fragility-example.toml"
    text = path.read_text()
    with open(path, "rb") as f:
        as_dict = tomllib.load(f)
    by_path = pa.table(pounding.sweep(path, backend="cpu", progress=False))
    by_text = pa.table(pounding.sweep(text, backend="cpu", progress=False))
    by_dict = pa.table(pounding.sweep(as_dict, backend="cpu", progress=False))
    assert by_path.num_rows == 1600
    assert by_text.equals(by_path)
    assert by_dict.equals(by_path)


def test_numbers_are_typed_buffers_not_python_objects():
    table = pounding.sweep(CONFIGS / "quickstart.toml", backend="cpu", progress=False)
    schema = pa.table(table).schema
    assert schema.field("run").type == pa.int64()
    assert schema.field("impacts").type == pa.int64()
    assert schema.field("peak_force_n").type == pa.float64()
    assert schema.field("formula").type == pa.string()
    df = table.to_pandas()
    assert str(df["peak_force_n"].dtype) == "float64"
    assert str(df["impacts"].dtype) == "int64"
    pl = table.to_polars()
    assert str(pl.schema["peak_force_n"]) == "Float64"
    assert pl.height == 2700
    # The numbers come through the Arrow stream, not as lists of Python floats.
    assert pa.table(table).column("peak_force_n").chunk(0).buffers()[1].size == 8 * 2700


def test_bad_input_raises_the_command_lines_messages(tmp_path):
    with pytest.raises(pounding.ConfigError, match="no-such.toml"):
        pounding.sweep(tmp_path / "no-such.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text((CONFIGS / "quickstart.toml").read_text().replace("[run]", "[run]\nsubsteps = 3", 1))
    with pytest.raises(pounding.ConfigError, match=r"bad\.toml"):
        pounding.sweep(bad, progress=False)
    missing = tmp_path / "missing-record.toml"
    missing.write_text(
        (CONFIGS / "fragility-sa.toml")
        .read_text()
        .replace("lomaprieta1989_corralitos_ns_RSN753_CLS000.AT2", "no-such-record.AT2")
    )
    with pytest.raises(pounding.ConfigError, match="no-such-record"):
        pounding.sweep(missing, progress=False)
    garbled = tmp_path / "garbled.AT2"
    garbled.write_text("not\na\nrecord\n")
    unreadable = tmp_path / "unreadable.toml"
    unreadable.write_text(
        (CONFIGS / "fragility-sa.toml")
        .read_text()
        .replace('file = "lomaprieta1989_corralitos_ns_RSN753_CLS000.AT2"', f'path = "{garbled}"')
    )
    with pytest.raises(pounding.RecordError, match="garbled"):
        pounding.sweep(unreadable, progress=False)
    with pytest.raises(pounding.SettingsError, match="`nope` is not a column"):
        pounding.sweep(CONFIGS / "quickstart.toml", columns=["nope"], progress=False)
    with pytest.raises(pounding.SettingsError, match="backend `tpu`"):
        pounding.sweep(CONFIGS / "quickstart.toml", backend="tpu", progress=False)
    with pytest.raises(pounding.SettingsError, match="target-error"):
        pounding.sweep(CONFIGS / "quickstart.toml", target_error=-1, progress=False)
    with pytest.raises(pounding.ConfigError, match="config dict"):
        pounding.sweep({"run": {"substeps_per_contact": object()}}, progress=False)
    with pytest.raises(pounding.ConfigError, match="^config: a int is not a config"):
        pounding.sweep(42)


def test_ctrl_c_stops_a_long_sweep_and_raises_keyboard_interrupt(tmp_path):
    # row-3-6 at 300 intensities: 18,000 runs, about a minute on two cores; interrupted after
    # it has run a while.
    config = tmp_path / "long.toml"
    text = (CONFIGS / "row-3-6.toml").read_text()
    config.write_text(text.replace("pga_g = [0.25, 0.35, 0.5]", "pga_g = { from = 0.1, to = 0.6, n = 300 }"))
    script = textwrap.dedent(
        f"""
        import sys, pounding
        print("started", flush=True)
        try:
            pounding.sweep(r"{config}", backend="cpu", progress=False)
        except KeyboardInterrupt:
            print("interrupted", flush=True)
            sys.exit(3)
        print("finished", flush=True)
        """
    )
    proc = subprocess.Popen(
        [sys.executable, "-c", script],
        cwd=REPO,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    assert proc.stdout.readline().strip() == "started"
    time.sleep(2.0)
    assert proc.poll() is None, "the sweep ended before it could be interrupted"
    sent = time.monotonic()
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=60)
    stopped = time.monotonic() - sent
    assert proc.returncode == 3, (out, err)
    assert "interrupted" in out
    assert stopped < 2.0, f"took {stopped:.2f} s to stop"


@pytest.mark.parametrize("config", ["quickstart.toml", "inelastic-row.toml"])
def test_the_gpu_gives_the_command_lines_cells(config, pound, tmp_path):
    # CI has Mesa's software adapter (lavapipe); POUND_REQUIRE_GPU there makes its absence fail.
    out = tmp_path / "runs.csv"
    pound("sweep", CONFIGS / config, "-o", out, "--backend", "gpu")
    table = pounding.sweep(CONFIGS / config, backend="gpu", progress=False)
    assert table.metadata["pound.backend"] == "gpu-f32"
    assert_same_cells(table, out)


def test_numpy_values_and_awkward_paths_are_taken_as_meant(tmp_path):
    import numpy as np

    assert tomllib is not None
    with open(CONFIGS / "fragility-example.toml", "rb") as f:
        plain = tomllib.load(f)
    # The same config with numpy's numbers where a notebook would put them.
    numpyish = tomllib.loads((CONFIGS / "fragility-example.toml").read_text())
    numpyish["record"] = [
        {"synthetic": {k: (np.int64(v) if isinstance(v, int) else np.float64(v)) for k, v in r["synthetic"].items()}}
        for r in numpyish["record"]
    ]
    numpyish.setdefault("run", {})["energy"] = np.bool_(False)
    expected = pa.table(pounding.sweep(plain, backend="cpu", progress=False))
    assert pa.table(pounding.sweep(numpyish, backend="cpu", progress=False)).equals(expected)
    # A folder named like a key is still a path.
    folder = tmp_path / "pga=0.3"
    folder.mkdir()
    (folder / "c.toml").write_text((CONFIGS / "fragility-example.toml").read_text())
    assert pa.table(pounding.sweep(str(folder / "c.toml"), backend="cpu", progress=False)).equals(expected)
    summary = pounding.sweep(
        CONFIGS / "quickstart.toml", backend="cpu", aggregate="formula", exceed={"peak_force_n": np.float64(1e6)}, progress=False
    )
    assert "exceed_peak_force_n>1000000" in summary.column_names
    for bad in ({"threads": -1}, {"threads": 1.5}, {"chunk": 0}):
        with pytest.raises(pounding.SettingsError):
            pounding.sweep(CONFIGS / "quickstart.toml", progress=False, **bad)


def test_a_peer_record_set_runs_as_the_command_lines_with_its_metadata(pound, tmp_path):
    """`[[record]] set = "DIR"`: a PEER NGA-West2 download (its files and _SearchResults.csv)
    runs one record per RSN and component, the search's metadata in typed columns."""
    import shutil

    records = Path(os.environ.get("POUND_RECORDS_DIR") or REPO.parent / "shared" / "records")
    folder = tmp_path / "peer"
    folder.mkdir()
    for src, dst in [
        ("elcentro1940_ns_RSN6_I-ELC180.AT2", "RSN6_IMPVALL.I_I-ELC180.AT2"),
        ("kobe1995_jma_ns_RSN1106_KJM000.AT2", "RSN1106_KOBE_KJM000.AT2"),
    ]:
        shutil.copy(records / src, folder / dst)
    (folder / "_SearchResults.csv").write_text(
        " -- Summary of Metadata of Selected Records --,,,,\n"
        " Result ID, Record Sequence Number, Scale Factor, Earthquake Name, Year, Magnitude,"
        " Rjb (km), Rrup (km), Vs30 (m/sec), Horizontal-1 Acc. Filename,"
        " Horizontal-2 Acc. Filename, Vertical Acc. Filename\n"
        '1, 6, 1.25," ""Imperial Valley-02""", 1940, 6.95, 6.09, 6.09, 213.44,'
        " RSN6_IMPVALL.I_I-ELC180.AT2, ---, ---\n"
        '2, 1106, 0.8," ""Kobe_ Japan""", 1995, 6.9, 0.94, 0.96, 312,'
        " RSN1106_KOBE_KJM000.AT2, ---, ---\n"
        ",,,,\n"
    )
    config = tmp_path / "set.toml"
    config.write_text(
        textwrap.dedent(
            """
            [building1]
            period_s = 0.5
            mass_kg = 1.0e5
            damping_ratio = 0.05
            [building2]
            period_s = 1.0
            mass_kg = 2.0e5
            damping_ratio = 0.05
            [contact]
            law = "linear"
            k_n_per_m = 1e8
            gap_m = 0.02
            [[record]]
            set = "peer"
            components = ["H1"]
            search_scale = true
            [intensity]
            scale = 1.0
            """
        )
    )
    out = tmp_path / "runs.csv"
    pound("sweep", config, "-o", out, "--backend", "cpu")
    table = pounding.sweep(config, backend="cpu", progress=False)
    assert_same_cells(table, out)
    rows = pa.table(table).to_pydict()
    assert rows["record"] == ["RSN6_H1", "RSN1106_H1"]
    assert rows["record_rsn"] == [6, 1106]
    assert rows["record_event"] == ["Imperial Valley-02", "Kobe_ Japan"]
    assert rows["record_magnitude"] == [6.95, 6.9]
    with pytest.raises(pounding.PoundingError, match="components"):
        pounding.sweep(_with(config, 'components = ["V"]'), backend="cpu", progress=False)


def _with(config, line):
    """`config` with its `components = [...]` line replaced by `line`, beside it."""
    other = config.with_name("other.toml")
    other.write_text(
        "\n".join(line if l.startswith("components") else l for l in config.read_text().splitlines())
    )
    return other
