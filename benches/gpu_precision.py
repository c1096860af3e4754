#!/usr/bin/env python3
"""What GPU arithmetic adds, per scene kind: each config swept on the CPU (f64, the reference
of this comparison) and on the GPU in f32 and f64, compared run by run.

    POUND_RECORDS_DIR=../shared/records python3 benches/gpu_precision.py [POUND] [CONFIG ...]

Prints, per config and precision: the peak force's relative difference (median, p99, max over
the runs that pounded), the largest relative difference of a peak roof displacement and of a
peak drift ratio, and the runs whose impact count or collapse differs. Standard library only.
"""
import csv
import os
import subprocess
import sys
import tempfile

CONFIGS = [
    "quickstart",  # pairs of one-storey buildings
    "row-3-6",  # elastic rows, 3 beside 6 storeys
    "row-of-three",  # three buildings, nonlinear viscoelastic
    "inelastic-pair",  # yielding storeys
    "inelastic-fragility",  # yielding storeys on real records
    "floor-column",  # floors that strike columns, yielding storeys
    "collapse-fragility",  # P-Delta and collapse
]


def load(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def quantile(v, p):
    v = sorted(v)
    return v[min(len(v) - 1, int(p * (len(v) - 1) + 0.5))] if v else float("nan")


def rel(a, b):
    return abs(float(a) - float(b)) / abs(float(b))


def compare(got, ref):
    force, roof, drift, impacts, collapse = [], [], [], 0, 0
    for a, b in zip(got, ref, strict=True):
        impacts += a["impacts"] != b["impacts"]
        flags = [k for k in b if k.endswith("collapsed")] + ["status"]
        collapse += any(a[k] != b[k] for k in flags)
        if float(b["peak_force_n"] or 0) > 0:
            force.append(rel(a["peak_force_n"], b["peak_force_n"]))
        for k in b:
            peak = k.endswith(("peak_roof_m", "peak_drift_ratio")) or k in ("peak_u1_m", "peak_u2_m")
            if not (peak and a.get(k) and b[k] and float(b[k]) != 0):
                continue
            (drift if k.endswith("peak_drift_ratio") else roof).append(rel(a[k], b[k]))
    return force, roof, drift, impacts, collapse


def main():
    args = sys.argv[1:]
    pound = args.pop(0) if args and not args[0].endswith(".toml") and "/" in args[0] else "target/release/pound"
    configs = args or [f"configs/{c}.toml" for c in CONFIGS]
    with tempfile.TemporaryDirectory() as d:
        for cfg in configs:
            name = os.path.splitext(os.path.basename(cfg))[0]
            out = {}
            for tag, flags in (("cpu", ["--backend", "cpu"]), ("f32", ["--backend", "gpu", "--precision", "f32"]), ("f64", ["--backend", "gpu", "--precision", "f64"])):
                out[tag] = os.path.join(d, f"{name}-{tag}.csv")
                subprocess.run([pound, "sweep", cfg, "-o", out[tag], *flags], check=True, stderr=subprocess.DEVNULL)
            ref = load(out["cpu"])
            for tag in ("f32", "f64"):
                force, roof, drift, impacts, collapse = compare(load(out[tag]), ref)
                print(
                    f"{name:20s} {tag} {len(ref):5d} runs | peak force median {quantile(force, 0.5):.1e} "
                    f"p99 {quantile(force, 0.99):.1e} max {max(force, default=0):.1e} | roof max "
                    f"{max(roof, default=0):.1e} | drift max {max(drift, default=0):.1e} | impact counts "
                    f"differ {impacts} | collapse differs {collapse}",
                    flush=True,
                )


if __name__ == "__main__":
    main()
