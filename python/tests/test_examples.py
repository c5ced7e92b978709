"""The Python examples (examples/python/) run and pass their own checks, on small sizes; their
plots are written."""

import os
import subprocess
import sys

import pytest

EXAMPLES = os.path.join(os.path.dirname(__file__), "..", "..", "examples", "python")


@pytest.mark.parametrize(
    "script,args,plot",
    [
        ("sort_trajectories.py", ["--n", "8", "--seed", "4"], "--out"),
        ("kdtree_range.py", ["--n", "300", "--queries", "40", "--times", "0.5", "3.0"], None),
        ("table1.py", ["--n", "49"], "--plot"),
    ],
)
def test_example_runs(tmp_path, script, args, plot):
    command = [sys.executable, os.path.join(EXAMPLES, script)] + args
    if plot:
        command += [plot, str(tmp_path / "plot.png")]
    env = dict(os.environ, MPLBACKEND="Agg")
    done = subprocess.run(command, capture_output=True, text=True, timeout=300, env=env)
    assert done.returncode == 0, done.stdout + done.stderr
    if plot:
        assert (tmp_path / "plot.png").stat().st_size > 1000
