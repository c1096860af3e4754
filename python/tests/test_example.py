"""The example notebook runs as a script from a fresh install and draws its figures."""

import os
import subprocess
import sys

from conftest import REPO


def test_the_example_notebook_runs(tmp_path):
    env = dict(os.environ, MPLBACKEND="Agg", POUNDING_EXAMPLE_OUT=str(tmp_path))
    done = subprocess.run(
        [sys.executable, str(REPO / "python/examples/notebook.py")],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    for figure in ("drift-against-gap.png", "fragility.png", "trace.png"):
        assert (tmp_path / figure).stat().st_size > 10_000, figure
    assert "| slight (0.005) |" in done.stdout
