"""The studies and the records from Python against their commands: `trace`, `gap`, `record`,
`spectrum`, `columns`, `fragility` and `ida` give the cells the command line writes."""

import pyarrow as pa
import pytest

import pounding
from conftest import CONFIGS, REPO, assert_same_cells, read_csv

RECORDS = REPO.parent / "shared" / "records"
RECORD = RECORDS / "kobe1995_jma_ns_RSN1106_KJM000.AT2"


def test_trace_is_the_command_lines_history_and_the_sweeps_row(pound, tmp_path):
    out = tmp_path / "trace.csv"
    shown = pound("trace", CONFIGS / "inelastic-row.toml", "--run", 5, "-o", out)
    history, row = pounding.trace(CONFIGS / "inelastic-row.toml", 5)
    header, rows = read_csv(out)
    at = pa.table(history)
    assert at.column_names == header and at.num_rows == len(rows) > 100
    assert_same_cells(history, out)
    # The row is the sweep's run 5, as the command prints it.
    lines = shown.stdout.strip().splitlines()
    assert pa.table(row).column_names == lines[0].split(",")
    sweep = pa.table(pounding.sweep(CONFIGS / "inelastic-row.toml", backend="cpu", progress=False))
    assert pa.table(row).to_pylist()[0] == sweep.slice(5, 1).to_pylist()[0]
    with pytest.raises(pounding.PoundingError, match="run 99"):
        pounding.trace(CONFIGS / "inelastic-row.toml", 99)


def test_gap_is_the_command_lines_table(pound, tmp_path):
    out = tmp_path / "gaps.csv"
    pound("gap", CONFIGS / "gap-example.toml", "-o", out)
    assert_same_cells(pounding.gap(CONFIGS / "gap-example.toml"), out)


def test_gap_takes_a_row_config_without_its_gaps(pound, tmp_path):
    # The gap study computes the gaps: a row config without gap_right_m or [contact] is taken,
    # as `pound gap` takes it, and gives the table of the same config with them (issue 65).
    text = (CONFIGS / "row-3-6.toml").read_text()
    bare = "\n".join(
        line for line in text.splitlines() if not line.startswith(("gap_right_m", "gap_m"))
    )
    assert "gap_right_m" not in bare and "gap_m" not in bare
    cfg = tmp_path / "bare.toml"
    cfg.write_text(bare)
    out = tmp_path / "gaps.csv"
    pound("gap", cfg, "-o", out)
    assert_same_cells(pounding.gap(cfg), out)
    assert pa.table(pounding.gap(cfg)).to_pylist() == pa.table(pounding.gap(CONFIGS / "row-3-6.toml")).to_pylist()


def test_record_and_spectrum_are_the_command_lines(pound, tmp_path):
    assert RECORD.exists(), f"{RECORD}: the shared records sit beside the clone"
    rec = pounding.record(RECORD)
    info = pound("record", "info", RECORD).stdout
    assert f"npts      {rec.npts}" in info
    assert f"pga       {rec.pga_g:.4f} g" in info
    assert f"pgv       {rec.pgv_m_s:.4f} m/s" in info
    assert len(rec.accel_m_s2) == rec.npts and abs(abs(rec.accel_g).max() - rec.pga_g) < 1e-12
    out = tmp_path / "spectrum.csv"
    pound("record", "spectrum", RECORD, "--periods", "0.1,0.2,0.5,1,2,4", "-o", out)
    table = pounding.spectrum(rec, [0.1, 0.2, 0.5, 1, 2, 4])
    assert_same_cells(table, out)
    with pytest.raises(pounding.RecordError, match="garbled"):
        bad = tmp_path / "garbled.AT2"
        bad.write_text("not\na\nrecord\n")
        pounding.record(bad)
    with pytest.raises(pounding.SettingsError, match="periods"):
        pounding.spectrum(rec, [0.0])


def test_a_columns_unit_is_in_its_fields_metadata():
    runs = pa.table(pounding.sweep(CONFIGS / "row-3-6.toml", backend="cpu", progress=False))
    for name, unit in [("peak_force_n", "N"), ("b2_peak_accel_m_s2", "m/s^2"), ("run", "-")]:
        assert runs.schema.field(name).metadata[b"unit"] == unit.encode()


