"""kinetic.sweep against a real local Dask cluster of worker processes: the rows equal those of
the same runs one after another in this process (all but the time each took); a worker process
killed while runs are in flight leaves every run written exactly once, with the same rows; a
second sweep over the same file resumes (runs nothing written already); a failing run is a row
with its error, not the end of the sweep."""

import json
import os
import signal
import subprocess
import sys

import pytest

import distributed  # noqa: E402  (Debian python3-distributed, scripts/install-deps.sh)

from kinetic import sweep  # noqa: E402


def without_time(row):
    return {k: v for k, v in row.items() if k != "wall_s"}


def lines(path):
    with open(path, encoding="utf-8") as f:
        return [json.loads(line) for line in f]


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    )
    c = distributed.Client(cluster)
    yield c
    c.close()
    cluster.close()


# Small runs under every scheduler, two sizes and two seeds: 12 runs.
RUNS = sweep.grid(
    dataset="random-linear", n=[40, 80], seed=[1, 2], queries=3, structure="sort",
    scheduler=["robust", "classic", "exact"],
)


def test_rows_equal_the_sequential_runs(tmp_path, client):
    import kinetic

    out = tmp_path / "rows.jsonl"
    rows = kinetic.sweep(RUNS, str(out), client=client, progress=False)  # the module is callable
    sequential = [sweep.execute(run) for run in RUNS]
    assert [without_time(r) for r in rows] == [without_time(r) for r in sequential]
    assert all(r["status"] == "ok" and r["stats"]["events"]["processed"] > 0 for r in rows)
    written = lines(out)
    assert sorted(r["key"] for r in written) == sorted(sweep.key_of(r) for r in RUNS)
    # Distinct runs, distinct answers (the digest reads them).
    assert len({r["answers_digest"] for r in rows}) > 1


def test_a_second_sweep_resumes(tmp_path, client):
    out = tmp_path / "rows.jsonl"
    first = RUNS[:5]
    sweep.sweep(first, str(out), client=client, progress=False)
    before = out.read_text()
    # A line cut short (a writer stopped mid-row) is not a row: that run is run again.
    with open(out, "a", encoding="utf-8") as f:
        f.write('{"key": "cut')
    ran = []
    rows = sweep.sweep(RUNS, str(out), client=client, progress=False, on_row=ran.append)
    assert len(ran) == len(RUNS) - len(first)
    assert out.read_text().startswith(before)
    written = lines(out)
    assert len(written) == len(RUNS)
    assert [r["key"] for r in rows] == [sweep.key_of(r) for r in RUNS]
    # Nothing left to run: the file stays as it is.
    ran.clear()
    sweep.sweep(RUNS, str(out), client=client, progress=False, on_row=ran.append)
    assert ran == []
    assert len(lines(out)) == len(RUNS)


def test_a_failing_run_is_a_row(tmp_path, client):
    out = tmp_path / "rows.jsonl"
    runs = [
        dict(dataset="random-linear", n=30, seed=1, structure="sort"),
        dict(scenario=str(tmp_path / "missing.json"), structure="sort"),
        dict(dataset="no-such-dataset", n=30, structure="sort"),
        dict(dataset="random-linear", n=30, seed=1, structure="no-such-structure"),
        dict(dataset="random-linear", n=30, seed=2, structure="sort"),
        # Past its time limit (a run of seconds, stopped after 0.05 s).
        dict(dataset="random-linear", n=400000, seed=3, structure="sort", time_limit=0.05),
        dict(dataset="random-linear", n=30, seed=2, structure="sort", time_limit=60,
             measure_delays=True),
    ]
    rows = sweep.sweep(runs, str(out), client=client, progress=False)
    assert [r["status"] for r in rows] == ["ok", "error", "error", "error", "ok", "error", "ok"]
    assert "missing.json" in rows[1]["error"]
    assert "no-such-dataset" in rows[2]["error"]
    assert "no-such-structure" in rows[3]["error"]
    assert "time limit of 0.05" in rows[5]["error"]
    assert rows[6]["stats"]["events"]["processed"] > 0
    assert len(lines(out)) == len(runs)


