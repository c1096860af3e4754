#!/usr/bin/env python3
"""Cross-check of multi-storey pounding against OpenSees: writes tests/data/opensees_multistorey.toml,
which the test `multistorey::opensees_cross_check` compares `pound`'s row schemes with.

Three scenes, each on the first seconds of a real record (to 6 s past its PGA) scaled to a PGA:
  A  4-storey beside 7-storey (uniform), Kobe JMA NS
  B  2-storey beside 5-storey with a soft first storey, Loma Prieta Corralitos
  C  a row of four: 3, 6, 4 and 2 storeys, San Fernando Pacoima 164

Conventions (the same in `pound`):
  - shear buildings: lumped floor masses, storey springs k_j between floor j-1 and j (floor 0 is
    the ground, fixed), displacements relative to the ground, building 1 on the left;
  - Rayleigh damping C = a0 M + a1 K with the ratio xi on modes 1 and 2, built here from
    explicit dashpots (a0 m_j from each floor to the ground, a1 k_j across each storey), so no
    OpenSees damping option is involved; modes from numpy's generalized eigensolver;
  - contact at every floor level the two neighbours share (same elevation): a linear
    compression-only spring (`ElasticPPGap`, `law = "linear"` in pound), one gap per pair;
  - the ground motion: the record's samples linearly interpolated (`Path` time series).

OpenSees integrates with Newmark average acceleration at two steps (dt and dt/2) so the file
states its own error. Peaks are over the recorded steps. Reported: peak contact force per level,
peak roof displacement and peak interstorey drift ratio per building.

Set-up (OpenSees 3.8 needs Python 3.12), from the repository root:
    PYENV_VERSION=3.12.1 python3.12 -m venv /tmp/ospy && /tmp/ospy/bin/pip install openseespy numpy
    /tmp/ospy/bin/python benches/opensees_multistorey.py [--dt 1e-4]

Records are read from POUND_RECORDS_DIR (default ../shared/records), never copied.
"""

import argparse
import math
import os
import re
import sys
import tempfile
import time
from importlib.metadata import version

import numpy as np

G = 9.80665
K_CONTACT = 1e9  # N/m
XI = 0.05


def read_at2(path):
    """PEER AT2: four header lines (the fourth gives NPTS and DT, spaced either way), values in g."""
    with open(path) as f:
        lines = f.read().splitlines()
    head = lines[3]
    npts = int(re.search(r"NPTS\s*=\s*(\d+)", head).group(1))
    dt = float(re.search(r"DT\s*=\s*([0-9.Ee+-]+)", head).group(1))
    values = [float(x) for line in lines[4:] for x in line.split()]
    return dt, values[:npts]


def uniform(n, mass, k, h=3.0):
    return {"masses": [mass] * n, "stiffness": [k] * n, "heights": [h] * n}


# Buildings by explicit storey stiffnesses (N/m) and masses (kg).
SCENES = [
    {
        "name": "A_4_beside_7",
        "record": "kobe1995_jma_ns_RSN1106_KJM000.AT2",
        "pga_g": 0.4,
        "buildings": [uniform(4, 2.5e5, 6.0e8, 3.2), uniform(7, 3.0e5, 5.0e8, 3.2)],
        "gaps": [0.02],
    },
    {
        "name": "B_2_beside_5_soft",
        "record": "lomaprieta1989_corralitos_ns_RSN753_CLS000.AT2",
        "pga_g": 0.45,
        "buildings": [
            uniform(2, 2.0e5, 5.0e8, 3.5),
            {
                "masses": [3.0e5, 2.8e5, 2.8e5, 2.8e5, 2.2e5],
                "stiffness": [1.2e8, 4.5e8, 4.0e8, 3.5e8, 3.0e8],
                "heights": [3.5, 3.5, 3.5, 3.5, 3.5],
            },
        ],
        "gaps": [0.01],
    },
    {
        "name": "C_row_3_6_4_2",
        "record": "sanfernando1971_pacoima_RSN77_PUL164.AT2",
        "pga_g": 0.35,
        "buildings": [
            uniform(3, 2.0e5, 4.0e8),
            uniform(6, 3.0e5, 5.5e8),
            uniform(4, 2.5e5, 3.0e8),
            uniform(2, 2.0e5, 6.0e8),
        ],
        "gaps": [0.012, 0.015, 0.01],
    },
]


