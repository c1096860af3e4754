"""The examples run as scripts from a fresh install: the notebook draws its figures, the
pelicun example takes its collapse fragility from the fits table."""

import os
import subprocess
import sys

from conftest import REPO


def run_example(name, tmp_path):
    """Run `python/examples/NAME` as a script in `tmp_path`, its files there; it must succeed."""
    env = dict(os.environ, MPLBACKEND="Agg", POUNDING_EXAMPLE_OUT=str(tmp_path))
    done = subprocess.run(
        [sys.executable, str(REPO / "python/examples" / name)],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    return done


def test_the_example_notebook_runs(tmp_path):
    done = run_example("notebook.py", tmp_path)
    for figure in ("drift-against-gap.png", "fragility.png", "trace.png"):
        assert (tmp_path / figure).stat().st_size > 10_000, figure
    assert "| slight (0.005) |" in done.stdout


def test_the_pelicun_example_takes_its_collapse_fragility_from_the_fits_table(tmp_path):
    done = run_example("pelicun_losses.py", tmp_path)
    assert (tmp_path / "pelicun/DL_summary_stats.csv").stat().st_size > 100
    # pelicun's share of collapsed realizations (1000 draws) against the fitted fragility at
    # the level: within 0.06 (4 standard deviations of the draws).
    last = done.stdout.strip().splitlines()[-1].split()
    share, fragility = float(last[2]), float(last[9])
    assert 0.1 < fragility < 0.9, last
    assert abs(share - fragility) < 0.06, last
