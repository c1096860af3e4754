"""Ctrl-C: every long call stops within 2 s of SIGINT and raises KeyboardInterrupt, on the shipped
configs whose calls run longest (the CPU looks at the stop before each run, the gap study before
each response and each run, the GPU before each dispatch, sized to about 0.2 s while a stop is
watched; a study of a table is left to end in the background)."""

import signal
import subprocess
import sys
import textwrap
import time

import pytest

from conftest import CONFIGS, REPO

# (call, config): each runs for longer than the signal's delay, one run or response at a time
# well under the bound (python/tests measures each: README, "Python").
LONG_CALLS = [
    # On one thread these last 1.9 s to 2.5 s on an idle two-core machine; the other shipped
    # configs end within 0.9 s there (row-of-five 0.8 s, floor-column 0.6 s, gap-study's gap
    # study 0.6 s), inside the bound whatever Ctrl-C does.
    ("sweep", "collapse-fragility.toml"),
    ("gap", "collapse-fragility.toml"),
    ("sweep", "fragility-sa.toml"),
    # A study of a table takes no stop flag: the call answers Ctrl-C at once, its work dropped.
    ("fragility", "inelastic-fragility.toml"),
    # On the GPU (CI: lavapipe) each of these is one chunk, which took 5.6 s to 8.3 s to stop
    # when the GPU looked at the stop only between chunks; `row-of-five` 3.5 s while its kernel
    # was built in one call no flag could cut short (a watched build is now left at the stop).
    ("sweep-gpu", "fragility-sa.toml"),
    ("sweep-gpu", "collapse-fragility.toml"),
    ("sweep-gpu", "floor-column.toml"),
    ("sweep-gpu", "row-of-five.toml"),
]

CALLS = {
    # One thread: each call lasts several times the signal's delay on any machine CI runs on.
    "sweep": 'pounding.sweep(config, backend="cpu", threads=1, progress=False)',
    "sweep-gpu": 'pounding.sweep(config, backend="gpu", progress=False)',
    "gap": "pounding.gap(config, threads=1)",
    # 100,000 bootstrap replicates of four damage states: about 15 s.
    "fragility": 'pounding.fragility(runs, edp="b1_peak_drift_ratio", '
    'damage_states="hazus-c1l-high", bootstrap=100_000, seed=1)',
}

# What a call needs before it starts (not timed).
SETUP = {"fragility": 'runs = pounding.sweep(config, backend="cpu", progress=False)'}

# SIGINT this long after the call starts (on the GPU, while lavapipe builds the kernel, which a
# watched call leaves at the stop); the bound README states.
DELAY_S = 0.3
BOUND_S = 2.0


@pytest.mark.parametrize("call, config", LONG_CALLS)
def test_sigint_stops_a_long_call_within_the_bound(call, config):
    script = textwrap.dedent(
        f"""
        import sys, warnings, pounding
        warnings.simplefilter("ignore")
        config = r"{CONFIGS / config}"
        {SETUP.get(call, "")}
        print("started", flush=True)
        try:
            {CALLS[call]}
        except KeyboardInterrupt:
            print("interrupted", flush=True)
            sys.exit(3)
        print("finished", flush=True)
        """
    )
    proc = subprocess.Popen(
        [sys.executable, "-c", script],
        cwd=REPO,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert proc.stdout.readline().strip() == "started"
        time.sleep(DELAY_S)
        assert proc.poll() is None, f"{call} on {config} ended before it could be interrupted"
        sent = time.monotonic()
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=120)
        stopped = time.monotonic() - sent
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 3, (out, err)
    assert "interrupted" in out
    # The interrupt, not a device error.
    assert "GpuError" not in err, err
    print(f"{call} {config}: stopped {stopped:.2f} s after SIGINT")
    assert stopped < BOUND_S, f"{call} on {config} took {stopped:.2f} s to stop"
