#!/usr/bin/env python3
"""Cross-check for issue 68, "the struck column as a column": writes
tests/data/opensees_struck_column.toml, the reference the `[[building]] struck_column_share`
key (alpha) is to be checked against, and prints the comparisons (R against pound, C against R,
K against C, K against R, the point mass's and the time step's effect) as markdown tables.

The scene (physics.md section 11; docs/floor-column.md's worked example, with elastic storeys):
a 3-storey of 3.5 m storeys (building 1, left; 2e5 kg floors, T1 0.45 s) beside a 4-storey of
3 m storeys (building 2, right; 3e5 kg floors, T1 0.6 s), 5 % Rayleigh damping on modes 1 and
2, uniform storey stiffness scaled to T1. No floor is at a floor of the other: building 1's
floors strike building 2's storeys 2, 3 and 4 at xi = 1/6, 1/3 and 1/2, and building 2's floors
strike building 1's storeys at xi = 6/7, 5/7 and 4/7 (six floor/column points). alpha is set
on building 2 only (its struck storeys carry the explicit columns); building 1's struck points
stay rigid points in every model. Ground motion: El Centro 1940 NS (PEER, I-ELC180), the first
6 s scaled by a factor, then a 1 s free tail. Two contact laws: `linear` (k 1e9 N/m) and
`nonlinear_viscoelastic` (beta 2.75e9 N/m^1.5, e 0.65, Jankowski's zeta formula).

Models (all in OpenSees, 2D, ndf 3, every node's vertical DOF fixed; floors have masses,
nothing else does, but for the point masses below):
  R  pound's own kinematics: the struck point is a massless node tied to the storey's floors by
     a stiff linkage: springs (1 - s) K to floor j-1, s K to floor j and -s (1 - s) K between
     the floors (K = K_RIGID). With no force on it the point sits at u_(j-1) + s (u_j - u_(j-1)),
     the linkage adds no storey stiffness, and a force F on it reaches the floors as (1 - s) F
     and s F; it is pound's rigid point but for a series compliance 1/K (the script runs R
     again at K / 10 and states the change: at most 3.3e-5 in a peak force measured).
  K  the rigid point plus a series spring k_loc = alpha k_j / (4 xi^3 (1 - xi)^3): the same
     linkage with K = k_loc (massless point; what the Rust key will be).
  C  explicit columns: storey j of building 2 is a shear spring (1 - alpha) k_j beside a
     fixed-fixed column, two `elasticBeamColumn`s (Euler-Bernoulli, no shear deformation)
     split at the struck point, 12 E I / h^3 = alpha k_j; the column's ends are tied to the
     floors' horizontal DOF (`equalDOF`) with rotation fixed, its point at xi has a free
     rotation and no mass; the contact element acts on that point (on a node tied to it).
  Storeys not struck, and building 1's, are shear springs in every model. The damping is the
  shear building's Rayleigh C = a0 M + a1 K (explicit dashpots: a0 m_j floor to ground, a1 k_j
  across each storey, the column and linkage undamped), the same in all models, as in pound.
  Note: condensing the massless column's point (its rotation) gives exactly three springs,
  (1 - s) k_loc to floor j-1, s k_loc to floor j and alpha k_j - s (1 - s) k_loc across, so K and
  C are the same equations: their gap measures the solver, not the model.

The massless point and JankowskiImpact: OpenSees' JankowskiImpact returns a tangent of the wrong
sign without the damping force's rate term, which Newton (and KrylovNewton) cannot get past at a
massless node where the contact meets only k_loc (measured: no convergence at dt 5e-4 with Newton
or KrylovNewton, nor at 5e-5 with KrylovNewton). Under that law, K's and C's struck points carry
a point mass of POINT_MASSES_KG (100 and 250 kg, against floors of 2e5 and 3e5 kg), and the
values written are extrapolated linearly to zero mass (over 100-1000 kg the peak forces move
linearly with the mass, about 0.5 % per tonne at xi = 1/2, alpha = 1); the 100 and 250 kg values
are written too. The linear law (ElasticPPGap) runs massless. K's column shear takes the force
its linkage passes on, k_loc (u_P - u_rigid), which is the contact force less the point mass's
inertia, as C's column feels it.

Contact: `ElasticPPGap` (linear, compression only) or `JankowskiImpact` (Kh = beta, xi = the
formula's zeta, n = 1.5) between the striking floor and the point, one gap. The damping's
effective mass is pound's: m_eff = m_f m_p / (m_f + m_p), m_p = 1 / ((1 - s)^2 / m_(j-1) +
s^2 / m_j) (ground's term 0), in every model.

Outputs per model, from OpenSees' steps (Newmark average acceleration, KrylovNewton, dt and dt / 2,
the finer one reported, the coarser kept to state the step error): per level peak contact force
and impacts (steps where the force turns positive), each building's peak interstorey drift
ratio and peak drift per storey, and per struck point the struck storey's peak column shear
while that point is in contact: in C the column elements' shear; in R and K
max(|alpha V + (1 - s) f|, |alpha V - s f|), V = k_j d_j, f the signed force on the point
(alpha = 1 for R, as pound's `column_shear_n`; R's shear at each alpha is written too, and
is what C and K are set against).

R is compared with `pound sweep` (reference scheme) on the same config (written into the TOML).

`--column-mass-ratio R` (not written to the TOML) also runs C with the struck columns' own mass,
distributed and consistent (`-mass`, `-cMass`), R alpha times the storey's top floor mass, on top
of the floor masses: what the massless column of K and C leaves out. It adds global mass too
(building 2's peak drift moves by 8.5 % at R = 0.1, alpha = 1), so it bounds the question rather
than answering it.

Set-up (OpenSees 3.8 needs Python 3.12), from the repository root:
    PYENV_VERSION=3.12.1 python3.12 -m venv /tmp/ospy && /tmp/ospy/bin/pip install openseespy numpy
    POUND_RECORDS_DIR=/work/shared/records /tmp/ospy/bin/python benches/opensees_struck_column.py \
        --pound target/release/pound [--dt 1e-4]

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

import numpy as np

G = 9.80665
K_RIGID = 1e16  # N/m: model R's linkage; R is rerun at K_RIGID / 10 to state what it costs
ALGORITHM = "KrylovNewton"
ALPHAS = [1.0, 0.25]
POINT_MASSES_KG = [100.0, 250.0]  # K and C's struck point under the nonlinear viscoelastic law  # struck_column_share of building 2
RECORD = "elcentro1940_ns_I-ELC180_peer2000.AT2"
WINDOW_S = 6.0
TAIL_S = 1.0
SCALE = 1.0
GAP_M = 0.01
E = 0.65

GEOMETRY = [  # pound's [[building]] keys; storeys uniform, stiffness scaled to period_s
    {"storeys": 3, "storey_height_m": 3.5, "mass_kg": 2.0e5, "period_s": 0.45, "damping_ratio": 0.05},
    {"storeys": 4, "storey_height_m": 3.0, "mass_kg": 3.0e5, "period_s": 0.6, "damping_ratio": 0.05},
]
LAWS = [
    {"law": "nonlinear_viscoelastic", "beta": 2.75e9},
    {"law": "linear", "k": 1.0e9},
]
ALPHA_BUILDING = 1  # building index (from 0) that carries alpha


def read_at2(path):
    """PEER AT2: four header lines (the fourth gives NPTS and DT, spaced either way), values in g."""
    with open(path) as f:
        lines = f.read().splitlines()
    head = lines[3]
    npts = re.search(r"NPTS\s*=?\s*(\d+)", head) or re.match(r"\s*(\d+)", head)
    dt = re.search(r"DT\s*=\s*([0-9.Ee+-]+)", head)
    if dt is None:  # "4000    0.0100    NPTS, DT"
        dt = re.match(r"\s*\d+\s+([0-9.Ee+-]+)", head)
    values = [float(x) for line in lines[4:] for x in line.split()]
    return float(dt.group(1)), values[: int(npts.group(1))]


def jankowski_zeta(e):
    """physics.md section 3, (6): `formula = "jankowski"` in pound."""
    return 9 * math.sqrt(5) * (1 - e * e) / (2 * e * (e * (9 * math.pi - 16) + 16))


def shear_building(spec):
    """Masses, storey stiffnesses (uniform, scaled so that mode 1 has period_s), heights, a0, a1."""
    n = spec["storeys"]
    m = np.full(n, spec["mass_kg"])
    unit = np.zeros((n, n))
    for j in range(n):  # storey j+1 joins floor j and j+1 (floor 0 the ground)
        unit[j, j] += 1.0
        if j > 0:
            unit[j - 1, j - 1] += 1.0
            unit[j - 1, j] -= 1.0
            unit[j, j - 1] -= 1.0
    lam = np.sort(np.linalg.eigvals(np.linalg.solve(np.diag(m), unit)).real)
    k = (2 * math.pi / spec["period_s"]) ** 2 / lam[0]
    w = np.sqrt(lam * k)
    xi = spec["damping_ratio"]
    a0, a1 = (2 * xi * w[0], 0.0) if n == 1 else (2 * xi * w[0] * w[1] / (w[0] + w[1]), 2 * xi / (w[0] + w[1]))
    h = spec["storey_height_m"]
    return {"m": list(m), "k": [k] * n, "h": [h] * n, "z": [h * (j + 1) for j in range(n)], "a0": a0, "a1": a1}


def contact_points(bs):
    """Floor/column points of the pair, as pound names them: each floor of one building at or
    below the other's roof, facing the other's storey j at xi."""
    pts = []
    for striker, struck in ((0, 1), (1, 0)):
        zs, zt = bs[striker]["z"], bs[struck]["z"]
        for f, z in enumerate(zs):
            if z > zt[-1] + 1e-9:
                continue
            j = next(i for i, top in enumerate(zt) if top >= z)  # storey index from 0
            bottom = zt[j - 1] if j > 0 else 0.0
            if min(abs(z - zt[j]), abs(z - bottom)) <= 0.01:
                raise SystemExit("a floor/floor level: this script models floor/column points only")
            xi = (z - bottom) / bs[struck]["h"][j]
            s = 3 * xi**2 - 2 * xi**3
            mb = bs[struck]["m"]
            inv = s**2 / mb[j] + ((1 - s) ** 2 / mb[j - 1] if j > 0 else 0.0)
            m_p = 1.0 / inv
            m_f = bs[striker]["m"][f]
            left = f"b1f{f + 1}" if striker == 0 else f"b1c{j + 1}"
            right = f"b2c{j + 1}" if striker == 0 else f"b2f{f + 1}"
            pts.append({
                "name": f"level_{left}_{right}", "striker": striker, "floor": f, "struck": struck,
                "storey": j, "xi": xi, "s": s, "z": z, "m_eff": m_f * m_p / (m_f + m_p),
            })
    return sorted(pts, key=lambda p: p["z"])


def k_loc(alpha, kj, xi):
    return alpha * kj / (4 * xi**3 * (1 - xi) ** 3)


def run_opensees(ops, tmp, bs, pts, law, model, alpha, ag, dt_rec, dt, duration, k_rigid=K_RIGID, m_point=0.0,
                 column_mass_ratio=0.0):
    """One analysis. model: R, K or C (alpha on building ALPHA_BUILDING for K and C, whose struck
    points carry m_point, kg, on their horizontal DOF). column_mass_ratio > 0 (C only, the
    --column-mass study): the struck columns get a distributed, consistent mass of that ratio times
    alpha times the storey's top floor mass, on top of the floor masses."""
    ops.wipe()
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    tags = iter(range(1, 10_000_000))
    ops.geomTransf("Linear", 1)

    def point_node(mass=0.0):
        """A node at the origin that moves horizontally only (zeroLength needs coincident nodes)."""
        n = next(tags)
        ops.node(n, 0.0, 0.0)
        ops.fix(n, 0, 1, 1)
        if mass:
            ops.mass(n, mass, 0.0, 0.0)
        return n

    def spring(i, j, kval, c=False):
        mat = next(tags)
        if c:
            ops.uniaxialMaterial("Viscous", mat, kval, 1.0)
        else:
            ops.uniaxialMaterial("Elastic", mat, kval)
        ops.element("zeroLength", next(tags), i, j, "-mat", mat, "-dir", 1)

    ground = next(tags)
    ops.node(ground, 0.0, 0.0)
    ops.fix(ground, 1, 1, 1)
    floors = []
    for b in bs:
        floors.append([ground] + [point_node(mj) for mj in b["m"]])
    # Explicit points (C, K) on building ALPHA_BUILDING's struck storeys.
    explicit = model in ("C", "K")
    struck_storeys = {(p["struck"], p["storey"]) for p in pts}
    columns = {}  # (building, storey) -> (element below point, element above point)
    point_of = {}
    linkage = {}  # K's explicit points: (building, storey) -> (node, k_loc)
    for bi, b in enumerate(bs):
        for j in range(len(b["m"])):
            lo, hi = floors[bi][j], floors[bi][j + 1]
            kj = b["k"][j]
            as_column = model == "C" and bi == ALPHA_BUILDING and (bi, j) in struck_storeys
            if not as_column:
                spring(lo, hi, kj)
            elif alpha < 1.0:
                spring(lo, hi, (1 - alpha) * kj)  # the share the struck columns do not carry
            spring(lo, hi, b["a1"] * kj, c=True)
            anchor = next(tags)
            ops.node(anchor, 0.0, 0.0)
            ops.fix(anchor, 1, 1, 1)
            spring(anchor, hi, b["a0"] * b["m"][j], c=True)
            if as_column:
                p = next(q for q in pts if q["struck"] == bi and q["storey"] == j)
                h = b["h"][j]
                ei = alpha * kj * h**3 / 12.0
                x = 10.0 * (bi + 1)  # the column stands apart from the origin's point nodes
                z0 = h * j
                bot, mid, top = next(tags), next(tags), next(tags)
                ops.node(bot, x, z0)
                ops.node(mid, x, z0 + p["xi"] * h)
                ops.node(top, x, z0 + h)
                ops.fix(bot, *((1, 1, 1) if j == 0 else (0, 1, 1)))
                ops.fix(top, 0, 1, 1)
                ops.fix(mid, 0, 1, 0)
                if m_point:
                    ops.mass(mid, m_point, 0.0, 0.0)
                if j > 0:
                    ops.equalDOF(lo, bot, 1)
                ops.equalDOF(hi, top, 1)
                e1, e2 = next(tags), next(tags)
                # E = 1: I carries EI; A large so nothing is axial (vertical DOFs fixed anyway).
                extra = []
                if column_mass_ratio:
                    extra = ["-mass", column_mass_ratio * alpha * b["m"][j] / h, "-cMass"]
                ops.element("elasticBeamColumn", e1, bot, mid, 1.0, 1.0, ei, 1, *extra)
                ops.element("elasticBeamColumn", e2, mid, top, 1.0, 1.0, ei, 1, *extra)
                pnode = point_node()
                ops.equalDOF(mid, pnode, 1)
                columns[(bi, j)] = (e1, e2)
                point_of[(bi, j)] = pnode
    contact_eles = []
    for p in pts:
        bi, j = p["struck"], p["storey"]
        if (bi, j) not in point_of:
            # Stiff (R) or local (K) linkage: (1-s) K to floor j-1, s K to floor j, -s(1-s) K across.
            local = explicit and bi == ALPHA_BUILDING
            kk = k_loc(alpha, bs[bi]["k"][j], p["xi"]) if local else k_rigid
            lo, hi = floors[bi][j], floors[bi][j + 1]
            pnode = point_node(m_point if local else 0.0)
            if local:
                linkage[(bi, j)] = (pnode, kk)
            spring(lo, pnode, (1 - p["s"]) * kk)
            spring(pnode, hi, p["s"] * kk)
            spring(lo, hi, -p["s"] * (1 - p["s"]) * kk)
            point_of[(bi, j)] = pnode
        fnode = floors[p["striker"]][p["floor"] + 1]
        left, right = (fnode, point_of[(bi, j)]) if p["striker"] == 0 else (point_of[(bi, j)], fnode)
        mat, ele = next(tags), next(tags)
        # Compression gap: contact when u_left - u_right > gap (the element shortens).
        if law["law"] == "linear":
            ops.uniaxialMaterial("ElasticPPGap", mat, law["k"], -1e30, -GAP_M)
        else:
            ops.uniaxialMaterial("JankowskiImpact", mat, law["beta"], jankowski_zeta(E), p["m_eff"], -max(GAP_M, 1e-12), 1.5)
        ops.element("zeroLength", ele, left, right, "-mat", mat, "-dir", 1)
        contact_eles.append(ele)
    ops.timeSeries("Path", 1, "-dt", dt_rec, "-values", *ag, "-factor", 1.0)
    ops.pattern("UniformExcitation", 1, 1, "-accel", 1)
    ops.constraints("Transformation")
    ops.numberer("RCM")
    ops.system("BandGeneral")
    ops.test("NormDispIncr", 1e-12, 50)
    ops.algorithm(ALGORITHM)
    ops.integrator("Newmark", 0.5, 0.25)
    ops.analysis("Transient")
    fl = [n for f in floors for n in f[1:]]
    files = {k: os.path.join(tmp, k + ".txt") for k in ("disp", "force", "col", "point")}
    lk = list(linkage)
    if lk:
        ops.recorder("Node", "-file", files["point"], "-precision", 14, "-node", *[linkage[x][0] for x in lk], "-dof", 1, "disp")
    ops.recorder("Node", "-file", files["disp"], "-precision", 14, "-node", *fl, "-dof", 1, "disp")
    ops.recorder("Element", "-file", files["force"], "-precision", 14, "-ele", *contact_eles, "force")
    col_eles = [e for p in pts for e in columns.get((p["struck"], p["storey"]), ())]
    if col_eles:
        ops.recorder("Element", "-file", files["col"], "-precision", 14, "-ele", *col_eles, "force")
    # JankowskiImpact writes a line per impact to stdout: keep the report clean.
    sys.stdout.flush()
    saved = os.dup(1)
    with open(os.devnull, "w") as null:
        os.dup2(null.fileno(), 1)
        try:
            ok = ops.analyze(int(round(duration / dt)), dt)
        finally:
            os.dup2(saved, 1)
            os.close(saved)
    if ok != 0:
        raise RuntimeError(f"OpenSees failed: {model} alpha {alpha}")
    ops.wipe()
    u = np.loadtxt(files["disp"], ndmin=2)
    fr = np.loadtxt(files["force"], ndmin=2)
    nf = 6  # zeroLength in 2D with ndf 3: 3 values per node
    forces = np.abs(fr[:, [nf * i for i in range(len(pts))]])  # compression magnitude, N
    col = np.loadtxt(files["col"], ndmin=2) if col_eles else None
    upt = np.loadtxt(files["point"], ndmin=2) if lk else None
    out = {"peak_force_n": [], "impacts": [], "column_shear_n": []}
    offs = np.cumsum([0] + [len(b["m"]) for b in bs])
    ub = [u[:, offs[i]:offs[i + 1]] for i in range(len(bs))]
    drifts = [ui - np.hstack([np.zeros((ui.shape[0], 1)), ui[:, :-1]]) for ui in ub]
    ci = 0
    for i, p in enumerate(pts):
        f = forces[:, i]
        on = f > 0.0
        out["peak_force_n"].append(float(f.max()))
        out["impacts"].append(int(np.sum(on[1:] & ~on[:-1]) + int(on[0])))
        if not on.any():
            out["column_shear_n"].append(0.0)
            if (p["struck"], p["storey"]) in columns:
                ci += 2
            continue
        if (p["struck"], p["storey"]) in columns:
            # Global X force at the element's node i: the segment's shear (the column is vertical).
            shear = np.maximum(np.abs(col[:, 6 * ci]), np.abs(col[:, 6 * (ci + 1)]))
            ci += 2
        else:
            bi, j = p["struck"], p["storey"]
            a = alpha if (explicit and bi == ALPHA_BUILDING) else 1.0
            v = a * bs[bi]["k"][j] * drifts[bi][:, j]
            sf = f if p["striker"] == 0 else -f  # the signed force on the point (right is +)
            if (bi, j) in linkage:
                # The force the linkage passes to the floors, k_loc (u_P - u_rigid): the contact
                # force less the point mass's inertia (the same where the point is massless).
                ub_lo = ub[bi][:, j - 1] if j > 0 else 0.0
                u_rigid = (1 - p["s"]) * ub_lo + p["s"] * ub[bi][:, j]
                sf = linkage[(bi, j)][1] * (upt[:, lk.index((bi, j))] - u_rigid)
            shear = np.maximum(np.abs(v + (1 - p["s"]) * sf), np.abs(v - p["s"] * sf))
            if model == "R" and bi == ALPHA_BUILDING:
                # The rigid point's column shear were the struck columns a share alpha of the
                # storey: alpha V plus the same contact shares (to set against C's at that alpha).
                for al in ALPHAS:
                    va = al * bs[bi]["k"][j] * drifts[bi][:, j]
                    sh = np.maximum(np.abs(va + (1 - p["s"]) * sf), np.abs(va - p["s"] * sf))
                    out.setdefault("shear_at", {}).setdefault(al, {})[i] = float(sh[on].max())
        out["column_shear_n"].append(float(shear[on].max()))
    out["peak_drift_ratio"] = [float(np.max(np.abs(d) / np.array(b["h"]))) for d, b in zip(drifts, bs)]
    out["peak_storey_drift_m"] = [[float(x) for x in np.max(np.abs(d), axis=0)] for d in drifts]
    out["peak_roof_m"] = [float(np.max(np.abs(ui[:, -1]))) for ui in ub]
    return out


