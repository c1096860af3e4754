#!/usr/bin/env python3
"""Cross-check of P-Delta and collapse against OpenSees: writes tests/data/opensees_pdelta.toml,
which the test `collapse_opensees::opensees_cross_check` compares `pound sweep` (both schemes)
with.

Three scenes on real records no other OpenSees cross-check uses, each scaled by a factor (from a
PGA), each followed by a 60 s free tail (ground at rest) for the residual drift:
  G  a yielding one-storey building with P-Delta (m 3e5 kg, T0 1.0 s, h 3.5 m: theta =
     g / (w0^2 h) = 0.071; strength 0.15 W, b = 0.02: post-yield tangent -0.051 k) beside a far
     elastic neighbour (gap 1 m, no contact), El Centro 1940 NS, Peknold version (the first
     15 s at 0.35 g): peaks and residual drift (peak drift 3.1 %, ductility 2.9)
  H  a yielding 3-storey P-Delta frame whose leaning column carries twice its floors' weight
     (gravity_mass_ratio 2: theta 0.083, 0.062, 0.035; yield drift 0.8 %, b = 0.03) beside an
     elastic 4-storey it pounds (gap 30 mm), San Fernando 1971 Pacoima Dam 254 (the first 12 s
     at 0.5 g): peaks, contact forces, residual drifts (every storey yields)
  I  a collapse: an elastic 2-storey beside a 2-storey P-Delta frame with a soft first storey
     (gravity_mass_ratio 3: theta 0.067, 0.018; yield drift 0.6 %, b = 0.01: tangent
     b k - P/h < 0), gap 20 mm, Tabas 1978 fault-normal (OpenSees' example record, the first
     20 s at 0.8 g): the two pound, then the frame's first storey runs away from its neighbour:
     the collapse time (the first time some |d_j| / h_j reaches 0.10, interpolated linearly
     between OpenSees' steps), building and storey, the frame's peaks over [0, t_c]; the frame
     then leaves the scene and the neighbour goes on through the record and the tail (its peak
     drift over the whole run)

The scales are chosen where the answers are well conditioned: a change of 1e-4 in the scale
moves G's and H's peak drifts by about 1.3e-4, their residual drifts by at most 4.4e-4 of the
peak drift, I's collapse time by 2.2e-4 s (measured at dt 1e-3).

Conventions (physics.md sections 6, 8 and 10; the same in `pound`):
  - shear buildings: lumped floor masses, storey springs between floor j-1 and j (floor 0 is the
    ground, fixed), displacements relative to the ground, building 1 on the left;
  - storey j: `Steel01 F_y,j k_j b_j` (bilinear, kinematic hardening, no isotropic hardening):
    the spring law does not see the P-Delta term;
  - P-Delta (`p_delta = true`, `gravity_mass_ratio = r`): a massless leaning column beside the
    building, one `elasticBeamColumn` per storey with a `PDelta` geomTransf (EA 2e11 N, EI
    2e-5 N m^2: its bending stiffness is below 1e-12 of the storeys'; rotations fixed, so it is a
    chain of pinned-in-effect links), its horizontal DOF tied to each floor (`equalDOF`), its
    nodes loaded with `g m_j r` in a static gravity analysis (`Plain` pattern, `LoadConst`)
    before the dynamic one. So storey j's lateral force gains exactly `-P_j d_j / h_j`, with
    `P_j` the gravity above it, linear in the drift;
  - Rayleigh damping on the initial elastic stiffness without the geometric term, C = a0 M +
    a1 K0 with 5 % on modes 1 and 2 of (K0, M), built from explicit dashpots (a0 m_j from each
    floor to a fixed point, a1 k_j across each storey, beside its Steel01 spring), none on the
    leaning column, so no OpenSees damping option is involved;
  - contact at every floor level two neighbours share: a linear compression-only spring
    (`ElasticPPGap`, `law = "linear"` in pound), one gap per pair;
  - the ground motion: the record's samples linearly interpolated (`Path` time series), then
    the ground at rest;
  - collapse (physics.md section 12): a building leaves the scene at the end of the step in
    which one of its storeys reaches the limit (stepping one step at a time once a standing
    building is past half of it): its contact elements and its own elements are removed
    (`remove element`), its leaning column's `equalDOF` ties too (`remove mp`), and every free
    DOF of its nodes is fixed, so it stands frozen out of the equations and its runaway cannot
    stop the analysis; the others go on to the end of the record and tail. pound takes it out at
    t_c, inside the step: the same for its neighbours where its contacts are open through that
    step (the script prints the largest contact force there).

The model is checked before any scene runs (printed, and written to the file's [checks]): (a)
an eigen analysis after gravity of an elastic P-Delta SDOF gives T0 / sqrt(1 - theta), and of
each scene's P-Delta frames the periods of (K0 - K_G, M) from numpy; (b) a static pushover
(displacement control) of an elastic-perfectly-plastic P-Delta SDOF rises with slope k - P/h to
F_y (1 - theta) and then falls with slope -P/h; (c) a building leaving the scene leaves its
neighbour as it was: scene I with the two 1 m apart (never touching) at dt 1e-3, against each
building alone, the neighbour's displacements over the whole run and the frame's up to its
collapse are the same (to 1e-12 of their peaks; measured: to the bit).

OpenSees integrates with Newmark average acceleration (Newton, NormDispIncr 1e-12) at two steps
(dt and dt / 2) so the file states its own error. Peaks are over the recorded steps (for a
collapsed building and its contacts, over the steps before t_c and the values interpolated at
t_c; for the others, over the whole run). Residual drift (buildings that stand): each storey's
drift at the end of the free tail (with P-Delta, at rest `k (d - p) = P d / h`, so
`d = p / (1 - theta)`). Reported per building: peak interstorey drift ratio, residual drift
ratio per storey (signed) and per level the peak contact force; per scene whether it collapsed
and when, where.

Set-up (OpenSees 3.8 needs Python 3.12), from the repository root:
    PYENV_VERSION=3.12.1 python3.12 -m venv /tmp/ospy && /tmp/ospy/bin/pip install openseespy numpy
    /tmp/ospy/bin/python benches/opensees_pdelta.py [--dt 2e-4] [--check]

`--check` runs only the checks. Records are read from POUND_RECORDS_DIR (default
../shared/records), never copied.
"""

