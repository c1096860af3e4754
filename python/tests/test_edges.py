"""The package's edges: every keyword of every function, given a value of the wrong type, out of
range, empty, a bool for a number, NaN or infinity, is refused with a PoundingError subclass
naming the keyword (never a bare TypeError, ValueError or OverflowError from the binding); numpy
arrays and numbers are taken where lists and numbers are."""

import copy
import glob

import numpy as np
import pyarrow as pa
import pytest

import pounding
from conftest import CONFIGS, REPO

try:
    import tomllib
except ImportError:  # Python < 3.11
    tomllib = None

pytestmark = pytest.mark.skipif(tomllib is None, reason="tomllib is Python 3.11's")

HUGE = 2**70


def small_pair():
    """The quickstart pair cut to two runs: a config dict as a notebook builds one."""
    with open(CONFIGS / "quickstart.toml", "rb") as f:
        d = tomllib.load(f)
    d["contact"].update(formula="exact", e=0.65, gap_m=[0.0, 0.01])
    d["building1"]["period_s"] = [0.3]
    d["building2"]["period_s"] = [0.2]
    return d


def sweep(config, **kw):
    return pounding.sweep(config, backend="cpu", progress=False, **kw)


@pytest.fixture(scope="module")
def runs():
    return sweep(small_pair())


@pytest.fixture(scope="module")
def record_path():
    found = sorted(glob.glob(str(REPO.parent / "shared/records/*.AT2")))
    import os

    given = os.environ.get("POUND_RECORDS_DIR")
    if given:
        found = sorted(glob.glob(os.path.join(given, "*.AT2"))) or found
    assert found, "no record: the record tests read ../shared/records or POUND_RECORDS_DIR"
    return found[0]


def test_numpy_arrays_in_a_dict_config_are_the_lists_they_hold():
    plain = small_pair()
    plain["building1"]["period_s"] = [0.3, 0.5]
    arrays = copy.deepcopy(plain)
    arrays["building1"]["period_s"] = np.array([0.3, 0.5])
    arrays["contact"]["gap_m"] = np.arange(2) * 0.01
    arrays["building2"]["period_s"] = np.array(0.2)  # a 0-d array: its number
    expected = pa.table(sweep(plain))
    assert expected.num_rows == 4
    assert pa.table(sweep(arrays)).equals(expected)


def test_a_numpy_array_of_the_wrong_shape_is_refused_naming_its_key():
    bad = small_pair()
    bad["contact"]["gap_m"] = np.array([[0.0, 0.01]])
    with pytest.raises(pounding.ConfigError, match="gap_m"):
        sweep(bad)


@pytest.mark.parametrize(
    "call, name",
    [
        (lambda r, p: sweep(small_pair(), threads=HUGE), "threads"),
        (lambda r, p: sweep(small_pair(), chunk=HUGE), "chunk"),
        (lambda r, p: pounding.gap(CONFIGS / "gap-example.toml", threads=HUGE), "threads"),
        (lambda r, p: pounding.trace(small_pair(), HUGE), "run"),
        (lambda r, p: pounding.fragility(r, thresholds=[1e5], bootstrap=HUGE), "bootstrap"),
        (lambda r, p: pounding.fragility(r, thresholds=[1e5], seed=HUGE), "seed"),
        (lambda r, p: pounding.record(p, skip_lines=HUGE), "skip_lines"),
        (lambda r, p: pounding.fragility(r, thresholds=[1e5], bootstrap=10**6), "bootstrap"),
        (lambda r, p: sweep(small_pair(), threads=5000), "threads"),
    ],
)
def test_a_whole_number_past_its_range_is_refused_naming_it_and_the_range(call, name, runs, record_path):
    with pytest.raises(pounding.SettingsError, match=rf"^{name}=\d+: expected a whole number from \d+ to \d+"):
        call(runs, record_path)


@pytest.mark.parametrize(
    "call, name",
    [
        (lambda r, p: sweep(small_pair(), threads=True), "threads"),
        (lambda r, p: sweep(small_pair(), chunk=False), "chunk"),
        (lambda r, p: pounding.trace(small_pair(), True), "run"),
        (lambda r, p: pounding.fragility(r, thresholds=[1e5], bootstrap=True), "bootstrap"),
        (lambda r, p: pounding.fragility(r, thresholds=[1e5], seed=False), "seed"),
        (lambda r, p: pounding.fragility(r, thresholds=True), "thresholds"),
        (lambda r, p: pounding.record(p, skip_lines=True), "skip_lines"),
        (lambda r, p: pounding.record(p, dt=True), "dt"),
        (lambda r, p: pounding.spectrum(p, [1.0], damping=False), "damping"),
        (lambda r, p: pounding.spectrum(p, True), "periods"),
        (lambda r, p: sweep(small_pair(), target_error=True), "target_error"),
        (lambda r, p: sweep(small_pair(), aggregate="formula", exceed={"peak_force_n": True}), "exceed"),
        (lambda r, p: pounding.record(p, window=(True, 2.0)), "window"),
    ],
)
def test_a_bool_where_a_number_is_expected_is_refused_naming_it(call, name, runs, record_path):
    with pytest.raises(pounding.SettingsError, match=rf"^{name}="):
        call(runs, record_path)


