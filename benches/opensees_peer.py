#!/usr/bin/env python3
"""Peer comparison: the same two-building pounding scene in OpenSees and in `pound`.

Both solve two SDOF buildings (explicit dashpots, no Rayleigh damping) under one real record
over a sweep of gaps, on one of two contact laws both codes have:
- `linear` (default scene: Loma Prieta Corralitos at 0.35 g, T 0.5 s and 1.2 s, gaps 0-45 mm):
  a linear compression-only spring (`ElasticPPGap` in OpenSees);
- `nonlinear_viscoelastic` (the seed's eq. 9, Jankowski's law; default scene: Kobe JMA, 0-20 s,
  at 0.5 g, T 0.5 s and 0.8 s, gaps 0-20 mm, beta 2.75e9 N/m^1.5, e 0.65 through Jankowski's
  formula): `JankowskiImpact` in OpenSees (Kh = beta, xi = the formula's zeta, the same m_eff,
  n = 1.5).
The truth is `pound`'s reference scheme (adaptive Dormand-Prince, events located, tol 1e-8).
Reported per solver: runs per second on one core and the relative peak-force error against
that truth (median and max over the gaps). OpenSees' peak is the largest force at its steps;
`pound` is run at its default accuracy setting and at each of `--settings`.

Set-up (OpenSees 3.8 needs Python 3.12), from the repository root:
    PYENV_VERSION=3.12.1 python3.12 -m venv /tmp/ospy && /tmp/ospy/bin/pip install openseespy
    cargo build --release
    /tmp/ospy/bin/python benches/opensees_peer.py [--law nonlinear_viscoelastic] [--dt 1e-3]
        [--gaps 10] [--record FILE] [--settings 8,16]

Records are read from POUND_RECORDS_DIR (default ../shared/records), never copied.
"""

import argparse
import csv
import math
import os
import re
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
    npts = re.search(r"NPTS\s*=\s*(\d+)", lines[3])
    npts = int(npts.group(1)) if npts else None
    dt = float(re.search(r"DT\s*=\s*([0-9.eE+-]+)", lines[3]).group(1))
    values = [float(x) for line in lines[4:] for x in line.split()]
    return dt, values[:npts] if npts else values


def jankowski_zeta(e):
    """Jankowski's impact damping ratio for a coefficient of restitution (`formula =
    "jankowski"` in pound; Jankowski 2006)."""
    return 9 * math.sqrt(5) * (1 - e * e) / (2 * e * (e * (9 * math.pi - 16) + 16))


def opensees_peak_force(ops, tmp, b1, b2, gap, contact, ag, dt_rec, dt, duration):
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
    if contact["law"] == "linear":
        ops.uniaxialMaterial("ElasticPPGap", 7, contact["k"], -1e30, -gap)
    else:
        # JankowskiImpact's gap must be negative (compression); zero is read as open.
        m_eff = b1["m"] * b2["m"] / (b1["m"] + b2["m"])
        xi = jankowski_zeta(contact["e"])
        ops.uniaxialMaterial("JankowskiImpact", 7, contact["beta"], xi, m_eff, -max(gap, 1e-12), 1.5)
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
    """Run `pound sweep` on one thread; returns (seconds, rows of the output CSV)."""
    cmd = [pound, "sweep", cfg, "--backend", "cpu", "--threads", "1", "-o", out]
    if scheme:
        cmd += ["--scheme", scheme]
    t = time.perf_counter()
    done = subprocess.run(cmd, stderr=subprocess.PIPE, text=True)
    seconds = time.perf_counter() - t
    if done.returncode != 0:
        raise SystemExit(f"pound sweep {cfg} failed:\n{done.stderr.strip()}")
    with open(out) as f:
        return seconds, list(csv.DictReader(f))


def peak_forces(rows):
    return {float(r["gap_m"]): float(r["peak_force_n"]) for r in rows}