import argparse
import math
import os
import sys
import tempfile
import time
from importlib.metadata import version

import numpy as np

# The elastic cross-check's record reader, Rayleigh coefficients (5 % on the initial modes 1 and
# 2), shared floor levels and TOML lists; the inelastic one's two-column reader.
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from opensees_inelastic import read_time_acc  # noqa: E402
from opensees_multistorey import G, K_CONTACT, XI, levels, rayleigh, read_at2, toml_list  # noqa: E402

TAIL_S = 60.0
COLLAPSE_DRIFT_RATIO = 0.10
# The leaning column: axially rigid, (almost) no bending stiffness.
LEAN_E, LEAN_A, LEAN_I = 2.0e11, 1.0, 1.0e-16


def read_values(path, dt):
    """One value per line (g), no header: dt from the record's scripts (SOURCES.md)."""
    return dt, [float(line) for line in open(path) if line.strip()]


def building(masses, stiffness, heights, fy=None, b=None, ratio=None):
    """fy: yield force per storey (None: elastic), b: post-yield ratio per storey, ratio: the
    gravity mass ratio of a P-Delta building (None: no P-Delta)."""
    return {
        "masses": masses,
        "stiffness": stiffness,
        "heights": heights,
        "fy": fy,
        "b": b,
        "ratio": ratio,
    }


def stiffness_matrix(ks):
    n = len(ks)
    k = np.zeros((n, n))
    for j, kj in enumerate(ks):
        k[j, j] += kj
        if j > 0:
            k[j - 1, j - 1] += kj
            k[j - 1, j] -= kj
            k[j, j - 1] -= kj
    return k


def storey_gravity(b):
    """P_j: the gravity each storey carries, g r sum_{i >= j} m_i."""
    return [G * b["ratio"] * sum(b["masses"][j:]) for j in range(len(b["masses"]))]


def periods(b, p_delta):
    """Periods of (K0, M) or, with p_delta, of (K0 - K_G, M), ascending."""
    k = stiffness_matrix(b["stiffness"])
    if p_delta:
        k = k - stiffness_matrix([p / h for p, h in zip(storey_gravity(b), b["heights"])])
    w2 = np.sort(np.linalg.eigvals(np.linalg.solve(np.diag(b["masses"]), k)).real)
    return [2 * math.pi / math.sqrt(x) for x in w2]


def thetas(b):
    return [p / (k * h) for p, k, h in zip(storey_gravity(b), b["stiffness"], b["heights"])]