@pytest.mark.parametrize(
    "call, name",
    [
        (lambda r, p: pounding.sweep(small_pair(), backend=3, progress=False), "backend"),
        (lambda r, p: sweep(small_pair(), precision=3), "precision"),
        (lambda r, p: sweep(small_pair(), scheme=3), "scheme"),
        (lambda r, p: sweep(small_pair(), target_error="x"), "target_error"),
        (lambda r, p: sweep(small_pair(), target_error=10**400), "target_error"),
        (lambda r, p: sweep(small_pair(), energy="no"), "energy"),
        (lambda r, p: pounding.sweep(small_pair(), backend="cpu", progress=None), "progress"),
        (lambda r, p: sweep(small_pair(), columns=3), "columns"),
        (lambda r, p: sweep(small_pair(), columns=["peak_force_n", 3]), "columns"),
        (lambda r, p: sweep(small_pair(), aggregate=3), "aggregate"),
        (lambda r, p: sweep(small_pair(), aggregate="formula", exceed=3), "exceed"),
        (lambda r, p: sweep(small_pair(), aggregate="formula", exceed={"peak_force_n": "x"}), "exceed"),
        (lambda r, p: sweep(small_pair(), threads=2.0), "threads"),
        (lambda r, p: pounding.trace(small_pair(), "0"), "run"),
        (lambda r, p: pounding.fragility(r, thresholds=[1e5], where=3), "where"),
        (lambda r, p: pounding.fragility(r, thresholds=[1e5], by=["record"]), "by"),
        (lambda r, p: pounding.fragility(r, thresholds=[1e5], bootstrap_groups=3), "bootstrap_groups"),
        (lambda r, p: pounding.ida(r, edp="peak_force_n", curves=3), "curves"),
        (lambda r, p: pounding.fragility(r, thresholds=[1e5], im=3), "im"),
        (lambda r, p: pounding.fragility(r, thresholds=[1e5], edp=None), "edp"),
        (lambda r, p: pounding.fragility(r, thresholds=[1e5], damage_states=1), "damage_states"),
        (lambda r, p: pounding.fragility(r, thresholds=[float("nan")]), "thresholds"),
        (lambda r, p: pounding.fragility(r, thresholds=[float("inf")]), "thresholds"),
        (lambda r, p: pounding.fragility(r, thresholds="1e5,x"), "thresholds"),
        (lambda r, p: pounding.ida(r, edp=3), "edp"),
        (lambda r, p: pounding.ida(r, edp="peak_force_n", by=3), "by"),
        (lambda r, p: pounding.ida(r, edp="peak_force_n", where=[3]), "where"),
        (lambda r, p: pounding.record(3), "path"),
        (lambda r, p: pounding.record(p, format=3), "format"),
        (lambda r, p: pounding.record(p, units=3), "units"),
        (lambda r, p: pounding.record(p, dt="a"), "dt"),
        (lambda r, p: pounding.record(p, dt=float("inf")), "dt"),
        (lambda r, p: pounding.record(p, window=(1.0, 2.0, 3.0)), "window"),
        (lambda r, p: pounding.record(p, window=(float("nan"), 2.0)), "window"),
        (lambda r, p: pounding.record(p, window=5.0), "window"),
        (lambda r, p: pounding.spectrum(3, [1.0]), "record"),
        (lambda r, p: pounding.spectrum(p, [1.0], damping="x"), "damping"),
        (lambda r, p: pounding.spectrum(p, [1.0], damping=None), "damping"),
        (lambda r, p: pounding.spectrum(p, [1.0], damping=float("nan")), "damping"),
        (lambda r, p: pounding.spectrum(p, [float("inf")]), "periods"),
        (lambda r, p: pounding.spectrum(p, np.array([[1.0], ["x"]])), "periods"),
    ],
)
def test_a_value_of_the_wrong_kind_is_refused_naming_its_keyword(call, name, runs, record_path):
    with pytest.raises(pounding.SettingsError, match=rf"^{name}="):
        call(runs, record_path)


@pytest.mark.parametrize("config", [42, b"configs/quickstart.toml", None, 1.5])
def test_a_config_of_no_config_type_is_a_config_error(config):
    with pytest.raises(pounding.ConfigError, match="^config"):
        sweep(config)
    with pytest.raises(pounding.ConfigError, match="^config"):
        pounding.gap(config)


