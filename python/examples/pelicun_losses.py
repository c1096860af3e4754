# %% [markdown]
# # Repair losses of a pounding frame with pelicun, from a sweep
#
# `pounding` runs the collapse study (`configs/collapse-fragility.toml`: a 3-storey frame
# beside a 6-storey one, 600 runs over twelve Sa(T1) levels); `pound fragility` fits building
# 1's collapse fragility and hands it over as data; `pound demands` writes building 1's demands
# at one intensity in the SimCenter format; pelicun (SimCenter's FEMA P-58 loss engine) takes
# both and computes repair costs, with no number copied by hand. Run it as a script
# (`python python/examples/pelicun_losses.py`); files go to `POUNDING_EXAMPLE_OUT` (default: the
# working folder).

# %%
import json
import os
from pathlib import Path

import pyarrow as pa
from pelicun.tools.DL_calculation import run_pelicun

import pounding

G = 9.80665  # standard gravity, m/s^2 per g
out = Path(os.environ.get("POUNDING_EXAMPLE_OUT", "."))
out.mkdir(parents=True, exist_ok=True)
repo = Path(__file__).resolve().parents[2]

# %% [markdown]
# ## The sweep, with every storey's and floor's demands

# %%
runs = pounding.sweep(
    repo / "configs/collapse-fragility.toml",
    backend="cpu",
    columns=["+storeys", "+floors"],
    progress=False,
)
print(runs.info["summary"] if "summary" in runs.info else f"{runs.num_rows} runs")

# %% [markdown]
# ## Building 1's collapse fragility, as a table
# The median and beta pelicun's collapse model takes, read from `info["fits"]`: P(building 1
# collapses | Sa(T1)), each run scaled to Sa at its own sampled period.

# %%
(collapse,) = pa.table(pounding.fragility(runs, edp="b1_collapsed").info["fits"]).to_pylist()
print(f"collapse: median Sa(T1) {collapse['median']:.3f} g, beta {collapse['beta']:.3f}")

# %% [markdown]
# ## The demands at Sa(T1) = 0.6 g, and the assessment
# `1-COL-0-1` marks the runs where building 1 collapsed: `CollapseLimits` drops them from the
# demand sample, and pelicun draws collapse from the fragility above on `1-SA_T1-0-1`.

# %%
level = 0.6
demands = out / "demands.csv"
pounding.demands(runs, building=1, where=f"target_sa_g={level}", path=demands)

# Components on each storey (direction 1, the direction of the sweep's motion): reinforced
# concrete moment frame joints and gypsum partitions on drift, suspended ceilings on floor
# acceleration; quantities of a 3-storey office bay.
components = out / "components.csv"
components.write_text(
    "ID,Units,Location,Direction,Theta_0,Blocks,Family,Theta_1,Comment\n"
    "B.10.41.002b,ea,1--3,1,3,3,,,24x36 ACI 318 SMF beam on both sides\n"
    "C.10.11.001a,ft,1--3,1,300,3,,,Gypsum partition with metal studs full height\n"
    "C.30.32.003b,ft2,all,0,5000,10,,,Suspended ceiling SDC D E\n"
)
config = {
    "GeneralInformation": {"units": {"force": "N", "length": "m", "time": "sec"}},
    "DL": {
        "Asset": {
            "ComponentAssignmentFile": str(components),
            "ComponentDatabase": "FEMA P-58",
            "NumberOfStories": "3",
            "OccupancyType": "COM1",
            "PlanArea": "500",
        },
        "Demands": {
            "DemandFilePath": str(demands),
            "SampleSize": "1000",
            # The runs as they are (resampled), their demands correlated as simulated.
            "Calibration": {"ALL": {"DistributionFamily": "empirical"}},
            "CollapseLimits": {"COL": "0.5"},
        },
        "Damage": {
            "CollapseFragility": {
                "DemandType": "SA_T1",
                "CapacityDistribution": "lognormal",
                # In the config's units (m/s^2 here): the fit's median is in g.
                "CapacityMedian": str(collapse["median"] * G),
                "Theta_1": str(collapse["beta"]),
            },
            "DamageProcess": "FEMA P-58",
            "IrreparableDamage": {"DriftCapacityMedian": "0.015", "DriftCapacityLogStd": "0.3"},
        },
        "Losses": {
            "BldgRepair": {
                "ConsequenceDatabase": "FEMA P-58",
                "MapApproach": "Automatic",
                "ReplacementCost": {"Unit": "USD_2011", "Median": "2000000", "Distribution": "normal", "Theta_1": "0.3"},
                "ReplacementTime": {"Unit": "worker_day", "Median": "2000", "Distribution": "lognormal", "Theta_1": "0.4"},
            }
        },
    },
}
(out / "input.json").write_text(json.dumps(config, indent=2))
run_pelicun(
    str(out / "input.json"),
    str(demands),
    str(out / "pelicun"),
    1000,
    None,
    None,
    ["csv"],
    detailed_results=False,
    coupled_edp=False,
)
summary = (out / "pelicun/DL_summary_stats.csv").read_text()
print(summary)

# %% [markdown]
# The share of realizations that collapsed is the fitted fragility at 0.6 g, drawn per
# realization (each run's own Sa(T1) target is 0.6 g); the others' repair costs come from the
# demands of the runs that stood.

# %%
from math import erf, log, sqrt

rows = {line.split(",")[0]: line.split(",")[1:] for line in summary.splitlines()}
header = summary.splitlines()[0].split(",")[1:]
collapsed = float(rows["mean"][header.index("collapse")])
expected = 0.5 * (1 + erf(log(level / collapse["median"]) / (collapse["beta"] * sqrt(2))))
print(f"collapsed in {collapsed:.3f} of the realizations; the fragility gives {expected:.3f} at {level} g")