SCENES = [
    {
        "name": "G_one_storey_p_delta_yielding",
        "record": "elcentro1940_ns_peknold_0.02s.AT2",
        "seconds": 15.0,
        "pga_g": 0.35,
        "buildings": [
            # T0 1.0 s, h 3.5 m: theta = g / (w^2 h) = 0.071; strength 0.15 W.
            building(
                [3.0e5],
                [3.0e5 * (2 * math.pi) ** 2],
                [3.5],
                [0.15 * G * 3.0e5],
                [0.02],
                1.0,
            ),
            building([2.0e5], [2.0e5 * (2 * math.pi / 0.4) ** 2], [3.5]),
        ],
        "gaps": [1.0],
    },
    {
        "name": "H_3_p_delta_leaning_beside_4",
        "record": "sanfernando1971_pacoima_RSN77_PUL254_timeacc.csv",
        "seconds": 12.0,
        "pga_g": 0.5,
        "buildings": [
            building(
                [3.0e5, 3.0e5, 2.5e5],
                [5.0e7, 5.0e7, 4.0e7],
                [4.0, 3.5, 3.5],
                [5.0e7 * 0.008 * 4.0, 5.0e7 * 0.008 * 3.5, 4.0e7 * 0.008 * 3.5],
                [0.03, 0.03, 0.03],
                2.0,
            ),
            building([2.5e5] * 4, [4.0e8] * 4, [4.0, 3.5, 3.5, 3.5]),
        ],
        "gaps": [0.03],
    },
    {
        "name": "I_collapse_2_soft_p_delta",
        "record": "tabas1978_FN_opensees_tabasFN.txt",
        "record_dt_s": 0.02,
        "seconds": 20.0,
        "pga_g": 0.8,
        "buildings": [
            building([2.5e5, 2.5e5], [3.5e8, 3.5e8], [4.0, 3.5]),
            building(
                [3.0e5, 2.5e5],
                [6.0e7, 1.2e8],
                [4.0, 3.5],
                [6.0e7 * 0.006 * 4.0, 1.2e8 * 0.006 * 3.5],
                [0.01, 0.01],
                3.0,
            ),
        ],
        "gaps": [0.02],
    },
]


def build(ops, buildings, gaps=None):
    """The scene's model with gravity applied and held (LoadConst); returns the floor nodes per
    building, the contact elements with the pair each joins (its left building, from 0) and per
    building what takes it out of the scene at its collapse: its elements and, per node, the
    DOFs that are free (to fix) and whether an equalDOF constrains it (to remove)."""
    ops.wipe()
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    ops.geomTransf("PDelta", 1)
    tags = iter(range(1, 1_000_000))
    floor_nodes, parts = [], []
    gravity = []
    for bi, b in enumerate(buildings):
        a0, a1 = rayleigh(b)
        ground = next(tags)
        # Every node of the frame at one point (zeroLength elements), free only horizontally.
        ops.node(ground, 0.0, 0.0)
        ops.fix(ground, 1, 1, 1)
        nodes = []
        part = {"elements": [], "free": [], "tied": []}
        below = ground
        for j, (mj, kj) in enumerate(zip(b["masses"], b["stiffness"])):
            node = next(tags)
            ops.node(node, 0.0, 0.0)
            ops.fix(node, 0, 1, 1)
            ops.mass(node, mj, 0.0, 0.0)
            nodes.append(node)
            spring, dashpot, storey = next(tags), next(tags), next(tags)
            if b["fy"] is None:
                ops.uniaxialMaterial("Elastic", spring, kj)
            else:
                ops.uniaxialMaterial("Steel01", spring, b["fy"][j], kj, b["b"][j])
            ops.uniaxialMaterial("Viscous", dashpot, a1 * kj, 1.0)
            ops.uniaxialMaterial("Parallel", storey, spring, dashpot)
            ele = next(tags)
            ops.element("zeroLength", ele, below, node, "-mat", storey, "-dir", 1)
            anchor, mass_dashpot = next(tags), next(tags)
            ops.node(anchor, 0.0, 0.0)
            ops.fix(anchor, 1, 1, 1)
            ops.uniaxialMaterial("Viscous", mass_dashpot, a0 * mj, 1.0)
            dashpot_ele = next(tags)
            ops.element("zeroLength", dashpot_ele, anchor, node, "-mat", mass_dashpot, "-dir", 1)
            part["elements"] += [ele, dashpot_ele]
            part["free"].append((node, (1, 0, 0)))
            below = node
        floor_nodes.append(nodes)
        if b["ratio"] is not None:
            # The leaning column, off to the side at x = 10 (bi + 1): massless, pinned base.
            x = 10.0 * (bi + 1)
            base = next(tags)
            ops.node(base, x, 0.0)
            ops.fix(base, 1, 1, 1)
            z, below = 0.0, base
            for j, (mj, h) in enumerate(zip(b["masses"], b["heights"])):
                z += h
                node = next(tags)
                ops.node(node, x, z)
                ops.fix(node, 0, 0, 1)
                ele = next(tags)
                ops.element("elasticBeamColumn", ele, below, node, LEAN_A, LEAN_E, LEAN_I, 1)
                ops.equalDOF(nodes[j], node, 1)
                gravity.append((node, G * mj * b["ratio"]))
                part["elements"].append(ele)
                part["free"].append((node, (1, 1, 0)))
                part["tied"].append(node)
                below = node
        parts.append(part)
    contacts = []
    if gaps is not None:
        for a, fa, fb in levels({"buildings": buildings}):
            gap_mat, ele = next(tags), next(tags)
            ops.uniaxialMaterial("ElasticPPGap", gap_mat, K_CONTACT, -1e30, -gaps[a])
            ops.element("zeroLength", ele, floor_nodes[a][fa], floor_nodes[a + 1][fb], "-mat", gap_mat, "-dir", 1)
            contacts.append((ele, a))
    ops.constraints("Plain")
    ops.numberer("RCM")
    ops.system("BandGeneral")
    ops.test("NormDispIncr", 1e-12, 50)
    ops.algorithm("Newton")
    if gravity:
        ops.timeSeries("Linear", 100)
        ops.pattern("Plain", 100, 100)
        for node, p in gravity:
            ops.load(node, 0.0, -p, 0.0)
        ops.integrator("LoadControl", 1.0)
        ops.analysis("Static")
        if ops.analyze(1) != 0:
            raise RuntimeError("gravity analysis failed")
        ops.loadConst("-time", 0.0)
        ops.wipeAnalysis()
        ops.constraints("Plain")
        ops.numberer("RCM")
        ops.system("BandGeneral")
        ops.test("NormDispIncr", 1e-12, 50)
        ops.algorithm("Newton")
    for nodes in floor_nodes:
        for n in nodes:
            assert ops.nodeDisp(n, 1) == 0.0, "gravity alone moved a floor sideways"
    return floor_nodes, contacts, parts