def pound_config(law):
    lines = ["[run]", 'scheme = "reference"', f"tail_s = {TAIL_S!r}", ""]
    for g in GEOMETRY:
        lines.append("[[building]]")
        lines += [f"{k} = {v!r}" for k, v in g.items()]
        lines.append("")
    lines.append("[contact]")
    lines.append(f'law = "{law["law"]}"')
    if law["law"] == "linear":
        lines.append(f"k_n_per_m = {law['k']!r}")
    else:
        lines += ['formula = "jankowski"', f"e = {E!r}", f"beta_n_per_m1_5 = {law['beta']!r}"]
    lines += [f"gap_m = {GAP_M!r}", "", "[[record]]", 'name = "el_centro_1940"', f'file = "{RECORD}"',
              f"window_s = [0.0, {WINDOW_S!r}]", "", "[intensity]", f"scale = {SCALE!r}", ""]
    return "\n".join(lines)


def run_pound(pound, tmp, text, name):
    cfg = os.path.join(tmp, name + ".toml")
    out = os.path.join(tmp, name + ".csv")
    with open(cfg, "w") as f:
        f.write(text)
    done = subprocess.run([pound, "sweep", cfg, "--backend", "cpu", "-o", out], stderr=subprocess.PIPE, text=True)
    if done.returncode != 0:
        raise SystemExit(f"pound sweep failed:\n{done.stderr}")
    with open(out) as f:
        return list(csv.DictReader(f))[0]