@pytest.mark.parametrize(
    "path",
    ["runs/pga=0.3/cfg.toml", "[draft]/cfg.toml", "runs/cfg.toml", "runs/x = 1"],
)
def test_a_missing_path_is_said_to_be_missing_whatever_it_holds(path):
    for call in (sweep, pounding.gap, pounding.columns, lambda c: pounding.trace(c, 0)):
        with pytest.raises(pounding.ConfigError, match="[Nn]o such file") as e:
            call(path)
        assert "TOML parse error" not in str(e.value)


def test_a_config_string_of_several_lines_is_still_toml(tmp_path):
    text = (CONFIGS / "quickstart.toml").read_text()
    assert pa.table(sweep(text)).equals(pa.table(sweep(CONFIGS / "quickstart.toml")))


@pytest.mark.parametrize("empty", [[], "", " , ", ()])
def test_empty_columns_are_refused_as_the_command_line_refuses_them(empty, pound):
    with pytest.raises(pounding.SettingsError, match="^columns="):
        sweep(small_pair(), columns=empty)
    with pytest.raises(pounding.SettingsError, match="^aggregate="):
        sweep(small_pair(), aggregate=empty)
    # The command line's own refusal of the same.
    done = pound("sweep", CONFIGS / "quickstart.toml", "-o", "/dev/null", "--columns", "", check=False)
    assert done.returncode != 0
    done = pound("sweep", CONFIGS / "quickstart.toml", "-o", "/dev/null", "--aggregate", "", check=False)
    assert done.returncode != 0


def test_numpy_numbers_are_taken_where_numbers_are(runs, record_path):
    ref = pounding.fragility(runs, thresholds=[1e5, 2e5])
    for given in (np.array([1e5, 2e5]), [np.float64(1e5), np.int64(200000)], "1e5,2e5"):
        assert pa.table(pounding.fragility(runs, thresholds=given)).equals(pa.table(ref))
    rec = pounding.record(record_path, skip_lines=np.int64(0), window=np.array([1.0, 5.0]))
    assert rec.duration == pytest.approx(4.0, abs=0.05)
    sa = pounding.spectrum(rec, np.array([0.5, 1.0]), damping=np.float64(0.05))
    assert sa.num_rows == 2
    assert sweep(small_pair(), threads=np.int64(1), chunk=np.uint8(7)).num_rows == 2


def test_a_dataframe_naming_a_column_twice_is_a_table_error_naming_it():
    pd = pytest.importorskip("pandas")
    df = pd.DataFrame({"a": [0.0] * 4, "record": ["a", "a", "b", "b"], "pga_g": [0.1, 0.2, 0.1, 0.2], "status": ["ok"] * 4, "b": [0, 1, 0, 1]})
    df.columns = ["peak_force_n", "record", "pga_g", "status", "peak_force_n"]
    for study in (
        lambda: pounding.fragility(df, edp="peak_force_n", thresholds=[0.5]),
        lambda: pounding.ida(df, edp="peak_force_n"),
    ):
        with pytest.raises(pounding.TableError, match=r"`peak_force_n` appears 2 times \(columns 1, 5\)"):
            study()


@pytest.mark.parametrize("name", ["im", "by", "damage_states"])
def test_an_empty_name_is_a_settings_error_naming_the_keyword(name):
    runs = pounding.sweep(CONFIGS / "inelastic-fragility.toml", backend="cpu", progress=False)
    kwargs = {"edp": "b1_peak_drift_ratio", "thresholds": [0.01], name: ""}
    if name == "damage_states":
        kwargs.pop("thresholds")
    with pytest.raises(pounding.SettingsError, match=rf"^{name}="):
        pounding.fragility(runs, **kwargs)


def test_a_dict_configs_error_names_the_key_not_a_line_of_generated_toml():
    # The dict's TOML is written by the package: its line and column mean nothing to the user.
    base = {
        "building1": {"mass_kg": 1e5, "period_s": 0.3, "damping_ratio": 0.05},
        "building2": {"mass_kg": 1e5, "period_s": 0.6, "damping_ratio": 0.05},
        "contact": {"law": "linear", "k_n_per_m": 1e9, "gap_m": 0.01},
        "record": [{"synthetic": {"seed": 1, "duration_s": 2.0}}],
    }
    nested = copy.deepcopy(base)
    nested["building2"]["period_s"] = np.array([[0.3, 0.4], [0.5, 0.6]])
    unknown = copy.deepcopy(base)
    unknown["building1"]["x"] = 1
    for config, key in ((nested, "building2.period_s"), (unknown, "building1.x")):
        with pytest.raises(pounding.ConfigError) as e:
            pounding.sweep(config, backend="cpu", progress=False)
        assert str(e.value).startswith(f"<config dict>: {key}: "), str(e.value)
        assert "TOML parse error" not in str(e.value) and "line" not in str(e.value), str(e.value)
    with pytest.raises(pounding.ConfigError, match=r"^<config dict>: missing field `building1`$"):
        pounding.sweep({}, backend="cpu", progress=False)
