#!/usr/bin/env python3
"""Peer comparison: the same two-building pounding scene in OpenSees and in `pound`.

Both solve two SDOF buildings (explicit dashpots, no Rayleigh damping) under one real record,
with a linear compression-only contact spring (`law = "linear"` here; `ElasticPPGap` in
OpenSees) over a sweep of gaps. The truth is `pound`'s reference scheme (adaptive
Dormand-Prince, events located, tol 1e-8). Reported per solver: runs per second on one core
and the relative peak-force error against that truth (median and max over the gaps).

Set-up (OpenSees 3.8 needs Python 3.12), from the repository root:
    PYENV_VERSION=3.12.1 python3.12 -m venv /tmp/ospy && /tmp/ospy/bin/pip install openseespy
    cargo build --release
    /tmp/ospy/bin/python benches/opensees_peer.py [--dt 1e-3] [--gaps 10] [--record FILE]

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

G = 9.80665


def read_at2(path):
    """PEER AT2: four header lines (the fourth gives NPTS and DT), then values in g."""
    with open(path) as f:
        lines = f.read().splitlines()
    head = lines[3].replace(",", " ").split()
    npts = int(head[head.index("NPTS=") + 1]) if "NPTS=" in head else None
    dt = float(head[head.index("DT=") + 1])
    values = [float(x) for line in lines[4:] for x in line.split()]
    return dt, values[:npts] if npts else values


def opensees_peak_force(ops, tmp, b1, b2, gap, k_contact, ag, dt_rec, dt, duration):
    """One run: the largest contact force over the analysis, N."""
    ops.wipe()
    ops.model("basic", "-ndm", 1, "-ndf", 1)
    for node in (1, 2, 3, 4):
        ops.node(node, 0.0)
    ops.fix(1, 1)
    ops.fix(3, 1)
    ops.mass(2, b1["m"])
    ops.mass(4, b2["m"])
    for tag, b in ((1, b1), (4, b2)):
        ops.uniaxialMaterial("Elastic", tag, b["k"])
        ops.uniaxialMaterial("Viscous", tag + 1, b["c"], 1.0)
        ops.uniaxialMaterial("Parallel", tag + 2, tag, tag + 1)
    ops.element("zeroLength", 1, 1, 2, "-mat", 3, "-dir", 1)
    ops.element("zeroLength", 2, 3, 4, "-mat", 6, "-dir", 1)
    # Building 1 is left of building 2: contact when u1 - u2 > gap, i.e. the element from
    # node 2 to node 4 shortens by more than the gap (a compression gap: negative Fy and gap).
    ops.uniaxialMaterial("ElasticPPGap", 7, k_contact, -1e30, -gap)
    ops.element("zeroLength", 3, 2, 4, "-mat", 7, "-dir", 1)
    ops.timeSeries("Path", 1, "-dt", dt_rec, "-values", *ag, "-factor", 1.0)
    ops.pattern("UniformExcitation", 1, 1, "-accel", 1)
    ops.constraints("Plain")
    ops.numberer("Plain")
    ops.system("FullGeneral")
    ops.test("NormDispIncr", 1e-10, 50)
    ops.algorithm("Newton")
    ops.integrator("Newmark", 0.5, 0.25)
    ops.analysis("Transient")
    # The contact force of every step goes to a file (one analyze call, no Python per step).
    out = os.path.join(tmp, f"force{gap}.txt")
    ops.recorder("Element", "-file", out, "-ele", 3, "force")
    if ops.analyze(int(round(duration / dt)), dt) != 0:
        raise RuntimeError(f"OpenSees failed at gap {gap}")
    ops.wipe()
    with open(out) as f:
        return max((abs(float(x)) for line in f for x in line.split()[:1]), default=0.0)


def pound_sweep(pound, cfg, out, scheme):
    """Run `pound sweep` on one thread; returns (seconds, {gap: peak force})."""
    cmd = [pound, "sweep", cfg, "--backend", "cpu", "--threads", "1", "-o", out]
    if scheme:
        cmd += ["--scheme", scheme]
    t = time.perf_counter()
    subprocess.run(cmd, check=True, stderr=subprocess.DEVNULL)
    seconds = time.perf_counter() - t
    with open(out) as f:
        rows = list(csv.DictReader(f))
    return seconds, {float(r["gap_m"]): float(r["peak_force_n"]) for r in rows}


def errors(got, truth):
    e = sorted(abs(got[g] - truth[g]) / truth[g] for g in truth if truth[g] > 0)
    return e[len(e) // 2], e[-1]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--pound", default="target/release/pound")
    ap.add_argument("--record", default="lomaprieta1989_corralitos_ns_RSN753_CLS000.AT2")
    ap.add_argument("--pga-g", type=float, default=0.35)
    ap.add_argument("--dt", type=float, default=1e-3, help="OpenSees time step, s")
    ap.add_argument("--gaps", type=int, default=10, help="gaps from 0 to 45 mm")
    ap.add_argument("--k", type=float, default=1e9, help="contact stiffness, N/m")
    ap.add_argument("--repeat", type=int, default=5, help="pound sweeps timed (runs/s median)")
    ap.add_argument("--timing-runs", type=int, default=2000, help="runs in each timed pound sweep")
    a = ap.parse_args()
    import openseespy.opensees as ops

    records = os.environ.get("POUND_RECORDS_DIR", "../shared/records")
    path = os.path.join(records, a.record)
    dt_rec, acc_g = read_at2(path)
    scale = a.pga_g / max(abs(x) for x in acc_g)
    ag = [x * scale * G for x in acc_g]  # m/s2
    duration = len(ag) * dt_rec
    gaps = [0.045 * i / max(a.gaps - 1, 1) for i in range(a.gaps)]

    def building(m, period, xi):
        w = 2 * math.pi / period
        k = m * w * w
        return {"m": m, "k": k, "c": 2 * xi * math.sqrt(k * m), "T": period, "xi": xi}

    b1, b2 = building(1e5, 0.5, 0.05), building(1e5, 1.2, 0.05)
    def config(gap_list):
        return f"""[run]