def rel(a, b):
    return abs(a - b) / max(abs(b), 1e-300) if (a or b) else 0.0


def toml_list(xs):
    return "[" + ", ".join(repr(x) if isinstance(x, int) else repr(float(x)) for x in xs) + "]"


FLOATS = ("peak_force_n", "column_shear_n", "peak_drift_ratio", "peak_roof_m")


def r_at(r, alpha, pts):
    """R with the alpha building's column shears taken at the share alpha."""
    out = dict(r)
    at = r.get("shear_at", {}).get(alpha, {})
    out["column_shear_n"] = [at.get(i, 0.0) if p["struck"] == ALPHA_BUILDING else r["column_shear_n"][i]
                             for i, p in enumerate(pts)]
    return out


def massless(r_small, r_large, m_small, m_large):
    """Linear extrapolation in the point mass to zero (measured linear over 100-1000 kg)."""
    w = m_small / (m_large - m_small)
    out = {k: [a + w * (a - b) for a, b in zip(r_small[k], r_large[k])] for k in FLOATS}
    out["impacts"] = r_small["impacts"]
    out["peak_storey_drift_m"] = [[a + w * (a - b) for a, b in zip(x, y)]
                                  for x, y in zip(r_small["peak_storey_drift_m"], r_large["peak_storey_drift_m"])]
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--dt", type=float, default=1e-4, help="OpenSees time step (coarse), s; dt/2 is reported")
    ap.add_argument("--pound", default="target/release/pound")
    ap.add_argument("-o", default="tests/data/opensees_struck_column.toml")
    ap.add_argument("--column-mass-ratio", type=float, default=0.0,
                    help="also run C with the struck columns' own distributed mass (this ratio times alpha "
                         "times the floor mass, on top of the floors'), printed against massless C, not written")
    a = ap.parse_args()
    import openseespy.opensees as ops

    records = os.environ.get("POUND_RECORDS_DIR", "../shared/records")
    dt_rec, acc_g = read_at2(os.path.join(records, RECORD))
    n = int(round(WINDOW_S / dt_rec)) + 1
    ag = [x * SCALE * G for x in acc_g[:n]]
    duration = WINDOW_S + TAIL_S
    bs = [shear_building(g) for g in GEOMETRY]
    pts = contact_points(bs)
    coarse_dt, fine_dt = a.dt, a.dt / 2
    lines = [
        "# Written by benches/opensees_struck_column.py (see its docstring for the models and conventions).",
        f"# openseespy {version('openseespy')}; Newmark average acceleration (gamma 1/2, beta 1/4), {ALGORITHM},",
        "# NormDispIncr 1e-12. Units: N, m, s, kg. Per model: the values at dt_s (for K and C under the",
        "# nonlinear viscoelastic law, extrapolated to a massless point from point masses of",
        "# point_masses_kg, both at dt_s), and *_coarse: the same model at dt_coarse_s (with the largest",
        "# point mass there, against which *_step at dt_s states the step error).",
        f"dt_s = {fine_dt!r}",
        f"dt_coarse_s = {coarse_dt!r}",
        'integrator = "Newmark average acceleration"',
        f'algorithm = "{ALGORITHM}"',
        f"k_rigid_n_per_m = {K_RIGID!r}",
        f'record = "{RECORD}"',
        f"window_s = [0.0, {WINDOW_S!r}]",
        f"tail_s = {TAIL_S!r}",
        f"scale = {SCALE!r}",
        f"gap_m = {GAP_M!r}",
        f"alpha_building = {ALPHA_BUILDING + 1}  # from 1, as pound's b2_",
        "",
    ]
    tables = {"pound": [], "CR": [], "KC": [], "KR": [], "mass": [], "step": [], "colmass": []}
    with tempfile.TemporaryDirectory() as tmp:

        def run(name, model, alpha, dt, m_point=0.0, k_rigid=K_RIGID):
            t = time.perf_counter()
            r = run_opensees(ops, tmp, bs, pts, law, model, alpha, ag, dt_rec, dt, duration, k_rigid, m_point)
            print(f"{name} {model} alpha {alpha} dt {dt:g} point mass {m_point:g} kg: {time.perf_counter() - t:.1f} s",
                  file=sys.stderr)
            return r

        for law in LAWS:
            name = f"worked_example_elastic_{law['law']}"
            text = pound_config(law)
            pr = run_pound(a.pound, tmp, text, name)
            # The massless point under JankowskiImpact does not converge in OpenSees (its tangent
            # leaves out the damping's rate term and has the wrong sign), so K and C there carry a
            # small point mass, at two values, extrapolated to zero.
            masses = POINT_MASSES_KG if law["law"] != "linear" else [0.0]
            res = {("R", 1.0): run(name, "R", 1.0, fine_dt)}
            coarse = {("R", 1.0): run(name, "R", 1.0, coarse_dt)}
            step = {("R", 1.0): res[("R", 1.0)]}
            by_mass = {}
            for al in ALPHAS:
                for model in ("K", "C"):
                    key = (model, al)
                    rs = [run(name, model, al, fine_dt, mp) for mp in masses]
                    by_mass[key] = rs
                    res[key] = rs[0] if len(rs) == 1 else massless(rs[0], rs[1], masses[0], masses[1])
                    coarse[key] = run(name, model, al, coarse_dt, masses[-1])
                    step[key] = rs[-1]
            r_soft = run(name, "R", 1.0, fine_dt, k_rigid=K_RIGID / 10)
            R = res[("R", 1.0)]
            for i, p in enumerate(pts):
                q = p["name"]
                for key in ("peak_force_n", "column_shear_n", "impacts"):
                    cast = int if key == "impacts" else float
                    tables["pound"].append((name, q, key, R[key][i], cast(pr[f"{q}_{key}"])))
            for bi in range(len(bs)):
                for key in ("peak_drift_ratio", "peak_roof_m"):
                    tables["pound"].append((name, f"b{bi + 1}", key, R[key][bi], float(pr[f"b{bi + 1}_{key}"])))
            soft = max(rel(r_soft["peak_force_n"][i], R["peak_force_n"][i]) for i in range(len(pts)))
            print(f"{name}: R at K_RIGID/10 moves the peak forces by at most {soft:.2e}", file=sys.stderr)
            for al in ALPHAS:
                tables["CR"].append((name, al, res[("C", al)], r_at(R, al, pts)))
                tables["KC"].append((name, al, res[("K", al)], res[("C", al)]))
                tables["KR"].append((name, al, res[("K", al)], r_at(R, al, pts)))
                if len(masses) > 1:
                    tables["mass"].append((name, al, by_mass[("C", al)][0], res[("C", al)]))
            for key in res:
                tables["step"].append((name, key, coarse[key], step[key]))
            if a.column_mass_ratio:
                for al in ALPHAS:
                    t = time.perf_counter()
                    cm = run_opensees(ops, tmp, bs, pts, law, "C", al, ag, dt_rec, fine_dt, duration,
                                      column_mass_ratio=a.column_mass_ratio)
                    print(f"{name} C alpha {al} column mass: {time.perf_counter() - t:.1f} s", file=sys.stderr)
                    tables["colmass"].append((name, al, cm, res[("C", al)]))
            lines += [
                "[[scene]]",
                f'name = "{name}"',
                f'law = "{law["law"]}"',
                f"pound_config = \'\'\'\n{text}\'\'\'",
                "# With the key: add `struck_column_share = alpha` to the second [[building]].",
                f"struck_column_share_alphas = {toml_list(ALPHAS)}",
                f"point_masses_kg = {toml_list(masses)}  # K and C's struck points (0: massless)",
                f"rigid_linkage_force_change = {soft!r}  # R at k_rigid / 10 against R, max over levels",
                f"levels = [{', '.join(chr(34) + p['name'] + chr(34) for p in pts)}]",
                f"xi = {toml_list([p['xi'] for p in pts])}",
                f"s = {toml_list([p['s'] for p in pts])}",
                f"m_eff_kg = {toml_list([p['m_eff'] for p in pts])}",
                f"struck_building = {toml_list([p['struck'] + 1 for p in pts])}",
                f"struck_storey = {toml_list([p['storey'] + 1 for p in pts])}",
                "# k_loc at alpha = 1 (0 where the struck building carries no alpha); alpha scales it",
                f"k_loc_alpha1_n_per_m = {toml_list([k_loc(1.0, bs[p['struck']]['k'][p['storey']], p['xi']) if p['struck'] == ALPHA_BUILDING else 0.0 for p in pts])}",
                f"storey_stiffness_n_per_m = {toml_list([b['k'][0] for b in bs])}",
                f"rayleigh_a0 = {toml_list([b['a0'] for b in bs])}",
                f"rayleigh_a1 = {toml_list([b['a1'] for b in bs])}",
                f"impact_damping_zeta = {jankowski_zeta(E) if law['law'] != 'linear' else 0.0!r}",
                "",
            ]
            for (model, alpha), r in res.items():
                lines += ["[[scene.model]]", f'model = "{model}"', f"alpha = {alpha!r}"]
                for key in ("peak_force_n", "impacts", "column_shear_n", "peak_drift_ratio", "peak_roof_m"):
                    lines.append(f"{key} = {toml_list(r[key])}")
                for bi in range(len(bs)):
                    lines.append(f"b{bi + 1}_peak_storey_drift_m = {toml_list(r['peak_storey_drift_m'][bi])}")
                if model == "R":
                    lines.append("# R's column shear with alpha V in place of V on the alpha building's points, per alpha")
                    lines.append("column_shear_n_alpha = [" + ", ".join(toml_list(r_at(r, al, pts)["column_shear_n"]) for al in ALPHAS) + "]")
                for key in ("peak_force_n", "impacts", "column_shear_n", "peak_drift_ratio"):
                    lines.append(f"{key}_coarse = {toml_list(coarse[(model, alpha)][key])}")
                    if step[(model, alpha)] is not r:
                        lines.append(f"{key}_step = {toml_list(step[(model, alpha)][key])}")
                for mp, rm in zip(masses, by_mass.get((model, alpha), [])):
                    if mp:
                        lines.append(f"peak_force_n_point_mass_{int(mp)} = {toml_list(rm['peak_force_n'])}")
                        lines.append(f"column_shear_n_point_mass_{int(mp)} = {toml_list(rm['column_shear_n'])}")
                lines.append("")
    os.makedirs(os.path.dirname(a.o), exist_ok=True)
    with open(a.o, "w") as f:
        f.write("\n".join(lines))
    print(f"wrote {a.o}", file=sys.stderr)
    report(tables, pts)