def test_a_killed_worker_loses_nothing_and_writes_nothing_twice(tmp_path, client):
    out = tmp_path / "rows.jsonl"
    # Runs long enough (a quarter of a second each) that the workers are busy when one is
    # killed: the worker killed holds a run in flight, lost with it and run again elsewhere.
    runs = sweep.grid(dataset="random-linear", n=40000, seed=[1, 2, 3, 4, 5, 6, 7, 8],
                      structure="sort", scheduler="robust")
    killed = []

    def kill_a_worker(row):
        if killed:
            return
        pids = client.run(os.getpid)
        busy = {w: keys for w, keys in client.processing().items() if keys}
        victim = sorted(busy)[0]
        os.kill(pids[victim], signal.SIGKILL)
        killed.append(busy[victim])

    rows = sweep.sweep(runs, str(out), client=client, progress=False, on_row=kill_a_worker)
    assert killed and killed[0], "no worker was killed with a run in flight"
    written = lines(out)
    assert sorted(r["key"] for r in written) == sorted(sweep.key_of(r) for r in runs)
    assert all(r["status"] == "ok" for r in rows)
    sequential = [sweep.execute(run) for run in runs]
    assert [without_time(r) for r in rows] == [without_time(r) for r in sequential]
    client.wait_for_workers(2, timeout=60)


def test_specifications_and_the_command(tmp_path):
    assert len(sweep.runs_from_spec({"grid": {"dataset": "grids", "n": [4, 9], "structure": "sort"}})) == 2
    with pytest.raises(ValueError, match="run 0: unknown field"):
        sweep.runs_from_spec({"runs": [{"dataset": "grids", "n": 4, "structure": "sort", "nn": 1}]})
    with pytest.raises(ValueError, match='no "structure"'):
        sweep.runs_from_spec({"runs": [{"dataset": "grids", "n": 4}]})
    with pytest.raises(ValueError, match="not both or neither"):
        sweep.runs_from_spec({"runs": [{"structure": "sort"}]})
    assert sweep.key_of({"a": 1, "b": 2}) == sweep.key_of({"b": 2, "a": 1})
    spec = tmp_path / "spec.json"
    spec.write_text(json.dumps({"grid": {"dataset": "random-linear", "n": 20, "seed": [1, 2],
                                          "structure": "sort"}}))
    out = tmp_path / "rows.jsonl"
    done = subprocess.run([sys.executable, "-m", "kinetic", "sweep", str(spec), "--out", str(out),
                           "--workers", "1", "--quiet"], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert len(lines(out)) == 2
    bad = subprocess.run([sys.executable, "-m", "kinetic", "sweep", str(tmp_path / "none.json"),
                          "--out", str(out)], capture_output=True, text=True, timeout=60)
    assert bad.returncode == 2 and "none.json" in bad.stderr


def test_the_experiments_on_workers_are_the_sequential_runs():
    import kinetic

    def runs(e):  # every figure but the wall time, arrays as lists
        return [{k: (v.tolist() if hasattr(v, "tolist") else v) for k, v in r.items()
                 if k != "seconds"} for r in e["runs"]]

    one = kinetic.experiment_sorting(n=40, bins=10, workers=1)
    two = kinetic.experiment_sorting(n=40, bins=10, workers=2)
    assert one["report"] == two["report"]
    assert runs(one) == runs(two)
    one = kinetic.experiment_tournament(n=500, bins=10, workers=1)
    two = kinetic.experiment_tournament(n=500, bins=10, workers=2)
    assert one["report"] == two["report"]
    assert runs(one) == runs(two)


def test_short_runs_go_several_to_a_task(tmp_path, client):
    runs = sweep.grid(dataset="random-linear", n=[2, 3], seed=list(range(40)), structure="sort")
    sequential = [without_time(sweep.execute(run)) for run in runs]
    for chunk in (None, 7):  # automatic (2 runs a task here), and 7
        out = tmp_path / ("rows-%s.jsonl" % chunk)
        rows = sweep.sweep(runs[:50], str(out), client=client, progress=False, chunk=chunk)
        rows = sweep.sweep(runs, str(out), client=client, progress=False, chunk=chunk)  # resumed
        assert [without_time(r) for r in rows] == sequential
        assert sorted(r["key"] for r in lines(out)) == sorted(sweep.key_of(r) for r in runs)
