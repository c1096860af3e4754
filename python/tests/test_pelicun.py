"""`pound demands` feeds pelicun (SimCenter's FEMA P-58 loss engine) with no mapping code: its
file loads through pelicun's own demand loader, every value the sweep's, and its collapse
column drops the collapsed runs through pelicun's own `CollapseLimits`."""

import math

import pandas as pd
from pelicun.assessment import Assessment, DLCalculationAssessment

from conftest import CONFIGS, read_csv


def test_pelicun_loads_pound_demands_with_every_value_the_sweeps(pound, tmp_path):
    runs_csv, out = tmp_path / "runs.csv", tmp_path / "demands.csv"
    pound(
        "sweep", CONFIGS / "collapse-fragility.toml", "-o", runs_csv, "--backend", "cpu",
        "--columns", "+storeys,+floors",
    )
    pound("demands", runs_csv, "--building", "1", "--where", "target_sa_g=1", "-o", out)
    # The package's function writes the command line's file.
    import pounding

    assert pounding.demands(runs_csv, building=1, where="target_sa_g=1") == out.read_text()
    header, rows = read_csv(runs_csv)
    sweep = {r[0]: dict(zip(header, r)) for r in rows}

    a = Assessment({"PrintLog": False})
    a.demand.load_sample(str(out))
    sample = a.demand.sample
    units = a.demand.user_units
    kept = [r for r in sweep.values() if r["target_sa_g"] == "1" and r["status"] in ("ok", "collapsed")]
    assert len(sample) == len(kept) == 50
    storeys = 3
    expected_columns = {("PID", str(j), "1") for j in range(1, storeys + 1)}
    expected_columns |= {("RID", str(j), "1") for j in range(1, storeys + 1)}
    expected_columns |= {("PFA", str(j), "1") for j in range(0, storeys + 1)}
    expected_columns |= {("SA_T1", "0", "1"), ("COL", "0", "1")}
    assert set(sample.columns) == expected_columns
    assert units[("PID", "1", "1")] == "rad" and units[("PFA", "0", "1")] == "mps2"

    def same(value, cell):
        # pelicun's loader cuts the drift ratios to 16 decimal places (0.017552338325756145
        # comes back 0.0175523383257561); the file holds every digit. The accelerations come
        # back to the bit.
        if cell == "":
            return math.isnan(value)
        return math.isclose(value, float(cell), rel_tol=1e-15, abs_tol=1.01e-16)

    raw = pd.read_csv(out, index_col=0, dtype=str, keep_default_na=False).drop("Units")
    collapsed = 0
    for position, run in enumerate(raw.index):
        r = sweep[run]
        got = sample.iloc[position]
        for j in range(1, storeys + 1):
            assert same(got[("PID", str(j), "1")], r[f"b1_s{j}_peak_drift_ratio"])
            residual = r[f"b1_s{j}_residual_drift_ratio"]
            assert same(got[("RID", str(j), "1")], residual and str(abs(float(residual))))
        for j in range(0, storeys + 1):
            assert same(got[("PFA", str(j), "1")], r[f"b1_f{j}_peak_accel_m_s2"])
        assert got[("COL", "0", "1")] == float(r["b1_collapsed"])
        # pelicun holds accelerations in m/s^2: the target in g times standard gravity.
        assert math.isclose(got[("SA_T1", "0", "1")], float(r["target_sa_g"]) * 9.80665, rel_tol=1e-15)
        collapsed += r["b1_collapsed"] == "1"
    assert 0 < collapsed < len(kept)

    # pelicun's CollapseLimits on the collapse column: the collapsed runs leave the sample.
    b = DLCalculationAssessment({"PrintLog": False})
    b.calculate_demand(
        out, {"COL": 0.5}, None, None, 100, None, None, coupled_demands=True
    )
    resampled = b.demand.sample
    assert len(resampled) == 100
    assert (resampled[("COL", "0", "1")] == 0).all()
    standing = {float(r["b1_s1_peak_drift_ratio"]) for r in kept if r["b1_collapsed"] == "0"}
    assert set(resampled[("PID", "1", "1")]) <= standing