def test_columns_are_the_command_lines_list(pound):
    listed = pound("columns", CONFIGS / "row-3-6.toml").stdout
    table = pa.table(pounding.columns(CONFIGS / "row-3-6.toml"))
    names = table.column("column").to_pylist()
    assert names == pounding.sweep(CONFIGS / "row-3-6.toml", backend="cpu", progress=False).column_names
    for name, unit in zip(names, table.column("unit").to_pylist()):
        assert f"| `{name}` | {unit} |" in listed
    types = dict(zip(names, table.column("type").to_pylist()))
    assert types["run"] == "int64" and types["record"] == "string" and types["gap_1_2_m"] == "float64"
    assert pounding.columns().num_rows > 10


@pytest.mark.parametrize(
    "flags, kwargs",
    [
        (["--edp", "b1_peak_ductility", "--threshold", "1,2,4"], {"edp": "b1_peak_ductility", "thresholds": [1, 2, 4]}),
        (
            ["--edp", "b1_peak_drift_ratio", "--damage-states", "hazus-c1l-high", "--bootstrap", "200", "--seed", "3"],
            {"edp": "b1_peak_drift_ratio", "damage_states": "hazus-c1l-high", "bootstrap": 200, "seed": 3},
        ),
        (
            ["--edp", "b1_peak_drift_ratio", "--threshold", "0.01", "--series", "gap_1_2_m"],
            {"edp": "b1_peak_drift_ratio", "thresholds": [0.01], "series": "gap_1_2_m"},
        ),
        (
            ["--edp", "b1_residual_drift_ratio", "--damage-states", "fema-p58-residual", "--where", "gap_1_2_m<=0.01"],
            {"edp": "b1_residual_drift_ratio", "damage_states": "fema-p58-residual", "where": "gap_1_2_m<=0.01"},
        ),
    ],
)
def test_fragility_is_the_command_lines_on_the_sweeps_table(flags, kwargs, pound, tmp_path):
    runs_csv, out = tmp_path / "runs.csv", tmp_path / "fragility.csv"
    fits = tmp_path / "fits.csv"
    pound("sweep", CONFIGS / "inelastic-fragility.toml", "-o", runs_csv, "--backend", "cpu")
    shown = pound("fragility", runs_csv, *flags, "-o", out, "--fits", fits)
    runs = pounding.sweep(CONFIGS / "inelastic-fragility.toml", backend="cpu", progress=False)
    # From the sweep's table, from a pandas DataFrame, and from the CSV's path: the same study.
    for given in (runs, runs.to_pandas(), runs.to_polars(), runs_csv):
        curves = pounding.fragility(given, **kwargs)
        assert_same_cells(curves, out)
        assert_same_cells(curves.info["fits"], fits)
        assert curves.info["report"] == shown.stdout
    # The fits table is the report's, unrounded: each fitted row's median and beta round to the
    # report's cells.
    table = pa.table(curves.info["fits"]).to_pylist()
    fitted = [r for r in table if r["fit"].startswith("ok")]
    assert fitted, table
    for r in fitted:
        assert f"| {r['median']:.4f} | {r['beta']:.4f} | {r['se_ln_median']:.4f} |" in shown.stdout
    if kwargs.get("bootstrap"):
        assert all(r["median_p5"] <= r["median"] <= r["median_p95"] for r in fitted)