def check_period(ops, b):
    """(OpenSees periods after gravity, numpy's of (K0 - K_G, M)) of building b alone."""
    build(ops, [b])
    lam = ops.eigen("-fullGenLapack", len(b["masses"]))
    ops.wipe()
    return [2 * math.pi / math.sqrt(x) for x in lam], periods(b, True)


def check_pushover(ops, b, to_ductility=6.0, steps=600):
    """Static pushover of a one-storey P-Delta building b after gravity: (drift, lateral load)."""
    floor_nodes, _, _ = build(ops, [b])
    node = floor_nodes[0][0]
    ops.timeSeries("Linear", 200)
    ops.pattern("Plain", 200, 200)
    ops.load(node, 1.0, 0.0, 0.0)
    dy = b["fy"][0] / b["stiffness"][0]
    ops.integrator("DisplacementControl", node, 1, to_ductility * dy / steps)
    ops.analysis("Static")
    u, f = [0.0], [0.0]
    for _ in range(steps):
        if ops.analyze(1) != 0:
            raise RuntimeError("pushover failed")
        u.append(ops.nodeDisp(node, 1))
        f.append(ops.getLoadFactor(200))
    ops.wipe()
    return np.array(u), np.array(f)


def closed_form_checks(ops):
    """(a) periods after gravity, (b) the pushover's slopes: printed, and returned as TOML."""
    out = []
    say = lambda s: print(s, file=sys.stderr)  # noqa: E731
    say("Closed-form checks of the OpenSees P-Delta model:")
    # (a) An elastic SDOF: T0 1 s, h 3.5 m, theta = g / (w0^2 h) = 0.071, then r = 3 (0.213).
    worst = 0.0
    for r in (1.0, 3.0):
        m, t0, h = 3.0e5, 1.0, 3.5
        b = building([m], [m * (2 * math.pi / t0) ** 2], [h], ratio=r)
        theta = thetas(b)[0]
        os_t, _ = check_period(ops, b)
        closed = t0 / math.sqrt(1 - theta)
        rel = abs(os_t[0] - closed) / closed
        worst = max(worst, rel)
        say(
            f"  (a) SDOF T0 {t0} s, theta {theta:.6f}: OpenSees T {os_t[0]:.12f} s, "
            f"T0 / sqrt(1 - theta) {closed:.12f} s, relative difference {rel:.1e}"
        )
        out += [
            "[[checks.period_sdof]]",
            f"t0_s = {t0!r}",
            f"theta = {theta!r}",
            f"opensees_period_s = {os_t[0]!r}",
            f"closed_form_period_s = {closed!r}",
        ]
    # Each scene's P-Delta frames: OpenSees' eigen periods against numpy's of (K0 - K_G, M).
    for scene in SCENES:
        for k, b in enumerate(scene["buildings"]):
            if b["ratio"] is None or len(b["masses"]) == 1:
                continue
            os_t, np_t = check_period(ops, b)
            rel = max(abs(x - y) / y for x, y in zip(os_t, np_t))
            worst = max(worst, rel)
            say(
                f"  (a) {scene['name']} building {k + 1}: OpenSees periods "
                f"{', '.join(f'{x:.9f}' for x in os_t)} s; (K0 - K_G, M): "
                f"{', '.join(f'{x:.9f}' for x in np_t)} s (K0 alone: "
                f"{', '.join(f'{x:.6f}' for x in periods(b, False))} s); largest relative "
                f"difference {rel:.1e}"
            )
            out += [
                "[[checks.period_frame]]",
                f'scene = "{scene["name"]}"',
                f"building = {k + 1}",
                f"opensees_periods_s = {toml_list(os_t)}",
                f"p_delta_periods_s = {toml_list(np_t)}",
                f"k0_periods_s = {toml_list(periods(b, False))}",
            ]
    # (b) The pushover of an elastic-perfectly-plastic SDOF with P-Delta.
    m, t0, h = 3.0e5, 1.0, 3.5
    k0 = m * (2 * math.pi / t0) ** 2
    fy = 0.15 * G * m
    b = building([m], [k0], [h], [fy], [0.0], 2.0)
    theta = thetas(b)[0]
    p = storey_gravity(b)[0]
    u, f = check_pushover(ops, b)
    dy = fy / k0
    pre = u < 0.9 * dy
    post = u > 1.5 * dy
    slope_pre = np.polyfit(u[pre], f[pre], 1)[0]
    slope_post, icpt = np.polyfit(u[post], f[post], 1)
    peak = float(np.max(f))
    err_pre = abs(slope_pre - (k0 - p / h)) / k0
    err_post = abs(slope_post - (-p / h)) / (p / h)
    err_peak = abs(peak - fy * (1 - theta)) / fy
    err_icpt = abs(icpt - fy) / fy
    say(
        f"  (b) EPP SDOF pushover, theta {theta:.6f}: elastic slope {slope_pre:.6e} N/m "
        f"(k - P/h = {k0 - p / h:.6e}, difference {err_pre:.1e} of k), post-yield slope "
        f"{slope_post:.6e} N/m (-P/h = {-p / h:.6e}, difference {err_post:.1e}), peak "
        f"{peak:.6e} N (F_y (1 - theta) = {fy * (1 - theta):.6e}, {err_peak:.1e} of F_y), "
        f"post-yield line at zero drift {icpt:.6e} N (F_y = {fy:.6e}, {err_icpt:.1e})"
    )
    worst = max(worst, err_pre, err_post, err_peak, err_icpt)
    out += [
        "[checks.pushover_epp]",
        f"theta = {theta!r}",
        f"stiffness_n_per_m = {k0!r}",
        f"gravity_n = {p!r}",
        f"height_m = {h!r}",
        f"yield_force_n = {fy!r}",
        f"elastic_slope_n_per_m = {float(slope_pre)!r}",
        f"post_yield_slope_n_per_m = {float(slope_post)!r}",
        f"peak_n = {peak!r}",
    ]
    if worst > 1e-9:
        raise RuntimeError(f"the OpenSees P-Delta model misses a closed form by {worst:.1e}")
    say(f"  worst relative difference {worst:.1e}")
    return out