def pct(x, y):
    return f"{100 * (x / y - 1):+.3g}" if y else ("0" if not x else "inf")


def report(tables, pts):
    print("\n## R (OpenSees, rigid point) against `pound sweep` (reference scheme)")
    print("| scene | where | output | OpenSees R | pound | rel. diff |")
    print("|---|---|---|---:|---:|---:|")
    worst = {}
    for name, where, key, o, p in tables["pound"]:
        d = rel(o, p)
        worst[key] = max(worst.get(key, 0.0), d)
        print(f"| {name.replace('worked_example_elastic_', '')} | {where} | {key} | {o:.7g} | {p:.7g} | {d:.1e} |")
    print("worst: " + ", ".join(f"{k} {v:.1e}" for k, v in worst.items()))
    head = [p["name"].replace("level_", "") + f" (xi {p['xi']:.3f})" for p in pts]
    for tag, title in (("CR", "C (explicit columns) against R (rigid point)"),
                       ("KC", "K (rigid point + series k_loc) against C"),
                       ("KR", "K against R (what the key changes)"),
                       ("mass", "C with a 100 kg point mass against C extrapolated to a massless point"),
                       ("colmass", "C with the columns' own distributed mass against massless C"),
                       ("step", "each model at dt_coarse against dt (same point mass)")):
        if not tables[tag]:
            continue
        print(f"\n## {title}: (first / second - 1), %; impacts: first / second")
        print("| scene | alpha | output | " + " | ".join(head) + " | b1 drift | b2 drift |")
        print("|---|---:|---|" + "---:|" * (len(pts) + 2))
        for name, al, x, y in tables[tag]:
            if isinstance(al, tuple):
                al = f"{al[0]} {al[1]}"
            sc = name.replace("worked_example_elastic_", "")
            for key in ("peak_force_n", "column_shear_n", "impacts"):
                if key == "impacts":
                    cells = [f"{x[key][i]} / {y[key][i]}" for i in range(len(pts))]
                else:
                    cells = [pct(x[key][i], y[key][i]) for i in range(len(pts))]
                dr = [pct(x["peak_drift_ratio"][b], y["peak_drift_ratio"][b]) for b in range(2)] if key == "peak_force_n" else ["", ""]
                print(f"| {sc} | {al} | {key} | " + " | ".join(cells) + " | " + " | ".join(dr) + " |")
    kc = max(rel(x[k][i], y[k][i]) for _, _, x, y in tables["KC"] for k in FLOATS for i in range(len(x[k])))
    print(f"\nK against C, largest relative difference over every float output: {kc:.1e}")


if __name__ == "__main__":
    sys.exit(main())