def errors(got, truth):
    """Median and max relative peak-force error over the gaps where the truth pounds; a
    comparison over no pounding run is an error, not a zero."""
    e = sorted(abs(got[g] - truth[g]) / truth[g] for g in truth if truth[g] > 0)
    if not e:
        raise SystemExit("no gap of the scene pounds: nothing to compare")
    return e[len(e) // 2], e[-1]


SCENES = {
    "linear": {
        "record": "lomaprieta1989_corralitos_ns_RSN753_CLS000.AT2",
        "window": None,
        "pga_g": 0.35,
        "periods": (0.5, 1.2),
        "max_gap": 0.045,
    },
    "nonlinear_viscoelastic": {
        "record": "kobe1995_jma_ns_RSN1106_KJM000.AT2",
        "window": (0.0, 20.0),
        "pga_g": 0.5,
        "periods": (0.5, 0.8),
        "max_gap": 0.02,
    },
}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--pound", default="target/release/pound")
    ap.add_argument("--law", choices=sorted(SCENES), default="linear")
    ap.add_argument("--record", help="AT2 file name (default: the law's scene)")
    ap.add_argument("--pga-g", type=float, help="(default: the law's scene)")
    ap.add_argument("--dt", type=float, default=1e-3, help="OpenSees time step, s")
    ap.add_argument("--gaps", type=int, default=10, help="gaps from 0 to the scene's largest")
    ap.add_argument("--k", type=float, default=1e9, help="linear contact stiffness, N/m")
    ap.add_argument("--beta", type=float, default=2.75e9, help="Hertz stiffness, N/m^1.5")
    ap.add_argument("--e", type=float, default=0.65, help="coefficient of restitution")
    ap.add_argument("--settings", default="", help="pound substeps per contact to add, e.g. 8,16")
    ap.add_argument("--repeat", type=int, default=5, help="pound sweeps timed (runs/s median)")
    ap.add_argument("--timing-runs", type=int, default=2000, help="runs in each timed pound sweep")
    a = ap.parse_args()
    import openseespy.opensees as ops

    scene = SCENES[a.law]
    record = a.record or scene["record"]
    pga_g = a.pga_g if a.pga_g is not None else scene["pga_g"]
    records = os.environ.get("POUND_RECORDS_DIR", "../shared/records")
    path = os.path.join(records, record)
    if not os.path.isfile(path):
        raise SystemExit(f"{path}: no such record (records are read from POUND_RECORDS_DIR, default ../shared/records)")
    if not os.path.isfile(a.pound):
        raise SystemExit(f"{a.pound}: no pound binary (run from the repository root after cargo build --release, or pass --pound)")
    dt_rec, acc_g = read_at2(path)
    if scene["window"] and not a.record:
        lo, hi = scene["window"]
        acc_g = acc_g[int(round(lo / dt_rec)) : int(round(hi / dt_rec))]
    duration = len(acc_g) * dt_rec
    max_gap = scene["max_gap"]
    gaps = [max_gap * i / max(a.gaps - 1, 1) for i in range(a.gaps)]
    contact = {"law": a.law, "k": a.k, "beta": a.beta, "e": a.e}

    def building(m, period, xi):
        w = 2 * math.pi / period
        k = m * w * w
        return {"m": m, "k": k, "c": 2 * xi * math.sqrt(k * m), "T": period, "xi": xi}

    b1, b2 = (building(1e5, t, 0.05) for t in scene["periods"])
    if a.law == "linear":
        contact_keys = f'law = "linear"\nk_n_per_m = {a.k}'
    else:
        contact_keys = (
            f'law = "nonlinear_viscoelastic"\nformula = "jankowski"\ne = {a.e}\n'
            f"beta_n_per_m1_5 = {a.beta}"
        )
    window = (
        f"window_s = [{scene['window'][0]}, {scene['window'][1]}]"
        if scene["window"] and not a.record
        else ""
    )

    def config(gap_list, substeps=None):
        run = f"substeps_per_contact = {substeps}\n" if substeps else ""
        return f"""[run]
tail_s = 0.0
{run}
[building1]
mass_kg = {b1['m']}
period_s = {b1['T']}
damping_ratio = {b1['xi']}

[building2]
mass_kg = {b2['m']}
period_s = {b2['T']}
damping_ratio = {b2['xi']}

[contact]
{contact_keys}
gap_m = [{", ".join(repr(g) for g in gap_list)}]

[[record]]
file = "{os.path.abspath(path)}"
{window}

[intensity]
pga_g = {pga_g}
"""

    settings = [None] + [float(x) for x in a.settings.split(",") if x]
    results = []
    with tempfile.TemporaryDirectory() as tmp:
        cfg = os.path.join(tmp, "peer.toml")
        with open(cfg, "w") as f:
            f.write(config(gaps))
        _, reference = pound_sweep(a.pound, cfg, os.path.join(tmp, "reference.csv"), "reference")
        truth = peak_forces(reference)
        # OpenSees gets the record at the factor pound applied (PGA of the windowed record).
        scale = float(reference[0]["scale_factor"])
        ag = [x * scale * G for x in acc_g]  # m/s2
        # Speed on a sweep long enough that process start and reading the record do not count:
        # the same scene at `--timing-runs` gaps over the same range.
        m = a.timing_runs
        for s in settings:
            with open(cfg, "w") as f:
                f.write(config(gaps, s))
            _, fast = pound_sweep(a.pound, cfg, os.path.join(tmp, "fast.csv"), "fast")
            timing = os.path.join(tmp, "timing.toml")
            with open(timing, "w") as f:
                f.write(config([max_gap * i / (m - 1) for i in range(m)], s))
            times = [
                pound_sweep(a.pound, timing, os.path.join(tmp, f"timing{i}.csv"), "fast")[0]
                for i in range(a.repeat)
            ]
            name = "default setting" if s is None else f"{s:g} substeps/contact"
            results.append(
                (
                    f"pound fast, {name} (1 thread, median of {a.repeat} sweeps of {m} runs)",
                    m / sorted(times)[len(times) // 2],
                    *errors(peak_forces(fast), truth),
                )
            )

        t = time.perf_counter()
        opensees = {
            g: opensees_peak_force(ops, tmp, b1, b2, g, contact, ag, dt_rec, a.dt, duration)
            for g in gaps
        }
        os_rate = len(gaps) / (time.perf_counter() - t)
    results.append(
        (
            f"OpenSees (openseespy {version('openseespy')}), Newmark dt {a.dt:g}",
            os_rate,
            *errors(opensees, truth),
        )
    )

    n = len(gaps)
    law = (
        f"linear contact k = {a.k:g} N/m"
        if a.law == "linear"
        else f"nonlinear viscoelastic contact beta = {a.beta:g} N/m^1.5, e = {a.e} (Jankowski's zeta "
        f"{jankowski_zeta(a.e):.4f}; JankowskiImpact in OpenSees)"
    )
    span = f" (window {scene['window'][0]:g}-{scene['window'][1]:g} s)" if window else ""
    print(f"Scene: {record}{span} at {pga_g} g ({duration:.1f} s), SDOF {b1['T']} s and {b2['T']} s (1e5 kg, 5 %),")
    print(f"{law}, {n} gaps 0-{max_gap * 1000:g} mm; truth: pound reference (tol 1e-8).")
    print()
    print("| solver | runs/s per core | peak force error median | max | pound / OpenSees |")
    print("|---|---:|---:|---:|---:|")
    for name, rate, med, mx in results:
        print(f"| {name} | {rate:.1f} | {med:.1e} | {mx:.1e} | {rate / os_rate:.0f}x |")


if __name__ == "__main__":
    sys.exit(main())