def leave_scene(ops, part, contacts, k):
    """Building k leaves the scene at its collapse (physics.md section 12): its contacts end, and
    its own elements go too (storeys, dashpots, leaning column), so its runaway cannot stop the
    analysis; its leaning column's equalDOF ties go and every free DOF of its nodes is fixed, so
    none of its DOFs is left in the equations (it stands frozen). The others' state carries on:
    the analysis sets itself up again and Newmark::domainChanged reads the committed
    displacements, velocities and accelerations back."""
    for ele, a in contacts:
        if k in (a, a + 1):
            ops.remove("element", ele)
    for ele in part["elements"]:
        ops.remove("element", ele)
    for node in part["tied"]:
        ops.remove("mp", node)
    for node, dofs in part["free"]:
        ops.fix(node, *dofs)


def simulate(ops, tmp, scene, ag, dt_rec, dt, duration, tail=TAIL_S):
    """The scene through the record and the tail, each building leaving at its collapse. Returns
    the times, the floor displacements (building by building; a collapsed building's frozen after
    it left), |force| per contact (0 once it ended), the contacts and, per collapsed building, the
    step at whose end it left."""
    buildings = scene["buildings"]
    floor_nodes, contacts, parts = build(ops, buildings, scene["gaps"])
    # The record, then the ground at rest through the tail.
    values = list(ag) + [0.0, 0.0]
    ops.timeSeries("Path", 1, "-dt", dt_rec, "-values", *values, "-factor", 1.0)
    ops.pattern("UniformExcitation", 1, 1, "-accel", 1)
    ops.integrator("Newmark", 0.5, 0.25)
    ops.analysis("Transient")
    all_nodes = [n for ns in floor_nodes for n in ns]
    # One recorder phase per stretch between collapses: an element recorder must not outlive the
    # contacts it reads, so the recorders are replaced at each collapse.
    live = list(range(len(contacts)))
    phases = []

    def record():
        disp = os.path.join(tmp, f"disp{len(phases)}.txt")
        force = os.path.join(tmp, f"force{len(phases)}.txt")
        ops.recorder(
            "Node", "-file", disp, "-precision", 14, "-time", "-node", *all_nodes, "-dof", 1, "disp"
        )
        if live:
            eles = [contacts[i][0] for i in live]
            ops.recorder("Element", "-file", force, "-precision", 14, "-ele", *eles, "force")
        phases.append((disp, force, list(live)))

    def largest_drift(k):
        out, below = 0.0, 0.0
        for n, h in zip(floor_nodes[k], buildings[k]["heights"]):
            u = ops.nodeDisp(n, 1)
            out = max(out, abs(u - below) / h)
            below = u
        return out

    record()
    steps = int(round((duration + tail) / dt))
    # In chunks of 0.05 s, step by step once a standing building is past half the collapse drift,
    # so a building leaves at the end of the step in which it reaches the limit.
    chunk = int(round(0.05 / dt))
    standing = list(range(len(buildings)))
    left = {}
    done = 0
    while done < steps and standing:
        near = any(largest_drift(k) >= 0.5 * COLLAPSE_DRIFT_RATIO for k in standing)
        n = 1 if near else min(chunk, steps - done)
        if ops.analyze(n, dt) != 0:
            raise RuntimeError(f"OpenSees failed on {scene['name']} near t = {done * dt:.2f} s")
        done += n
        crossed = [k for k in standing if largest_drift(k) >= COLLAPSE_DRIFT_RATIO]
        if crossed and n > 1:
            raise RuntimeError(
                f"{scene['name']}: building {crossed[0] + 1} reached the collapse drift inside a "
                f"chunk of {n} steps (t = {done * dt:.2f} s): shorten the chunk"
            )
        if crossed:
            ops.remove("recorders")
            for k in crossed:
                leave_scene(ops, parts[k], contacts, k)
                live = [i for i in live if k not in (contacts[i][1], contacts[i][1] + 1)]
                standing.remove(k)
                left[k] = done
            if standing:
                record()
    ops.wipe()
    nc = len(contacts)
    t, u, f = [np.zeros(1)], [np.zeros((1, len(all_nodes)))], [np.zeros((1, nc))]
    for disp, force, cols in phases:
        if os.path.getsize(disp) == 0:
            continue
        rows = np.loadtxt(disp, ndmin=2)
        t.append(rows[:, 0])
        u.append(rows[:, 1:])
        fp = np.zeros((rows.shape[0], nc))
        if cols:
            fr = np.loadtxt(force, ndmin=2)
            per = fr.shape[1] // len(cols)  # global forces at both nodes: 2 x 3 per element
            fp[:, cols] = np.abs(fr[:, [per * i for i in range(len(cols))]])
        f.append(fp)
    t, u, f = np.concatenate(t), np.vstack(u), np.vstack(f)
    if len(t) != done + 1 or np.any(np.diff(t) <= 0):
        raise RuntimeError(f"{scene['name']}: the recorders hold {len(t) - 1} steps, not {done}")
    return t, u, f, contacts, left


