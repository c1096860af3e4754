#!/usr/bin/env python3
"""Peer comparison on yielding storeys: the same inelastic pounding scene in OpenSees and `pound`.

The scene is `benches/opensees_inelastic.py`'s pair D: two one-storey buildings, one
elastic-perfectly-plastic (`Steel01`, b = 0, strength 0.12 W), one with 5 % kinematic hardening,
5 % Rayleigh damping on the initial stiffness, linear compression-only contact (k 1e9 N/m), the
whole El Centro 1940 record (RSN6) scaled to a PGA, over a sweep of gaps. The truth is `pound`'s
reference scheme (adaptive Dormand-Prince, yield and contact events located). Reported per
solver: runs per second on one core and the relative error of the peak contact force and of the
peak drift ratios (the larger of the two buildings') against that truth, median and max over the
gaps. OpenSees runs the record alone (no free tail); `pound` also runs its free vibration after
the record until no storey can yield again (its residual drift), which counts in its time.

Set-up (OpenSees 3.8 needs Python 3.12), from the repository root:
    PYENV_VERSION=3.12.1 python3.12 -m venv /tmp/ospy && /tmp/ospy/bin/pip install openseespy numpy
    cargo build --release
    /tmp/ospy/bin/python benches/opensees_inelastic_peer.py [--dt 1e-3 5e-4] [--gaps 10] [--substeps 64]

Records are read from POUND_RECORDS_DIR (default ../shared/records), never copied.
"""

import argparse
import csv
import math
import os
import subprocess
import sys
import tempfile
import time
from importlib.metadata import version

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from opensees_inelastic import SCENES, run_opensees  # noqa: E402
from opensees_multistorey import G, K_CONTACT, read_at2  # noqa: E402


def pound_sweep(pound, cfg, out, scheme):
    """`pound sweep` on one thread: (seconds, {gap: (peak force, largest peak drift ratio)})."""
    cmd = [pound, "sweep", cfg, "--backend", "cpu", "--threads", "1", "-o", out, "--scheme", scheme]
    t = time.perf_counter()
    subprocess.run(cmd, check=True, stderr=subprocess.DEVNULL)
    seconds = time.perf_counter() - t
    with open(out) as f:
        rows = list(csv.DictReader(f))
    return seconds, {
        float(r["gap_1_2_m"]): (
            float(r["peak_force_n"]),
            max(float(r["b1_peak_drift_ratio"]), float(r["b2_peak_drift_ratio"])),
        )
        for r in rows
    }


def errors(got, truth, i):
    e = sorted(abs(got[g][i] - truth[g][i]) / truth[g][i] for g in truth if truth[g][i] > 0)
    return e[len(e) // 2], e[-1]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--pound", default="target/release/pound")
    ap.add_argument("--dt", type=float, nargs="+", default=[1e-3], help="OpenSees time steps, s")
    ap.add_argument("--gaps", type=int, default=10, help="gaps from 0 to 30 mm")
    ap.add_argument("--repeat", type=int, default=5, help="pound sweeps timed (runs/s median)")
    ap.add_argument("--timing-runs", type=int, default=500, help="runs in each timed pound sweep")
    ap.add_argument("--substeps", type=float, default=64, help="pound's substeps_per_contact")
    a = ap.parse_args()
    import openseespy.opensees as ops

    scene = dict(SCENES[0])
    records = os.environ.get("POUND_RECORDS_DIR", "../shared/records")
    path = os.path.join(records, scene["record"])
    dt_rec, acc_g = read_at2(path)
    scale = scene["pga_g"] / max(abs(x) for x in acc_g)
    ag = [x * scale * G for x in acc_g]
    duration = (len(ag) - 1) * dt_rec
    gaps = [0.03 * i / max(a.gaps - 1, 1) for i in range(a.gaps)]

    def building(b):
        m, k = b["masses"][0], b["stiffness"][0]
        return f"""[[building]]
storeys = 1
storey_height_m = {b['heights'][0]!r}
mass_kg = {m!r}
period_s = {2 * math.pi / math.sqrt(k / m)!r}
damping_ratio = 0.05
yield_force_n = {b['fy'][0]!r}
post_yield_ratio = {b['b'][0]!r}
"""

    def config(gap_list):
        b1, b2 = scene["buildings"]
        return f"""[run]
tail_s = 0.0
substeps_per_contact = {a.substeps!r}

{building(b1)}gap_right_m = [{", ".join(repr(g) for g in gap_list)}]

{building(b2)}
[contact]
law = "linear"
k_n_per_m = {K_CONTACT!r}

[[record]]
file = "{os.path.abspath(path)}"

[intensity]
pga_g = {scene['pga_g']!r}
"""

    with tempfile.TemporaryDirectory() as tmp:
        cfg = os.path.join(tmp, "peer.toml")
        with open(cfg, "w") as f:
            f.write(config(gaps))
        _, truth = pound_sweep(a.pound, cfg, os.path.join(tmp, "reference.csv"), "reference")
        _, fast = pound_sweep(a.pound, cfg, os.path.join(tmp, "fast.csv"), "fast")
        timing = os.path.join(tmp, "timing.toml")
        n = a.timing_runs
        with open(timing, "w") as f:
            f.write(config([0.03 * i / (n - 1) for i in range(n)]))
        times = [
            pound_sweep(a.pound, timing, os.path.join(tmp, f"timing{i}.csv"), "fast")[0]
            for i in range(a.repeat)
        ]
        pound_rate = n / sorted(times)[len(times) // 2]

        rows = [
            (f"pound fast, {a.substeps:g} substeps (1 thread, median of {a.repeat} sweeps of {n} runs)", pound_rate, fast),
        ]
        for dt in a.dt:
            opensees = {}
            t = time.perf_counter()
            for g in gaps:
                s = dict(scene, gaps=[g])
                forces, drifts, _ = run_opensees(ops, tmp, s, ag, dt_rec, dt, duration, tail=0.0)
                opensees[g] = (forces[0], max(drifts))
            os_rate = len(gaps) / (time.perf_counter() - t)
            rows.append((f"OpenSees (openseespy {version('openseespy')}), Newmark dt {dt:g}", os_rate, opensees))

    print(f"Scene: {scene['record']} at {scene['pga_g']} g ({duration:.1f} s), pair D of")
    print("benches/opensees_inelastic.py (EPP beside 5 % hardening, one storey each), linear")
    print(f"contact k = {K_CONTACT:g} N/m, {len(gaps)} gaps 0-30 mm; truth: pound reference.")
    print()
    print("| solver | runs/s per core | peak force error median | max | peak drift error median | max |")
    print("|---|---:|---:|---:|---:|---:|")
    for name, rate, got in rows:
        f, d = errors(got, truth, 0), errors(got, truth, 1)
        print(f"| {name} | {rate:.1f} | {f[0]:.1e} | {f[1]:.1e} | {d[0]:.1e} | {d[1]:.1e} |")
    print()
    for name, rate, _ in rows[1:]:
        print(f"pound / {name}: {rows[0][1] / rate:.0f}x runs per second")


if __name__ == "__main__":
    sys.exit(main())
