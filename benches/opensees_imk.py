#!/usr/bin/env python3
"""Cross-check of the IMK storey (physics.md section 13) against OpenSees' IMKBilin and
IMKPeakOriented: writes tests/data/opensees_imk.toml, which the test
`hysteresis::opensees_peaks_past_capping` compares `pound hysteresis storey` with.

One storey spring (a zeroLength element, node 1 fixed, node 2 free in x) driven quasi-statically
(DisplacementControl, Newton, NormDispIncr 1e-12) through cyclic drift protocols in steps of
0.05 mm, and again in 0.1 mm steps so the file states OpenSees' own step error. `pound
hysteresis storey` runs the same storey and protocol (its loop is exact: every branch is linear
and each change of branch is located); the two are compared at each protocol target (the
peaks), as |F_pound - F_OpenSees| / F_y.

The storey: k 2e7 N/m, h 3 m, theta_y 0.005, b 0.03, theta_p 0.02, theta_pc 0.08, kappa 0.2,
theta_u 0.15, gamma 50 (pound's default storey), changed per case. Arguments (IMKBilin.cpp
:50-92, IMKPeakOriented.cpp :50-93; their meaning from the code, docs/collapse.md "IMK storeys:
the OpenSees cross-check"):
    Ke = k, Fy = k theta_y h, Up = theta_p h, Upc = theta_pc h, Uu = theta_u h,
    FcapFy = 1 + b theta_p / theta_y, FresFy = kappa, Lamda{S,C,K} = gamma theta_y h (m;
    E_t = Lamda Fy), LamdaA = 0 (PeakOriented), c = 1, D = 1; no cyclic deterioration: every
    Lamda 0 (with c = 1 the factor is clamped to 0, IMKBilin.cpp:168-175).

Cases:
  below_capping         +-0.012 (below capping at 0.025) for 6 cycles, gamma 50
  below_capping_no_e    the same with no cyclic deterioration (gamma none, Lamda 0)
  past_capping          0.01, 0.02, 0.03, 0.04, two cycles each (pound's default protocol)
  residual              0.02, 0.06, 0.10, 0.14, one cycle each, gamma none: onto the residual
                        plateau (0.0907 on the undeteriorated backbone) without reaching theta_u
  residual_gamma        0.02, 0.06, 0.10, one cycle each, gamma 200
  zero_strength         kappa 0, 0.03, 0.06, 0.12, one cycle each, gamma none: the post-capping
                        line reaches zero strength (0.105) on the way to 0.12
  energy_spent          gamma 10, +-0.03 for 3 cycles: the first half cycle's energy exceeds
                        what is left of E_t (beta > 1): no strength in either direction, in
                        OpenSees (Failure_State 5 / Failure_Flag) as in pound
each with both rules.

Set-up (as the other OpenSees scripts; openseespy 3.7.1.2, whose IMK sources are identical to
3.8.0's, runs on Python 3.11), from the repository root, after `cargo build --release`:
    /tmp/ospy/bin/python benches/opensees_imk.py [--pound target/release/pound]
"""

import argparse
import importlib.metadata
import csv
import io
import os
import subprocess
import sys

import openseespy.opensees as ops

BASE = dict(k=2.0e7, h=3.0, thy=0.005, b=0.03, thp=0.02, thpc=0.08, kap=0.2, thu=0.15, gam=50.0)

# name, changes to BASE, amplitudes (drift ratios), cycles at each
CASES = [
    ("below_capping", {}, [0.012], 6),
    ("below_capping_no_e", {"gam": None}, [0.012], 6),
    ("past_capping", {}, [0.01, 0.02, 0.03, 0.04], 2),
    ("residual", {"gam": None}, [0.02, 0.06, 0.10, 0.14], 1),
    ("residual_gamma", {"gam": 200.0}, [0.02, 0.06, 0.10], 1),
    ("zero_strength", {"kap": 0.0, "gam": None}, [0.03, 0.06, 0.12], 1),
    ("energy_spent", {"gam": 10.0}, [0.03], 3),
]
RULES = [("imk_bilinear", "IMKBilin"), ("imk_peak_oriented", "IMKPeakOriented")]
STEP_FINE = 5e-5
STEP_COARSE = 1e-4


def args_for(mat, s):
    """The material's arguments for storey `s` (the mapping in the docstring)."""
    k, h = s["k"], s["h"]
    fy = k * s["thy"] * h
    up, upc, uu = s["thp"] * h, s["thpc"] * h, s["thu"] * h
    fcapfy = 1.0 + s["b"] * s["thp"] / s["thy"]
    lam = 0.0 if s["gam"] is None else s["gam"] * s["thy"] * h
    side = [up, upc, uu, fy, fcapfy, s["kap"]]
    if mat == "IMKBilin":
        return [k] + side + side + [lam, lam, lam, 1.0, 1.0, 1.0, 1.0, 1.0]
    return [k] + side + side + [lam, lam, 0.0, lam, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0]


def targets(amplitudes, cycles):
    """The protocol's drift ratios, as `pound hysteresis storey` visits them."""
    out = []
    for a in amplitudes:
        out += [a, -a] * cycles
    return out + [0.0]


