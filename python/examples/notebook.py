# %% [markdown]
# # Pounding of a yielding frame beside a stiff neighbour, from Python
#
# A small fragility study with the `pounding` package: a 6-storey frame whose storeys yield
# (soft first storey) beside a stiff elastic 3-storey building, scaled to the frame's
# Sa(T1) on six synthetic records, four separation gaps. Cells in the percent format: open
# this file in Jupyter (jupytext, VS Code) or run it as a script
# (`python python/examples/notebook.py`); figures go to `POUNDING_EXAMPLE_OUT` (default: the
# working folder).

# %%
import os
import sys
from pathlib import Path

import matplotlib

if "ipykernel" not in sys.modules and not os.environ.get("DISPLAY"):
    matplotlib.use("Agg")  # a script without a display writes files only
import matplotlib.pyplot as plt

import pounding

out = Path(os.environ.get("POUNDING_EXAMPLE_OUT", "."))
out.mkdir(parents=True, exist_ok=True)

# %% [markdown]
# ## The sweep
# A config is a path, a TOML string, or (here) a dict with the same keys (README.md,
# "A config"). 6 records x 6 Sa(T1) levels x 4 gaps = 144 runs.

# %%
frame = {
    "storeys": 6,
    "storey_height_m": [4.0, 3.0, 3.0, 3.0, 3.0, 3.0],
    "mass_kg": 3.0e5,
    "stiffness_profile": [0.5, 1.0, 1.0, 0.9, 0.8, 0.7],
    "period_s": 0.8,
    "damping_ratio": 0.05,
    "yield_drift_ratio": 0.005,
    "post_yield_ratio": 0.03,
    "gap_right_m": [0.0, 0.01, 0.02, 0.04],
}
neighbour = {
    "storeys": 3,
    "storey_height_m": [4.0, 3.0, 3.0],
    "mass_kg": 2.5e5,
    "period_s": 0.25,
    "damping_ratio": 0.05,
}
config = {
    "run": {"tail_s": 2.0},
    "building": [frame, neighbour],
    "contact": {
        "law": "nonlinear_viscoelastic",
        "formula": "ebrahimi",
        "e": 0.65,
        "beta_n_per_m1_5": 2.75e9,
    },
    "record": [
        {"synthetic": {"seed": seed, "duration_s": 12.0, "dt_s": 0.01}} for seed in range(21, 27)
    ],
    "intensity": {"sa_g": [0.1, 0.2, 0.35, 0.5, 0.75, 1.0], "sa_period_s": "building1"},
}

runs = pounding.sweep(config)
print(runs, runs.info["runs_per_second"], "runs/s on", runs.info["engine"])
df = runs.to_pandas()
df[["run", "record", "target_sa_g", "gap_1_2_m", "b1_peak_drift_ratio", "b1_peak_ductility"]].head()

# %% [markdown]
# ## Drift against the gap
# The frame's peak storey drift ratio, median over the records, against the gap, one line per
# Sa(T1).

# %%
median = df.groupby(["target_sa_g", "gap_1_2_m"])["b1_peak_drift_ratio"].median().unstack(0)
ax = median.plot(marker="o")
ax.set_xlabel("gap (m)")
ax.set_ylabel("frame's peak drift ratio (median of 6 records)")
ax.legend(title="Sa(T1) (g)")
plt.savefig(out / "drift-against-gap.png", dpi=110)

# %% [markdown]
# ## Fragility with damage states
# HAZUS-MH's drift limits for a low-rise concrete moment frame (C1L, high code), read on the
# frame's peak drift, fitted by maximum likelihood, with bootstrap bands over the records.

# %%
fragility = pounding.fragility(
    runs,
    im="target_sa_g",
    edp="b1_peak_drift_ratio",
    damage_states="hazus-c1l-high",
    bootstrap=200,
    seed=1,
)
print(fragility.info["report"])
curves = fragility.to_pandas()
curves.head()

# %%
fig, ax = plt.subplots()
for state, group in curves.groupby("state", sort=False):
    ax.plot(group["target_sa_g"], group["fraction"], "o-", label=f"{state} (> {group['threshold'].iloc[0]})")
ax.set_xlabel("Sa(T1) (g)")
ax.set_ylabel("share of runs exceeding")
ax.legend(title="damage state")
plt.savefig(out / "fragility.png", dpi=110)

# %% [markdown]
# ## One run whole
# The time history of the run with the largest frame drift: both roofs against time.

# %%
worst = int(df.loc[df["b1_peak_drift_ratio"].idxmax(), "run"])
history, row = pounding.trace(config, worst)
h = history.to_pandas()
roofs = [c for c in h.columns if c.endswith("_u_m") and ("b1_f6" in c or "b2_f3" in c)]
ax = h.plot(x="t_s", y=roofs)
ax.set_xlabel("t (s)")
ax.set_ylabel("roof displacement (m)")
ax.set_title(f"run {worst}: {row.to_pandas().loc[0, 'impacts']} impacts")
plt.savefig(out / "trace.png", dpi=110)
print("figures in", out.resolve())
