#!/usr/bin/env python3
"""Cross-check of yielding storeys against OpenSees: writes tests/data/opensees_inelastic.toml,
which the test `inelastic::opensees_cross_check` compares `pound`'s row schemes with.

Three scenes on real records other than any the issues or the elastic cross-check use, scaled
to a PGA, each followed by a free tail (ground at rest) long enough for the motion to decay:
  D  a pair of one-storey buildings: elastic-perfectly-plastic beside 5 % hardening, El Centro
     1940 (RSN6, the first 15 s)
  E  a 3-storey frame with a soft first storey (b = 0.02) beside an elastic 5-storey, Tabas
     1978 L1 (the first 16 s)
  F  a row of three: a yielding 2-storey, an elastic 4-storey, a yielding 3-storey (b = 0.05),
     Tabas 1978 T1 (the first 16 s)

Conventions (the same in `pound`, docs/inelastic.md):
  - shear buildings: lumped floor masses, storey springs between floor j-1 and j (floor 0 is the
    ground, fixed), displacements relative to the ground, building 1 on the left;
  - storey j: `Steel01 F_y,j k_j b_j` (bilinear, kinematic hardening, no isotropic hardening);
  - Rayleigh damping on the initial stiffness, C = a0 M + a1 K0 with 5 % on modes 1 and 2 of the
    initial stiffness, built from explicit dashpots (a0 m_j from each floor to a fixed point,
    a1 k_j across each storey, beside its Steel01 spring), so no OpenSees damping option is
    involved;
  - contact at every floor level two neighbours share: a linear compression-only spring
    (`ElasticPPGap`, `law = "linear"` in pound), one gap per pair;
  - the ground motion: the record's samples linearly interpolated (`Path` time series).

OpenSees integrates with Newmark average acceleration (Newton, NormDispIncr 1e-12) at two steps
(dt and dt / 2) so the file states its own error. Peaks are over the recorded steps. Residual
drift: each storey's drift at the end of the free tail. Reported per building: peak
interstorey drift ratio, residual drift ratio (largest over storeys, signed values per storey
too) and per level the peak contact force.

Set-up (OpenSees 3.8 needs Python 3.12), from the repository root:
    PYENV_VERSION=3.12.1 python3.12 -m venv /tmp/ospy && /tmp/ospy/bin/pip install openseespy numpy
    /tmp/ospy/bin/python benches/opensees_inelastic.py [--dt 2e-4]

Records are read from POUND_RECORDS_DIR (default ../shared/records), never copied.
"""

import argparse
import os
import sys
import tempfile
import time
from importlib.metadata import version

import numpy as np

# The elastic cross-check's record reader, Rayleigh coefficients (5 % on the initial modes 1 and
# 2), shared floor levels and TOML lists.
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from opensees_multistorey import G, K_CONTACT, XI, levels, rayleigh, read_at2, toml_list  # noqa: E402

TAIL_S = 30.0


def read_time_acc(path):
    """Two columns "time,acc" (g), no header, evenly spaced from t = dt."""
    rows = [tuple(map(float, line.split(","))) for line in open(path) if line.strip()]
    dt = rows[1][0] - rows[0][0]
    return dt, [a for _, a in rows]


def building(masses, stiffness, heights, fy, b):
    """fy: yield force per storey (None: elastic), b: post-yield ratio per storey."""
    return {"masses": masses, "stiffness": stiffness, "heights": heights, "fy": fy, "b": b}