def run_opensees(ops, tmp, scene, ag, dt_rec, dt, duration, tail=TAIL_S):
    """Peak contact forces, peak drift ratios and residual drift ratios per building (None for
    a collapsed one), and the collapses (time, building, storey, drift rate there), by time."""
    t, u, f, contacts, left = simulate(ops, tmp, scene, ag, dt_rec, dt, duration, tail)
    # Drift ratios, storey by storey (building by building).
    ratios = []
    col = 0
    for b in scene["buildings"]:
        n = len(b["masses"])
        ub = u[:, col : col + n]
        col += n
        below = np.hstack([np.zeros((ub.shape[0], 1)), ub[:, :-1]])
        ratios.append((ub - below) / np.array(b["heights"]))
    # Each collapse: the first step at which some |d_j| / h_j of the building reaches the limit
    # (the step at whose end it left); the time each storey crosses it inside that step, by
    # linear interpolation, the earliest of them. Its peaks, and those of its contacts, are over
    # [0, t_c]: the steps before it and the values interpolated at t_c. The others' are over the
    # whole run.
    forces = [f[:, c] for c in range(f.shape[1])]
    collapses = []
    for k, step in sorted(left.items(), key=lambda x: x[1]):
        r = np.abs(ratios[k])
        i = int(np.nonzero(np.max(r, axis=1) >= COLLAPSE_DRIFT_RATIO)[0][0])
        if i != step:
            raise RuntimeError(f"{scene['name']}: building {k + 1} left at step {step}, not {i}")
        best = None
        for c in range(r.shape[1]):
            a, b_ = r[i - 1, c], r[i, c]
            if b_ >= COLLAPSE_DRIFT_RATIO:
                s = (COLLAPSE_DRIFT_RATIO - a) / (b_ - a)
                if best is None or s < best[0]:
                    best = (s, c)
        s, c = best
        tc = t[i - 1] + s * (t[i] - t[i - 1])
        # The drift ratio's rate there: how a drift error maps to a time error.
        rate = (r[i, c] - r[i - 1, c]) / (t[i] - t[i - 1])
        # It left at t_i, not t_c: the same for its neighbours where its contacts are open
        # through that step (printed).
        mine = [e for e, (_, a) in enumerate(contacts) if k in (a, a + 1)]
        touching = [float(f[j, e]) for e in mine for j in (i - 1, i)]
        collapses.append((float(tc), k + 1, c + 1, float(rate), max(touching, default=0.0)))
        cut = lambda x: np.concatenate([x[:i], [(1 - s) * x[i - 1] + s * x[i]]])  # noqa: E731
        ratios[k] = np.vstack([ratios[k][:i], (1 - s) * ratios[k][i - 1] + s * ratios[k][i]])
        for e, (_, a) in enumerate(contacts):
            # A contact ends at the earlier collapse of its two buildings.
            if k in (a, a + 1) and len(forces[e]) == len(t):
                forces[e] = cut(forces[e])
    peak_forces = [float(np.max(x)) for x in forces]
    drifts = [float(np.max(np.abs(r))) for r in ratios]
    residuals = [None if k in left else [float(x) for x in r[-1, :]] for k, r in enumerate(ratios)]
    return peak_forces, drifts, residuals, collapses