def test_ida_is_the_command_lines(pound, tmp_path):
    runs_csv, out = tmp_path / "runs.csv", tmp_path / "ida.csv"
    pound("sweep", CONFIGS / "collapse-ida.toml", "-o", runs_csv, "--backend", "cpu")
    long = tmp_path / "long.csv"
    shown = pound("ida", runs_csv, "--edp", "b1_peak_drift_ratio", "-o", out, "--long", long)
    runs = pounding.sweep(CONFIGS / "collapse-ida.toml", backend="cpu", progress=False)
    curves = pounding.ida(runs, edp="b1_peak_drift_ratio")
    assert_same_cells(curves, out)
    # `curves=` names the curves; `by=`, its old spelling, still works.
    assert_same_cells(pounding.ida(runs, edp="b1_peak_drift_ratio", curves="record"), out)
    assert_same_cells(pounding.ida(runs, edp="b1_peak_drift_ratio", by="record"), out)
    assert_same_cells(curves.info["long"], long)
    # The long form holds the wide table's every value: a row per curve and level.
    wide = pa.table(curves).to_pylist()
    im = curves.column_names[0]
    rows = pa.table(curves.info["long"]).to_pylist()
    assert len(rows) == sum(1 for w in wide for c in curves.column_names[7:] if w[c] is not None)
    for r in rows:
        (w,) = [w for w in wide if w[im] == r[im]]
        assert w[r["record"]] == r["b1_peak_drift_ratio"]
        assert r["collapsed"] == (r["b1_peak_drift_ratio"] == float("inf"))
    assert curves.info["report"] == shown.stdout
    # A collapsed curve's demand is infinite: a real column holding inf, as the CSV's `inf`.
    demands = pa.table(curves).select(curves.column_names[7:]).to_pylist()
    assert pa.table(curves).schema.field("kobe_1995_jma").type == pa.float64()
    assert any(v == float("inf") for row in demands for v in row.values())


def test_studies_refuse_bad_input_with_the_command_lines_messages(tmp_path):
    runs = pounding.sweep(CONFIGS / "inelastic-fragility.toml", backend="cpu", progress=False)
    with pytest.raises(pounding.TableError, match="no column `nope`"):
        pounding.fragility(runs, edp="nope", thresholds=[1])
    with pytest.raises(pounding.SettingsError, match="bootstrap"):
        pounding.fragility(runs, edp="b1_peak_ductility", thresholds=[1], bootstrap=5)
    with pytest.raises(pounding.TableError, match="not a table"):
        pounding.fragility(42, edp="b1_peak_ductility", thresholds=[1])
    with pytest.raises(pounding.TableError, match="missing.csv"):
        pounding.ida(tmp_path / "missing.csv", edp="b1_peak_drift_ratio")


def test_a_studys_columns_keep_their_types_whatever_the_values():
    import polars as pl

    pounded = pounding.trace(CONFIGS / "quickstart.toml", 0).history
    untouched = pounding.trace(CONFIGS / "quickstart.toml", 4).history
    assert pa.table(pounded).schema == pa.table(untouched).schema
    assert pl.concat([pounded.to_polars(), untouched.to_polars()]).height == pounded.num_rows + untouched.num_rows
    with pytest.raises(pounding.SettingsError, match="run=-1"):
        pounding.trace(CONFIGS / "quickstart.toml", -1)


def test_categories_are_read_and_other_columns_left_out(pound, tmp_path):
    runs = pounding.sweep(CONFIGS / "inelastic-fragility.toml", backend="cpu", progress=False)
    df = runs.to_pandas()
    df["record"] = df["record"].astype("category")
    df["when"] = __import__("pandas").Timestamp("2020-01-01")
    expected = pa.table(pounding.fragility(runs, edp="b1_peak_ductility", thresholds=[1, 2], bootstrap=100))
    got = pa.table(pounding.fragility(df, edp="b1_peak_ductility", thresholds=[1, 2], bootstrap=100))
    assert got.equals(expected)
    with pytest.raises(pounding.TableError, match="without when"):
        pounding.fragility(df, edp="when", thresholds=[1])


def test_a_table_naming_a_column_twice_is_refused_naming_it():
    # A zeros column placed first under the same name once turned a drift fit into another fit:
    # the studies refuse the table instead of reading either column (issue 65, item 4).
    runs = pa.table(pounding.sweep(CONFIGS / "inelastic-fragility.toml", backend="cpu", progress=False))
    drift = runs.column("b1_peak_drift_ratio")
    twice = runs.add_column(0, "b1_peak_drift_ratio", pa.array([0.0] * len(runs)))
    assert twice.column_names.count("b1_peak_drift_ratio") == 2 and len(drift) == len(runs)
    with pytest.raises(pounding.TableError, match="b1_peak_drift_ratio"):
        pounding.fragility(twice, edp="b1_peak_drift_ratio", thresholds=[0.005])
    with pytest.raises(pounding.TableError, match="b1_peak_drift_ratio"):
        pounding.ida(twice, edp="b1_peak_drift_ratio")