SCENES = [
    {
        "name": "D_pair_epp_and_hardening",
        "record": "elcentro1940_ns_RSN6_I-ELC180.AT2",
        "seconds": 15.0,
        "pga_g": 0.5,
        "buildings": [
            building([3.0e5], [1.2e8], [3.5], [0.12 * G * 3.0e5], [0.0]),
            building([2.0e5], [2.0e8], [3.5], [2.0e8 * 0.004 * 3.5], [0.05]),
        ],
        "gaps": [0.015],
    },
    {
        "name": "E_3_soft_yielding_beside_5",
        "record": "tabas1978_tabas_L1_RSN143_TAB-L1_timeacc.csv",
        "seconds": 16.0,
        "pga_g": 0.45,
        "buildings": [
            building(
                [2.8e5, 2.6e5, 2.2e5],
                [1.5e8, 3.5e8, 3.0e8],
                [4.0, 3.2, 3.2],
                [1.5e8 * 0.006 * 4.0, 3.5e8 * 0.006 * 3.2, 3.0e8 * 0.006 * 3.2],
                [0.02, 0.02, 0.02],
            ),
            building([2.4e5] * 5, [4.5e8] * 5, [4.0, 3.2, 3.2, 3.2, 3.2], None, None),
        ],
        "gaps": [0.02],
    },
    {
        "name": "F_row_2y_4_3y",
        "record": "tabas1978_tabas_T1_RSN143_TAB-T1_timeacc.csv",
        "seconds": 16.0,
        "pga_g": 0.4,
        "buildings": [
            building([2.0e5, 1.8e5], [2.2e8, 1.8e8], [3.0, 3.0], [9.0e5, 6.5e5], [0.0, 0.0]),
            building([2.5e5] * 4, [4.0e8] * 4, [3.0] * 4, None, None),
            building(
                [2.2e5, 2.2e5, 1.8e5],
                [2.6e8, 2.4e8, 2.0e8],
                [3.0] * 3,
                [2.6e8 * 0.005 * 3.0, 2.4e8 * 0.005 * 3.0, 2.0e8 * 0.005 * 3.0],
                [0.05, 0.05, 0.05],
            ),
        ],
        "gaps": [0.012, 0.01],
    },
]