def ground_motion(records, scene):
    """The scene's record, its first `seconds` scaled to `pga_g`: (ground acceleration m/s^2,
    its dt, npts, the scale, the duration)."""
    path = os.path.join(records, scene["record"])
    if path.endswith(".AT2"):
        dt_rec, acc_g = read_at2(path)
    elif "record_dt_s" in scene:
        dt_rec, acc_g = read_values(path, scene["record_dt_s"])
    else:
        dt_rec, acc_g = read_time_acc(path)
    npts = min(len(acc_g), int(round(scene["seconds"] / dt_rec)) + 1)
    acc_g = acc_g[:npts]
    ipga = max(range(npts), key=lambda i: abs(acc_g[i]))
    scale = scene["pga_g"] / abs(acc_g[ipga])
    return [x * scale * G for x in acc_g], dt_rec, npts, scale, (npts - 1) * dt_rec


def leaving_check(ops, tmp, records, dt=1e-3, gap=1.0):
    """(c) A building that leaves the scene leaves its neighbour as it was: scene I with the
    neighbours 1 m apart (they never touch), run through the record and the tail with the
    collapsing frame leaving at its collapse, against each building alone (the frame's run ends
    at its collapse, nothing being left standing): the neighbour's displacements over the whole
    run and the frame's up to its collapse. Printed, and returned as TOML."""
    scene = next(s for s in SCENES if s["name"].startswith("I_"))
    ag, dt_rec, _, _, duration = ground_motion(records, scene)
    far = dict(scene, gaps=[gap])
    t, u, f, _, left = simulate(ops, tmp, far, ag, dt_rec, dt, duration)
    alone = [
        simulate(ops, tmp, dict(scene, buildings=[b], gaps=[]), ag, dt_rec, dt, duration)
        for b in scene["buildings"]
    ]
    if np.any(f != 0.0) or sorted(left) != [1] or sorted(alone[1][4]) != [0]:
        raise RuntimeError("the leaving check's scene: the frame must collapse, untouched")
    n0 = len(scene["buildings"][0]["masses"])
    t0, u0 = alone[0][0], alone[0][1]
    t1, u1 = alone[1][0], alone[1][1]
    standing = float(np.max(np.abs(u[:, :n0] - u0))) if np.array_equal(t, t0) else math.inf
    frame = math.inf
    if np.array_equal(t[: len(t1)], t1):
        frame = float(np.max(np.abs(u[: len(t1), n0:] - u1)))
    peak0, peak1 = float(np.max(np.abs(u0))), float(np.max(np.abs(u1)))
    print(
        f"  (c) scene I, gap {gap} m, dt {dt}: the frame leaves at t = {t[left[1]]:.4f} s; the "
        f"neighbour over {t[-1]:.1f} s against it alone: largest difference {standing:.1e} m "
        f"(its peak {peak0:.3e} m); the frame up to its collapse against it alone {frame:.1e} m",
        file=sys.stderr,
    )
    # The same equations in another order at most (the numberer runs again): rounding.
    if standing > 1e-12 * peak0 or frame > 1e-12 * peak1:
        raise RuntimeError("a building leaving the scene changed its neighbour's response")
    return [
        "[checks.leaving]",
        f'scene = "{scene["name"]}"',
        f"gap_m = {gap!r}",
        f"dt_s = {dt!r}",
        f"left_at_s = {float(t[left[1]])!r}",
        f"run_s = {float(t[-1])!r}",
        f"neighbour_largest_difference_m = {standing!r}",
        f"frame_largest_difference_m = {frame!r}",
    ]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--dt", type=float, default=2e-4, help="OpenSees time step, s (and half of it)")
    ap.add_argument("--check", action="store_true", help="only the closed-form checks")
    ap.add_argument("--scenes", default="", help="only these scenes (first letters, e.g. GI)")
    ap.add_argument("-o", default="tests/data/opensees_pdelta.toml")
    a = ap.parse_args()
    import openseespy.opensees as ops

    checks = closed_form_checks(ops)
    records = os.environ.get("POUND_RECORDS_DIR", "../shared/records")
    with tempfile.TemporaryDirectory() as tmp:
        checks += leaving_check(ops, tmp, records)
    if a.check:
        return 0
    lines = [
        "# Written by benches/opensees_pdelta.py (see its docstring for the conventions).",
        f"# openseespy {version('openseespy')}, Newmark average acceleration at dt and dt / 2.",
        f"contact_k_n_per_m = {K_CONTACT!r}",
        f"damping_ratio = {XI!r}",
        f"g_m_s2 = {G!r}",
        f"collapse_drift_ratio = {COLLAPSE_DRIFT_RATIO!r}",
        f"tail_s = {TAIL_S!r}",
        f"dt_fine_s = {a.dt / 2!r}",
        f"dt_coarse_s = {a.dt!r}",
        "",
    ]
    with tempfile.TemporaryDirectory() as tmp:
        for scene in SCENES:
            if a.scenes and scene["name"][0] not in a.scenes:
                continue
            ag, dt_rec, npts, scale, duration = ground_motion(records, scene)
            results = {}
            for dt in (a.dt, a.dt / 2):
                t = time.perf_counter()
                results[dt] = run_opensees(ops, tmp, scene, ag, dt_rec, dt, duration)
                forces, drifts, residuals, collapses = results[dt]
                print(
                    f"{scene['name']}: dt {dt:g}: {time.perf_counter() - t:.1f} s: peak drift "
                    f"{drifts}, peak force {forces}, residual {residuals}, collapses (t_c, "
                    f"building, storey, drift rate, largest force of its contacts over the step "
                    f"it left in) {collapses}",
                    file=sys.stderr,
                )
            coarse, fine = results[a.dt], results[a.dt / 2]
            if [c[1:3] for c in coarse[3]] != [c[1:3] for c in fine[3]]:
                raise RuntimeError(f"{scene['name']}: dt and dt / 2 disagree on the collapse")
            if len(fine[3]) > 1:
                raise RuntimeError(f"{scene['name']}: the file holds one collapse per scene")
            collapse, collapse_coarse = (fine[3][0], coarse[3][0]) if fine[3] else (None, None)
            names = [f"b{a_ + 1}f{fa + 1}_b{a_ + 2}f{fb + 1}" for a_, fa, fb in levels(scene)]
            lines += [
                "[[scene]]",
                f'name = "{scene["name"]}"',
                f'record = "{scene["record"]}"',
            ]
            if "record_dt_s" in scene:
                lines.append(f"record_dt_s = {scene['record_dt_s']!r}")
            lines += [
                f"npts = {npts}",
                f"scale = {scale!r}",
                f"gaps_m = {toml_list(scene['gaps'])}",
                "levels = [" + ", ".join(f'"{n}"' for n in names) + "]",
                f"peak_force_n = {toml_list(fine[0])}",
                f"peak_force_n_coarse = {toml_list(coarse[0])}",
                f"peak_drift_ratio = {toml_list(fine[1])}",
                f"peak_drift_ratio_coarse = {toml_list(coarse[1])}",
                f"collapsed = {'true' if collapse else 'false'}",
            ]
            if collapse:
                lines += [
                    f"collapse_time_s = {collapse[0]!r}",
                    f"collapse_time_s_coarse = {collapse_coarse[0]!r}",
                    f"collapse_building = {collapse[1]}",
                    f"collapse_storey = {collapse[2]}",
                    f"collapse_drift_rate_per_s = {collapse[3]!r}",
                ]
            for b, r, rc in zip(scene["buildings"], fine[2], coarse[2]):
                lines += [
                    "[[scene.building]]",
                    f"masses_kg = {toml_list(b['masses'])}",
                    f"stiffness_n_per_m = {toml_list(b['stiffness'])}",
                    f"heights_m = {toml_list(b['heights'])}",
                    f"period_s = {periods(b, False)[0]!r}",
                ]
                if b["ratio"] is not None:
                    lines += [
                        f"gravity_mass_ratio = {b['ratio']!r}",
                        f"stability_coefficient = {toml_list(thetas(b))}",
                        f"p_delta_period_s = {periods(b, True)[0]!r}",
                    ]
                if b["fy"] is not None:
                    lines += [
                        f"yield_force_n = {toml_list(b['fy'])}",
                        f"post_yield_ratio = {toml_list(b['b'])}",
                    ]
                    if r is not None:
                        lines += [
                            f"residual_drift_ratio = {toml_list(r)}",
                            f"residual_drift_ratio_coarse = {toml_list(rc)}",
                        ]
            lines.append("")
    lines += checks + [""]
    os.makedirs(os.path.dirname(a.o), exist_ok=True)
    with open(a.o, "w") as f:
        f.write("\n".join(lines))
    print(f"wrote {a.o}", file=sys.stderr)


if __name__ == "__main__":
    sys.exit(main())