def rayleigh(b):
    """a0, a1 for the ratio XI on modes 1 and 2 (mode 1 alone for one storey)."""
    n = len(b["masses"])
    k = np.zeros((n, n))
    for j, kj in enumerate(b["stiffness"]):
        k[j, j] += kj
        if j > 0:
            k[j - 1, j - 1] += kj
            k[j - 1, j] -= kj
            k[j, j - 1] -= kj
    m = np.diag(b["masses"])
    w = np.sqrt(np.sort(np.linalg.eigvals(np.linalg.solve(m, k)).real))
    if n == 1:
        return 2 * XI * w[0], 0.0  # mass-proportional: xi = a0 / (2 w)
    return 2 * XI * w[0] * w[1] / (w[0] + w[1]), 2 * XI / (w[0] + w[1])


def levels(scene):
    """(pair, floor_left, floor_right) from 0, for floors at equal elevations."""
    out = []
    bs = scene["buildings"]
    for a in range(len(bs) - 1):
        za = np.cumsum(bs[a]["heights"])
        zb = np.cumsum(bs[a + 1]["heights"])
        for fa, ea in enumerate(za):
            for fb, eb in enumerate(zb):
                if abs(ea - eb) <= 0.01:
                    out.append((a, fa, fb))
    return out


def run_opensees(ops, tmp, scene, ag, dt_rec, dt, duration):
    ops.wipe()
    ops.model("basic", "-ndm", 1, "-ndf", 1)
    tags = iter(range(1, 1_000_000))
    floor_nodes = []
    for bi, b in enumerate(scene["buildings"]):
        a0, a1 = rayleigh(b)
        ground = next(tags)
        ops.node(ground, 0.0)
        ops.fix(ground, 1)
        nodes = []
        below = ground
        for mj, kj in zip(b["masses"], b["stiffness"]):
            node = next(tags)
            ops.node(node, 0.0)
            ops.mass(node, mj)
            nodes.append(node)
            # Storey spring and its a1 k_j dashpot.
            spring, dashpot, storey = next(tags), next(tags), next(tags)
            ops.uniaxialMaterial("Elastic", spring, kj)
            ops.uniaxialMaterial("Viscous", dashpot, a1 * kj, 1.0)
            ops.uniaxialMaterial("Parallel", storey, spring, dashpot)
            ops.element("zeroLength", next(tags), below, node, "-mat", storey, "-dir", 1)
            # The a0 m_j dashpot to a fixed point.
            anchor, mass_dashpot = next(tags), next(tags)
            ops.node(anchor, 0.0)
            ops.fix(anchor, 1)
            ops.uniaxialMaterial("Viscous", mass_dashpot, a0 * mj, 1.0)
            ops.element("zeroLength", next(tags), anchor, node, "-mat", mass_dashpot, "-dir", 1)
            below = node
        floor_nodes.append(nodes)
    contact_eles = []
    for a, fa, fb in levels(scene):
        # Left floor to right floor: contact when u_left - u_right > gap, i.e. the element
        # shortens by more than the gap (a compression gap: negative Fy and gap).
        gap_mat, ele = next(tags), next(tags)
        ops.uniaxialMaterial("ElasticPPGap", gap_mat, K_CONTACT, -1e30, -scene["gaps"][a])
        ops.element("zeroLength", ele, floor_nodes[a][fa], floor_nodes[a + 1][fb], "-mat", gap_mat, "-dir", 1)
        contact_eles.append(ele)
    ops.timeSeries("Path", 1, "-dt", dt_rec, "-values", *ag, "-factor", 1.0)
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
    ops.recorder("Node", "-file", disp, "-precision", 12, "-node", *all_nodes, "-dof", 1, "disp")
    ops.recorder("Element", "-file", force, "-precision", 12, "-ele", *contact_eles, "force")
    steps = int(round(duration / dt))
    if ops.analyze(steps, dt) != 0:
        raise RuntimeError(f"OpenSees failed on {scene['name']}")
    ops.wipe()
    u = np.loadtxt(disp, ndmin=2)
    f = np.loadtxt(force, ndmin=2)
    # Element force: two values (end i, end j) per element; compression is negative at end j.
    forces = [float(np.max(np.abs(f[:, 2 * i]))) for i in range(len(contact_eles))]
    roofs, drifts = [], []
    col = 0
    for b in scene["buildings"]:
        n = len(b["masses"])
        ub = u[:, col : col + n]
        col += n
        roofs.append(float(np.max(np.abs(ub[:, -1]))))
        below = np.hstack([np.zeros((ub.shape[0], 1)), ub[:, :-1]])
        drifts.append(float(np.max(np.abs(ub - below) / np.array(b["heights"]))))
    return forces, roofs, drifts