tail_s = 0.0

[building1]
mass_kg = {b1['m']}
period_s = {b1['T']}
damping_ratio = {b1['xi']}

[building2]
mass_kg = {b2['m']}
period_s = {b2['T']}
damping_ratio = {b2['xi']}

[contact]
law = "linear"
k_n_per_m = {a.k}
gap_m = [{", ".join(repr(g) for g in gap_list)}]

[[record]]
file = "{os.path.abspath(path)}"

[intensity]
pga_g = {a.pga_g}
"""
    with tempfile.TemporaryDirectory() as tmp:
        cfg = os.path.join(tmp, "peer.toml")
        with open(cfg, "w") as f:
            f.write(config(gaps))
        _, truth = pound_sweep(a.pound, cfg, os.path.join(tmp, "reference.csv"), "reference")
        _, fast = pound_sweep(a.pound, cfg, os.path.join(tmp, "fast.csv"), "fast")
        # Speed on a sweep long enough that process start and reading the record do not count:
        # the same scene at `--timing-runs` gaps over the same range.
        timing = os.path.join(tmp, "timing.toml")
        m = a.timing_runs
        with open(timing, "w") as f:
            f.write(config([0.045 * i / (m - 1) for i in range(m)]))
        times = [
            pound_sweep(a.pound, timing, os.path.join(tmp, f"timing{i}.csv"), "fast")[0]
            for i in range(a.repeat)
        ]
        pound_rate = m / sorted(times)[len(times) // 2]

        t = time.perf_counter()
        opensees = {
            g: opensees_peak_force(ops, tmp, b1, b2, g, a.k, ag, dt_rec, a.dt, duration)
            for g in gaps
        }
        os_rate = len(gaps) / (time.perf_counter() - t)

    n = len(gaps)
    rows = [
        (f"pound fast (1 thread, median of {a.repeat} sweeps of {m} runs)", pound_rate, *errors(fast, truth)),
        (f"OpenSees (openseespy {version('openseespy')}), Newmark dt {a.dt:g}", os_rate, *errors(opensees, truth)),
    ]
    print(f"Scene: {a.record} at {a.pga_g} g ({duration:.1f} s), SDOF 0.5 s and 1.2 s (1e5 kg, 5 %),")
    print(f"linear contact k = {a.k:g} N/m, {n} gaps 0-45 mm; truth: pound reference (tol 1e-8).")
    print()
    print("| solver | runs/s per core | peak force error median | max |")
    print("|---|---:|---:|---:|")
    for name, rate, med, mx in rows:
        print(f"| {name} | {rate:.1f} | {med:.1e} | {mx:.1e} |")
    print()
    print(f"pound / OpenSees runs per second: {rows[0][1] / rows[1][1]:.0f}x")


if __name__ == "__main__":
    sys.exit(main())