def run_opensees(ops, tmp, scene, ag, dt_rec, dt, duration, tail=TAIL_S):
    ops.wipe()
    ops.model("basic", "-ndm", 1, "-ndf", 1)
    tags = iter(range(1, 1_000_000))
    floor_nodes = []
    for b in scene["buildings"]:
        a0, a1 = rayleigh(b)
        ground = next(tags)
        ops.node(ground, 0.0)
        ops.fix(ground, 1)
        nodes = []
        below = ground
        for j, (mj, kj) in enumerate(zip(b["masses"], b["stiffness"])):
            node = next(tags)
            ops.node(node, 0.0)
            ops.mass(node, mj)
            nodes.append(node)
            spring, dashpot, storey = next(tags), next(tags), next(tags)
            if b["fy"] is None:
                ops.uniaxialMaterial("Elastic", spring, kj)
            else:
                ops.uniaxialMaterial("Steel01", spring, b["fy"][j], kj, b["b"][j])
            ops.uniaxialMaterial("Viscous", dashpot, a1 * kj, 1.0)
            ops.uniaxialMaterial("Parallel", storey, spring, dashpot)
            ops.element("zeroLength", next(tags), below, node, "-mat", storey, "-dir", 1)
            anchor, mass_dashpot = next(tags), next(tags)
            ops.node(anchor, 0.0)
            ops.fix(anchor, 1)
            ops.uniaxialMaterial("Viscous", mass_dashpot, a0 * mj, 1.0)
            ops.element("zeroLength", next(tags), anchor, node, "-mat", mass_dashpot, "-dir", 1)
            below = node
        floor_nodes.append(nodes)
    contact_eles = []
    for a, fa, fb in levels(scene):
        gap_mat, ele = next(tags), next(tags)
        ops.uniaxialMaterial("ElasticPPGap", gap_mat, K_CONTACT, -1e30, -scene["gaps"][a])
        ops.element("zeroLength", ele, floor_nodes[a][fa], floor_nodes[a + 1][fb], "-mat", gap_mat, "-dir", 1)
        contact_eles.append(ele)
    # The record, then the ground at rest through the tail.
    values = list(ag) + [0.0, 0.0]
    ops.timeSeries("Path", 1, "-dt", dt_rec, "-values", *values, "-factor", 1.0)
    ops.pattern("UniformExcitation", 1, 1, "-accel", 1)
    ops.constraints("Plain")
    ops.numberer("RCM")
    ops.system("BandGeneral")
    ops.test("NormDispIncr", 1e-12, 50)
    ops.algorithm("Newton")
    ops.integrator("Newmark", 0.5, 0.25)
    ops.analysis("Transient")
    all_nodes = [n for ns in floor_nodes for n in ns]
    disp = os.path.join(tmp, "disp.txt")
    force = os.path.join(tmp, "force.txt")
    ops.recorder("Node", "-file", disp, "-precision", 14, "-node", *all_nodes, "-dof", 1, "disp")
    ops.recorder("Element", "-file", force, "-precision", 14, "-ele", *contact_eles, "force")
    steps = int(round((duration + tail) / dt))
    if ops.analyze(steps, dt) != 0:
        raise RuntimeError(f"OpenSees failed on {scene['name']}")
    ops.wipe()
    u = np.loadtxt(disp, ndmin=2)
    f = np.loadtxt(force, ndmin=2)
    forces = [float(np.max(np.abs(f[:, 2 * i]))) for i in range(len(contact_eles))]
    drifts, residuals = [], []
    col = 0
    for b in scene["buildings"]:
        n = len(b["masses"])
        ub = u[:, col : col + n]
        col += n
        below = np.hstack([np.zeros((ub.shape[0], 1)), ub[:, :-1]])
        ratio = (ub - below) / np.array(b["heights"])
        drifts.append(float(np.max(np.abs(ratio))))
        residuals.append([float(x) for x in ratio[-1, :]])
    return forces, drifts, residuals


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--dt", type=float, default=2e-4, help="OpenSees time step, s (and half of it)")
    ap.add_argument("-o", default="tests/data/opensees_inelastic.toml")
    a = ap.parse_args()
    import openseespy.opensees as ops

    records = os.environ.get("POUND_RECORDS_DIR", "../shared/records")
    lines = [
        "# Written by benches/opensees_inelastic.py (see its docstring for the conventions).",
        f"# openseespy {version('openseespy')}, Newmark average acceleration at dt and dt / 2.",
        f"contact_k_n_per_m = {K_CONTACT!r}",
        f"damping_ratio = {XI!r}",
        f"tail_s = {TAIL_S!r}",
        f"dt_fine_s = {a.dt / 2!r}",
        f"dt_coarse_s = {a.dt!r}",
        "",
    ]
    with tempfile.TemporaryDirectory() as tmp:
        for scene in SCENES:
            path = os.path.join(records, scene["record"])
            dt_rec, acc_g = read_at2(path) if path.endswith(".AT2") else read_time_acc(path)
            npts = min(len(acc_g), int(round(scene["seconds"] / dt_rec)) + 1)
            acc_g = acc_g[:npts]
            ipga = max(range(npts), key=lambda i: abs(acc_g[i]))
            scale = scene["pga_g"] / abs(acc_g[ipga])
            ag = [x * scale * G for x in acc_g]
            duration = (npts - 1) * dt_rec
            results = {}
            for dt in (a.dt, a.dt / 2):
                t = time.perf_counter()
                results[dt] = run_opensees(ops, tmp, scene, ag, dt_rec, dt, duration)
                print(f"{scene['name']}: dt {dt:g}: {time.perf_counter() - t:.1f} s", file=sys.stderr)
            coarse, fine = results[a.dt], results[a.dt / 2]
            lines += [
                "[[scene]]",
                f'name = "{scene["name"]}"',
                f'record = "{scene["record"]}"',
                f"npts = {npts}",
                f"scale = {scale!r}",
                f"gaps_m = {toml_list(scene['gaps'])}",
                f"peak_force_n = {toml_list(fine[0])}",
                f"peak_force_n_coarse = {toml_list(coarse[0])}",
                f"peak_drift_ratio = {toml_list(fine[1])}",
                f"peak_drift_ratio_coarse = {toml_list(coarse[1])}",
            ]
            for b, r, rc in zip(scene["buildings"], fine[2], coarse[2]):
                lines += [
                    "[[scene.building]]",
                    f"masses_kg = {toml_list(b['masses'])}",
                    f"stiffness_n_per_m = {toml_list(b['stiffness'])}",
                    f"heights_m = {toml_list(b['heights'])}",
                ]
                if b["fy"] is not None:
                    lines += [
                        f"yield_force_n = {toml_list(b['fy'])}",
                        f"post_yield_ratio = {toml_list(b['b'])}",
                        f"residual_drift_ratio = {toml_list(r)}",
                        f"residual_drift_ratio_coarse = {toml_list(rc)}",
                    ]
            lines.append("")
    os.makedirs(os.path.dirname(a.o), exist_ok=True)
    with open(a.o, "w") as f:
        f.write("\n".join(lines))
    print(f"wrote {a.o}", file=sys.stderr)


if __name__ == "__main__":
    sys.exit(main())