def toml_list(xs):
    return "[" + ", ".join(repr(float(x)) for x in xs) + "]"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--dt", type=float, default=1e-4, help="OpenSees time step, s (and half of it)")
    ap.add_argument("-o", default="tests/data/opensees_multistorey.toml")
    a = ap.parse_args()
    import openseespy.opensees as ops

    records = os.environ.get("POUND_RECORDS_DIR", "../shared/records")
    lines = [
        "# Written by benches/opensees_multistorey.py (see its docstring for the conventions).",
        f"# openseespy {version('openseespy')}, Newmark average acceleration at dt and dt / 2.",
        f"contact_k_n_per_m = {K_CONTACT!r}",
        f"damping_ratio = {XI!r}",
        f"dt_fine_s = {a.dt / 2!r}",
        f"dt_coarse_s = {a.dt!r}",
        "",
    ]
    with tempfile.TemporaryDirectory() as tmp:
        for scene in SCENES:
            dt_rec, acc_g = read_at2(os.path.join(records, scene["record"]))
            ipga = max(range(len(acc_g)), key=lambda i: abs(acc_g[i]))
            npts = min(len(acc_g), ipga + int(round(6.0 / dt_rec)) + 1)
            acc_g = acc_g[:npts]
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
                f"name = {scene['name']!r}".replace("'", '"'),
                f"record = {scene['record']!r}".replace("'", '"'),
                f"npts = {npts}",
                f"scale = {scale!r}",
                f"gaps_m = {toml_list(scene['gaps'])}",
                f"peak_force_n = {toml_list(fine[0])}",
                f"peak_force_n_coarse = {toml_list(coarse[0])}",
                f"peak_roof_m = {toml_list(fine[1])}",
                f"peak_roof_m_coarse = {toml_list(coarse[1])}",
                f"peak_drift_ratio = {toml_list(fine[2])}",
                f"peak_drift_ratio_coarse = {toml_list(coarse[2])}",
            ]
            for b in scene["buildings"]:
                lines += [
                    "[[scene.building]]",
                    f"masses_kg = {toml_list(b['masses'])}",
                    f"stiffness_n_per_m = {toml_list(b['stiffness'])}",
                    f"heights_m = {toml_list(b['heights'])}",
                ]
            lines.append("")
    os.makedirs(os.path.dirname(a.o), exist_ok=True)
    with open(a.o, "w") as f:
        f.write("\n".join(lines))
    print(f"wrote {a.o}", file=sys.stderr)


if __name__ == "__main__":
    sys.exit(main())