def opensees(mat, s, path, step):
    """The spring force at each target drift (m) of `path`, in steps of at most `step` m."""
    ops.wipe()
    ops.model("basic", "-ndm", 1, "-ndf", 1)
    ops.node(1, 0.0)
    ops.node(2, 0.0)
    ops.fix(1, 1)
    ops.uniaxialMaterial(mat, 1, *args_for(mat, s))
    ops.element("zeroLength", 1, 1, 2, "-mat", 1, "-dir", 1)
    ops.timeSeries("Linear", 1)
    ops.pattern("Plain", 1, 1)
    ops.load(2, 1.0)
    ops.constraints("Plain")
    ops.numberer("Plain")
    ops.system("BandGeneral")
    ops.test("NormDispIncr", 1e-12, 50)
    ops.algorithm("Newton")
    u, out = 0.0, []
    for target in path:
        n = max(1, int(round(abs(target - u) / step)))
        ops.integrator("DisplacementControl", 2, 1, (target - u) / n)
        ops.analysis("Static")
        for _ in range(n):
            if ops.analyze(1) != 0:
                raise RuntimeError(f"{mat}: no convergence on the way to {target}")
        out.append(ops.eleResponse(1, "material", 1, "stress")[0])
        u = target
    return out


def flags(rule, s, amplitudes, cycles):
    """`pound hysteresis storey`'s flags for the case."""
    gam = "none" if s["gam"] is None else repr(s["gam"])
    return [
        "--hysteresis", rule,
        "--stiffness", repr(s["k"]), "--height", repr(s["h"]),
        "--yield-drift-ratio", repr(s["thy"]), "--post-yield-ratio", repr(s["b"]),
        "--plastic-drift-ratio", repr(s["thp"]), "--post-capping-drift-ratio", repr(s["thpc"]),
        "--residual-strength-ratio", repr(s["kap"]), "--ultimate-drift-ratio", repr(s["thu"]),
        "--energy-capacity-ratio", gam,
        "--amplitudes", ",".join(repr(a) for a in amplitudes), "--cycles", str(cycles),
    ]


def pound(binary, fl, tmp):
    """pound's force at each protocol target (N)."""
    out, plot = os.path.join(tmp, "l.csv"), os.path.join(tmp, "l.svg")
    subprocess.run([binary, "hysteresis", "storey", *fl, "-o", out, "--plot", plot],
                   check=True, capture_output=True)
    with open(out) as f:
        rows = list(csv.DictReader(f))
    return [float(r["shear_n"]) for r in rows if r["point"] == "target"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--pound", default="target/release/pound")
    ap.add_argument("--out", default="tests/data/opensees_imk.toml")
    a = ap.parse_args()
    import tempfile

    toml = io.StringIO()
    toml.write("# Written by benches/opensees_imk.py (see its docstring for the mapping).\n")
    toml.write(f"# openseespy {importlib.metadata.version('openseespy')}, "
               f"DisplacementControl steps {STEP_FINE} m and {STEP_COARSE} m.\n")
    toml.write(f"step_m = {STEP_FINE!r}\nstep_coarse_m = {STEP_COARSE!r}\n")
    print("| case | rule | peaks | max |dF|/F_y pound vs OpenSees | OpenSees 0.1 mm vs 0.05 mm | worst peak (target, pound, OpenSees) |")
    print("|---|---|---:|---:|---:|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for name, change, amplitudes, cycles in CASES:
            s = dict(BASE, **change)
            fy = s["k"] * s["thy"] * s["h"]
            path = targets(amplitudes, cycles)
            for rule, mat in RULES:
                fine = opensees(mat, s, [x * s["h"] for x in path], STEP_FINE)
                coarse = opensees(mat, s, [x * s["h"] for x in path], STEP_COARSE)
                fl = flags(rule, s, amplitudes, cycles)
                ours = pound(a.pound, fl, tmp)
                assert len(ours) == len(fine), (name, rule, len(ours), len(fine))
                diffs = [abs(p - o) / fy for p, o in zip(ours, fine)]
                own = max(abs(c - f) / fy for c, f in zip(coarse, fine))
                i = max(range(len(diffs)), key=lambda j: diffs[j])
                print(f"| {name} | {rule} | {len(path)} | {max(diffs):.2e} | {own:.2e} | "
                      f"{path[i]}: {ours[i]:.1f}, {fine[i]:.1f} |")
                sys.stdout.flush()
                toml.write(f"\n[[case]]\nname = \"{name}\"\nrule = \"{rule}\"\n")
                toml.write("flags = [" + ", ".join(f'"{x}"' for x in fl) + "]\n")
                toml.write(f"fy_n = {fy!r}\n")
                toml.write("targets = [" + ", ".join(repr(x) for x in path) + "]\n")
                toml.write("opensees_n = [" + ", ".join(repr(x) for x in fine) + "]\n")
                toml.write("opensees_coarse_n = [" + ", ".join(repr(x) for x in coarse) + "]\n")
                toml.write(f"max_diff_over_fy = {max(diffs)!r}\n")
    with open(a.out, "w") as f:
        f.write(toml.getvalue())
    print(f"wrote {a.out}", file=sys.stderr)


if __name__ == "__main__":
    main()
